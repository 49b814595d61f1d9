//! Compares the pixels of two EXRs (as `glint` writes them) bit for bit, ignoring metadata:
//! `cargo run -p glint --example exr_compare -- A.exr B.exr`. Prints `identical: ...` and
//! exits 0 when every value has the same bits, prints the differing values' count and the
//! largest difference and exits 1 otherwise, exits 2 when a file cannot be read or the images'
//! windows differ. The farm scripts' CI test (`farm/ci.sh test`) uses it.

use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [a, b] = args.as_slice() else {
        eprintln!("usage: exr_compare A.exr B.exr");
        return ExitCode::from(2);
    };
    let read = |path: &str| glint_io::read_exr(Path::new(path));
    let (a, b) = match (read(a), read(b)) {
        (Ok(a), Ok(b)) => (a.film, b.film),
        (Err(error), _) | (_, Err(error)) => {
            eprintln!("error: {error}");
            return ExitCode::from(2);
        }
    };
    let window = |f: &glint_render::Film| (f.origin, f.width, f.height, f.full_size);
    if window(&a) != window(&b) {
        eprintln!(
            "error: the windows differ: {:?} vs {:?} (origin, width, height, full size)",
            window(&a),
            window(&b)
        );
        return ExitCode::from(2);
    }
    let values = |f: &glint_render::Film| -> Vec<f32> {
        f.pixels.iter().flat_map(|c| c.to_array()).collect()
    };
    let (va, vb) = (values(&a), values(&b));
    let mut differing = 0usize;
    let mut largest = 0.0f64;
    for (x, y) in va.iter().zip(&vb) {
        if x.to_bits() != y.to_bits() {
            differing += 1;
            largest = largest.max((f64::from(*x) - f64::from(*y)).abs());
        }
    }
    if differing == 0 {
        println!("identical: {} values bit for bit", va.len());
        ExitCode::SUCCESS
    } else {
        println!(
            "differ: {differing} of {} values, largest difference {largest:e}",
            va.len()
        );
        ExitCode::from(1)
    }
}
