//! The GPU path tracer against the CPU one (`glint_render::render` with
//! `IntegratorKind::Path`), on whatever Vulkan adapter wgpu finds: in CI, Mesa's software
//! Vulkan (lavapipe). Without an adapter the tests print SKIPPED and pass, except under
//! `CI=1`, where they fail: CI installs the driver, so a missing adapter is a broken setup.
//!
//! The criterion is the noise-aware one of `glint_render::testing::compare` (that of
//! `crates/io/tests/path_cornell.rs`), with the CPU in Mitsuba's place and the reference's own
//! noise measured instead of taken from a table: the GPU renders the scene twice with
//! different seeds at N/2 samples per pixel, the CPU twice at M/2 (M much larger than N), and
//! the GPU's mean must agree with the CPU's within 1.15 times what the noise of both explains
//! in relMSE, and every 16x16 block within 2% per channel, or within five standard errors of
//! the difference where that is larger; blocks the CPU renders black are not judged. Negative
//! control: the GPU's images made 3% darker must fail the same test.
//!
//! `--nocapture` prints the figures and the timings.

mod common;

use std::time::Instant;

use common::{cornell, gpu};
use glint_gpu::{GpuError, GpuRenderer};
use glint_render::testing::compare::{judge, scaled, to_pixels, Criterion, Pixel, Reference};
use glint_render::{
    Background, Camera, Color, ColorSource, CubeMap, GeometryDesc, Image, Instance, IntegratorKind,
    Light, Material, Matrix4, Projection, RenderSettings, Scene, SceneParts, Shape, Transform,
    Vec3,
};

const SIZE: u32 = 64;
const BLOCK: u32 = 16;
/// Block channels the CPU renders at or below this are not judged.
const DARK_BLOCK: f64 = 1e-4;

type Pixels = Vec<Pixel>;

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

fn render_cpu(parts: &SceneParts, samples: u32, seed: u64) -> Pixels {
    let scene = Scene::new(parts.clone());
    let (film, stats) = glint_render::render(&scene, &settings(samples, seed), &|_| true).unwrap();
    assert_eq!(stats.nonfinite_samples, 0);
    to_pixels(&film.pixels)
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
    to_pixels(&film.pixels)
}

/// Renders `parts` on both back ends and applies the criterion, then the negative control.
fn compare(test: &str, parts: &SceneParts, gpu_samples: u32, cpu_samples: u32) {
    compare_with_control(test, parts, None, gpu_samples, cpu_samples);
}

/// `compare`, and where `without` is given (the scene with the feature under test taken
/// away), a second negative control: the GPU's render of `without` must fail against the
/// CPU's of `parts`, so the test can tell whether the feature was rendered at all.
fn compare_with_control(
    test: &str,
    parts: &SceneParts,
    without: Option<&SceneParts>,
    gpu_samples: u32,
    cpu_samples: u32,
) {
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
    let criterion = Criterion {
        dark_block: Some(DARK_BLOCK),
        ..Criterion::new(SIZE, SIZE, BLOCK)
    };
    let cpu = Reference::Halves(&r1, &r2);
    let verdict = judge(&criterion, (&g1, &g2), cpu);
    println!(
        "{test}: GPU {gpu_samples} spp ({gpu_seconds:.1} s) vs CPU {cpu_samples} spp \
         ({cpu_seconds:.1} s): {}",
        verdict.as_ref().unwrap_or_else(|e| e)
    );
    if let Err(failure) = verdict {
        panic!("{test}: {failure}");
    }
    let dark = judge(&criterion, (&scaled(&g1, 0.97), &scaled(&g2, 0.97)), cpu);
    println!(
        "{test}: GPU 3% darker (must fail): {}",
        dark.as_ref().unwrap_or_else(|e| e)
    );
    assert!(dark.is_err(), "{test}: a 3% darker GPU image passed");
    if let Some(without) = without {
        let w1 = render_gpu(&gpu, without, gpu_samples / 2, 1);
        let w2 = render_gpu(&gpu, without, gpu_samples / 2, 2);
        let verdict = judge(&criterion, (&w1, &w2), cpu);
        println!(
            "{test}: GPU without the feature (must fail): {}",
            verdict.as_ref().unwrap_or_else(|e| e)
        );
        assert!(
            verdict.is_err(),
            "{test}: the GPU without the feature passed"
        );
    }
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
        physical: Default::default(),
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
        physical: Default::default(),
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

/// A Mitsuba scene of physically based diffuse surfaces under every wrapper the scenes use:
/// Mitsuba's sphere with a checkerboard in its own uv, an OBJ sphere (corner normals and
/// uvs, scaled and turned) under a normal map, one under a blend by a nearest-lookup bitmap,
/// a floor under a bump map and a mask, lit by an area emitter (`tests/scenes/physical.xml`).
#[test]
fn physical_surfaces_and_wrappers_agree_with_the_cpu() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/physical.xml");
    let loaded = glint_io::load_scene(&path).unwrap_or_else(|error| panic!("{error}"));
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    compare(
        "physical",
        &loaded.parts,
        samples("GLINT_GPU_TEST_SPP", 256),
        samples("GLINT_CPU_TEST_SPP", 2048),
    );
}

// ---------------------------------------------------------------------------------------
// Mitsuba's emitters, its envmap, pixel filters, the thin lens and the scene's defaults.

/// A floor, three spheres (diffuse, glossy, mirror) and a back wall under `lights` and
/// `background`, seen from above the floor.
fn lit_scene(lights: Vec<Light>, background: Background) -> SceneParts {
    let materials = vec![
        Material::Diffuse {
            diffuse: Color::splat(0.7).into(),
        },
        Material::Diffuse {
            diffuse: Color::new(0.8, 0.3, 0.2).into(),
        },
        Material::BlinnPhong {
            diffuse: Color::new(0.2, 0.4, 0.7).into(),
            specular: Color::splat(0.3).into(),
            phong_exponent: 25.0,
            mirror_coef: 0.0,
        },
        Material::Mirror { roughness: 0.0 },
    ];
    SceneParts {
        physical: Default::default(),
        camera: Camera::new(
            Projection::Perspective,
            Vec3::new(0.0, 1.6, 4.0),
            Vec3::new(0.0, -0.35, -1.0),
            0.5,
            0.5,
        ),
        materials,
        textures: vec![],
        lights,
        background,
        geometries: vec![GeometryDesc {
            shapes: vec![
                Shape::Box {
                    min: Vec3::new(-3.0, -0.2, -3.0),
                    max: Vec3::new(3.0, 0.0, 3.0),
                },
                Shape::Box {
                    min: Vec3::new(-3.0, 0.0, -3.2),
                    max: Vec3::new(3.0, 1.2, -3.0),
                },
                Shape::Sphere {
                    center: Vec3::new(-0.9, 0.5, 0.0),
                    radius: 0.5,
                },
                Shape::Sphere {
                    center: Vec3::new(0.3, 0.5, -0.8),
                    radius: 0.5,
                },
                Shape::Sphere {
                    center: Vec3::new(1.1, 0.35, 0.7),
                    radius: 0.35,
                },
            ],
            materials: vec![0, 0, 1, 2, 3],
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    }
}

fn gpu_spp() -> u32 {
    samples("GLINT_GPU_TEST_SPP", 256)
}

fn cpu_spp() -> u32 {
    samples("GLINT_CPU_TEST_SPP", 2048)
}

/// A spot above the floor shining down (its +z turned to −y), the falloff ring between
/// the beam width and the cutoff inside the image.
fn spot_light() -> Light {
    Light::Spot {
        to_world: Transform::from_matrix(
            &Matrix4::translate(Vec3::new(-0.2, 3.0, 0.0)).mul(&Matrix4::rotate(0, 90.0)),
        )
        .unwrap(),
        intensity: Color::new(9.0, 8.0, 6.0),
        cutoff_angle: 32.0,
        beam_width: 20.0,
        texture: None,
    }
}

#[test]
fn spot_light_agrees_with_the_cpu() {
    let parts = lit_scene(vec![spot_light()], Background::Color(Color::ZERO));
    // Without the spot the image is black: a point light at its place instead.
    let point = lit_scene(
        vec![Light::Point {
            position: Vec3::new(-0.2, 3.0, 0.0),
            intensity: Color::new(9.0, 8.0, 6.0),
        }],
        Background::Color(Color::ZERO),
    );
    compare_with_control("spot", &parts, Some(&point), gpu_spp(), cpu_spp());
}

#[test]
fn directional_light_agrees_with_the_cpu() {
    let light = Light::Directional {
        direction: Vec3::new(0.4, -1.0, -0.3).normalized(),
        irradiance: Color::new(1.5, 1.4, 1.2),
    };
    let parts = lit_scene(vec![light], Background::Color(Color::ZERO));
    // The light from the other side: the shadows and shading move.
    let other = lit_scene(
        vec![Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.3).normalized(),
            irradiance: Color::new(1.5, 1.4, 1.2),
        }],
        Background::Color(Color::ZERO),
    );
    compare_with_control("directional", &parts, Some(&other), gpu_spp(), cpu_spp());
}

/// A 32x16 lat-long sky: a gradient from a blue zenith to a dark ground, with a small bright
/// sun, turned about y and tilted, times 1.2.
fn envmap(turn: f64) -> Background {
    let sky = image(32, 16, |x, y| {
        if (20..22).contains(&x) && (4..6).contains(&y) {
            Color::new(30.0, 26.0, 20.0)
        } else if y < 8 {
            Color::new(0.3, 0.45, 0.8) * (1.0 - y as f32 / 10.0) + Color::splat(0.02 * x as f32)
        } else {
            Color::new(0.15, 0.12, 0.1) * (1.0 + 0.05 * x as f32)
        }
    });
    Background::Environment {
        image: Box::new(sky),
        scale: 1.2,
        to_world: Transform::from_matrix(&Matrix4::rotate(1, turn).mul(&Matrix4::rotate(0, 10.0)))
            .unwrap(),
    }
}

#[test]
fn envmap_lights_and_is_seen_as_the_cpu_renders_it() {
    let parts = lit_scene(vec![], envmap(40.0));
    // The same map turned the other way.
    let turned = lit_scene(vec![], envmap(-40.0));
    compare_with_control("envmap", &parts, Some(&turned), gpu_spp(), cpu_spp());
}

/// A black box's slanted edge against a grey sky, seen by an orthographic camera: pixels away
/// from the edge are exact, pixels near it are what the filter makes of the edge.
fn edge_scene(filter: glint_render::PixelFilter) -> SceneParts {
    let mut parts = SceneParts {
        physical: Default::default(),
        camera: Camera::new(
            Projection::Orthographic,
            Vec3::new(0.0, 0.0, 5.0),
            -Vec3::Z,
            1.0,
            4.0,
        ),
        materials: vec![Material::Diffuse {
            diffuse: Color::ZERO.into(),
        }],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Color::new(0.8, 0.7, 0.6)),
        geometries: vec![GeometryDesc {
            shapes: vec![Shape::Box {
                min: Vec3::new(-4.0, -4.0, -1.0),
                max: Vec3::new(0.1, 4.0, 1.0),
            }],
            materials: vec![0],
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: Some(Transform::from_matrix(&Matrix4::rotate(2, 12.0)).unwrap()),
            material: None,
            casts_shadow: true,
        }],
    };
    parts.physical.defaults.filter = filter;
    parts
}

#[test]
fn tent_filter_agrees_with_the_cpu_and_differs_from_a_box() {
    use glint_render::PixelFilter;
    let tent = edge_scene(PixelFilter::Tent { radius: 1.0 });
    let boxed = edge_scene(PixelFilter::Box);
    compare_with_control("tent", &tent, Some(&boxed), gpu_spp(), cpu_spp());
}

#[test]
fn gaussian_filter_agrees_with_the_cpu_and_differs_from_a_box() {
    use glint_render::PixelFilter;
    let gaussian = edge_scene(PixelFilter::Gaussian { stddev: 0.5 });
    let boxed = edge_scene(PixelFilter::Box);
    compare_with_control("gaussian", &gaussian, Some(&boxed), gpu_spp(), cpu_spp());
}

/// The lit scene under a point and an area light.
fn course_lit_scene() -> SceneParts {
    lit_scene(
        vec![
            Light::Point {
                position: Vec3::new(2.0, 3.0, 2.5),
                intensity: Color::splat(6.0),
            },
            Light::Area {
                position: Vec3::new(0.0, 2.4, 0.5),
                normal: -Vec3::Y,
                width: 0.8,
                length: 0.6,
                intensity: Color::splat(5.0),
            },
        ],
        Background::Color(Color::new(0.1, 0.12, 0.15)),
    )
}

#[test]
fn thin_lens_agrees_with_the_cpu() {
    let pinhole = course_lit_scene();
    let mut lens = pinhole.clone();
    // Focused in front of the spheres: they and the wall blur by pixels.
    lens.camera.lens = Some(glint_render::ThinLens {
        focus_distance: 3.0,
        radius: 0.4,
    });
    compare_with_control("thin lens", &lens, Some(&pinhole), gpu_spp(), cpu_spp());
}

#[test]
fn hidden_emitters_agree_with_the_cpu() {
    let mut shown = course_lit_scene();
    // An emitting sphere in view, and a sky: hidden from the camera, not from the paths.
    shown.materials.push(Material::Emissive {
        radiance: Color::new(3.0, 2.0, 1.0),
        surface: None,
        light: Some(2),
    });
    shown.lights.push(Light::Sphere {
        center: Vec3::new(-1.0, 0.3, 1.5),
        radius: 0.3,
        intensity: Color::new(3.0, 2.0, 1.0),
    });
    shown.geometries[0].shapes.push(Shape::Sphere {
        center: Vec3::new(-1.0, 0.3, 1.5),
        radius: 0.3,
    });
    shown.geometries[0].materials.push(4);
    shown.background = Background::Color(Color::new(0.3, 0.4, 0.6));
    let mut hidden = shown.clone();
    hidden.physical.defaults.hide_emitters = true;
    compare_with_control("hide_emitters", &hidden, Some(&shown), gpu_spp(), cpu_spp());
}

/// `lit_scene` under three lights that read a texture node (a bilinear 4x4 bitmap, `flip`
/// mirroring it): a spot with a cone texture, a projector, and an area emitter of two
/// triangles whose radiance is textured, seen directly too (its uvs are the mesh's).
fn textured_lights_scene(flip: bool) -> SceneParts {
    use glint_render::{
        MeshAttributes, PhysicalParts, TexelFilter, TextureKind, TextureNode, Wrap,
    };
    let mut parts = lit_scene(vec![], Background::Color(Color::ZERO));
    parts.textures.push(image(4, 4, |x, y| {
        let x = if flip { 3 - x } else { x };
        Color::new(
            0.2 + 0.25 * x as f32,
            0.3 + 0.2 * y as f32,
            1.0 - 0.2 * x as f32,
        )
    }));
    parts.physical = PhysicalParts {
        textures: vec![TextureNode {
            kind: TextureKind::Bitmap {
                image: 0,
                filter: TexelFilter::Bilinear,
                wrap: [Wrap::Clamp; 2],
            },
            to_uv: glint_render::IDENTITY_UV,
            uv_set: 0,
        }],
        ..PhysicalParts::default()
    };
    let Light::Spot {
        to_world,
        intensity,
        cutoff_angle,
        beam_width,
        ..
    } = spot_light()
    else {
        unreachable!()
    };
    parts.lights.push(Light::Spot {
        to_world,
        intensity,
        cutoff_angle,
        beam_width,
        texture: Some(0),
    });
    parts.lights.push(Light::Projector {
        to_world: Transform::from_matrix(
            &Matrix4::translate(Vec3::new(1.5, 2.0, 2.0))
                .mul(&Matrix4::rotate(1, 200.0))
                .mul(&Matrix4::rotate(0, 35.0)),
        )
        .unwrap(),
        irradiance: 0,
        scale: 6.0,
        fov: 40.0,
    });
    // A quad above the scene, facing down, its corners' uvs spanning the image.
    let (a, b, c, d) = (
        Vec3::new(-1.6, 2.2, -1.8),
        Vec3::new(-0.4, 2.2, -1.8),
        Vec3::new(-0.4, 2.2, -0.6),
        Vec3::new(-1.6, 2.2, -0.6),
    );
    let triangles = vec![[a, c, b], [a, d, c]];
    let uvs = vec![
        [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0)],
        [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0)],
    ];
    let light = parts.lights.len() as u32;
    parts.lights.push(Light::TexturedTriangles {
        triangles: triangles.clone(),
        uvs: uvs.clone(),
        texture: 0,
        intensity: Color::splat(4.0),
    });
    parts.materials.push(Material::Emissive {
        radiance: Color::splat(4.0),
        surface: None,
        light: Some(light),
    });
    let emitter = parts.materials.len() as u32 - 1;
    parts.geometries.push(GeometryDesc {
        shapes: triangles
            .iter()
            .map(|&vertices| Shape::Triangle { vertices })
            .collect(),
        materials: vec![emitter; 2],
    });
    parts.physical.attributes = vec![
        None,
        Some(MeshAttributes {
            uvs: Some(uvs),
            ..MeshAttributes::default()
        }),
    ];
    parts.instances.push(Instance {
        geometry: 1,
        transform: None,
        material: None,
        casts_shadow: false,
    });
    parts
}

#[test]
fn textured_spot_projector_and_area_emitter_agree_with_the_cpu() {
    let parts = textured_lights_scene(false);
    // The same lights with their texture mirrored.
    let mirrored = textured_lights_scene(true);
    compare_with_control(
        "textured lights",
        &parts,
        Some(&mirrored),
        gpu_spp(),
        cpu_spp(),
    );
}

/// Every physically based family on spheres over a textured floor under an area light
/// (`tests/scenes/families.xml`): smooth and rough conductors (anisotropic GGX, Beckmann over
/// all normals), dielectric, roughdielectric, thindielectric, plastic, nonlinear roughplastic,
/// principled (metallic with clearcoat and sheen; transmissive), principledthin, a twosided
/// roughplastic.
#[test]
fn every_physical_family_agrees_with_the_cpu() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/families.xml");
    let loaded = glint_io::load_scene(&path).unwrap_or_else(|error| panic!("{error}"));
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    compare("families", &loaded.parts, gpu_spp(), cpu_spp());
}
