//! Prints a digest of the pixels Glint renders for every scene of the course corpus, with
//! every integrator, at a fixed small size, sample count and seed: one line per scene and
//! integrator. `scripts/same-images.sh` compares these lines with `scripts/image-digests.txt`
//! to show that a change to the renderer left every image bit-identical.
//!
//! The digest is FNV-1a over the bits of each f32 channel (beauty, then feature layers), so
//! it does not depend on any file format's metadata.
//!
//! ```sh
//! cargo run --release -p glint-io --example image_digest -- ../shared/scenes/course
//! ```

// The corpus walk the corpus tests use.
#[path = "../tests/common/mod.rs"]
mod common;

use common::{load_as_the_course_did, scene_files};

use std::path::PathBuf;

use glint_render::{render, IntegratorKind, RenderSettings, Scene};

const WIDTH: u32 = 40;
const HEIGHT: u32 = 30;
/// Nine rays per pixel: the course loop's 3x3 jittered grid, traced as ray packets.
const COURSE_RPP: u32 = 9;
const PATH_SPP: u32 = 4;
const SEED: u64 = 7;

fn fnv1a(hash: &mut u64, values: impl IntoIterator<Item = f32>) {
    for value in values {
        for byte in value.to_bits().to_le_bytes() {
            *hash ^= byte as u64;
            *hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
    }
}

fn main() {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "../shared/scenes/course".into()),
    );
    let files = scene_files(&dir);
    for (path, name) in &files {
        // The course's images, so its leniency: two scenes name files that exist nowhere.
        let loaded = match load_as_the_course_did(path) {
            Ok(loaded) => loaded,
            Err(error) => {
                println!(
                    "{name} load-error {}",
                    error.to_string().lines().next().unwrap_or("")
                );
                continue;
            }
        };
        let scene = Scene::new(loaded.parts);
        for (label, integrator) in [
            ("course", IntegratorKind::Course),
            ("normals", IntegratorKind::Normals),
            ("path", IntegratorKind::Path),
        ] {
            let path = integrator == IntegratorKind::Path;
            let settings = RenderSettings {
                width: WIDTH,
                height: HEIGHT,
                samples_per_pixel: if path { PATH_SPP } else { COURSE_RPP },
                seed: SEED,
                integrator,
                // The path tracer's feature layers are part of what must not change.
                features: path,
                ..RenderSettings::default()
            };
            let mut hash = 0xcbf2_9ce4_8422_2325u64;
            let (film, _) = render(&scene, &settings, &|_| true).unwrap();
            fnv1a(&mut hash, film.to_rgb_f32());
            if let Some(features) = &film.features {
                fnv1a(&mut hash, features.albedo.iter().flat_map(|c| c.to_array()));
                fnv1a(&mut hash, features.normal.iter().flat_map(|n| n.to_array()));
            }
            println!("{name} {label} {hash:016x}");
        }
    }
}
