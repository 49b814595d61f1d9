//! Stand-alone triangle meshes (`.obj` through the one OBJ reader of `obj.rs`, `.ply`), outside
//! any scene file: what `glint bench` traces and what the acceleration tests and benches load
//! from `../shared/models`.

use std::path::{Path, PathBuf};

use glint_render::Vec3;

use crate::assets::{Assets, FileSystem};
use crate::mesh::Mesh;
use crate::ply;

/// Why a mesh file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Format { path: PathBuf, message: String },
    #[error("{path}: unknown mesh format (expected .obj or .ply)")]
    UnknownFormat { path: PathBuf },
}

/// Loads an OBJ (by tobj, polygons fan-triangulated) or PLY (`ply.rs`) mesh, told apart by
/// the extension.
pub fn load_mesh(path: &Path) -> Result<Mesh, MeshError> {
    load_mesh_from(path, &FileSystem)
}

/// [`load_mesh`] reading from `assets` (files held in memory, as the fuzz targets do).
pub fn load_mesh_from(path: &Path, assets: &dyn Assets) -> Result<Mesh, MeshError> {
    let extension = path
        .extension()
        .map(|extension| extension.to_string_lossy().to_lowercase());
    let format_error = |message: String| MeshError::Format {
        path: path.to_path_buf(),
        message,
    };
    if !matches!(extension.as_deref(), Some("ply" | "obj")) {
        return Err(MeshError::UnknownFormat {
            path: path.to_path_buf(),
        });
    }
    let bytes = assets.read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if extension.as_deref() == Some("ply") {
        let (positions, triangles) = ply::parse(&bytes).map_err(|e| format_error(e.0))?;
        Ok(Mesh {
            positions: positions.into_iter().map(Vec3::from_array).collect(),
            triangles,
        })
    } else {
        crate::obj::read_obj(&bytes).map_err(format_error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_and_ply_give_the_same_mesh() {
        let directory = tempfile::tempdir().unwrap();
        let obj = directory.path().join("quad.obj");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        let ply = directory.path().join("quad.PLY");
        std::fs::write(
            &ply,
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
        )
        .unwrap();
        let a = load_mesh(&obj).unwrap();
        let b = load_mesh(&ply).unwrap();
        assert_eq!(a.triangles.len(), 2);
        assert_eq!(
            (0..2).map(|i| a.triangle(i)).collect::<Vec<_>>(),
            (0..2).map(|i| b.triangle(i)).collect::<Vec<_>>()
        );
        assert_eq!(a.geometry().shapes.len(), 2);
    }

    #[test]
    fn errors_name_the_file() {
        let missing = load_mesh(Path::new("/nonexistent/x.ply")).unwrap_err();
        assert!(
            missing.to_string().contains("/nonexistent/x.ply"),
            "{missing}"
        );
        assert!(matches!(
            load_mesh(Path::new("x.stl")),
            Err(MeshError::UnknownFormat { .. })
        ));
    }

    #[test]
    fn shared_models_load_when_present() {
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
        for (name, triangles) in [("bunny.ply", 69_451), ("stanford-bunny.obj", 69_451)] {
            let path = models.join(name);
            if !path.exists() {
                assert!(
                    std::env::var_os("CI").is_none(),
                    "{} is missing",
                    path.display()
                );
                eprintln!("SKIPPED: {} is absent", path.display());
                continue;
            }
            let mesh = load_mesh(&path).unwrap();
            assert_eq!(mesh.triangles.len(), triangles, "{name}");
        }
    }
}
