//! Mitsuba's `.serialized` meshes, versions 3 and 4 (what Mitsuba 0.6 and the released Mitsuba 3
//! write and read), as a pure function of the file's bytes.
//!
//! The layout, all little-endian: a `u16` magic `0x041C` and a `u16` version, then a zlib
//! stream holding a `u32` flag word (0x1 normals, 0x2 uvs, 0x8 vertex colours, 0x10 face
//! normals, 0x1000 single, 0x2000 double precision), in version 4 the shape's NUL-terminated
//! name, `u64` vertex and triangle counts, the positions, normals, uvs and colours (one array
//! each, f32 or f64) and `3 F` `u32` indices. Several shapes are concatenated, each with its own
//! header and stream, and the file ends with a dictionary: each shape's file offset (`u64` in
//! version 4, `u32` in version 3) and a `u32` shape count. As Mitsuba does, shape 0 is read
//! from the start of the file and the dictionary only for the others.
//!
//! The file is hostile until proven otherwise: every count is checked against the limits and
//! against what the compressed bytes present could possibly inflate to before anything is
//! allocated, arrays grow only as their data actually arrives, inflation stops at the size
//! the header claims, and every value is checked (finite numbers, indices in range).
//!
//! Mitsuba's newer version 5 (packed vertex records, written by its development branch) is
//! refused with an error that says so.

use std::io::{ErrorKind, Read};

use flate2::read::ZlibDecoder;
use glint_render::{Color, Vec3};

use super::shapes::{ShapeError, ShapeMesh};
use crate::limits::{format_bytes, Limits};

/// The first two bytes of every shape in a `.serialized` file (little-endian `0x041C`).
pub const SERIALIZED_MAGIC: u16 = 0x041C;

const FLAG_NORMALS: u32 = 0x0001;
const FLAG_UVS: u32 = 0x0002;
const FLAG_COLORS: u32 = 0x0008;
const FLAG_FACE_NORMALS: u32 = 0x0010;
const FLAG_DOUBLE: u32 = 0x2000;

/// zlib's DEFLATE cannot inflate by more than 1032 to 1, so a claim beyond that many times the
/// compressed bytes present is a lie, refused before anything is allocated.
const MAX_INFLATE_RATIO: u64 = 1032;

/// A version 4 name longer than this is taken for a missing terminator.
const MAX_NAME_BYTES: usize = 64 << 10;

/// Values decoded per read while an array is filled, so that an array only grows as fast as
/// its data really inflates.
const CHUNK_VALUES: usize = 1 << 14;

/// One shape of a `.serialized` file.
#[derive(Clone, Debug, PartialEq)]
pub struct SerializedShape {
    /// The shape's name (version 4; empty in version 3).
    pub name: String,
    /// The mesh, its normals normalised. Colours are kept although Mitsuba 3 drops them.
    pub mesh: ShapeMesh,
    /// The file's face-normals flag (0x10). Mitsuba 3 ignores it in version 3 and 4 files and
    /// follows the scene's `face_normals` property alone; it is reported for the reader to
    /// decide.
    pub face_normals: bool,
}

/// The number of shapes in a `.serialized` file, from its end-of-file dictionary.
pub fn serialized_shape_count(bytes: &[u8]) -> Result<u32, ShapeError> {
    let version = read_file_header(bytes, 0)?;
    let (count, _) = dictionary(bytes, version)?;
    Ok(count)
}

/// Reads shape `shape_index` of a `.serialized` file (Mitsuba's `shape_index`, 0 by default)
/// under `limits` (`max_file_bytes` for the file, `max_triangles` for the shape; at most three
/// vertices per allowed triangle).
pub fn read_serialized(
    bytes: &[u8],
    shape_index: u32,
    limits: &Limits,
) -> Result<SerializedShape, ShapeError> {
    if bytes.len() as u64 > limits.max_file_bytes {
        return Err(ShapeError::new(format!(
            "the file is {}, over the limit of {}",
            format_bytes(bytes.len() as u64),
            format_bytes(limits.max_file_bytes)
        )));
    }
    let version = read_file_header(bytes, 0)?;
    let start = if shape_index == 0 {
        0
    } else {
        shape_offset(bytes, version, shape_index)?
    };
    let shape_version = read_file_header(bytes, start)?;
    if shape_version != version {
        return Err(ShapeError::at(
            start,
            format!(
                "shape {shape_index} is version {shape_version} but the file is version {version}"
            ),
        ));
    }
    let stream_start = start + 4;
    let compressed = &bytes[stream_start as usize..];
    let mut stream = Inflate {
        decoder: ZlibDecoder::new(compressed),
        file_offset: stream_start,
        position: 0,
        shape_index,
    };
    read_shape(&mut stream, version, compressed.len() as u64, limits)
}

/// Checks the magic and the version at `offset` and returns the version.
fn read_file_header(bytes: &[u8], offset: u64) -> Result<u16, ShapeError> {
    let at = offset as usize;
    let Some(header) = bytes.get(at..at.saturating_add(4)) else {
        return Err(ShapeError::at(
            offset,
            "the file ends inside a .serialized header (4 bytes: magic and version)",
        ));
    };
    let magic = u16::from_le_bytes([header[0], header[1]]);
    let version = u16::from_le_bytes([header[2], header[3]]);
    if magic != SERIALIZED_MAGIC {
        return Err(ShapeError::at(
            offset,
            format!(
                "not a Mitsuba .serialized shape: its magic number is {magic:#06x}, not {SERIALIZED_MAGIC:#06x}"
            ),
        ));
    }
    match version {
        3 | 4 => Ok(version),
        5 => Err(ShapeError::at(
            offset + 2,
            "version 5 .serialized files (Mitsuba's packed records) are not supported; \
             versions 3 and 4 are",
        )),
        _ => Err(ShapeError::at(
            offset + 2,
            format!("unknown .serialized version {version} (versions 3 and 4 are read)"),
        )),
    }
}

/// The shape count at the end of the file and the file offset of the dictionary's first entry.
fn dictionary(bytes: &[u8], version: u16) -> Result<(u32, u64), ShapeError> {
    let len = bytes.len() as u64;
    if len < 8 {
        return Err(ShapeError::at(
            len,
            "the file is too short to end with a dictionary of shape offsets",
        ));
    }
    let count_at = len - 4;
    let count = u32::from_le_bytes(bytes[count_at as usize..].try_into().expect("4 bytes"));
    let entry = if version >= 4 { 8 } else { 4 };
    // No overflow in u64: count < 2^32, entry ≤ 8.
    let table = u64::from(count) * entry;
    if table > count_at {
        return Err(ShapeError::at(
            count_at,
            format!(
                "the dictionary claims {count} shapes, whose offsets would take {table} bytes, \
                 more than the file holds"
            ),
        ));
    }
    Ok((count, count_at - table))
}

/// The file offset of shape `shape_index`, from the dictionary, checked to lie in the file.
fn shape_offset(bytes: &[u8], version: u16, shape_index: u32) -> Result<u64, ShapeError> {
    let (count, table) = dictionary(bytes, version)?;
    if shape_index >= count {
        return Err(ShapeError::at(
            bytes.len() as u64 - 4,
            format!(
                "shape_index {shape_index} is out of range: the file holds {count} shape{}",
                if count == 1 { "" } else { "s" }
            ),
        ));
    }
    let at = if version >= 4 {
        let at = table + 8 * u64::from(shape_index);
        let raw = &bytes[at as usize..at as usize + 8];
        (at, u64::from_le_bytes(raw.try_into().expect("8 bytes")))
    } else {
        let at = table + 4 * u64::from(shape_index);
        let raw = &bytes[at as usize..at as usize + 4];
        (
            at,
            u64::from(u32::from_le_bytes(raw.try_into().expect("4 bytes"))),
        )
    };
    let (entry_at, offset) = at;
    // A shape starts before the dictionary and leaves room for its header.
    if offset.checked_add(4).is_none_or(|end| end > table) {
        return Err(ShapeError::at(
            entry_at,
            format!("shape {shape_index}'s offset {offset} lies outside the file's shapes"),
        ));
    }
    Ok(offset)
}

/// The decompressed stream of one shape, counting its position for messages. Its reads never
/// ask for more than the caller's claim, so inflation stops at the size the header promises.
struct Inflate<'a> {
    decoder: ZlibDecoder<&'a [u8]>,
    /// File offset where the compressed stream starts.
    file_offset: u64,
    /// Bytes decompressed so far.
    position: u64,
    shape_index: u32,
}

impl Inflate<'_> {
    fn read_exact(&mut self, buffer: &mut [u8], what: &str) -> Result<(), ShapeError> {
        match self.decoder.read_exact(buffer) {
            Ok(()) => {
                self.position += buffer.len() as u64;
                Ok(())
            }
            Err(error) if error.kind() == ErrorKind::UnexpectedEof => Err(ShapeError::at(
                self.file_offset + self.decoder.total_in(),
                format!(
                    "shape {}'s compressed data ends after {} bytes of content, inside {what}: \
                     the file is truncated or its counts are wrong",
                    self.shape_index, self.position
                ),
            )),
            Err(error) => Err(ShapeError::at(
                self.file_offset + self.decoder.total_in(),
                format!(
                    "shape {}'s zlib data is corrupt ({error}) at byte {} of its content, in {what}",
                    self.shape_index, self.position
                ),
            )),
        }
    }

    /// Reads on to the stream's end marker, at most one byte, so that a corrupted stream is
    /// caught by zlib's checksum even when its content parsed; content beyond the counts is
    /// ignored, as Mitsuba does.
    fn finish(&mut self) -> Result<(), ShapeError> {
        let mut byte = [0u8];
        match self.decoder.read(&mut byte) {
            // Zero bytes is the end; one is content past the counts, which Mitsuba ignores.
            Ok(0 | 1) => Ok(()),
            Ok(_) => Ok(()),
            Err(error) => Err(ShapeError::at(
                self.file_offset + self.decoder.total_in(),
                format!(
                    "shape {}'s zlib data is corrupt ({error}) after its {} bytes of content",
                    self.shape_index, self.position
                ),
            )),
        }
    }

    fn u32(&mut self, what: &str) -> Result<u32, ShapeError> {
        let mut raw = [0; 4];
        self.read_exact(&mut raw, what)?;
        Ok(u32::from_le_bytes(raw))
    }

    fn u64(&mut self, what: &str) -> Result<u64, ShapeError> {
        let mut raw = [0; 8];
        self.read_exact(&mut raw, what)?;
        Ok(u64::from_le_bytes(raw))
    }

    /// An error about the content at decompressed byte `position`.
    fn error_at(&self, position: u64, message: String) -> ShapeError {
        ShapeError::at(
            self.file_offset,
            format!(
                "in shape {} (zlib stream at this byte), at byte {position} of its content: {message}",
                self.shape_index
            ),
        )
    }

    /// Reads `count` floats of `width` bytes each (4 or 8), every one finite, into f32s.
    fn floats(&mut self, count: u64, width: usize, what: &str) -> Result<Vec<f32>, ShapeError> {
        let mut values = Vec::with_capacity(count.min(CHUNK_VALUES as u64) as usize);
        let mut raw = vec![0u8; CHUNK_VALUES * width];
        let mut left = count;
        while left > 0 {
            let n = left.min(CHUNK_VALUES as u64) as usize;
            let start = self.position;
            self.read_exact(&mut raw[..n * width], what)?;
            for (i, bytes) in raw[..n * width].chunks_exact(width).enumerate() {
                let value = if width == 8 {
                    f64::from_le_bytes(bytes.try_into().expect("8 bytes")) as f32
                } else {
                    f32::from_le_bytes(bytes.try_into().expect("4 bytes"))
                };
                if !value.is_finite() {
                    let position = start + (i * width) as u64;
                    return Err(self.error_at(position, format!("{what} holds {value}")));
                }
                values.push(value);
            }
            left -= n as u64;
        }
        Ok(values)
    }

    /// Reads `count` triangles, every index below `vertex_count`.
    fn triangles(&mut self, count: u64, vertex_count: u64) -> Result<Vec<[u32; 3]>, ShapeError> {
        let mut triangles = Vec::with_capacity(count.min(CHUNK_VALUES as u64) as usize);
        let mut raw = vec![0u8; CHUNK_VALUES * 12];
        let mut left = count;
        while left > 0 {
            let n = left.min(CHUNK_VALUES as u64) as usize;
            let start = self.position;
            self.read_exact(&mut raw[..n * 12], "the triangle indices")?;
            for (i, bytes) in raw[..n * 12].chunks_exact(12).enumerate() {
                let index = |k: usize| {
                    u32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().expect("4 bytes"))
                };
                let triangle = [index(0), index(1), index(2)];
                if let Some(&bad) = triangle.iter().find(|&&v| u64::from(v) >= vertex_count) {
                    let number = count - left + i as u64;
                    return Err(self.error_at(
                        start + 12 * i as u64,
                        format!(
                            "triangle {number} names vertex {bad}, but there are {vertex_count} vertices"
                        ),
                    ));
                }
                triangles.push(triangle);
            }
            left -= n as u64;
        }
        Ok(triangles)
    }
}

fn read_shape(
    stream: &mut Inflate,
    version: u16,
    compressed_len: u64,
    limits: &Limits,
) -> Result<SerializedShape, ShapeError> {
    let flags = stream.u32("the flag word")?;
    let name = if version >= 4 {
        read_name(stream)?
    } else {
        String::new()
    };
    let counts_at = stream.position;
    let vertex_count = stream.u64("the vertex count")?;
    let triangle_count = stream.u64("the triangle count")?;

    if triangle_count > limits.max_triangles {
        return Err(stream.error_at(
            counts_at + 8,
            format!(
                "the shape claims {triangle_count} triangles, over the limit of {}",
                limits.max_triangles
            ),
        ));
    }
    // More vertices than three per allowed triangle is unreferenced data or a lie; indices are
    // u32 besides.
    let max_vertices = limits
        .max_triangles
        .saturating_mul(3)
        .min(u64::from(u32::MAX));
    if vertex_count > max_vertices {
        return Err(stream.error_at(
            counts_at,
            format!("the shape claims {vertex_count} vertices, over the limit of {max_vertices}"),
        ));
    }
    let width: u64 = if flags & FLAG_DOUBLE != 0 { 8 } else { 4 };
    let has = |flag: u32| flags & flag != 0;
    let per_vertex = 3
        + if has(FLAG_NORMALS) { 3 } else { 0 }
        + if has(FLAG_UVS) { 2 } else { 0 }
        + if has(FLAG_COLORS) { 3 } else { 0 };
    // Both counts are bounded above, so this cannot overflow; checked all the same.
    let claimed = vertex_count.checked_mul(per_vertex * width).and_then(|v| {
        triangle_count
            .checked_mul(12)
            .and_then(|t| v.checked_add(t))
    });
    let possible = compressed_len.saturating_mul(MAX_INFLATE_RATIO);
    match claimed {
        Some(claimed) if claimed <= possible => {}
        _ => {
            return Err(stream.error_at(
                counts_at,
                format!(
                    "the shape claims {vertex_count} vertices and {triangle_count} triangles, \
                     more data than the file's {compressed_len} compressed bytes can hold"
                ),
            ))
        }
    }

    let width = width as usize;
    let positions = stream.floats(vertex_count * 3, width, "the positions")?;
    let normals = if has(FLAG_NORMALS) {
        let values = stream.floats(vertex_count * 3, width, "the normals")?;
        let start = stream.position - vertex_count * 3 * width as u64;
        let mut normals = Vec::with_capacity(vertex_count as usize);
        for (i, n) in values.chunks_exact(3).enumerate() {
            let n = Vec3::new(n[0], n[1], n[2]);
            let length = n.length();
            if !(length > 0.0 && length.is_finite()) {
                return Err(stream.error_at(
                    start + (i * 3 * width) as u64,
                    format!("vertex {i}'s normal has length {length}"),
                ));
            }
            normals.push(n / length);
        }
        Some(normals)
    } else {
        None
    };
    let uvs = if has(FLAG_UVS) {
        let values = stream.floats(vertex_count * 2, width, "the uvs")?;
        Some(values.chunks_exact(2).map(|uv| (uv[0], uv[1])).collect())
    } else {
        None
    };
    let colors = if has(FLAG_COLORS) {
        let values = stream.floats(vertex_count * 3, width, "the vertex colours")?;
        Some(to_vec3s(&values))
    } else {
        None
    };
    let triangles = stream.triangles(triangle_count, vertex_count)?;
    stream.finish()?;
    Ok(SerializedShape {
        name,
        mesh: ShapeMesh {
            positions: to_vec3s(&positions),
            triangles,
            normals,
            uvs,
            colors,
        },
        face_normals: has(FLAG_FACE_NORMALS),
    })
}

fn to_vec3s(values: &[f32]) -> Vec<Color> {
    values
        .chunks_exact(3)
        .map(|v| Vec3::new(v[0], v[1], v[2]))
        .collect()
}

/// Version 4's NUL-terminated name, bounded, as UTF-8 (invalid bytes replaced: a name is only
/// shown).
fn read_name(stream: &mut Inflate) -> Result<String, ShapeError> {
    let start = stream.position;
    let mut name = Vec::new();
    loop {
        let mut byte = [0u8];
        stream.read_exact(&mut byte, "the shape's name")?;
        if byte[0] == 0 {
            return Ok(String::from_utf8_lossy(&name).into_owned());
        }
        if name.len() == MAX_NAME_BYTES {
            return Err(stream.error_at(
                start,
                format!("the shape's name runs past {MAX_NAME_BYTES} bytes without ending"),
            ));
        }
        name.push(byte[0]);
    }
}
