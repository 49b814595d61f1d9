//! The course render loop traces each pixel's camera rays in packets of eight
//! (`Scene::intersect_lanes`) and hands the hits to the integrator; the frames it makes are
//! bit for bit the frames of tracing every camera ray on its own, which this test computes
//! with the loop written out here (the lecture's jittered grid, one random stream per sample,
//! `CourseIntegrator::radiance` on each ray).

use std::path::{Path, PathBuf};

use glint_render::integrator::course::{shade_camera_ray, SampleContext};
use glint_render::light::sampler::LightSampler;
use glint_render::sampling::Rng;
use glint_render::{render, Color, RenderSettings, Scene};

fn course_scene(relative: &str) -> Scene {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/course/willemsen")
        .join(relative);
    let loaded = glint_io::load_scene(&path).unwrap_or_else(|e| panic!("{relative}: {e}"));
    Scene::new(loaded.parts)
}

/// The course loop one camera ray at a time: (pixels, rays traced).
fn single_ray_frame(scene: &Scene, settings: &RenderSettings) -> (Vec<Color>, u64) {
    let (width, height) = (settings.width, settings.height);
    let aspect = settings.aspect.unwrap_or(width as f32 / height as f32);
    let samples = settings.samples_per_pixel();
    let grid = (samples as f64).sqrt() as u32;
    let lights = LightSampler::new(scene);
    let mut pixels = Vec::new();
    let mut rays = 0;
    for y in 0..height {
        for x in 0..width {
            let pixel_index = y as u64 * width as u64 + x as u64;
            let j = height - 1 - y;
            let (mut sum, mut valid) = (Color::ZERO, 0u32);
            for s in 0..samples {
                let mut rng = Rng::for_sample(settings.seed, pixel_index, s as u64);
                let (ox, oy) = if samples == 1 {
                    (0.5, 0.5)
                } else {
                    (
                        ((s % grid) as f32 + rng.next_f32()) / grid as f32,
                        ((s / grid) as f32 + rng.next_f32()) / grid as f32,
                    )
                };
                let ray = scene
                    .camera
                    .ray(x as f32 + ox, j as f32 + oy, width, height, aspect);
                let mut ctx = SampleContext {
                    rng,
                    lights: Some(&lights),
                    sample_index: s,
                    grid_size: grid,
                    pixel_key: pixel_index ^ settings.seed.rotate_left(32),
                    max_depth: settings.max_depth(),
                    rays: 1,
                };
                let c = shade_camera_ray(scene, &ray, &mut ctx);
                rays += ctx.rays;
                if c.is_finite() {
                    sum += c;
                    valid += 1;
                }
            }
            pixels.push(if valid > 0 {
                sum / valid as f32
            } else {
                Color::ZERO
            });
        }
    }
    (pixels, rays)
}

fn check(relative: &str, size: u32, rays_per_pixel: u32) {
    let scene = course_scene(relative);
    let settings = RenderSettings {
        width: size,
        height: size * 3 / 4,
        samples_per_pixel: rays_per_pixel,
        seed: 7,
        ..RenderSettings::default()
    };
    let (film, stats) = render(&scene, &settings, &|_| true).expect("not cancelled");
    let (expected, rays) = single_ray_frame(&scene, &settings);
    assert_eq!(stats.rays, rays, "{relative}: rays traced");
    for (k, (a, b)) in film.pixels.iter().zip(&expected).enumerate() {
        assert!(
            a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits),
            "{relative} at {rays_per_pixel} rpp, pixel ({}, {}): packets {a:?}, single rays {b:?}",
            k as u32 % settings.width,
            k as u32 / settings.width
        );
    }
}

#[test]
fn instanced_meshes() {
    check("scenes_B/StanfordDragon_Instanced.json", 40, 16);
    check("scenes_B/rowOfBunnys.json", 32, 9);
}

#[test]
fn spheres_boxes_and_triangles() {
    check("scenes_A/spheres_1K.xml", 40, 16);
    check("scenes_A/spheresAndTriangles.json", 32, 4);
    check("scenes_A/boxSphereTest.xml", 32, 1);
}

#[test]
fn area_lights_mirrors_and_glass() {
    check("scenes_A/CornellRoom_wMirroredSpheres.xml", 32, 16);
    check("scenes_B/threeEggs_SoftShadows.xml", 32, 9);
    check("scenes_B/CornellBox_Dielectric.json", 32, 16);
}
