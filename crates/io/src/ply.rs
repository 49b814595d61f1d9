//! PLY meshes (Greg Turk's polygon file format): ASCII and binary of either byte order, the
//! `vertex` element's `x y z` of any scalar type, polygons from the `face` element's index list
//! (fan-triangulated as `(v0, vk, vk+1)`, like the OBJ loader and the bench tools'
//! `meshio_min.py`) and triangle strips from a `tristrips` element (`-1` restarts a strip).
//! Every other element and property is read past and ignored.
//!
//! Binary files take two fast paths where their layout allows (`fast_vertices`,
//! `fast_faces`): vertex records of scalars only, read at fixed offsets, and a face element
//! holding its index list alone, read without a per-value call. The general reader gives the
//! same values and errors (a test compares the two on many layouts, truncations included), and
//! reads whatever the fast paths leave (ASCII, other layouts, a record that does not fit). The
//! shared models (`../shared/models/*.ply`: binary little-endian, `float x,y,z`, `uchar count +
//! int indices`) take both, which is why they exist: igea-sub4 (537K vertices, 1.07M faces)
//! loads in 104M instructions instead of the general reader's 685M, about 160 ms less.

use std::fmt;

/// Scalar property types, with their PLY names (both the old and the sized spellings).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
enum Property {
    Scalar {
        name: String,
        kind: Scalar,
    },
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// Why a PLY file could not be read: a message, with the header line or element it concerns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlyError(pub String);

impl fmt::Display for PlyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

fn error<T>(message: impl Into<String>) -> Result<T, PlyError> {
    Err(PlyError(message.into()))
}

/// Vertex positions and triangle corner indices.
pub type PlyMesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// Positions and triangles of a PLY file. Indices are checked against the vertex count and
/// positions for being finite; polygons with fewer than three corners are skipped.
pub fn parse(bytes: &[u8]) -> Result<PlyMesh, PlyError> {
    parse_with(bytes, true)
}

/// `parse`, with or without the binary fast paths (without: the general reader alone, their
/// tests' reference).
fn parse_with(bytes: &[u8], fast: bool) -> Result<PlyMesh, PlyError> {
    let (elements, body, mut reader) = open(bytes)?;
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut polygon: Vec<i64> = Vec::new();
    for element in &elements {
        match element.name.as_str() {
            "vertex" => {
                let axis = |name: &str| {
                    element
                        .properties
                        .iter()
                        .position(|p| matches!(p, Property::Scalar { name: n, .. } if n == name))
                };
                let (Some(x), Some(y), Some(z)) = (axis("x"), axis("y"), axis("z")) else {
                    return error("the vertex element has no x, y and z properties");
                };
                // A header may declare any count; reserve no more than the body could hold.
                positions.reserve(element.count.min(body.len()));
                let mut values = vec![0.0f64; element.properties.len()];
                let done = match &mut reader {
                    Reader::Binary(binary) if fast => {
                        fast_vertices(binary, element, [x, y, z], &mut positions)?
                    }
                    _ => 0,
                };
                for index in done..element.count {
                    for (slot, property) in values.iter_mut().zip(&element.properties) {
                        *slot = match property {
                            Property::Scalar { kind, .. } => reader.scalar(*kind)?,
                            Property::List { count, item, .. } => {
                                let n = reader.count(*count)?;
                                for _ in 0..n {
                                    reader.scalar(*item)?;
                                }
                                0.0
                            }
                        };
                    }
                    let p = [values[x] as f32, values[y] as f32, values[z] as f32];
                    if !p.iter().all(|c| c.is_finite()) {
                        return error(format!("vertex {index} is not finite"));
                    }
                    positions.push(p);
                }
            }
            "face" | "tristrips" => {
                let strips = element.name == "tristrips";
                let list = element.properties.iter().position(|p| {
                    matches!(p, Property::List { name, .. }
                        if name == "vertex_indices" || name == "vertex_index" || strips)
                });
                let Some(list) = list else {
                    return error(format!("the {} element has no index list", element.name));
                };
                if !strips {
                    triangles.reserve(element.count.min(body.len()));
                }
                let done = match &mut reader {
                    Reader::Binary(binary) if fast && !strips && element.properties.len() == 1 => {
                        fast_faces(binary, element, positions.len(), &mut triangles)?
                    }
                    _ => 0,
                };
                for _ in done..element.count {
                    for (k, property) in element.properties.iter().enumerate() {
                        match property {
                            Property::Scalar { kind, .. } => {
                                reader.scalar(*kind)?;
                            }
                            Property::List { count, item, .. } => {
                                let n = reader.count(*count)?;
                                polygon.clear();
                                for _ in 0..n {
                                    polygon.push(reader.scalar(*item)? as i64);
                                }
                                if k == list {
                                    let vertex_count = positions.len();
                                    if strips {
                                        push_strips(&polygon, vertex_count, &mut triangles)?;
                                    } else {
                                        push_fan(&polygon, vertex_count, &mut triangles)?;
                                    }
                                }
                            }
                        }
                    }
                }
            }
            _ => {
                for _ in 0..element.count {
                    for property in &element.properties {
                        match property {
                            Property::Scalar { kind, .. } => {
                                reader.scalar(*kind)?;
                            }
                            Property::List { count, item, .. } => {
                                let n = reader.count(*count)?;
                                for _ in 0..n {
                                    reader.scalar(*item)?;
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    Ok((positions, triangles))
}

/// A PLY mesh with every scalar property of its vertices and faces, for readers that use
/// more than positions (Mitsuba's `ply` shape: normals, uv, colours and other attributes).
#[derive(Clone, Debug, Default)]
pub(crate) struct PlyAttributes {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the face (record of the `face` element) it was cut from.
    pub triangle_faces: Vec<u32>,
    /// Scalar vertex properties other than x, y, z, by name, one value a vertex.
    pub vertex_columns: Vec<(String, Vec<f32>)>,
    /// Scalar face properties, by name, one value a face.
    pub face_columns: Vec<(String, Vec<f32>)>,
}

/// Reads every scalar property of the `vertex` and `face` elements (the general reader
/// only: these files are small next to the scanned models the fast paths serve).
/// `max_triangles` is checked as faces are cut, so a hostile file stops early.
pub(crate) fn parse_attributes(
    bytes: &[u8],
    max_triangles: u64,
) -> Result<PlyAttributes, PlyError> {
    let (elements, body, mut reader) = open(bytes)?;
    let mut out = PlyAttributes::default();
    let mut polygon: Vec<i64> = Vec::new();
    for element in &elements {
        let is_vertex = element.name == "vertex";
        let is_face = element.name == "face";
        let scalar_names: Vec<Option<String>> = element
            .properties
            .iter()
            .map(|p| match p {
                Property::Scalar { name, .. } => Some(name.clone()),
                Property::List { .. } => None,
            })
            .collect();
        let mut columns: Vec<(String, Vec<f32>)> = scalar_names
            .iter()
            .flatten()
            .filter(|name| !(is_vertex && matches!(name.as_str(), "x" | "y" | "z")))
            .map(|name| (name.clone(), Vec::new()))
            .collect();
        let axis = |name: &str| scalar_names.iter().position(|n| n.as_deref() == Some(name));
        let xyz = (axis("x"), axis("y"), axis("z"));
        if is_vertex && !matches!(xyz, (Some(_), Some(_), Some(_))) {
            return error("the vertex element has no x, y and z properties");
        }
        let list = element.properties.iter().position(|p| {
            matches!(p, Property::List { name, .. } if name == "vertex_indices" || name == "vertex_index")
        });
        if is_face && list.is_none() {
            return error("the face element has no vertex_indices list");
        }
        let capacity = element.count.min(body.len());
        if is_vertex {
            out.positions.reserve(capacity);
        }
        for index in 0..element.count {
            let mut position = [0.0f32; 3];
            let mut column = 0;
            for (k, property) in element.properties.iter().enumerate() {
                match property {
                    Property::Scalar { kind, name } => {
                        let value = reader.scalar(*kind)?;
                        if is_vertex && matches!(name.as_str(), "x" | "y" | "z") {
                            position[usize::from(name.as_bytes()[0] - b'x')] = value as f32;
                        } else if is_vertex || is_face {
                            columns[column].1.push(value as f32);
                            column += 1;
                        }
                    }
                    Property::List { count, item, .. } => {
                        let n = reader.count(*count)?;
                        polygon.clear();
                        for _ in 0..n {
                            polygon.push(reader.scalar(*item)? as i64);
                        }
                        if is_face && Some(k) == list {
                            let before = out.triangles.len();
                            push_fan(&polygon, out.positions.len(), &mut out.triangles)?;
                            if out.triangles.len() as u64 > max_triangles {
                                return error(format!(
                                    "its faces make more than the limit of {max_triangles} \
                                     triangles (--max-triangles raises it)"
                                ));
                            }
                            let cut = out.triangles.len() - before;
                            out.triangle_faces
                                .extend(std::iter::repeat_n(index as u32, cut));
                        }
                    }
                }
            }
            if is_vertex {
                if !position.iter().all(|c| c.is_finite()) {
                    return error(format!("vertex {index} is not finite"));
                }
                out.positions.push(position);
            }
        }
        if is_vertex {
            out.vertex_columns = columns;
        } else if is_face {
            out.face_columns = columns;
        }
    }
    Ok(out)
}

/// The first records of a binary `vertex` element whose properties are all scalars, read at
/// their fixed offsets: as many as the body holds whole (the general reader takes the rest and
/// reports the end of the file). Returns how many were read.
fn fast_vertices(
    reader: &mut BinaryReader,
    element: &Element,
    [x, y, z]: [usize; 3],
    positions: &mut Vec<[f32; 3]>,
) -> Result<usize, PlyError> {
    let mut offsets = Vec::with_capacity(element.properties.len());
    let mut size = 0;
    for property in &element.properties {
        let Property::Scalar { kind, .. } = property else {
            return Ok(0);
        };
        offsets.push((size, *kind));
        size += kind.size();
    }
    let rest = &reader.bytes[reader.position..];
    let count = element.count.min(rest.len() / size);
    let axes = [offsets[x], offsets[y], offsets[z]];
    let big_endian = reader.big_endian;
    // Floats (the common case) as themselves: the general reader's f32 -> f64 -> f32 changes
    // no finite value.
    let floats = axes.iter().all(|&(_, kind)| kind == Scalar::F32);
    for (index, record) in rest.chunks_exact(size).take(count).enumerate() {
        let p = if floats {
            axes.map(|(at, _)| {
                let raw: [u8; 4] = record[at..at + 4].try_into().expect("4 bytes");
                if big_endian {
                    f32::from_be_bytes(raw)
                } else {
                    f32::from_le_bytes(raw)
                }
            })
        } else {
            axes.map(|(at, kind)| decode(kind, &record[at..], big_endian) as f32)
        };
        if !p.iter().all(|c| c.is_finite()) {
            return error(format!("vertex {index} is not finite"));
        }
        positions.push(p);
    }
    reader.position += count * size;
    Ok(count)
}

/// The first records of a binary `face` element that holds its index list alone, each read
/// without a call per value: the faces before the first one that does not fit in the body, has
/// a length the general reader would refuse or more than `MAX_FAST` corners (the general
/// reader takes it and the rest). Returns how many were read.
fn fast_faces(
    reader: &mut BinaryReader,
    element: &Element,
    vertex_count: usize,
    triangles: &mut Vec<[u32; 3]>,
) -> Result<usize, PlyError> {
    const MAX_FAST: usize = 16;
    let Some(Property::List { count, item, .. }) = element.properties.first() else {
        return Ok(0);
    };
    let (count, item) = (*count, *item);
    let big_endian = reader.big_endian;
    // The common layout: a byte count and 4-byte indices, 13 bytes a triangle.
    let common = count == Scalar::U8 && matches!(item, Scalar::I32 | Scalar::U32);
    let mut polygon = [0i64; MAX_FAST];
    for done in 0..element.count {
        let rest = &reader.bytes[reader.position..];
        if common && rest.len() >= 13 && rest[0] == 3 {
            let index = |k: usize| -> i64 {
                let raw: [u8; 4] = rest[1 + 4 * k..5 + 4 * k].try_into().expect("4 bytes");
                let bits = if big_endian {
                    u32::from_be_bytes(raw)
                } else {
                    u32::from_le_bytes(raw)
                };
                if item == Scalar::I32 {
                    i64::from(bits as i32)
                } else {
                    i64::from(bits)
                }
            };
            let corners = [index(0), index(1), index(2)];
            if corners
                .iter()
                .all(|&c| c >= 0 && (c as u64) < vertex_count as u64)
            {
                triangles.push(corners.map(|c| c as u32));
                reader.position += 13;
                continue;
            }
            // An index out of range: the general code below reports it.
        }
        let Some(raw) = rest.get(..count.size()) else {
            return Ok(done);
        };
        let n = decode(count, raw, big_endian);
        // What `ValueReader::count` accepts; anything else is left for it to refuse.
        if !(n >= 0.0 && n <= MAX_FAST as f64 && n.fract() == 0.0) {
            return Ok(done);
        }
        let n = n as usize;
        let Some(items) = rest.get(count.size()..count.size() + n * item.size()) else {
            return Ok(done);
        };
        for (slot, raw) in polygon.iter_mut().zip(items.chunks_exact(item.size())) {
            *slot = decode(item, raw, big_endian) as i64;
        }
        reader.position += count.size() + n * item.size();
        push_fan(&polygon[..n], vertex_count, triangles)?;
    }
    Ok(element.count)
}

/// The value of `kind` at the start of `raw` (which holds at least its size), in the byte order
/// given, as the general reader returns it.
#[inline(always)]
fn decode(kind: Scalar, raw: &[u8], big_endian: bool) -> f64 {
    // Fixed-size reads, one per type: a copy of the type's size chosen at run time would be
    // a call to memcpy per value.
    macro_rules! read {
        ($t:ty) => {{
            let bytes = raw[..std::mem::size_of::<$t>()]
                .try_into()
                .expect("a slice of the type's size");
            if big_endian {
                <$t>::from_be_bytes(bytes) as f64
            } else {
                <$t>::from_le_bytes(bytes) as f64
            }
        }};
    }
    match kind {
        Scalar::I8 => raw[0] as i8 as f64,
        Scalar::U8 => raw[0] as f64,
        Scalar::I16 => read!(i16),
        Scalar::U16 => read!(u16),
        Scalar::I32 => read!(i32),
        Scalar::U32 => read!(u32),
        Scalar::F32 => read!(f32),
        Scalar::F64 => read!(f64),
    }
}

fn vertex_index(index: i64, vertex_count: usize) -> Result<u32, PlyError> {
    if index < 0 || index as u64 >= vertex_count as u64 {
        return error(format!(
            "a face uses vertex {index}, but there are {vertex_count} vertices (the vertex \
             element must come before the faces)"
        ));
    }
    Ok(index as u32)
}

fn push_fan(polygon: &[i64], vertex_count: usize, out: &mut Vec<[u32; 3]>) -> Result<(), PlyError> {
    if polygon.len() < 3 {
        return Ok(());
    }
    let first = vertex_index(polygon[0], vertex_count)?;
    for k in 1..polygon.len() - 1 {
        out.push([
            first,
            vertex_index(polygon[k], vertex_count)?,
            vertex_index(polygon[k + 1], vertex_count)?,
        ]);
    }
    Ok(())
}

/// Triangle strips: every odd triangle of a run is flipped so that all keep the strip's
/// winding; triangles that repeat a vertex (the usual stitching trick) are dropped.
fn push_strips(
    strip: &[i64],
    vertex_count: usize,
    out: &mut Vec<[u32; 3]>,
) -> Result<(), PlyError> {
    for run in strip.split(|&i| i < 0) {
        for k in 0..run.len().saturating_sub(2) {
            let (mut a, mut b) = (run[k], run[k + 1]);
            let c = run[k + 2];
            if k % 2 == 1 {
                std::mem::swap(&mut a, &mut b);
            }
            if a != b && b != c && a != c {
                out.push([
                    vertex_index(a, vertex_count)?,
                    vertex_index(b, vertex_count)?,
                    vertex_index(c, vertex_count)?,
                ]);
            }
        }
    }
    Ok(())
}

/// The header's elements, the body after it, and a reader of the body in its encoding.
fn open(bytes: &[u8]) -> Result<(Vec<Element>, &[u8], Reader<'_>), PlyError> {
    let (encoding, elements, body_start) = parse_header(bytes)?;
    let body = &bytes[body_start..];
    let binary = |big_endian| {
        Reader::Binary(BinaryReader {
            bytes: body,
            position: 0,
            big_endian,
        })
    };
    let reader = match encoding {
        Encoding::Ascii => Reader::Ascii(AsciiReader::new(body)),
        Encoding::BinaryLittleEndian => binary(false),
        Encoding::BinaryBigEndian => binary(true),
    };
    Ok((elements, body, reader))
}

fn parse_header(bytes: &[u8]) -> Result<(Encoding, Vec<Element>, usize), PlyError> {
    let mut position = 0;
    let mut next_line = || -> Option<&[u8]> {
        if position >= bytes.len() {
            return None;
        }
        let rest = &bytes[position..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        position += (end + 1).min(rest.len());
        Some(&rest[..end])
    };
    let text = |line: &[u8]| String::from_utf8_lossy(line).trim().to_string();
    match next_line().map(text) {
        Some(magic) if magic == "ply" => {}
        _ => return error("not a PLY file (it must start with the line `ply`)"),
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(line) = next_line() else {
            return error("the header has no `end_header` line");
        };
        let line = text(line);
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", kind, _version] => {
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittleEndian,
                    "binary_big_endian" => Encoding::BinaryBigEndian,
                    other => return error(format!("unknown PLY format `{other}`")),
                });
            }
            ["element", name, count] => {
                let Ok(count) = count.parse::<usize>() else {
                    return error(format!("element `{name}` has a bad count `{count}`"));
                };
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count, item, name] => {
                let (Some(count), Some(item)) = (Scalar::parse(count), Scalar::parse(item)) else {
                    return error(format!("property `{name}` has an unknown type"));
                };
                let Some(element) = elements.last_mut() else {
                    return error("a property comes before any element");
                };
                element.properties.push(Property::List {
                    name: name.to_string(),
                    count,
                    item,
                });
            }
            ["property", kind, name] => {
                let Some(kind) = Scalar::parse(kind) else {
                    return error(format!("property `{name}` has an unknown type `{kind}`"));
                };
                let Some(element) = elements.last_mut() else {
                    return error("a property comes before any element");
                };
                element.properties.push(Property::Scalar {
                    name: name.to_string(),
                    kind,
                });
            }
            ["end_header"] => break,
            _ => return error(format!("unexpected header line `{line}`")),
        }
    }
    let Some(encoding) = encoding else {
        return error("the header has no `format` line");
    };
    Ok((encoding, elements, position))
}

trait ValueReader {
    fn scalar(&mut self, kind: Scalar) -> Result<f64, PlyError>;

    /// A list length: a non-negative integer.
    fn count(&mut self, kind: Scalar) -> Result<usize, PlyError> {
        let n = self.scalar(kind)?;
        if !(n >= 0.0 && n <= u32::MAX as f64 && n.fract() == 0.0) {
            return error(format!("bad list length {n}"));
        }
        Ok(n as usize)
    }
}

struct BinaryReader<'a> {
    bytes: &'a [u8],
    position: usize,
    big_endian: bool,
}

impl ValueReader for BinaryReader<'_> {
    #[inline]
    fn scalar(&mut self, kind: Scalar) -> Result<f64, PlyError> {
        let size = kind.size();
        let Some(raw) = self.bytes.get(self.position..self.position + size) else {
            return error("the file ends before its last element");
        };
        self.position += size;
        Ok(decode(kind, raw, self.big_endian))
    }
}

/// The body's reader, by the file's encoding.
enum Reader<'a> {
    Ascii(AsciiReader<'a>),
    Binary(BinaryReader<'a>),
}

impl ValueReader for Reader<'_> {
    #[inline]
    fn scalar(&mut self, kind: Scalar) -> Result<f64, PlyError> {
        match self {
            Reader::Ascii(reader) => reader.scalar(kind),
            Reader::Binary(reader) => reader.scalar(kind),
        }
    }
}

struct AsciiReader<'a> {
    words: std::str::SplitAsciiWhitespace<'a>,
    valid: bool,
}

impl<'a> AsciiReader<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        match std::str::from_utf8(bytes) {
            Ok(text) => AsciiReader {
                words: text.split_ascii_whitespace(),
                valid: true,
            },
            Err(_) => AsciiReader {
                words: "".split_ascii_whitespace(),
                valid: false,
            },
        }
    }
}

impl ValueReader for AsciiReader<'_> {
    fn scalar(&mut self, kind: Scalar) -> Result<f64, PlyError> {
        if !self.valid {
            return error("the ASCII body is not text");
        }
        let Some(word) = self.words.next() else {
            return error("the file ends before its last element");
        };
        let value: f64 = match word.parse() {
            Ok(value) => value,
            Err(_) => return error(format!("`{word}` is not a number")),
        };
        if !matches!(kind, Scalar::F32 | Scalar::F64) && value.fract() != 0.0 {
            return error(format!("`{word}` is not an integer"));
        }
        Ok(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\ncomment a unit quad\nelement vertex 4\n\
        property float x\nproperty float y\nproperty float z\nproperty uchar red\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_polygons_become_fans() {
        let (positions, triangles) = parse(ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(positions.len(), 4);
        assert_eq!(positions[2], [1.0, 1.0, 0.0]);
        assert_eq!(triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    fn binary(big_endian: bool) -> Vec<u8> {
        let format = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut bytes = format!(
            "ply\nformat {format} 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
             property double z\nelement face 1\nproperty uchar flags\n\
             property list uchar uint vertex_indices\nelement extra 2\nproperty short s\n\
             end_header\n"
        )
        .into_bytes();
        let f64_bytes = |v: f64| {
            if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let u32_bytes = |v: u32| {
            if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        for v in [0.0, 0.0, 1.0, 2.0, 0.0, 1.0, 0.0, 3.0, 1.0] {
            bytes.extend_from_slice(&f64_bytes(v));
        }
        bytes.push(7);
        bytes.push(3);
        for i in [0, 1, 2] {
            bytes.extend_from_slice(&u32_bytes(i));
        }
        bytes.extend_from_slice(&[0, 1, 0, 2]);
        bytes
    }

    #[test]
    fn binary_of_both_byte_orders() {
        for big_endian in [false, true] {
            let (positions, triangles) = parse(&binary(big_endian)).unwrap();
            assert_eq!(
                positions,
                vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 3.0, 1.0]]
            );
            assert_eq!(triangles, vec![[0, 1, 2]]);
        }
    }

    #[test]
    fn strips_keep_their_winding() {
        let text = "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n\
            property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
            end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 1 0\n6 0 1 2 3 -1 4\n";
        let (_, triangles) = parse(text.as_bytes()).unwrap();
        assert_eq!(triangles, vec![[0, 1, 2], [2, 1, 3]]);
    }

    #[test]
    fn malformed_files_are_errors_not_panics() {
        let mut truncated = binary(false);
        truncated.truncate(truncated.len() - 7);
        let cases: Vec<Vec<u8>> = vec![
            b"".to_vec(),
            b"obj\n".to_vec(),
            b"ply\nformat ascii 1.0\n".to_vec(),
            b"ply\nformat zip 1.0\nend_header\n".to_vec(),
            b"ply\nproperty float x\nend_header\n".to_vec(),
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n".to_vec(),
            ASCII_QUAD.replace("4 0 1 2 3", "4 0 1 2 9").into_bytes(),
            ASCII_QUAD.replace("4 0 1 2 3", "4 0 1 2").into_bytes(),
            ASCII_QUAD.replace("1 1 0 0", "1 nan 0 0").into_bytes(),
            ASCII_QUAD.replace("4 0 1 2 3", "-4 0 1 2 3").into_bytes(),
            truncated,
            vec![0xff; 64],
            // A header may declare any count: reserving room for it up front would abort the
            // process, so the reader lets the body run out first.
            b"ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000000\n\
              property float x\nproperty float y\nproperty float z\nend_header\n"
                .to_vec(),
            b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
              property float z\nelement face 1000000000000000\n\
              property list uchar int vertex_indices\nend_header\n3 0 0 0\n"
                .to_vec(),
        ];
        for (index, bytes) in cases.iter().enumerate() {
            assert!(parse(bytes).is_err(), "case {index} was accepted");
        }
    }

    /// A binary PLY file with the given vertex and face layouts, its values chosen by `seed`.
    fn layout(
        big_endian: bool,
        xyz: Scalar,
        extra: Option<Scalar>,
        count: Scalar,
        item: Scalar,
        faces: &[Vec<i64>],
        seed: u64,
    ) -> Vec<u8> {
        let name = |k: Scalar| match k {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        };
        let format = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let vertices = 6;
        let mut header = format!("ply\nformat {format} 1.0\nelement vertex {vertices}\n");
        if let Some(extra) = extra {
            header += &format!("property {} nx\n", name(extra));
        }
        for axis in ["x", "y", "z"] {
            header += &format!("property {} {axis}\n", name(xyz));
        }
        if let Some(extra) = extra {
            header += &format!("property {} red\n", name(extra));
        }
        header += &format!(
            "element face {}\nproperty list {} {} vertex_indices\nend_header\n",
            faces.len(),
            name(count),
            name(item)
        );
        let mut bytes = header.into_bytes();
        let put = |bytes: &mut Vec<u8>, kind: Scalar, value: f64| {
            let mut raw = match kind {
                Scalar::I8 => (value as i8).to_le_bytes().to_vec(),
                Scalar::U8 => (value as u8).to_le_bytes().to_vec(),
                Scalar::I16 => (value as i16).to_le_bytes().to_vec(),
                Scalar::U16 => (value as u16).to_le_bytes().to_vec(),
                Scalar::I32 => (value as i32).to_le_bytes().to_vec(),
                Scalar::U32 => (value as u32).to_le_bytes().to_vec(),
                Scalar::F32 => (value as f32).to_le_bytes().to_vec(),
                Scalar::F64 => value.to_le_bytes().to_vec(),
            };
            if big_endian {
                raw.reverse();
            }
            bytes.extend_from_slice(&raw);
        };
        let mut random = crate::testing::xorshift(seed | 1);
        let mut next = || (random() >> 40) as f64 / (1u64 << 24) as f64;
        for _ in 0..vertices {
            if let Some(extra) = extra {
                put(&mut bytes, extra, next() * 100.0);
            }
            for _ in 0..3 {
                put(&mut bytes, xyz, next() * 200.0 - 50.0);
            }
            if let Some(extra) = extra {
                put(&mut bytes, extra, 7.0);
            }
        }
        for face in faces {
            put(&mut bytes, count, face.len() as f64);
            for &index in face {
                put(&mut bytes, item, index as f64);
            }
        }
        bytes
    }

    /// The fast paths give what the general reader gives, values and errors alike: on layouts
    /// of every scalar type and both byte orders, with extra properties around x, y, z, faces
    /// of 0 to 17 corners, indices out of range, list lengths the reader refuses, and every
    /// truncation of the body; and on the shared models.
    #[test]
    fn fast_paths_read_what_the_general_reader_reads() {
        let same = |bytes: &[u8], what: &str| {
            let (fast, general) = (parse_with(bytes, true), parse_with(bytes, false));
            match (&fast, &general) {
                (Ok((fp, ft)), Ok((gp, gt))) => {
                    let bits = |p: &[[f32; 3]]| -> Vec<[u32; 3]> {
                        p.iter().map(|v| v.map(f32::to_bits)).collect()
                    };
                    assert!(bits(fp) == bits(gp) && ft == gt, "{what}");
                }
                _ => assert_eq!(fast, general, "{what}"),
            }
            fast.is_ok()
        };
        use Scalar::*;
        let faces: Vec<Vec<i64>> = vec![
            vec![0, 1, 2],
            vec![3, 4, 5, 0],
            vec![1, 2],
            vec![],
            vec![5, 4, 3, 2, 1],
            (0..17).map(|k| k % 6).collect(),
            vec![2, 3, 4],
        ];
        let mut accepted = 0;
        let mut seed = 1;
        for big_endian in [false, true] {
            for xyz in [F32, F64, I16, U8, I32] {
                for extra in [None, Some(U8), Some(F64)] {
                    for (count, item) in [(U8, I32), (U16, U32), (I32, I16), (U8, U16)] {
                        seed += 1;
                        let bytes = layout(big_endian, xyz, extra, count, item, &faces, seed);
                        let what = format!("{big_endian} {xyz:?} {extra:?} {count:?} {item:?}");
                        accepted += same(&bytes, &what) as usize;
                        let body = bytes.len()
                            - bytes
                                .windows(11)
                                .position(|w| w == b"end_header\n")
                                .unwrap()
                            - 11;
                        for cut in 1..=body {
                            same(&bytes[..bytes.len() - cut], &format!("{what} cut {cut}"));
                        }
                    }
                }
            }
        }
        assert!(accepted > 100, "only {accepted} files read whole");
        // Refused by both: an index out of range, a negative length, a NaN vertex.
        let bad = [vec![vec![0, 1, 6]], vec![vec![0, 1, -1]]];
        for faces in bad {
            assert!(!same(
                &layout(false, F32, None, U8, I32, &faces, 3),
                "bad index"
            ));
        }
        let mut negative = layout(false, F32, None, I8, I32, &[vec![0, 1, 2]], 3);
        let at = negative.len() - 13;
        negative[at] = 0xff;
        assert!(!same(&negative, "negative length"));
        let mut nan = layout(false, F32, None, U8, I32, &[vec![0, 1, 2]], 3);
        let at = nan.len() - 13 - 12 * 6;
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(!same(&nan, "NaN vertex"));
        let models =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
        let mut read = 0;
        for entry in std::fs::read_dir(&models).expect("../shared/models") {
            let path = entry.expect("a directory entry").path();
            if path.extension().is_some_and(|e| e == "ply") {
                let bytes = std::fs::read(&path).expect("a model");
                assert!(same(&bytes, &path.display().to_string()));
                read += 1;
            }
        }
        assert!(read >= 2, "{read} PLY models in {}", models.display());
    }
}
