//! Ray files and hit-distance files in the format of `../shared/bench/embree_rays.py`, so that
//! Glint and another engine trace exactly the same rays and can be compared ray by ray.
//!
//! `.rays`: little-endian f32, six values per ray (origin x y z, direction x y z), no header;
//! every ray spans t in [0, ∞). `.t`: little-endian f32, the closest-hit t of each ray, ∞ for a
//! miss.

use std::path::{Path, PathBuf};

use glint_render::{Ray, Vec3};

/// Why a ray or t file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum RayFileError {
    #[error("cannot read or write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {size} bytes is not a whole number of rays (24 bytes each)")]
    Size { path: PathBuf, size: usize },
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> RayFileError + '_ {
    move |source| RayFileError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads a `.rays` file.
pub fn read_rays(path: &Path) -> Result<Vec<Ray>, RayFileError> {
    let bytes = std::fs::read(path).map_err(io_error(path))?;
    if bytes.len() % 24 != 0 {
        return Err(RayFileError::Size {
            path: path.to_path_buf(),
            size: bytes.len(),
        });
    }
    let value = |chunk: &[u8], k: usize| {
        f32::from_le_bytes([
            chunk[4 * k],
            chunk[4 * k + 1],
            chunk[4 * k + 2],
            chunk[4 * k + 3],
        ])
    };
    Ok(bytes
        .chunks_exact(24)
        .map(|c| {
            Ray::new(
                Vec3::new(value(c, 0), value(c, 1), value(c, 2)),
                Vec3::new(value(c, 3), value(c, 4), value(c, 5)),
            )
        })
        .collect())
}

/// Writes a `.rays` file (t windows are not stored: the format's rays span [0, ∞)).
pub fn write_rays(path: &Path, rays: &[Ray]) -> Result<(), RayFileError> {
    let mut bytes = Vec::with_capacity(rays.len() * 24);
    for ray in rays {
        for v in ray
            .origin
            .to_array()
            .into_iter()
            .chain(ray.direction.to_array())
        {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).map_err(io_error(path))
}

/// Writes a `.t` file: one closest-hit t per ray, ∞ for a miss.
pub fn write_hit_distances(path: &Path, t: &[f32]) -> Result<(), RayFileError> {
    let bytes: Vec<u8> = t.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(path, bytes).map_err(io_error(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_round_trip() {
        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("a.rays");
        let rays = vec![
            Ray::new(Vec3::new(1.0, -2.0, 3.5), Vec3::new(0.0, 0.0, -1.0)),
            Ray::new(Vec3::ZERO, Vec3::new(f32::NAN, 1e30, -0.0)),
        ];
        write_rays(&path, &rays).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().len(), 48);
        let back = read_rays(&path).unwrap();
        assert_eq!(back[0], rays[0]);
        assert!(back[1].direction.x.is_nan());
        assert_eq!(back[1].direction.z.to_bits(), (-0.0f32).to_bits());
        std::fs::write(&path, [0u8; 25]).unwrap();
        assert!(matches!(
            read_rays(&path),
            Err(RayFileError::Size { size: 25, .. })
        ));
    }
}
