//! The common case of an OBJ file read in parallel: `v` and `f` records only (FORMAT.md 4.6;
//! every course mesh, most of `../shared/models`), cut into chunks at line ends and parsed one
//! chunk per task, then stitched by prefix sums of the chunks' vertex counts.
//!
//! It gives exactly the triangles tobj gives (`obj::read_obj`'s other path), or declines
//! (`None`) and leaves the file to tobj: it accepts only what it can read the way tobj does,
//! with the same tokenising (`str::split_whitespace`'s words, found a byte at a time), the
//! same number parsing (`f32` `FromStr`, and `isize`'s by `parse_index`), the same fan
//! triangulation `(v0, vk, vk+1)` and the same relative indices. Anything else declines: a
//! byte that is not ASCII, `vt`, `vn` and `l` records, a face corner with a `/`, a face of
//! fewer than three corners, a `v` with a fourth value, a malformed number, an index 0 or one
//! naming a vertex not yet defined at its line (tobj accepts forward references within an
//! object; this reader does not try), an `usemtl` without a name, a face on a non-finite
//! vertex. Errors are therefore always tobj's. `tests::agrees_with_tobj` holds it to that on
//! every OBJ file of the course corpus and the shared models and on the malformed cases of
//! `obj.rs`.

use glint_render::Vec3;

use crate::mesh::Mesh;

/// Chunks are at least this long: below it, the work of a task is less than its cost.
const CHUNK_BYTES: usize = 1 << 18;

/// What one chunk of lines holds.
#[derive(Default)]
struct Chunk {
    vertices: Vec<Vec3>,
    /// Per face: its corners' range in `corners` and how many of this chunk's vertices were
    /// defined before its line.
    faces: Vec<Face>,
    /// Corner indices as written: `x >= 1` is vertex `x - 1` of the file, `x < 0` counts back
    /// from the vertices defined before the face's line.
    corners: Vec<isize>,
    /// The triangles its faces make: Σ (corners − 2).
    triangles: usize,
}

struct Face {
    first: u32,
    count: u32,
    defined: u32,
}

/// The mesh of an OBJ file's bytes, or `None` when tobj should read it (module docs).
pub(crate) fn read(bytes: &[u8]) -> Option<Mesh> {
    parse(bytes)?.mesh()
}

/// An OBJ file's chunks, parsed, and its vertices stitched in file order: what `read` and
/// `Parsed::triangles` go on from.
pub(crate) struct Parsed {
    chunks: Vec<Chunk>,
    /// The file's vertex index of each chunk's first vertex.
    bases: Vec<usize>,
    positions: Vec<Vec3>,
}

/// The chunks of an OBJ file's bytes, parsed, or `None` when tobj should read it.
pub(crate) fn parse(bytes: &[u8]) -> Option<Parsed> {
    if bytes.len() >= u32::MAX as usize {
        return None;
    }
    // Each piece checked for ASCII (then every offset in it is a char boundary) in its task.
    let chunks = map(&line_pieces(bytes), |range| {
        let piece = &bytes[range.clone()];
        if !piece.is_ascii() {
            return None;
        }
        parse_chunk(std::str::from_utf8(piece).ok()?)
    })
    .into_iter()
    .collect::<Option<Vec<Chunk>>>()?;
    let mut bases = Vec::with_capacity(chunks.len());
    let mut total = 0usize;
    for chunk in &chunks {
        bases.push(total);
        total += chunk.vertices.len();
    }
    if total > u32::MAX as usize {
        return None;
    }
    let positions = stitch(
        &chunks,
        |chunk| chunk.vertices.len(),
        |chunk, out| {
            out.copy_from_slice(&chunk.vertices);
            Some(())
        },
    )?;
    Some(Parsed {
        chunks,
        bases,
        positions,
    })
}

impl Parsed {
    /// How many triangles the faces make, fan-triangulated: what `obj::count_triangles`
    /// counts (the tests hold the two together).
    #[cfg(test)]
    fn triangle_count(&self) -> u64 {
        self.chunks.iter().map(|chunk| chunk.triangles as u64).sum()
    }

    /// The mesh: positions, and the faces as fans of indices into them.
    pub(crate) fn mesh(self) -> Option<Mesh> {
        let jobs: Vec<(&Chunk, usize)> = self.chunks.iter().zip(self.bases).collect();
        let triangles = map(&jobs, |&(chunk, base)| {
            let mut triangles = Vec::with_capacity(chunk.triangles);
            triangulate(chunk, base, &self.positions, |triangle| {
                triangles.push(triangle);
            })?;
            Some(triangles)
        })
        .into_iter()
        .collect::<Option<Vec<Vec<[u32; 3]>>>>()?
        .concat();
        Some(Mesh {
            positions: self.positions,
            triangles,
        })
    }

    /// The triangles' corners, in file order: `mesh().triangle(i)` for every i, made straight
    /// from the chunks in parallel, each chunk into its own part of the result, without the
    /// mesh's index array (made, then concatenated serially, then read again, that was a
    /// fifth of the instanced dragon's load on 2 threads).
    pub(crate) fn triangles(self) -> Option<Vec<[Vec3; 3]>> {
        let positions = &self.positions;
        let bases: Vec<(&Chunk, usize)> = self.chunks.iter().zip(self.bases).collect();
        stitch(
            &bases,
            |(chunk, _)| chunk.triangles,
            |&(chunk, base), out| {
                // The chunk's part has as many slots as its faces make triangles (`Chunk::triangles`,
                // counted with the faces).
                let mut slots = out.iter_mut();
                triangulate(chunk, base, positions, |corners| {
                    let slot = slots.next();
                    debug_assert!(
                        slot.is_some(),
                        "a chunk made more triangles than it counted"
                    );
                    if let Some(slot) = slot {
                        *slot = corners.map(|corner| positions[corner as usize]);
                    }
                })?;
                debug_assert!(
                    slots.next().is_none(),
                    "a chunk made fewer triangles than it counted"
                );
                Some(())
            },
        )
    }
}

/// One array of the parts' items in order, each part filling its own slice of it, `len(part)`
/// long (`fill`), in parallel: the array first made with `T::default()` in parallel (its pages
/// are first touched, and faulted in, by every thread at once), then filled. `None` when a
/// part's `fill` is.
fn stitch<P: Sync, T: Copy + Default + Send + Sync>(
    parts: &[P],
    len: impl Fn(&P) -> usize,
    fill: impl Fn(&P, &mut [T]) -> Option<()> + Sync + Send,
) -> Option<Vec<T>> {
    let mut out: Vec<T> = filled(parts.iter().map(&len).sum());
    let mut slices = Vec::with_capacity(parts.len());
    let mut rest = out.as_mut_slice();
    for part in parts {
        let (mine, tail) = std::mem::take(&mut rest).split_at_mut(len(part));
        slices.push((part, mine));
        rest = tail;
    }
    for_each_mut(slices, |(part, slice)| fill(part, slice))?;
    Some(out)
}

/// Byte ranges covering `bytes`, each ending after a `\n` but the last, about `CHUNK_BYTES`
/// or more long, at most four per thread.
fn line_pieces(bytes: &[u8]) -> Vec<std::ops::Range<usize>> {
    let pieces = (bytes.len() / CHUNK_BYTES).clamp(1, 4 * threads());
    let target = bytes.len().div_ceil(pieces).max(1);
    let mut out = Vec::with_capacity(pieces);
    let mut start = 0;
    while bytes.len() - start > target {
        match bytes[start + target..]
            .iter()
            .position(|&byte| byte == b'\n')
        {
            Some(offset) => {
                let end = start + target + offset + 1;
                out.push(start..end);
                start = end;
            }
            None => break,
        }
    }
    out.push(start..bytes.len());
    out
}

/// `f(piece)` summed over pieces of `bytes` cut at line ends, in parallel.
pub(crate) fn sum_over_lines(bytes: &[u8], f: impl Fn(&[u8]) -> u64 + Sync + Send) -> u64 {
    map(&line_pieces(bytes), |range| f(&bytes[range.clone()]))
        .into_iter()
        .sum()
}

/// The byte ranges of the lines of `bytes` as `split(|&b| b == b'\n')` gives them (the last
/// one after the last `\n`, empty when `bytes` ends with one), found by `memchr`.
pub(crate) fn line_ranges(bytes: &[u8]) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let mut start = 0;
    memchr::memchr_iter(b'\n', bytes)
        .chain(std::iter::once(bytes.len()))
        .map(move |end| {
            let line = start..end;
            start = end + 1;
            line
        })
}

fn parse_chunk(text: &str) -> Option<Chunk> {
    let mut chunk = Chunk::default();
    for range in line_ranges(text.as_bytes()) {
        // `\n` is ASCII: every line range lies on char boundaries.
        let line = &text[range];
        // tobj reads lines with `BufRead::lines`, which drops a `\r` before the `\n`.
        let line = line.strip_suffix('\r').unwrap_or(line);
        let mut words = Words { line, at: 0 };
        match words.next() {
            None | Some("#") => {}
            Some("v") => {
                let mut xyz = [0.0f32; 3];
                for value in &mut xyz {
                    *value = words.next()?.parse().ok()?;
                }
                if words.next().is_some() {
                    return None;
                }
                chunk.vertices.push(Vec3::from_array(xyz));
            }
            Some("f") => {
                let first = chunk.corners.len();
                for word in words {
                    // A corner with a `/` (`1/2/3`, `3//7`) is no number: declined here too.
                    let index = parse_index(word)?;
                    if index == 0 {
                        return None;
                    }
                    chunk.corners.push(index);
                }
                let count = chunk.corners.len() - first;
                if count < 3 {
                    return None;
                }
                chunk.triangles += count - 2;
                chunk.faces.push(Face {
                    first: first as u32,
                    count: count as u32,
                    defined: chunk.vertices.len() as u32,
                });
            }
            Some("vt" | "vn" | "l") => return None,
            Some("usemtl") => {
                // tobj refuses a nameless `usemtl`, read this way.
                if line.split_once(' ').unwrap_or_default().1.trim().is_empty() {
                    return None;
                }
            }
            // `o`, `g`, `s`, `mtllib` and unknown records change no triangle.
            Some(_) => {}
        }
    }
    Some(chunk)
}

/// `word.parse::<isize>().ok()`: an optional sign, then one or more ASCII digits, `None` on
/// anything else and on overflow; without the generic parser's calls per digit.
fn parse_index(word: &str) -> Option<isize> {
    let bytes = word.as_bytes();
    let (negative, digits) = match bytes.first()? {
        b'-' => (true, &bytes[1..]),
        b'+' => (false, &bytes[1..]),
        _ => (false, bytes),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: isize = 0;
    for &byte in digits {
        let digit = byte.wrapping_sub(b'0');
        if digit > 9 {
            return None;
        }
        value = value.checked_mul(10)?;
        value = if negative {
            value.checked_sub(isize::from(digit))?
        } else {
            value.checked_add(isize::from(digit))?
        };
    }
    Some(value)
}

/// The words of an ASCII line as `str::split_whitespace` gives them, a byte at a time
/// instead of a `char` at a time.
struct Words<'a> {
    line: &'a str,
    at: usize,
}

/// `char::is_whitespace` of an ASCII byte: tab, line feed, vertical tab, form feed, carriage
/// return and space.
fn is_whitespace(byte: u8) -> bool {
    matches!(byte, b'\t' | b'\n' | 0x0b | 0x0c | b'\r' | b' ')
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        let bytes = self.line.as_bytes();
        let mut at = self.at;
        while at < bytes.len() && is_whitespace(bytes[at]) {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && !is_whitespace(bytes[at]) {
            at += 1;
        }
        self.at = at;
        // Every byte is ASCII (checked by `read`), so every offset is a char boundary.
        (start < at).then(|| &self.line[start..at])
    }
}

/// The chunk's faces as fans of vertex indices of the file, handed to `emit` in order; `None`
/// on an index tobj would refuse or a vertex that is not finite.
fn triangulate(
    chunk: &Chunk,
    base: usize,
    positions: &[Vec3],
    mut emit: impl FnMut([u32; 3]),
) -> Option<()> {
    for face in &chunk.faces {
        let defined = base + face.defined as usize;
        let resolve = |index: isize| -> Option<u32> {
            let vertex = if index < 0 {
                defined.checked_sub(index.unsigned_abs())?
            } else {
                index as usize - 1
            };
            (vertex < defined && positions[vertex].is_finite()).then_some(vertex as u32)
        };
        let corners = &chunk.corners[face.first as usize..(face.first + face.count) as usize];
        let apex = resolve(corners[0])?;
        let mut previous = resolve(corners[1])?;
        for &corner in &corners[2..] {
            let next = resolve(corner)?;
            emit([apex, previous, next]);
            previous = next;
        }
    }
    Some(())
}

#[cfg(not(target_arch = "wasm32"))]
fn threads() -> usize {
    rayon::current_num_threads()
}

#[cfg(not(target_arch = "wasm32"))]
fn map<T: Sync, U: Send>(items: &[T], f: impl Fn(&T) -> U + Sync + Send) -> Vec<U> {
    use rayon::prelude::*;
    items.par_iter().map(f).collect()
}

/// `f` on every item, in parallel; `None` when any is.
#[cfg(not(target_arch = "wasm32"))]
fn for_each_mut<T: Send>(items: Vec<T>, f: impl Fn(T) -> Option<()> + Sync + Send) -> Option<()> {
    use rayon::prelude::*;
    items.into_par_iter().try_for_each(f)
}

/// `len` default values, made in parallel.
#[cfg(not(target_arch = "wasm32"))]
fn filled<T: Copy + Default + Send>(len: usize) -> Vec<T> {
    use rayon::prelude::*;
    (0..len)
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|_| T::default())
        .collect()
}

// The browser's module has no threads: the same pieces, one after the other.
#[cfg(target_arch = "wasm32")]
fn threads() -> usize {
    1
}

#[cfg(target_arch = "wasm32")]
fn map<T, U>(items: &[T], f: impl Fn(&T) -> U) -> Vec<U> {
    items.iter().map(f).collect()
}

#[cfg(target_arch = "wasm32")]
fn for_each_mut<T>(items: Vec<T>, f: impl Fn(T) -> Option<()>) -> Option<()> {
    items.into_iter().try_for_each(f)
}

#[cfg(target_arch = "wasm32")]
fn filled<T: Copy + Default>(len: usize) -> Vec<T> {
    vec![T::default(); len]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// tobj's triangles of `bytes` (the other path of `read_obj`), as coordinates.
    fn tobj_triangles(bytes: &[u8]) -> Result<Vec<[Vec3; 3]>, String> {
        let mesh = crate::obj::read_with_tobj(&mut &bytes[..])?;
        Ok((0..mesh.triangles.len())
            .map(|i| mesh.triangle(i))
            .collect())
    }

    fn bits(triangles: &[[Vec3; 3]]) -> Vec<[u32; 9]> {
        triangles
            .iter()
            .map(|t| {
                let f = t.map(|v| v.to_array()).concat();
                std::array::from_fn(|i| f[i].to_bits())
            })
            .collect()
    }

    /// Where the fast path reads a file, its triangles are tobj's bit for bit; where it
    /// declines, tobj's answer stands. Returns whether it read the file.
    fn check(name: &str, bytes: &[u8]) -> bool {
        let expected = tobj_triangles(bytes);
        match read(bytes) {
            Some(mesh) => {
                let ours: Vec<[Vec3; 3]> = (0..mesh.triangles.len())
                    .map(|i| mesh.triangle(i))
                    .collect();
                let expected = expected.unwrap_or_else(|error| {
                    panic!("{name}: read fast, but tobj refuses it: {error}")
                });
                assert_eq!(
                    bits(&ours),
                    bits(&expected),
                    "{name}: triangles differ from tobj's"
                );
                // The scene loader's path: the corners straight from the chunks, counted
                // before they are made as the limit's count counts them.
                let parsed = parse(bytes).unwrap();
                assert_eq!(
                    parsed.triangle_count(),
                    crate::obj::count_triangles(bytes),
                    "{name}: counts differ"
                );
                let direct = parsed.triangles().expect("read, so triangulated");
                assert_eq!(
                    bits(&direct),
                    bits(&expected),
                    "{name}: direct triangles differ from tobj's"
                );
                true
            }
            None => false,
        }
    }

    fn obj_files(directory: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        let Ok(entries) = std::fs::read_dir(directory) else {
            return;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                obj_files(&path, out);
            } else if path
                .extension()
                .is_some_and(|extension| extension.eq_ignore_ascii_case("obj"))
            {
                out.push(path);
            }
        }
    }

    #[test]
    fn agrees_with_tobj_on_the_shared_meshes() {
        let shared = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared");
        let mut files = Vec::new();
        obj_files(&shared.join("scenes/course"), &mut files);
        obj_files(&shared.join("models"), &mut files);
        if files.is_empty() {
            assert!(
                std::env::var_os("CI").is_none(),
                "no OBJ file under {} (CI needs ../shared)",
                shared.display()
            );
            eprintln!("SKIPPED: no ../shared OBJ files");
            return;
        }
        let mut fast = 0;
        for path in &files {
            let bytes = std::fs::read(path).unwrap();
            fast += usize::from(check(&path.display().to_string(), &bytes));
        }
        // The course's meshes (the dragon, the bunny, `al.obj`) are plain `v`/`f` files: the
        // fast path must read them, not decline.
        let course_fast = files
            .iter()
            .filter(|path| path.to_string_lossy().contains("scenes/course"))
            .all(|path| read(&std::fs::read(path).unwrap()).is_some());
        assert!(course_fast, "a course mesh fell back to tobj");
        eprintln!("{fast} of {} OBJ files read by the fast path", files.len());
    }

    #[test]
    fn agrees_with_tobj_on_small_and_odd_files() {
        let cases: &[(&str, bool)] = &[
            (
                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 2 0\nf 1 2 3 4 5\n",
                true,
            ),
            ("v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf -3 -2 -1\r\n", true),
            (
                "# c\n\nv 0 0 0\no a\nv 1 0 0\ng b\ns 1\nv 0 1 0\nusemtl m\nf 1 +2 3\n",
                true,
            ),
            ("v 0 0 0\x0bv 1 0 0\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -5 1 2\n", false),
            ("v a b c\nf 1 2 3\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3 2/9/9 3//7\n", false),
            ("f\nv\nvt 1\nvn\n", false),
            ("v 1e40 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", false),
            ("v 0 0 0 2\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", false),
            ("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\nf 1 2 3\n", false),
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", false),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# caf\u{e9}\n", false),
        ];
        for (index, (text, fast)) in cases.iter().enumerate() {
            let read_fast = check(&format!("case {index}"), text.as_bytes());
            assert_eq!(read_fast, *fast, "case {index}: {text:?}");
        }
    }

    /// Many chunks: faces that name vertices of earlier chunks, relative and absolute.
    #[test]
    fn chunks_stitch_across_their_boundaries() {
        let mut text = String::new();
        let mut vertices = 0usize;
        for row in 0..40_000 {
            text.push_str(&format!("v {row} {}.25 -{}e-3\n", row % 7, row % 13));
            vertices += 1;
            if vertices >= 3 && row % 3 == 0 {
                text.push_str("f -1 -2 -3\n");
                text.push_str(&format!(
                    "f {} 1 {} {}\n",
                    vertices,
                    vertices / 2 + 1,
                    vertices - 1
                ));
            }
        }
        assert!(
            text.len() > 4 * CHUNK_BYTES,
            "the test needs several chunks"
        );
        assert!(line_pieces(text.as_bytes()).len() > 1);
        assert!(check("generated", text.as_bytes()));
        // The limit's count, summed over pieces, is the triangles made.
        let made = read(text.as_bytes()).unwrap().triangles.len() as u64;
        assert_eq!(crate::obj::count_triangles(text.as_bytes()), made);
    }

    /// The byte-at-a-time words are `str::split_whitespace`'s on ASCII lines: every ASCII
    /// byte (the whitespace of `char::is_whitespace` and of `u8::is_ascii_whitespace` differ
    /// in the vertical tab) in random lines of up to 40 bytes.
    #[test]
    fn words_are_split_whitespace_words() {
        let mut random = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15u64);
        for _ in 0..200_000 {
            let length = (random() % 41) as usize;
            // Half the bytes from all of ASCII, half from the whitespace and three others.
            let line: String = (0..length)
                .map(|_| {
                    let r = random();
                    if r & 1 == 0 {
                        ((r >> 8) % 128) as u8 as char
                    } else {
                        let bytes = b"\t\n\x0b\x0c\r v1#";
                        bytes[((r >> 8) % bytes.len() as u64) as usize] as char
                    }
                })
                .collect();
            let ours: Vec<&str> = Words { line: &line, at: 0 }.collect();
            let std: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(ours, std, "{line:?}");
        }
    }

    /// `parse_index` is `isize`'s `FromStr`: on the edges of its range, signs alone and
    /// doubled, corners with slashes, and random words of digits, signs and a few others.
    #[test]
    fn indices_parse_as_isize_parses_them() {
        let max = isize::MAX.to_string();
        let min = isize::MIN.to_string();
        let mut words: Vec<String> = [
            "",
            "+",
            "-",
            "0",
            "-0",
            "+0",
            "7",
            "+7",
            "-7",
            "--1",
            "+-1",
            "-+1",
            "1/2/3",
            "3//7",
            "1.0",
            " 1",
            "1 ",
            "0x1f",
            "٣",
            "00000000000000000000000000012",
        ]
        .iter()
        .map(|word| word.to_string())
        .collect();
        for edge in [&max, &min] {
            words.push(edge.clone());
            // One past the edge: the last digit raised (9223372036854775808, ...809).
            let mut past = edge.clone().into_bytes();
            *past.last_mut().unwrap() += 1;
            words.push(String::from_utf8(past).unwrap());
            words.push(format!("{edge}0"));
        }
        let mut random = crate::testing::xorshift(0x2545_f491_4f6c_dd1du64);
        for _ in 0..100_000 {
            let length = (random() % 22) as usize;
            words.push(
                (0..length)
                    .map(|_| {
                        let bytes = b"0123456789+-/a9";
                        bytes[(random() % bytes.len() as u64) as usize] as char
                    })
                    .collect(),
            );
        }
        for word in &words {
            assert_eq!(parse_index(word), word.parse::<isize>().ok(), "{word:?}");
        }
    }

    #[test]
    fn pieces_cover_the_text_and_end_at_line_ends() {
        let text = "v 1 2 3\n".repeat(200_000);
        let pieces: Vec<&str> = line_pieces(text.as_bytes())
            .into_iter()
            .map(|range| &text[range])
            .collect();
        assert!(pieces.len() > 1);
        assert_eq!(pieces.concat(), text);
        assert!(pieces.iter().all(|piece| piece.ends_with('\n')));
    }
}
