//! PLY meshes (Greg Turk's polygon file format): ASCII and binary of either byte order, the
//! `vertex` element's `x y z` of any scalar type, polygons from the `face` element's index list
//! (fan-triangulated as `(v0, vk, vk+1)`, like the OBJ loader and the bench tools'
//! `meshio_min.py`) and triangle strips from a `tristrips` element (`-1` restarts a strip).
//! Every other element and property is read past and ignored.
//!
//! The shared models (`../shared/models/*.ply`) are binary little-endian with `float x,y,z`
//! and `uchar count + int indices`; the general reader below is only a little slower than a
//! special case for that layout would be, so there is none.

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
    let (encoding, elements, body_start) = parse_header(bytes)?;
    let body = &bytes[body_start..];
    let mut reader: Box<dyn ValueReader + '_> = match encoding {
        Encoding::Ascii => Box::new(AsciiReader::new(body)),
        Encoding::BinaryLittleEndian => Box::new(BinaryReader {
            bytes: body,
            position: 0,
            big_endian: false,
        }),
        Encoding::BinaryBigEndian => Box::new(BinaryReader {
            bytes: body,
            position: 0,
            big_endian: true,
        }),
    };
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
                for index in 0..element.count {
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
                for _ in 0..element.count {
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
        let mut buffer = [0u8; 8];
        buffer[..size].copy_from_slice(raw);
        if self.big_endian {
            buffer[..size].reverse();
        }
        let b = buffer;
        Ok(match kind {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        })
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
            // A header may declare any count: reserving it aborted the process (found in
            // review for issue 9); now the body runs out first.
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
}
