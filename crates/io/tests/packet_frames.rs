//! The course render loop traces each pixel's camera rays in packets of eight
//! (`Scene::intersect_lanes`) and hands the hits to the integrator; the frames it makes are
//! bit for bit the frames of tracing every camera ray on its own, which this test computes
//! with the loop written out here (the lecture's jittered grid, one random stream per sample,
//! `CourseIntegrator::radiance` on each ray). The path tracer's camera rays travel in packets
//! too (eight samples of a pixel at a time); its frames are held to `PathIntegrator::trace` on
//! each camera ray alone in the same way, feature layers included.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glint_render::bench::{
    shade_camera_ray, FirstHit, LightSampler, PathIntegrator, PathSampler, PathSettings, Rng,
    SampleContext, SobolPixel,
};
use glint_render::{render, Color, IntegratorKind, RenderSettings, Scene, ThinLens, Vec3};

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
                    ray_budget: glint_render::bench::RAY_BUDGET,
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
    check_scene(&course_scene(relative), relative, size, rays_per_pixel);
}

fn check_scene(scene: &Scene, relative: &str, size: u32, rays_per_pixel: u32) {
    let settings = RenderSettings {
        width: size,
        height: size * 3 / 4,
        samples_per_pixel: rays_per_pixel,
        seed: 7,
        ..RenderSettings::default()
    };
    let (film, stats) = render(scene, &settings, &|_| true).expect("not cancelled");
    let (expected, rays) = single_ray_frame(scene, &settings);
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

/// At 1 and 4 rays a pixel the camera rays of neighbouring pixels share packets (runs of up to
/// eight pixels of a row): 37 pixels wide, so that tiles end in runs of 5 pixels (5 lanes at
/// 1 ray a pixel go ray by ray; 20 at 4 rays, two packets and a partial one).
#[test]
fn pixel_runs_at_one_and_four_rays_a_pixel() {
    for rays_per_pixel in [1, 4] {
        check("scenes_B/StanfordDragon_Instanced.json", 37, rays_per_pixel);
        check("scenes_A/spheres_1K.xml", 37, rays_per_pixel);
        check("scenes_B/threeEggs_SoftShadows.xml", 37, rays_per_pixel);
        for lights in [8, 9] {
            let scene = lights_scene(lights);
            check_scene(&scene, &format!("{lights} lights"), 37, rays_per_pixel);
        }
    }
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

/// A course scene with `lights` point lights around two spheres on a floor of triangles, in
/// Lambertian, Blinn-Phong and glaze, written to a file and loaded as the CLI loads it.
fn lights_scene(lights: usize) -> Scene {
    let light = |i: usize| {
        let a = i as f32 * 0.7;
        format!(
            r#"{{"position": "{} {} {}", "intensity": "0.15 0.12 0.1", "_type": "point"}}"#,
            6.0 * a.cos(),
            3.0 + (i % 3) as f32,
            6.0 * a.sin() - 4.0
        )
    };
    let lights: Vec<String> = (0..lights).map(light).collect();
    let json = format!(
        r#"{{"scene": {{
  "camera": [{{"position": "0 1 4", "viewDir": "0 -0.2 -1", "focalLength": 0.4,
    "imagePlaneWidth": 0.5, "_name": "main", "_type": "perspective"}}],
  "light": [{}],
  "shader": [
    {{"diffuse": "0.7 0.6 0.5", "_name": "matte", "_type": "Lambertian"}},
    {{"diffuse": "0.2 0.4 0.8", "specular": "1 1 1", "phongExp": 32.0, "_name": "shiny",
      "_type": "BlinnPhong"}},
    {{"diffuse": "0.5 0.5 0.5", "mirrorCoef": 0.4, "_name": "glazed", "_type": "Glaze"}}
  ],
  "shape": [
    {{"shader": {{"_ref": "shiny"}}, "center": "-0.8 0 -4", "radius": 0.9, "_name": "a",
      "_type": "sphere"}},
    {{"shader": {{"_ref": "matte"}}, "center": "1.2 -0.2 -5", "radius": 0.7, "_name": "b",
      "_type": "sphere"}},
    {{"shader": {{"_ref": "glazed"}}, "v0": "-8 -1 0", "v1": "8 -1 0", "v2": "8 -1 -12",
      "_name": "f0", "_type": "triangle"}},
    {{"shader": {{"_ref": "glazed"}}, "v0": "-8 -1 0", "v1": "8 -1 -12", "v2": "-8 -1 -12",
      "_name": "f1", "_type": "triangle"}}
  ],
  "_bgColor": "0.1 0.1 0.2"
}}}}"#,
        lights.join(",\n    ")
    );
    // A directory of its own per call: the tests calling this run at once.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("lights_{}.json", lights.len()));
    std::fs::write(&path, json).unwrap();
    let loaded = glint_io::load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    Scene::new(loaded.parts)
}

/// The first-hit shadow rays of a packet are traced ahead for up to eight lights (a bit each),
/// ray by ray beyond: both hold the frames of the single-ray loop, at the limit and past it.
#[test]
fn first_hit_shadows_up_to_eight_lights_and_past() {
    for lights in [1, 8, 9] {
        let scene = lights_scene(lights);
        assert_eq!(scene.lights.len(), lights);
        check_scene(&scene, &format!("{lights} lights"), 32, 16);
    }
}

/// The path tracer one camera ray at a time, as `PathIntegrator::pixel_samples` took them
/// before its packets: per pixel the scrambled Sobol' sampler of each sample, the camera ray
/// through the sample's first two dimensions (and the lens's next two), `trace` on it; the
/// film's averages of the finite samples and features. (pixels, features, rays traced).
fn single_ray_path_frame(
    scene: &Scene,
    settings: &RenderSettings,
) -> (Vec<Color>, Vec<(Color, Vec3, f32)>, u64) {
    let (width, height) = (settings.width, settings.height);
    let aspect = width as f32 / height as f32;
    let integrator = PathIntegrator::new(scene, PathSettings::with_max_depth(settings.max_depth()));
    let (mut pixels, mut features, mut rays) = (Vec::new(), Vec::new(), 0);
    for y in 0..height {
        for x in 0..width {
            let pixel_index = y as u64 * width as u64 + x as u64;
            let sobol = SobolPixel::new(settings.seed, pixel_index, settings.samples_per_pixel);
            let (mut sum, mut valid) = (Color::ZERO, 0u32);
            let (mut albedo, mut normal, mut depth, mut counted) =
                (Color::ZERO, Vec3::ZERO, 0.0f32, 0u32);
            for s in settings.samples() {
                let mut sampler = sobol.sampler(s);
                let (ox, oy) = sampler.sample_2d(0);
                let lens = match scene.camera.lens {
                    Some(_) => sampler.sample_2d(2),
                    None => (0.5, 0.5),
                };
                let j = height - 1 - y;
                let ray = scene.camera.lens_ray(
                    x as f32 + ox,
                    j as f32 + oy,
                    width,
                    height,
                    aspect,
                    lens,
                );
                let mut first_hit = FirstHit::default();
                let c = integrator.trace(scene, &ray, &mut sampler, &mut rays, &mut first_hit);
                if c.is_finite() {
                    sum += c;
                    valid += 1;
                }
                if first_hit.albedo.is_finite()
                    && first_hit.normal.is_finite()
                    && first_hit.depth.is_finite()
                {
                    albedo += first_hit.albedo;
                    normal += first_hit.normal;
                    depth += first_hit.depth;
                    counted += 1;
                }
            }
            pixels.push(if valid > 0 {
                sum / valid as f32
            } else {
                Color::ZERO
            });
            let n = counted.max(1) as f32;
            features.push((albedo / n, normal / n, depth / n));
        }
    }
    (pixels, features, rays)
}

fn check_path(scene: &Scene, name: &str, samples_per_pixel: u32, range: Option<Range<u32>>) {
    let settings = RenderSettings {
        width: 24,
        height: 18,
        samples_per_pixel,
        seed: 5,
        integrator: IntegratorKind::Path,
        features: true,
        sample_range: range.clone(),
        ..RenderSettings::default()
    };
    let (film, stats) = render(scene, &settings, &|_| true).expect("not cancelled");
    let (expected, expected_features, rays) = single_ray_path_frame(scene, &settings);
    let what = format!("{name} at {samples_per_pixel} spp, samples {range:?}");
    assert_eq!(stats.rays, rays, "{what}: rays traced");
    let layers = film.features.as_ref().expect("feature layers");
    let bits = |c: Color| c.to_array().map(f32::to_bits);
    for (k, (a, b)) in film.pixels.iter().zip(&expected).enumerate() {
        let (albedo, normal, depth) = expected_features[k];
        let at = (k as u32 % settings.width, k as u32 / settings.width);
        assert!(
            bits(*a) == bits(*b),
            "{what}, pixel {at:?}: packets {a:?}, single rays {b:?}"
        );
        assert!(
            bits(layers.albedo[k]) == bits(albedo)
                && layers.normal[k].to_array().map(f32::to_bits)
                    == normal.to_array().map(f32::to_bits)
                && layers.depth[k].to_bits() == depth.to_bits(),
            "{what}, pixel {at:?}: features differ"
        );
    }
}

/// Packets of eight camera rays and partial ones (12 samples: 8 + 4; a farm's sample range
/// 3..21 of 24: 8 + 8 + 2), a pinhole and a thin lens, triangles, spheres and instanced meshes.
#[test]
fn path_tracer_frames() {
    let cornell = course_scene("scenes_A/CornellRoom_wMirroredSpheres.xml");
    check_path(&cornell, "Cornell room", 12, None);
    check_path(&cornell, "Cornell room", 24, Some(3..21));
    let mut lens = course_scene("scenes_B/CornellBox_Dielectric.json");
    lens.camera.lens = Some(ThinLens {
        focus_distance: 3.0,
        radius: 0.1,
    });
    check_path(&lens, "Cornell box with a lens", 8, None);
    check_path(
        &course_scene("scenes_B/rowOfBunnys.json"),
        "bunnies",
        9,
        None,
    );
    // Fewer than eight samples go ray by ray.
    check_path(&cornell, "Cornell room", 4, None);
}
