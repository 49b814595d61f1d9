//! Any bytes as an image file through glint-io's one image reader: as an EXR (header, then
//! pixels, as merge and resume read parts and checkpoints) and as any format the decoder knows
//! (textures, environment maps, `glint diff`). Small limits, so that a header declaring a
//! huge image must be refused before its memory is taken (libFuzzer's RSS limit catches the
//! other outcome).
#![no_main]

use std::path::PathBuf;

use glint_io::ImageLimits;

const LIMITS: ImageLimits = ImageLimits {
    max_side: 1024,
    max_bytes: 64 << 20,
};

/// One file per fuzzing process, rewritten for each input.
fn scratch() -> PathBuf {
    std::env::temp_dir().join(format!("glint-fuzz-image-{}", std::process::id()))
}

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let path = scratch();
    std::fs::write(&path, bytes).expect("cannot write the scratch file");
    if let Ok(header) = glint_io::read_exr_header(&path, &LIMITS) {
        assert!(header.width <= LIMITS.max_side && header.height <= LIMITS.max_side);
        assert!(header.origin.0 + header.width <= header.full_size.0);
        assert!(header.origin.1 + header.height <= header.full_size.1);
        if let Ok(exr) = glint_io::read_exr_with(&path, &LIMITS) {
            let film = &exr.film;
            assert_eq!(
                film.pixels.len(),
                film.width as usize * film.height as usize
            );
            assert!(film
                .pixels
                .iter()
                .all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite()));
        }
    }
    if let Ok(file) = glint_io::open_image(&path, &LIMITS, 12) {
        if let Ok(image) = file.decode() {
            assert!(image.width <= LIMITS.max_side && image.height <= LIMITS.max_side);
        }
    }
});
