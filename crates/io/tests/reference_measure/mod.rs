//! The reference-image tests' error measure, in its own file so that `glint diff`'s test
//! (crates/cli/tests/diff.rs) checks its numbers against this very code.

/// How far a render is from its reference, in 8-bit levels.
pub struct ImageError {
    /// Mean absolute difference over all pixels and channels, in levels of 255.
    pub mean_absolute: f64,
    /// Fraction of pixels where any channel differs by more than 8 levels.
    pub fraction_over_8: f64,
}

/// Compares two interleaved 8-bit RGB images of the same size.
pub fn compare(rendered: &[u8], reference: &[u8]) -> ImageError {
    assert_eq!(rendered.len(), reference.len());
    let mut sum = 0u64;
    let mut over = 0usize;
    for (a, b) in rendered.chunks(3).zip(reference.chunks(3)) {
        let mut worst = 0;
        for c in 0..3 {
            let d = (a[c] as i32 - b[c] as i32).unsigned_abs();
            sum += d as u64;
            worst = worst.max(d);
        }
        if worst > 8 {
            over += 1;
        }
    }
    ImageError {
        mean_absolute: sum as f64 / rendered.len() as f64,
        fraction_over_8: over as f64 / (rendered.len() / 3) as f64,
    }
}
