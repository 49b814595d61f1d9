//! Any bytes as a Mitsuba `.serialized` mesh (every shape index its dictionary names, and one
//! past) and as an `sdfgrid`'s `.vol` grid.
#![no_main]

// Only its limits: these readers take bytes, not scenes.
#[allow(dead_code)]
mod common;

use glint_io::mitsuba_shapes::{read_sdfgrid, read_serialized, serialized_shape_count, ShapeMesh};

/// What every mesh the readers return must hold.
fn check(mesh: &ShapeMesh) {
    let n = mesh.positions.len();
    assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    if let Some(normals) = &mesh.normals {
        assert_eq!(normals.len(), n);
        assert!(normals.iter().all(|v| (v.length() - 1.0).abs() < 1e-3));
    }
    assert!(mesh.uvs.as_ref().is_none_or(|uvs| uvs.len() == n));
    assert!(mesh.colors.as_ref().is_none_or(|colors| colors.len() == n));
}

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let limits = common::limits();
    let count = serialized_shape_count(bytes).unwrap_or(0).min(4);
    for index in 0..=count {
        match read_serialized(bytes, index, &limits) {
            Ok(shape) => check(&shape.mesh),
            Err(error) => assert!(error.offset.is_none_or(|at| at <= bytes.len() as u64)),
        }
    }
    match read_sdfgrid(bytes, &limits) {
        Ok(mesh) => check(&mesh),
        Err(error) => assert!(error.offset.is_none_or(|at| at <= bytes.len() as u64)),
    }
});
