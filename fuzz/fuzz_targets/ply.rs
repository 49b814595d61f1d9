//! Any bytes as a PLY mesh.
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let mut assets = glint_io::MemoryAssets::new();
    assets.insert("mesh.ply", bytes.to_vec());
    if let Ok(mesh) = glint_io::load_mesh_from(std::path::Path::new("mesh.ply"), &assets) {
        for triangle in &mesh.triangles {
            for &corner in triangle {
                assert!((corner as usize) < mesh.positions.len());
            }
        }
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
    }
});
