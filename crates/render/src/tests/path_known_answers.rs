//! The path tracer on scenes whose answer is known in closed form, built by hand as
//! `SceneParts`: white furnaces (a lossless object inside a uniform environment of radiance 1
//! must look exactly like the environment), direct lighting from a point light, a small area
//! light, a triangle emitter and a sphere emitter, plus the render-loop properties the path
//! tracer promises (thread-count independence, no allocation per sample, denoiser features).

use crate::integrator::path::{PathIntegrator, PathSettings};
use crate::integrator::FirstHit;
use crate::sampling::Rng;
use crate::{
    render, Background, Camera, Color, GeometryDesc, Instance, IntegratorKind, Light, Material,
    Projection, Ray, RenderSettings, Scene, SceneParts, Shape, Vec3,
};

pub(super) fn instance(geometry: u32, casts_shadow: bool) -> Instance {
    Instance {
        geometry,
        transform: None,
        material: None,
        casts_shadow,
    }
}

pub(super) fn camera_looking_at_origin(distance: f32) -> Camera {
    Camera::new(
        Projection::Perspective,
        Vec3::new(0.0, 0.0, distance),
        -Vec3::Z,
        1.0,
        0.9,
    )
}

/// A unit sphere of `material` at the origin inside a uniform environment of radiance 1.
fn furnace(material: Material) -> Scene {
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: camera_looking_at_origin(3.0),
        materials: vec![material],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Color::ONE),
        geometries: vec![GeometryDesc {
            shapes: vec![Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            }],
            materials: vec![0],
        }],
        instances: vec![instance(0, true)],
    })
}

pub(super) fn path_settings(size: u32, samples: u32) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        samples_per_pixel: samples,
        seed: 11,
        integrator: IntegratorKind::Path,
        features: true,
        ..RenderSettings::default()
    }
}

/// Renders the furnace at `size`² pixels and returns the worst per-pixel error (over pixels and
/// channels) and the mean of the sphere's pixels minus 1.
fn furnace_errors(material: Material, size: u32, samples: u32) -> (f32, f32) {
    let scene = furnace(material);
    let (film, stats) =
        render(&scene, &path_settings(size, samples), &|_| true).expect("not cancelled");
    let normals = &film.features.as_ref().expect("features").normal;
    assert_eq!(stats.nonfinite_samples, 0);
    let mut worst = 0.0f32;
    let mut sum = 0.0f64;
    let mut sphere_pixels = 0;
    for (pixel, normal) in film.pixels.iter().zip(normals) {
        for channel in pixel.to_array() {
            worst = worst.max((channel - 1.0).abs());
        }
        if *normal != Vec3::ZERO {
            sum += (pixel.x + pixel.y + pixel.z) as f64 / 3.0;
            sphere_pixels += 1;
        }
    }
    assert!(
        sphere_pixels * 3 > size * size,
        "the sphere should fill much of the image"
    );
    (worst, (sum / sphere_pixels as f64 - 1.0) as f32)
}

#[test]
fn white_furnace_diffuse() {
    let (worst, mean) = furnace_errors(
        Material::Diffuse {
            diffuse: Color::ONE.into(),
        },
        12,
        32768,
    );
    println!(
        "white furnace, diffuse albedo 1, 32768 spp: worst pixel error {worst:.5}, mean − 1 {mean:.6}"
    );
    assert!(worst < 0.01, "a pixel is off by {worst}");
}

#[test]
fn white_furnace_lossless_materials() {
    // Every material that absorbs nothing must disappear into the furnace as well: a glaze over
    // a white base (0.7 diffuse + 0.3 mirror), a perfect mirror, and clear glass (the 1/η² of
    // entering and the η² of leaving must cancel).
    let cases = [
        (
            "Glaze (kd 1, km 0.3)",
            Material::Glaze {
                diffuse: Color::ONE.into(),
                mirror_coef: 0.3,
            },
            32768,
        ),
        ("Mirror", Material::Mirror { roughness: 0.0 }, 256),
        (
            "Dielectric (η 1.5)",
            Material::Dielectric {
                refractive_index: 1.5,
                attenuation: Color::ONE,
            },
            1024,
        ),
    ];
    for (name, material, samples) in cases {
        let (worst, mean) = furnace_errors(material, 12, samples);
        println!(
            "white furnace, {name}, {samples} spp: worst pixel error {worst:.5}, mean − 1 {mean:.6}"
        );
        assert!(worst < 0.01, "{name}: a pixel is off by {worst}");
    }
    // Materials that lose energy at grazing angles stay at or below 1 on average.
    let (_, mean_minus_one) = furnace_errors(
        Material::BlinnPhong {
            diffuse: Color::splat(0.5).into(),
            specular: Color::splat(0.5).into(),
            phong_exponent: 20.0,
            mirror_coef: 0.0,
        },
        12,
        256,
    );
    println!("furnace, BlinnPhong kd 0.5 ks 0.5, p 20: mean − 1 = {mean_minus_one:.4}");
    assert!(mean_minus_one < 0.0);
}

/// A floor (z = 0, 20 units wide) of `material` in a uniform environment of radiance 1, seen
/// straight down by an orthographic camera: every pixel sees the floor at normal incidence, and
/// everything that leaves the floor upwards reaches the environment, so every pixel's expected
/// value is the BSDF's directional albedo at normal incidence. Returns the mean over the
/// pixels and its standard error (the pixels are independent estimates of the same value).
fn floor_furnace(material: Material) -> (f64, f64) {
    let corner = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let (a, b, c, d) = (
        corner(-10.0, -10.0),
        corner(10.0, -10.0),
        corner(10.0, 10.0),
        corner(-10.0, 10.0),
    );
    let scene = Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(
            Projection::Orthographic,
            Vec3::new(0.0, 0.0, 3.0),
            -Vec3::Z,
            1.0,
            2.0,
        ),
        materials: vec![material],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Color::ONE),
        geometries: vec![GeometryDesc {
            shapes: vec![
                Shape::Triangle {
                    vertices: [a, b, c],
                },
                Shape::Triangle {
                    vertices: [a, c, d],
                },
            ],
            materials: vec![0, 0],
        }],
        instances: vec![instance(0, true)],
    });
    let (film, stats) = render(&scene, &path_settings(16, 256), &|_| true).expect("not cancelled");
    assert_eq!(stats.nonfinite_samples, 0);
    let values: Vec<f64> = film
        .pixels
        .iter()
        .map(|p| (p.x + p.y + p.z) as f64 / 3.0)
        .collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

/// Whether the floor furnace's mean is the known albedo, within five standard errors.
fn check_floor_furnace(
    name: &str,
    (mean, standard_error): (f64, f64),
    expected: f64,
) -> Result<(), String> {
    println!("floor furnace, {name}: {mean:.5} ± {standard_error:.5}, known answer {expected:.5}");
    if (mean - expected).abs() > 5.0 * standard_error + 1e-4 {
        return Err(format!(
            "{name}: {mean:.5} ± {standard_error:.5}, expected {expected:.5}"
        ));
    }
    Ok(())
}

/// BlinnPhong kd 0.5 ks 0.5 p 20 at normal incidence reflects 0.5 + 0.5 A(20), where
/// A(p) = 2(p+1)/(p+3) (1 − a^(p+3)) − (1 − a^(p+1)), a = 1/√2, is the Blinn-Phong lobe's
/// albedo at normal incidence (derived in `chi2_sampling.rs`,
/// `blinn_phong_albedo_at_normal_incidence`: the mean of cos 2θh over h drawn from
/// (p+1)/(2π) cos^p θh, above the horizon only). The sphere furnace above only bounds its
/// mean by 1; this pins the value, through the whole path tracer.
#[test]
fn furnace_blinn_phong_has_its_known_albedo() {
    let a = std::f64::consts::FRAC_1_SQRT_2;
    let p = 20.0f64;
    let lobe = 2.0 * (p + 1.0) / (p + 3.0) * (1.0 - a.powf(p + 3.0)) - (1.0 - a.powf(p + 1.0));
    let blinn_phong = |ks: f32| Material::BlinnPhong {
        diffuse: Color::splat(0.5).into(),
        specular: Color::splat(ks).into(),
        phong_exponent: p as f32,
        mirror_coef: 0.0,
    };
    let expected = 0.5 + 0.5 * lobe;
    check_floor_furnace(
        "BlinnPhong kd 0.5 ks 0.5 p 20",
        floor_furnace(blinn_phong(0.5)),
        expected,
    )
    .unwrap();
    // Negative controls, the same check on wrong surfaces: a black Blinn-Phong lobe (which
    // passed the sphere furnace's `mean − 1 < 0`), and one with 10% of its energy missing.
    for (name, ks) in [("black lobe", 0.0), ("lobe 10% dark", 0.45)] {
        assert!(
            check_floor_furnace(name, floor_furnace(blinn_phong(ks)), expected).is_err(),
            "{name} passed"
        );
    }
}

/// A square diffuse floor (z = 0, normal +z) of albedo `albedo`, 20 units wide.
pub(super) fn floor(albedo: f32) -> (GeometryDesc, Material) {
    let corner = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let (a, b, c, d) = (
        corner(-10.0, -10.0),
        corner(10.0, -10.0),
        corner(10.0, 10.0),
        corner(-10.0, 10.0),
    );
    (
        GeometryDesc {
            shapes: vec![
                Shape::Triangle {
                    vertices: [a, b, c],
                },
                Shape::Triangle {
                    vertices: [a, c, d],
                },
            ],
            materials: vec![0, 0],
        },
        Material::Diffuse {
            diffuse: Color::splat(albedo).into(),
        },
    )
}

/// The radiance the path tracer sees at floor point `p`, looking down from above, averaged
/// over `samples` independent samples.
pub(super) fn radiance_at(
    scene: &Scene,
    integrator: &PathIntegrator,
    p: Vec3,
    samples: u32,
) -> Color {
    let eye = p + Vec3::new(0.05, -0.03, 0.4);
    let ray = Ray::new(eye, p - eye);
    let mut sum = Color::ZERO;
    for s in 0..samples {
        let mut rng = Rng::for_sample(5, 17, s as u64);
        let mut rays = 0;
        let mut first_hit = FirstHit::default();
        sum += integrator.trace(scene, &ray, &mut rng, &mut rays, &mut first_hit);
    }
    sum / samples as f32
}

#[test]
fn point_light_direct_lighting_is_exact() {
    // L = ρ/π · I · cos θ / r², nothing else: the floor is the only surface and the background
    // is black, so the answer is deterministic.
    let albedo = 0.6;
    let intensity = Color::new(2.0, 3.0, 4.0);
    let light_position = Vec3::new(0.3, 0.2, 1.5);
    let (geometry, material) = floor(albedo);
    let scene = Scene::new(SceneParts {
        physical: Default::default(),
        camera: camera_looking_at_origin(3.0),
        materials: vec![material],
        textures: vec![],
        lights: vec![Light::Point {
            position: light_position,
            intensity,
        }],
        background: Background::Color(Color::ZERO),
        geometries: vec![geometry],
        instances: vec![instance(0, true)],
    });
    let integrator = PathIntegrator::new(&scene, PathSettings::default());
    for p in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.3, 0.2, 0.0),
        Vec3::new(-1.5, 2.0, 0.0),
    ] {
        let to_light = light_position - p;
        let r2 = to_light.length_squared();
        let cos_theta = to_light.normalized().z;
        let expected = intensity * (albedo * std::f32::consts::FRAC_1_PI * cos_theta / r2);
        let got = radiance_at(&scene, &integrator, p, 4);
        let error = ((got - expected).abs().max_component()) / expected.max_component();
        println!(
            "point light at {p:?}: expected {expected:?}, got {got:?}, rel. error {error:.2e}"
        );
        assert!(error < 1e-4);
    }
}

/// Irradiance at `p` (normal +z) from a Lambertian polygon of radiance 1, by Lambert's
/// formula: E = ½ Σ_i β_i (n · (r_i × r_{i+1}) / |r_i × r_{i+1}|), with r_i the unit vectors to
/// the vertices and β_i the angle between consecutive ones.
fn polygon_irradiance(p: Vec3, vertices: &[Vec3]) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..vertices.len() {
        let a = (vertices[i] - p).normalized();
        let b = (vertices[(i + 1) % vertices.len()] - p).normalized();
        let beta = (a.dot(b) as f64).clamp(-1.0, 1.0).acos();
        let normal = a.cross(b).normalized();
        sum += beta * normal.z as f64;
    }
    0.5 * sum.abs()
}

/// A floor under a one-sided emitter whose visible geometry carries `Material::Emissive` tied to
/// light 0, so BSDF samples that hit it are weighed against light sampling (MIS).
fn floor_under(light: Light, emitter_shapes: Vec<Shape>, casts_shadow: bool) -> Scene {
    let (geometry, material) = floor(0.5);
    let radiance = light.intensity();
    let emitter_count = emitter_shapes.len();
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: camera_looking_at_origin(3.0),
        materials: vec![
            material,
            Material::Emissive {
                radiance,
                surface: None,
                light: Some(0),
            },
        ],
        textures: vec![],
        lights: vec![light],
        background: Background::Color(Color::ZERO),
        geometries: vec![
            geometry,
            GeometryDesc {
                shapes: emitter_shapes,
                materials: vec![1; emitter_count],
            },
        ],
        instances: vec![instance(0, true), instance(1, casts_shadow)],
    })
}

/// The direct-lighting case of a planar emitter: one bounce (max depth 1), so the answer is
/// ρ/π · L · E(p) with E from Lambert's formula.
fn check_planar_emitter(name: &str, scene: &Scene, polygon: &[Vec3], radiance: f32) {
    let integrator = PathIntegrator::new(
        scene,
        PathSettings {
            max_depth: 1,
            ..PathSettings::default()
        },
    );
    for p in [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.7, -0.4, 0.0)] {
        let expected =
            0.5 / std::f64::consts::PI * radiance as f64 * polygon_irradiance(p, polygon);
        let got = radiance_at(scene, &integrator, p, 40_000);
        let error = (got.y as f64 - expected).abs() / expected;
        println!(
            "{name} at {p:?}: expected {expected:.5}, got {:.5}, rel. error {error:.2e}",
            got.y
        );
        assert!(error < 0.01, "{name}: {error}");
    }
}

#[test]
fn small_area_light_direct_lighting() {
    let (width, length, height) = (0.5, 0.3, 1.0);
    let light = Light::Area {
        position: Vec3::new(0.1, 0.0, height),
        normal: -Vec3::Z,
        width,
        length,
        intensity: Color::splat(5.0),
    };
    let Light::Area {
        position, normal, ..
    } = light
    else {
        unreachable!()
    };
    let (u, v) = Light::area_edges(normal, width, length);
    let corners = [
        position - u * 0.5 - v * 0.5,
        position + u * 0.5 - v * 0.5,
        position + u * 0.5 + v * 0.5,
        position - u * 0.5 + v * 0.5,
    ];
    // The loader's visible stand-in: two triangles that do not cast shadows (FORMAT.md A10).
    let shapes = vec![
        Shape::Triangle {
            vertices: [corners[0], corners[1], corners[2]],
        },
        Shape::Triangle {
            vertices: [corners[0], corners[2], corners[3]],
        },
    ];
    let scene = floor_under(light, shapes, false);
    check_planar_emitter("area light", &scene, &corners, 5.0);
}

#[test]
fn triangle_emitter_direct_lighting() {
    // Wound so that (v1 − v0) × (v2 − v0) points down, towards the floor.
    let triangle = [
        Vec3::new(-0.3, -0.2, 0.8),
        Vec3::new(0.1, 0.5, 0.8),
        Vec3::new(0.4, -0.3, 0.8),
    ];
    assert!(
        (triangle[1] - triangle[0])
            .cross(triangle[2] - triangle[0])
            .z
            < 0.0
    );
    let scene = floor_under(
        Light::Triangles {
            triangles: vec![triangle],
            intensity: Color::splat(3.0),
        },
        vec![Shape::Triangle { vertices: triangle }],
        true,
    );
    check_planar_emitter("triangle emitter", &scene, &triangle, 3.0);
    // Flipped, it emits upwards and the floor stays dark.
    let flipped = [triangle[0], triangle[2], triangle[1]];
    let dark = floor_under(
        Light::Triangles {
            triangles: vec![flipped],
            intensity: Color::splat(3.0),
        },
        vec![Shape::Triangle { vertices: flipped }],
        true,
    );
    let integrator = PathIntegrator::new(&dark, PathSettings::default());
    assert_eq!(
        radiance_at(&dark, &integrator, Vec3::ZERO, 256),
        Color::ZERO
    );
}

#[test]
fn sphere_emitter_direct_lighting() {
    // A sphere of radiance L seen from a point on the axis under it, wholly above the horizon:
    // E = π L sin²α = π L r²/d², so the floor shows ρ L r²/d².
    let (radius, distance, radiance) = (0.3f32, 1.2f32, 4.0f32);
    let center = Vec3::new(0.0, 0.0, distance);
    let scene = floor_under(
        Light::Sphere {
            center,
            radius,
            intensity: Color::splat(radiance),
        },
        vec![Shape::Sphere { center, radius }],
        true,
    );
    let integrator = PathIntegrator::new(
        &scene,
        PathSettings {
            max_depth: 1,
            ..PathSettings::default()
        },
    );
    let expected = 0.5 * radiance * radius * radius / (distance * distance);
    let got = radiance_at(&scene, &integrator, Vec3::ZERO, 40_000).y;
    let error = (got - expected).abs() / expected;
    println!("sphere emitter: expected {expected:.5}, got {got:.5}, rel. error {error:.2e}");
    assert!(error < 0.01);
}

#[test]
fn same_image_on_any_thread_count() {
    let scene = floor_under(
        Light::Sphere {
            center: Vec3::new(0.0, 0.0, 1.2),
            radius: 0.3,
            intensity: Color::splat(4.0),
        },
        vec![Shape::Sphere {
            center: Vec3::new(0.0, 0.0, 1.2),
            radius: 0.3,
        }],
        true,
    );
    let settings = path_settings(40, 9);
    let render_on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, &settings, &|_| true).unwrap())
    };
    let (one, one_stats) = render_on(1);
    let (three, three_stats) = render_on(3);
    assert_eq!(one, three);
    assert_eq!(one_stats, three_stats);
    // Without feature layers, the same beauty image.
    let plain = RenderSettings {
        features: false,
        ..settings.clone()
    };
    let (film, _) = render(&scene, &plain, &|_| true).unwrap();
    assert_eq!(film.pixels, one.pixels);
}

#[test]
fn denoiser_features() {
    // Looking straight down at the floor: albedo ρ, normal +z; the background where the ray
    // escapes. The floor's edge is out of view.
    let (geometry, _) = floor(0.5);
    let scene = Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(
            Projection::Perspective,
            Vec3::new(0.0, 0.0, 2.0),
            -Vec3::Z,
            1.0,
            1.0,
        ),
        materials: vec![Material::Lambertian {
            diffuse: Color::new(0.2, 0.4, 0.6).into(),
        }],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Color::splat(3.0)),
        geometries: vec![geometry],
        instances: vec![instance(0, true)],
    });
    let (film, _) = render(&scene, &path_settings(8, 4), &|_| true).unwrap();
    let features = film.features.expect("features");
    for (albedo, normal) in features.albedo.iter().zip(&features.normal) {
        assert!((*albedo - Color::new(0.2, 0.4, 0.6)).abs().max_component() < 1e-6);
        assert!((*normal - Vec3::Z).abs().max_component() < 1e-6);
    }
}
