//! OBJ meshes. The course meshes hold only `v` and `f` records (FORMAT.md 4.6): those are read
//! in parallel by `obj_fast`, which gives tobj's triangles bit for bit or leaves the file to
//! tobj; normals and texture coordinates are not used, and materials (`mtllib`, `usemtl`) are
//! ignored because the course gives one shader per mesh.

use std::io::BufRead;
use std::path::Path;

use rayon::prelude::*;

use glint_render::Vec3;

use crate::assets::{AssetError, Assets, TooLarge};
use crate::limits::Limits;
use crate::mesh::Mesh;

/// The triangles of an OBJ file, polygons fan-triangulated (`al.obj` has faces of 3 to 23
/// vertices). Errors are messages for a warning.
/// The file is refused (not only skipped) when it is over the limits: more than
/// `limits.max_file_bytes`, or faces that would make more than `limits.max_triangles`.
pub(crate) fn load_triangles(
    path: &Path,
    assets: &dyn Assets,
    limits: &Limits,
) -> Result<Vec<[Vec3; 3]>, AssetError> {
    let bytes =
        assets
            .read_at_most(path, limits.max_file_bytes)
            .map_err(|error| match TooLarge::of(&error) {
                Some(too_large) => {
                    AssetError::Refused(format!("{too_large} (--max-file-size raises it)"))
                }
                None => AssetError::Failed(crate::assets::reason(&error)),
            })?;
    // Counted first, so that a face of millions of corners is refused before any of it is
    // parsed (the parser's corner list alone takes up to four times the file's size).
    let triangles = count_triangles(&bytes);
    if triangles > limits.max_triangles {
        return Err(AssetError::Refused(format!(
            "its faces make {triangles} triangles, more than the limit of {} \
             (--max-triangles raises it)",
            limits.max_triangles
        )));
    }
    // What the parse and the scene's copy of the triangles hold, against the memory budget,
    // before any of it is taken.
    let mut memory = crate::limits::MemoryBudget::new(limits);
    if !memory.charge(
        (bytes.len() as u64)
            .saturating_add(triangles.saturating_mul(crate::limits::MESH_BYTES_PER_TRIANGLE)),
    ) {
        return Err(AssetError::Refused(
            memory.refusal(&format!("its {triangles} triangles")),
        ));
    }
    if let Some(triangles) = crate::obj_fast::parse(&bytes).and_then(|parsed| parsed.triangles()) {
        return Ok(triangles);
    }
    let mesh = read_with_tobj(&mut &bytes[..]).map_err(AssetError::Failed)?;
    // In parallel like the parse.
    Ok((0..mesh.triangles.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|index| mesh.triangle(index))
        .collect())
}

/// How many triangles the `f` records of an OBJ file make when fan-triangulated, counted
/// before parsing so that a face of millions of corners is refused before it is expanded.
pub(crate) fn count_triangles(bytes: &[u8]) -> u64 {
    crate::obj_fast::sum_over_lines(bytes, count_triangles_of_lines)
}

fn count_triangles_of_lines(bytes: &[u8]) -> u64 {
    let mut triangles = 0u64;
    // Only `f` lines are walked, a byte at a time, counting the starts of their words
    // (`u8::is_ascii_whitespace` separates them).
    for range in crate::obj_fast::line_ranges(bytes) {
        let line = &bytes[range];
        let Some(rest) = line.strip_prefix(b"f") else {
            continue;
        };
        if !rest.first().is_some_and(u8::is_ascii_whitespace) {
            continue;
        }
        let mut corners = 0u64;
        let mut in_word = false;
        for byte in rest {
            let word = !byte.is_ascii_whitespace();
            corners += u64::from(word && !in_word);
            in_word = word;
        }
        triangles += corners.saturating_sub(2);
    }
    triangles
}

/// The one OBJ reader: scene meshes (`load_triangles`) and stand-alone meshes
/// (`crate::load_mesh`) both read through it. A face that names a vertex that does not exist
/// or is not finite is an error.
pub(crate) fn read_obj(bytes: &[u8]) -> Result<Mesh, String> {
    match crate::obj_fast::read(bytes) {
        Some(mesh) => Ok(mesh),
        None => read_with_tobj(&mut &bytes[..]),
    }
}

/// `read_obj` by tobj, for every file: what `obj_fast` declines, and its tests' reference.
pub(crate) fn read_with_tobj(reader: &mut impl BufRead) -> Result<Mesh, String> {
    // `..Default::default()` is needless today, but tobj's optional features (merging,
    // reordering) add fields, and feature unification could turn them on.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        // tobj triangulates a polygon as the fan (v0, vi, vi+1).
        triangulate: true,
        // Only positions are used, so whether indices are unified does not matter.
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // Never open the material library: the course ignores OBJ materials.
    let (models, _materials) = tobj::load_obj_buf(reader, &options, |_| Ok(Default::default()))
        .map_err(|error| format!("not a readable OBJ file ({error})"))?;
    let mut mesh = Mesh::default();
    for model in &models {
        let base = mesh.positions.len() as u32;
        let positions: Vec<Vec3> = model
            .mesh
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        for face in model.mesh.indices.chunks_exact(3) {
            let usable = |index: u32| positions.get(index as usize).is_some_and(|v| v.is_finite());
            if !face.iter().all(|&index| usable(index)) {
                return Err(format!(
                    "a face in `{}` uses a vertex that does not exist or is not finite",
                    model.name
                ));
            }
            mesh.triangles
                .push([base + face[0], base + face[1], base + face[2]]);
        }
        mesh.positions.extend(positions);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The count by line ends and word starts is the count by `split`s it replaced (kept
    /// here as the definition), on random texts of the bytes that matter to it.
    #[test]
    fn triangle_count_follows_its_definition() {
        fn by_splits(bytes: &[u8]) -> u64 {
            bytes
                .split(|&byte| byte == b'\n')
                .filter_map(|line| {
                    let line = line.strip_prefix(b"f")?;
                    if !line.first().is_some_and(u8::is_ascii_whitespace) {
                        return None;
                    }
                    let corners = line
                        .split(u8::is_ascii_whitespace)
                        .filter(|token| !token.is_empty())
                        .count() as u64;
                    Some(corners.saturating_sub(2))
                })
                .sum()
        }
        let mut random = crate::testing::xorshift(0xd1b5_4a32_d192_ed03u64);
        for _ in 0..20_000 {
            let length = (random() % 120) as usize;
            let bytes = b"f f1 \n\t\r\x0b\x0cv#/";
            let text: Vec<u8> = (0..length)
                .map(|_| bytes[(random() % bytes.len() as u64) as usize])
                .collect();
            assert_eq!(
                count_triangles_of_lines(&text),
                by_splits(&text),
                "{text:?}"
            );
        }
    }

    #[test]
    fn polygons_become_fans() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("quad.obj");
        std::fs::write(
            &path,
            "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 2 0\nusemtl x\nf 1 2 3 4 5\n",
        )
        .unwrap();
        let triangles = load_triangles(&path, &crate::FileSystem, &Limits::default()).unwrap();
        assert_eq!(triangles.len(), 3);
        assert_eq!(
            triangles[0],
            [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)]
        );
        assert_eq!(triangles[2][0], Vec3::ZERO);
        assert_eq!(triangles[2][2], Vec3::new(0.0, 2.0, 0.0));
    }

    #[test]
    fn missing_file_is_an_error_message() {
        let error = load_triangles(
            Path::new("/nonexistent/file.obj"),
            &crate::FileSystem,
            &Limits::default(),
        )
        .unwrap_err();
        assert!(matches!(&error, AssetError::Failed(m) if m.contains("No such file")));
    }

    #[test]
    fn malformed_obj_files_do_not_panic() {
        let directory = tempfile::tempdir().unwrap();
        let cases = [
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -5 1 2\n",
            "v a b c\nf 1 2 3\n",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3 2/9/9 3//7\n",
            "f\nv\nvt 1\nvn\n",
            "\u{0}\u{1}binary",
            "v 1e40 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        ];
        for (index, contents) in cases.iter().enumerate() {
            let path = directory.path().join(format!("case{index}.obj"));
            std::fs::write(&path, contents).unwrap();
            let _ = load_triangles(&path, &crate::FileSystem, &Limits::default());
        }
        let path = directory.path().join("case7.obj");
        let error = load_triangles(&path, &crate::FileSystem, &Limits::default()).unwrap_err();
        assert!(error.to_string().contains("not finite"), "{error}");
    }

    #[test]
    fn meshes_over_the_limits_are_refused() {
        assert_eq!(
            count_triangles(b"v 0 0 0\nf 1 2 3\nf 1 2 3 4 5\nfoo 1 2 3\n"),
            4
        );
        let mut assets = crate::MemoryAssets::new();
        assets.insert(
            "huge.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 1 2 3 1 2 3\n".to_vec(),
        );
        let limits = Limits {
            max_triangles: 6,
            ..Limits::default()
        };
        let error = load_triangles(Path::new("huge.obj"), &assets, &limits).unwrap_err();
        assert!(
            matches!(&error, AssetError::Refused(m) if m.contains("7 triangles")),
            "{error}"
        );
        // A file the fast path declines (a `vt` record) is counted before tobj reads it.
        assets.insert(
            "textured.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 2 3 1 2 3 1 2 3\n".to_vec(),
        );
        assert!(crate::obj_fast::parse(&assets.read(Path::new("textured.obj")).unwrap()).is_none());
        let error = load_triangles(Path::new("textured.obj"), &assets, &limits).unwrap_err();
        assert!(
            matches!(&error, AssetError::Refused(m) if m.contains("7 triangles")),
            "{error}"
        );
        let limits = Limits {
            max_file_bytes: 10,
            ..Limits::default()
        };
        let error = load_triangles(Path::new("huge.obj"), &assets, &limits).unwrap_err();
        assert!(
            matches!(&error, AssetError::Refused(m) if m.contains("10 bytes")),
            "{error}"
        );
    }
}
