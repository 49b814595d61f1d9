//! The GPU path tracer against the CPU one (`glint_render::render` with
//! `IntegratorKind::Path`), on whatever Vulkan adapter wgpu finds: in CI, Mesa's software
//! Vulkan (lavapipe). Without an adapter the tests print SKIPPED and pass, except under
//! `CI=1`, where they fail: CI installs the driver, so a missing adapter is a broken setup.
//!
//! The criterion is the noise-aware one of `crates/io/tests/path_cornell.rs`, with the CPU in
//! Mitsuba's place and the reference's own noise measured instead of taken from a table:
//!
//! - The GPU renders the scene twice with different seeds at N/2 samples per pixel, g1 and
//!   g2; g is their mean. The CPU renders it twice at M/2 (M much larger than N), r1 and r2;
//!   r is their mean.
//! - relMSE(a, b) = mean over pixels and channels of (a − b)² / (r² + 0.01).
//! - If both are unbiased, E[relMSE(g, r)] = σ²_g + σ²_r, and each σ² is a quarter of the
//!   relMSE between its own two halves (E[(x1 − x2)²] = 4 Var(mean)).
//! - Pass: relMSE(g, r) ≤ 1.15 · (σ²_g + σ²_r), and every 16x16 block's mean agrees with the
//!   CPU's within 2% per channel, or within five standard errors of the difference where
//!   that is larger.
//! - Negative control: the GPU's images made 3% darker must fail the same test.
//!
//! `--nocapture` prints the figures and the timings.

mod common;

use std::time::Instant;

use common::{cornell, gpu};
use glint_gpu::{GpuError, GpuRenderer};
use glint_render::{
    Background, Camera, Color, ColorSource, CubeMap, GeometryDesc, Image, Instance, IntegratorKind,
    Light, Material, Matrix4, Projection, RenderSettings, Scene, SceneParts, Shape, Transform,
    Vec3,
};

const SIZE: u32 = 64;
const BLOCK: u32 = 16;
const TOLERANCE: f64 = 1.15;
const BLOCK_TOLERANCE: f64 = 0.02;

type Pixels = Vec<[f64; 3]>;

fn settings(samples: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: SIZE,
        height: SIZE,
        samples_per_pixel: samples,
        seed,
        integrator: IntegratorKind::Path,
        ..RenderSettings::default()
    }
}

fn to_pixels(film: &glint_render::Film) -> Pixels {
    film.pixels
        .iter()
        .map(|c: &Color| [c.x as f64, c.y as f64, c.z as f64])
        .collect()
}

fn render_cpu(parts: &SceneParts, samples: u32, seed: u64) -> Pixels {
    let scene = Scene::new(parts.clone());
    let (film, stats) = glint_render::render(&scene, &settings(samples, seed), &|_| true).unwrap();
    assert_eq!(stats.nonfinite_samples, 0);
    to_pixels(&film)
}

fn render_gpu(gpu: &GpuRenderer, parts: &SceneParts, samples: u32, seed: u64) -> Pixels {
    let (film, stats) = gpu
        .render(parts, &settings(samples, seed), &|_, _| true)
        .unwrap();
    assert_eq!(
        stats.nonfinite_samples, 0,
        "first at {:?}",
        stats.first_nonfinite_pixel
    );
    assert_eq!(stats.samples, (SIZE * SIZE * samples) as u64);
    to_pixels(&film)
}

fn mean_of(a: &Pixels, b: &Pixels) -> Pixels {
    a.iter()
        .zip(b)
        .map(|(a, b)| std::array::from_fn(|c| 0.5 * (a[c] + b[c])))
        .collect()
}

/// Mean over pixels and channels of (a − b)² / (r² + 0.01).
fn relative_mse(a: &Pixels, b: &Pixels, reference: &Pixels) -> f64 {
    let mut sum = 0.0;
    for ((a, b), r) in a.iter().zip(b).zip(reference) {
        for c in 0..3 {
            sum += (a[c] - b[c]).powi(2) / (r[c] * r[c] + 0.01);
        }
    }
    sum / (3 * a.len()) as f64
}

/// Means of the blocks, per channel, row-major.
fn block_means(image: &Pixels) -> Pixels {
    let blocks = SIZE / BLOCK;
    let mut means = vec![[0.0; 3]; (blocks * blocks) as usize];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let block = &mut means[((y / BLOCK) * blocks + x / BLOCK) as usize];
            for c in 0..3 {
                block[c] += image[(y * SIZE + x) as usize][c] / (BLOCK * BLOCK) as f64;
            }
        }
    }
    means
}

/// Per-pixel variance of the mean of two halves: ((x1 − x2) / 2)².
fn half_variance(a: &Pixels, b: &Pixels) -> Pixels {
    a.iter()
        .zip(b)
        .map(|(a, b)| std::array::from_fn(|c| ((a[c] - b[c]) / 2.0).powi(2)))
        .collect()
}

/// The comparison of the module docs: `Ok` with the figures, or `Err` with the failure.
fn judge(gpu: (&Pixels, &Pixels), cpu: (&Pixels, &Pixels)) -> Result<String, String> {
    let g = mean_of(gpu.0, gpu.1);
    let r = mean_of(cpu.0, cpu.1);
    let error = relative_mse(&g, &r, &r);
    let gpu_noise = relative_mse(gpu.0, gpu.1, &r) / 4.0;
    let cpu_noise = relative_mse(cpu.0, cpu.1, &r) / 4.0;
    let expected = gpu_noise + cpu_noise;

    let ours = block_means(&g);
    let theirs = block_means(&r);
    // block_means divides by the block's pixel count once; a mean's variance needs it twice.
    let variance_g = block_means(&half_variance(gpu.0, gpu.1));
    let variance_r = block_means(&half_variance(cpu.0, cpu.1));
    let pixels_per_block = (BLOCK * BLOCK) as f64;
    // (error / limit, error, block, channel, noise) of the block closest to failing.
    let mut worst = (f64::NEG_INFINITY, 0.0, 0, 0, 0.0);
    for (block, r) in theirs.iter().enumerate() {
        for c in 0..3 {
            if r[c] <= 1e-4 {
                continue;
            }
            let error = (ours[block][c] - r[c]).abs() / r[c];
            let noise =
                ((variance_g[block][c] + variance_r[block][c]) / pixels_per_block).sqrt() / r[c];
            let limit = BLOCK_TOLERANCE.max(5.0 * noise);
            if error / limit > worst.0 {
                worst = (error / limit, error, block, c, noise);
            }
        }
    }
    let (_, block_error, block, channel, block_noise) = worst;
    let block_limit = BLOCK_TOLERANCE.max(5.0 * block_noise);
    let blocks = SIZE / BLOCK;
    let (bx, by) = (block as u32 % blocks, block as u32 / blocks);
    let figures = format!(
        "relMSE GPU vs CPU {error:.3e}, expected from noise {expected:.3e} (GPU {gpu_noise:.3e}, \
         CPU {cpu_noise:.3e}), ratio {:.3} (limit {TOLERANCE}); worst {BLOCK}x{BLOCK} block \
         {:.2}% (block {bx},{by} channel {channel}; limit {:.2}%, noise {:.2}%)",
        error / expected,
        100.0 * block_error,
        100.0 * block_limit,
        100.0 * block_noise,
    );
    if error > TOLERANCE * expected {
        return Err(format!(
            "relMSE {error:.3e} exceeds {TOLERANCE} x the noise-expected {expected:.3e}: {figures}"
        ));
    }
    if block_error > block_limit {
        return Err(format!(
            "block ({bx},{by}) channel {channel} is off by {:.2}%: {figures}",
            100.0 * block_error
        ));
    }
    Ok(figures)
}

/// Renders `parts` on both back ends and applies the criterion, then the negative control.
fn compare(test: &str, parts: &SceneParts, gpu_samples: u32, cpu_samples: u32) {
    let Some(gpu) = gpu(test) else {
        return;
    };
    let start = Instant::now();
    let g1 = render_gpu(&gpu, parts, gpu_samples / 2, 1);
    let g2 = render_gpu(&gpu, parts, gpu_samples / 2, 2);
    let gpu_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let r1 = render_cpu(parts, cpu_samples / 2, 11);
    let r2 = render_cpu(parts, cpu_samples / 2, 12);
    let cpu_seconds = start.elapsed().as_secs_f64();
    let verdict = judge((&g1, &g2), (&r1, &r2));
    println!(
        "{test}: GPU {gpu_samples} spp ({gpu_seconds:.1} s) vs CPU {cpu_samples} spp \
         ({cpu_seconds:.1} s): {}",
        verdict.as_ref().unwrap_or_else(|e| e)
    );
    if let Err(failure) = verdict {
        panic!("{test}: {failure}");
    }
    let darker = |image: &Pixels| -> Pixels {
        image
            .iter()
            .map(|p| [0.97 * p[0], 0.97 * p[1], 0.97 * p[2]])
            .collect()
    };
    let dark = judge((&darker(&g1), &darker(&g2)), (&r1, &r2));
    println!(
        "{test}: GPU 3% darker (must fail): {}",
        dark.as_ref().unwrap_or_else(|e| e)
    );
    assert!(dark.is_err(), "{test}: a 3% darker GPU image passed");
}

fn samples(variable: &str, default: u32) -> u32 {
    std::env::var(variable)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn cornell_box_agrees_with_the_cpu() {
    compare(
        "cornell",
        &cornell(),
        samples("GLINT_GPU_TEST_SPP", 256),
        samples("GLINT_CPU_TEST_SPP", 2048),
    );
}

#[test]
fn glass_mirror_texture_environment_agree_with_the_cpu() {
    compare(
        "features",
        &feature_scene(),
        samples("GLINT_GPU_TEST_SPP", 256),
        samples("GLINT_CPU_TEST_SPP", 2048),
    );
}

#[test]
fn other_shaders_orthographic_camera_and_sky_agree_with_the_cpu() {
    compare(
        "shaders",
        &shader_scene(),
        samples("GLINT_GPU_TEST_SPP", 256),
        samples("GLINT_CPU_TEST_SPP", 2048),
    );
}

/// The shaders `feature_scene` leaves out (Phong, Glaze, CoolToWarm, a rough Mirror, an
/// emitter no light samples) seen by an orthographic camera under a constant sky, which the
/// path tracer samples as a uniform environment light.
fn shader_scene() -> SceneParts {
    let materials = vec![
        Material::Phong {
            diffuse: Color::new(0.5, 0.3, 0.2).into(),
            specular: Color::splat(0.4).into(),
            phong_exponent: 20.0,
        },
        Material::Glaze {
            diffuse: Color::new(0.2, 0.4, 0.6).into(),
            mirror_coef: 0.35,
        },
        Material::CoolToWarm {
            diffuse: Color::new(0.7, 0.7, 0.3).into(),
        },
        Material::Mirror { roughness: 0.25 },
        // An emitter without a light: it shines where seen or hit, and no light samples it.
        Material::Emissive {
            radiance: Color::new(2.0, 1.5, 1.0),
            surface: None,
            light: None,
        },
    ];
    let sphere = |x: f32, z: f32| Shape::Sphere {
        center: Vec3::new(x, 0.5, z),
        radius: 0.5,
    };
    SceneParts {
        camera: Camera::new(
            Projection::Orthographic,
            Vec3::new(0.0, 2.0, 4.0),
            Vec3::new(0.0, -0.4, -1.0),
            1.0,
            4.5,
        ),
        materials,
        textures: vec![],
        lights: vec![Light::Point {
            position: Vec3::new(-2.0, 4.0, 3.0),
            intensity: Color::splat(6.0),
        }],
        background: Background::Color(Color::new(0.5, 0.6, 0.8)),
        geometries: vec![GeometryDesc {
            shapes: vec![
                Shape::Box {
                    min: Vec3::new(-3.0, -0.2, -3.0),
                    max: Vec3::new(3.0, 0.0, 3.0),
                },
                sphere(-1.2, 0.0),
                sphere(0.0, -0.3),
                sphere(1.2, 0.0),
                Shape::Box {
                    min: Vec3::new(-0.4, 0.0, 0.8),
                    max: Vec3::new(0.4, 0.3, 1.4),
                },
            ],
            materials: vec![1, 0, 3, 2, 4],
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    }
}

/// An image of `width` x `height` texels from a function of (x, y).
fn image(width: u32, height: u32, texel: impl Fn(u32, u32) -> Color) -> Image {
    Image {
        width,
        height,
        texels: (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| texel(x, y))
            .collect(),
    }
}

fn translate_scale(t: Vec3, s: Vec3) -> Transform {
    Transform::from_matrix(&Matrix4::translate(t).mul(&Matrix4::scale(s))).unwrap()
}

/// Two triangles covering the rectangle of an area light, wound so their normal is the
/// light's (as glint-io builds a visible area light).
fn rectangle(center: Vec3, u: Vec3, v: Vec3, normal: Vec3) -> Vec<Shape> {
    let corners = [
        center - u * 0.5 - v * 0.5,
        center + u * 0.5 - v * 0.5,
        center + u * 0.5 + v * 0.5,
        center - u * 0.5 + v * 0.5,
    ];
    let mut triangles = vec![
        [corners[0], corners[1], corners[2]],
        [corners[0], corners[2], corners[3]],
    ];
    for t in &mut triangles {
        if (t[1] - t[0]).cross(t[2] - t[0]).dot(normal) < 0.0 {
            t.swap(1, 2);
        }
    }
    triangles
        .into_iter()
        .map(|vertices| Shape::Triangle { vertices })
        .collect()
}

/// Glass, a mirror, a glossy instanced ellipsoid, a textured floor box and a textured
/// instanced box, under a point light, a visible area light, an emitting sphere and an
/// environment cube map.
fn feature_scene() -> SceneParts {
    let checker = image(8, 8, |x, y| {
        if (x + y) % 2 == 0 {
            Color::new(0.85, 0.8, 0.7)
        } else {
            Color::new(0.2, 0.3, 0.45)
        }
    });
    let stripes = image(16, 1, |x, _| Color::new(0.2 + 0.05 * x as f32, 0.5, 0.3));
    // Six faces of a sky: brighter up, warm towards +X, dark below.
    let face = |f: usize| {
        image(4, 4, move |x, y| {
            let base = match f {
                0 => Color::new(1.2, 0.9, 0.6),
                1 => Color::new(0.4, 0.5, 0.7),
                2 => Color::new(0.9, 1.1, 1.5),
                3 => Color::new(0.05, 0.05, 0.05),
                4 => Color::new(0.6, 0.7, 0.9),
                _ => Color::new(0.5, 0.6, 0.8),
            };
            base * (0.7 + 0.1 * (x + y) as f32)
        })
    };
    let materials = vec![
        // 0: textured floor.
        Material::Lambertian {
            diffuse: ColorSource {
                color: Color::ONE,
                texture: Some(0),
            },
        },
        // 1: mirror.
        Material::Mirror { roughness: 0.0 },
        // 2: glass.
        Material::Dielectric {
            refractive_index: 1.5,
            attenuation: Color::new(0.9, 0.95, 0.9),
        },
        // 3: glossy, textured: the instanced ellipsoid.
        Material::BlinnPhong {
            diffuse: ColorSource {
                color: Color::new(0.9, 0.9, 0.9),
                texture: Some(1),
            },
            specular: Color::splat(0.3).into(),
            phong_exponent: 30.0,
            mirror_coef: 0.0,
        },
        // 4: the area light's visible rectangle.
        Material::Emissive {
            radiance: Color::splat(4.0),
            surface: None,
            light: Some(1),
        },
        // 5: Phong with a rough mirror blended in (BlinnPhongMirrored).
        Material::BlinnPhongMirrored {
            diffuse: Color::new(0.3, 0.5, 0.2).into(),
            specular: Color::splat(0.2).into(),
            phong_exponent: 12.0,
            mirror_coef: 0.4,
            roughness: 0.3,
        },
        // 6: the emitting sphere, white diffuse on its emitting side.
        Material::Emissive {
            radiance: Color::new(3.0, 2.0, 1.0),
            surface: Some(7),
            light: Some(2),
        },
        // 7: plain white.
        Material::Diffuse {
            diffuse: Color::splat(0.7).into(),
        },
    ];
    let area_center = Vec3::new(0.0, 2.4, 0.5);
    let area_normal = Vec3::new(0.0, -1.0, 0.0);
    let (u_edge, v_edge) = Light::area_edges(area_normal, 0.8, 0.6);
    let lights = vec![
        Light::Point {
            position: Vec3::new(2.0, 3.0, 2.5),
            intensity: Color::splat(3.0),
        },
        Light::Area {
            position: area_center,
            normal: area_normal,
            width: 0.8,
            length: 0.6,
            intensity: Color::splat(4.0),
        },
        Light::Sphere {
            center: Vec3::new(-1.6, 0.25, 0.9),
            radius: 0.2,
            intensity: Color::new(3.0, 2.0, 1.0),
        },
    ];
    let geometries = vec![
        // 0: the plain shapes.
        GeometryDesc {
            shapes: vec![
                Shape::Box {
                    min: Vec3::new(-3.0, -0.2, -3.0),
                    max: Vec3::new(3.0, 0.0, 3.0),
                },
                Shape::Sphere {
                    center: Vec3::new(-0.75, 0.5, -0.2),
                    radius: 0.5,
                },
                Shape::Sphere {
                    center: Vec3::new(0.7, 0.45, 0.5),
                    radius: 0.45,
                },
                Shape::Sphere {
                    center: Vec3::new(-1.6, 0.25, 0.9),
                    radius: 0.2,
                },
            ],
            materials: vec![0, 1, 2, 6],
        },
        // 1: a unit sphere and a unit box, placed by instances.
        GeometryDesc {
            shapes: vec![Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            }],
            materials: vec![7],
        },
        GeometryDesc {
            shapes: vec![Shape::Box {
                min: Vec3::splat(-0.5),
                max: Vec3::splat(0.5),
            }],
            materials: vec![0],
        },
        // 3: the area light's rectangle.
        GeometryDesc {
            materials: vec![4, 4],
            shapes: rectangle(area_center, u_edge, v_edge, area_normal),
        },
    ];
    let instances = vec![
        Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        },
        Instance {
            geometry: 1,
            transform: Some(translate_scale(
                Vec3::new(0.1, 0.3, -1.3),
                Vec3::new(0.7, 0.3, 0.3),
            )),
            material: Some(3),
            casts_shadow: true,
        },
        Instance {
            geometry: 2,
            transform: Some(
                Transform::from_matrix(
                    &Matrix4::translate(Vec3::new(1.5, 0.3, -0.6))
                        .mul(&Matrix4::rotate(1, 30.0))
                        .mul(&Matrix4::scale(Vec3::splat(0.6))),
                )
                .unwrap(),
            ),
            material: Some(5),
            casts_shadow: true,
        },
        Instance {
            geometry: 3,
            transform: None,
            material: None,
            casts_shadow: false,
        },
    ];
    SceneParts {
        camera: Camera::new(
            Projection::Perspective,
            Vec3::new(0.0, 1.3, 4.0),
            Vec3::new(0.0, -0.35, -1.0),
            0.5,
            0.5,
        ),
        materials,
        textures: vec![checker, stripes],
        lights,
        background: Background::CubeMap(Box::new(CubeMap {
            faces: std::array::from_fn(face),
        })),
        geometries,
        instances,
    }
}

/// llvmpipe (lavapipe) ends an invocation's loops after 65535 iterations in all; 256 Cornell
/// samples in one invocation pass that, and the render must fail rather than return an image
/// with paths cut short. On adapters without the limit the render succeeds and is checked
/// for having every sample.
#[test]
fn loop_limit_is_detected_not_rendered() {
    let Some(mut gpu) = gpu("loop limit") else {
        return;
    };
    gpu.set_samples_per_pass(Some(256));
    let settings = RenderSettings {
        width: 16,
        height: 16,
        ..settings(256, 1)
    };
    match gpu.render(&cornell(), &settings, &|_, _| true) {
        Err(GpuError::Device(message)) => {
            println!("loop limit: {message}");
            assert!(message.contains("65535"), "{message}");
        }
        Ok((_, stats)) => {
            assert!(
                !gpu.adapter_name().contains("llvmpipe"),
                "llvmpipe rendered 256 samples per invocation without hitting its loop limit"
            );
            assert_eq!(stats.nonfinite_samples, 0);
        }
        Err(error) => panic!("{error}"),
    }
}
