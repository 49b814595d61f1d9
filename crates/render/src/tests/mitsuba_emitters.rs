//! Mitsuba 3's emitters in the path tracer, against answers worked out on paper from Mitsuba's
//! definitions (`src/emitters/*.cpp` of Mitsuba 3.9): the environment map's lookup of a
//! direction, its sampling density's normalisation and an integral it must reproduce, the
//! directional light on a diffuse floor, the spot's falloff and texture, the projector's
//! irradiance and orientation, and a furnace lit by an environment map. Each check carries a
//! negative control: a deliberately wrong mapping, falloff or Jacobian that the same check
//! must reject.

use super::path_known_answers::{
    camera_looking_at_origin, floor, instance, path_settings, radiance_at,
};

/// A unit sphere (diffuse, albedo 0.5) at the origin, seen from 3 away, under a black sky.
fn furnace_parts() -> SceneParts {
    SceneParts {
        physical: PhysicalParts::default(),
        camera: camera_looking_at_origin(3.0),
        materials: vec![Material::Diffuse {
            diffuse: Color::splat(0.5).into(),
        }],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Color::ZERO),
        geometries: vec![GeometryDesc {
            shapes: vec![Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            }],
            materials: vec![0],
        }],
        instances: vec![instance(0, true)],
    }
}
use crate::integrator::path::{PathIntegrator, PathSettings};
use crate::light::envmap::{direction_to_uv, environment_radiance, uv_to_direction};
use crate::light::sampler::LightSampler;
use crate::sampling::Rng;
use crate::scene::physical::PhysicalParts;
use crate::texture::{TexelFilter, TextureKind, TextureNode, Wrap, IDENTITY_UV};
use crate::{
    render, Background, Color, GeometryDesc, Image, Light, Material, Matrix4, Scene, SceneParts,
    Shape, Transform, Vec3,
};

use std::f64::consts::PI;

/// Mitsuba's `lookat`: local +z along `target − origin`, +x = up × z (the camera's left),
/// +y = z × x.
fn look_at(origin: Vec3, target: Vec3, up: Vec3) -> Transform {
    let z = (target - origin).normalized();
    let x = up.cross(z).normalized();
    let y = z.cross(x);
    let mut m = Matrix4::IDENTITY;
    for (column, v) in [x, y, z, origin].into_iter().enumerate() {
        for (row, value) in v.to_array().into_iter().enumerate() {
            m.m[row][column] = value as f64;
        }
    }
    Transform::from_matrix(&m).expect("invertible")
}

fn rotation() -> Transform {
    let m = Matrix4::rotate(1, 70.0).mul(&Matrix4::rotate(0, -35.0));
    Transform::from_matrix(&m).expect("invertible")
}

/// An image whose texel (x, y) is (x, y, 1) + a small random part, so every texel differs.
fn distinct_image(width: u32, height: u32) -> Image {
    Image {
        width,
        height,
        texels: (0..width * height)
            .map(|i| Color::new((i % width) as f32, (i / width) as f32, 1.0))
            .collect(),
    }
}

fn close(a: Color, b: Color, tolerance: f32) -> bool {
    (a - b).abs().max_component() <= tolerance * b.abs().max_component().max(1.0)
}

// ---- envmap ------------------------------------------------------------------------------

/// The lookup as the check below computes it by hand: texel centres at u = (x + ½) / W, rows
/// at v = y / (H − 1), bilinear between them. `mapping` turns a local direction into (u, v).
fn envmap_lookup_check(
    mapping: &dyn Fn(Vec3) -> Color,
    image: &Image,
    to_world: &Transform,
) -> Result<(), String> {
    let (w, h) = (image.width, image.height);
    let texel = |x: u32, y: u32| image.texel(x % w, y);
    // Directions the map's own frame puts on texel centres, between two columns (across
    // u = 0 too) and between two rows, each with the value worked out by hand.
    let mut cases = vec![];
    // The poles' rows are left out: there every u is the same direction, and the u the
    // lookup reads is whatever atan2 makes of ±0.
    for y in 1..h - 1 {
        for x in 0..w {
            let u = (x as f32 + 0.5) / w as f32;
            let v = y as f32 / (h - 1) as f32;
            cases.push((u, v, texel(x, y)));
        }
    }
    // u = 0: halfway between the last column and the first.
    cases.push((
        0.0,
        1.0 / (h - 1) as f32,
        (texel(w - 1, 1) + texel(0, 1)) * 0.5,
    ));
    // A quarter of the way from column 1 to 2, a third of the way from row 0 to row 1.
    let u = (1.5 + 0.25) / w as f32;
    let v = (1.0 / 3.0) / (h - 1) as f32;
    let top = texel(1, 0) * 0.75 + texel(2, 0) * 0.25;
    let bottom = texel(1, 1) * 0.75 + texel(2, 1) * 0.25;
    cases.push((u, v, top * (2.0 / 3.0) + bottom * (1.0 / 3.0)));
    for (u, v, want) in cases {
        // The direction by Mitsuba's formula, written out: θ from +y, φ from −z towards +x.
        let (theta, phi) = (v * std::f32::consts::PI, u * 2.0 * std::f32::consts::PI);
        let local = Vec3::new(
            phi.sin() * theta.sin(),
            theta.cos(),
            -phi.cos() * theta.sin(),
        );
        let world = to_world.vector_to_world(local);
        let got = mapping(world);
        if !close(got, want, 1e-3) {
            return Err(format!("(u, v) = ({u}, {v}): got {got:?}, want {want:?}"));
        }
    }
    Ok(())
}

#[test]
fn envmap_looks_up_directions_as_mitsuba() {
    let image = distinct_image(5, 4);
    let to_world = rotation();
    let scale = 1.0;
    envmap_lookup_check(
        &|d| environment_radiance(&image, scale, &to_world, d),
        &image,
        &to_world,
    )
    .unwrap();
    // Through `Scene::background_radiance`, with a scale.
    let mut parts = furnace_parts();
    parts.background = Background::Environment {
        image: Box::new(image.clone()),
        scale: 2.5,
        to_world,
    };
    let scene = Scene::new(parts);
    envmap_lookup_check(
        &|d| scene.background_radiance(d) * (1.0 / 2.5),
        &image,
        &to_world,
    )
    .unwrap();
    // Negative controls: u measured from +z (pbrt's origin), the map not turned, v from −y.
    let from_plus_z = |d: Vec3| {
        let local = to_world.vector_to_object(d).normalized();
        let (u, v) = direction_to_uv(local);
        let turned = uv_to_direction(u + 0.5, v).0;
        environment_radiance(
            &image,
            1.0,
            &Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
            turned,
        )
    };
    assert!(envmap_lookup_check(&from_plus_z, &image, &to_world).is_err());
    let unturned = |d: Vec3| {
        environment_radiance(
            &image,
            1.0,
            &Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
            d,
        )
    };
    assert!(envmap_lookup_check(&unturned, &image, &to_world).is_err());
    let upside_down = |d: Vec3| environment_radiance(&image, 1.0, &to_world, -d);
    assert!(envmap_lookup_check(&upside_down, &image, &to_world).is_err());
}

/// Mitsuba pads maps to 2 x 3 texels by repeating the last column and row: a two-row map's
/// middle row is its second row, not the mean of both.
#[test]
fn envmap_pads_small_maps_as_mitsuba() {
    let identity = Transform::from_matrix(&Matrix4::IDENTITY).unwrap();
    let image = Image {
        width: 1,
        height: 2,
        texels: vec![Color::splat(1.0), Color::splat(3.0)],
    };
    let horizon = Vec3::new(1.0, 0.0, 0.0);
    assert_eq!(
        environment_radiance(&image, 1.0, &identity, horizon),
        Color::splat(3.0)
    );
    assert_eq!(
        environment_radiance(&image, 1.0, &identity, Vec3::Y),
        Color::splat(1.0)
    );
    let one = Image {
        width: 1,
        height: 1,
        texels: vec![Color::new(0.1, 0.2, 0.3)],
    };
    for d in [Vec3::X, Vec3::Y, -Vec3::Y, Vec3::new(0.3, -0.4, 0.8)] {
        assert!(close(
            environment_radiance(&one, 2.0, &identity, d),
            Color::new(0.2, 0.4, 0.6),
            1e-6
        ));
    }
}

/// A map with a bright spot, a black band and random texels.
fn test_envmap() -> Image {
    let (width, height) = (24u32, 12u32);
    let mut rng = Rng::new(41, 9);
    Image {
        width,
        height,
        texels: (0..width * height)
            .map(|i| {
                let (x, y) = (i % width, i / width);
                let base = Color::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                if y == 7 {
                    Color::ZERO
                } else if (x, y) == (5, 3) {
                    base * 80.0
                } else {
                    base
                }
            })
            .collect(),
    }
}

fn envmap_scene(image: Image, scale: f32, to_world: Transform) -> Scene {
    let mut parts = furnace_parts();
    parts.background = Background::Environment {
        image: Box::new(image),
        scale,
        to_world,
    };
    Scene::new(parts)
}

/// ∫ pdf dω over the sphere, in the map's (u, v) where dω = 2π² sin θ du dv, by the midpoint
/// rule on a grid `n` times finer than the sampling cells of `test_envmap`.
fn envmap_pdf_integral(pdf: &dyn Fn(Vec3) -> f64, to_world: &Transform, n: usize) -> f64 {
    // The sampling cells' edges (24 columns, 11 rows of cells) lie on the grid's lines.
    let (columns, rows) = (24 * n, 11 * n);
    let mut sum = 0.0;
    for j in 0..rows {
        for i in 0..columns {
            let u = (i as f64 + 0.5) / columns as f64;
            let v = (j as f64 + 0.5) / rows as f64;
            let (local, sin_theta) = uv_to_direction(u as f32, v as f32);
            let world = to_world.vector_to_world(local);
            sum += pdf(world) * 2.0 * PI * PI * sin_theta as f64;
        }
    }
    sum / (columns * rows) as f64
}

#[test]
fn envmap_pdf_integrates_to_one() {
    let to_world = rotation();
    let scene = envmap_scene(test_envmap(), 1.0, to_world);
    let sampler = LightSampler::new(&scene);
    let index = sampler.environment_index().expect("the map emits");
    let pdf = |d: Vec3| sampler.pdf_light_direction(index, Vec3::ZERO, d) as f64;
    let integral = envmap_pdf_integral(&pdf, &to_world, 8);
    println!("∫ envmap pdf dω = {integral:.6}");
    assert!((integral - 1.0).abs() < 2e-3, "{integral}");
    // Negative control: the density without its 1 / sin θ is not a density.
    let without_jacobian = |d: Vec3| {
        let local = to_world.vector_to_object(d).normalized();
        pdf(d) * (local.x * local.x + local.z * local.z).sqrt() as f64
    };
    let wrong = envmap_pdf_integral(&without_jacobian, &to_world, 8);
    println!("without the Jacobian: {wrong:.6}");
    assert!((wrong - 1.0).abs() > 0.05, "{wrong}");
}

/// Importance sampling the map reproduces its irradiance on a tilted plane, ∫ L cos⁺ dω,
/// worked out by quadrature of the lookup itself: the sampled pdf and the lookup agree about
/// where the light is. A sampler whose pdf lacks the sin θ Jacobian misses by far.
#[test]
fn envmap_sampling_reproduces_the_irradiance() {
    let to_world = rotation();
    let image = test_envmap();
    let scale = 1.7;
    let scene = envmap_scene(image.clone(), scale, to_world);
    let sampler = LightSampler::new(&scene);
    let index = sampler.environment_index().unwrap();
    let normal = Vec3::new(0.3, 0.8, -0.5).normalized();
    let lum = |c: Color| c.luminance() as f64;
    // Quadrature: midpoint rule in the map's (u, v), fine enough for bilinear texels.
    let (columns, rows) = (24 * 24, 12 * 48);
    let mut quadrature = 0.0;
    for j in 0..rows {
        for i in 0..columns {
            let u = (i as f64 + 0.5) / columns as f64;
            let v = (j as f64 + 0.5) / rows as f64;
            let (local, sin_theta) = uv_to_direction(u as f32, v as f32);
            let d = to_world.vector_to_world(local);
            let cos = d.dot(normal).max(0.0) as f64;
            quadrature +=
                lum(scene.background_radiance(d)) * cos * 2.0 * PI * PI * sin_theta as f64;
        }
    }
    quadrature /= (columns * rows) as f64;
    let estimate = |with_jacobian: bool| {
        let mut rng = Rng::new(12, 4);
        let n = 400_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let Some(s) =
                sampler.sample_light(&scene, index, Vec3::ZERO, (rng.next_f32(), rng.next_f32()))
            else {
                continue;
            };
            let cos = s.direction.dot(normal).max(0.0) as f64;
            let mut pdf = s.pdf as f64;
            if !with_jacobian {
                let local = to_world.vector_to_object(s.direction);
                pdf *= (local.x * local.x + local.z * local.z).sqrt() as f64;
            }
            sum += lum(s.radiance) * cos / pdf;
        }
        sum / n as f64
    };
    let (right, wrong) = (estimate(true), estimate(false));
    println!("irradiance: quadrature {quadrature:.5}, sampled {right:.5}, no Jacobian {wrong:.5}");
    assert!(
        (right / quadrature - 1.0).abs() < 0.01,
        "{right} vs {quadrature}"
    );
    assert!(
        (wrong / quadrature - 1.0).abs() > 0.05,
        "{wrong} vs {quadrature}"
    );
}

/// A white diffuse sphere inside a constant environment map of radiance 1 (a 3 x 2 map of
/// 0.4 times scale 2.5, turned) looks like the environment: the envmap's sampling, its pdf
/// and the path tracer's MIS add up to exactly 1.
#[test]
fn envmap_white_furnace() {
    let image = Image {
        width: 3,
        height: 2,
        texels: vec![Color::splat(0.4); 6],
    };
    let mut parts = furnace_parts();
    parts.background = Background::Environment {
        image: Box::new(image),
        scale: 2.5,
        to_world: rotation(),
    };
    parts.materials = vec![Material::Diffuse {
        diffuse: Color::ONE.into(),
    }];
    let scene = Scene::new(parts);
    let (film, _) = render(&scene, &path_settings(16, 64), &|_| true).expect("not cancelled");
    let mean: f64 = film
        .pixels
        .iter()
        .map(|p| (p.x + p.y + p.z) as f64 / 3.0)
        .sum::<f64>()
        / film.pixels.len() as f64;
    println!("envmap furnace: mean {mean:.5}");
    assert!((mean - 1.0).abs() < 0.01, "{mean}");
}

// ---- directional -------------------------------------------------------------------------

fn floor_scene(lights: Vec<Light>, physical: PhysicalParts, textures: Vec<Image>) -> Scene {
    let (geometry, material) = floor(0.6);
    Scene::new(SceneParts {
        physical,
        camera: camera_looking_at_origin(3.0),
        materials: vec![material],
        textures,
        lights,
        background: Background::Color(Color::ZERO),
        geometries: vec![geometry],
        instances: vec![instance(0, true)],
    })
}

/// The floor (albedo 0.6, facing +z) under a directional light: ρ/π · E · cos θ everywhere,
/// exactly (a delta light, a black background).
#[test]
fn directional_light_on_a_diffuse_floor() {
    let irradiance = Color::new(2.0, 1.0, 0.5);
    let travel = Vec3::new(0.5, -0.2, -0.8).normalized();
    let scene = floor_scene(
        vec![Light::Directional {
            direction: travel,
            irradiance,
        }],
        PhysicalParts::default(),
        vec![],
    );
    let integrator = PathIntegrator::new(&scene, PathSettings::default());
    let cos_theta = -travel.z;
    let right = irradiance * (0.6 / std::f32::consts::PI * cos_theta);
    // Negative control: irradiance taken as radiance at normal incidence (no cos θ).
    let wrong = irradiance * (0.6 / std::f32::consts::PI);
    for p in [Vec3::ZERO, Vec3::new(2.0, -3.0, 0.0)] {
        let got = radiance_at(&scene, &integrator, p, 4);
        println!("directional at {p:?}: got {got:?}, want {right:?}");
        assert!(close(got, right, 1e-4));
        assert!(!close(got, wrong, 1e-4));
    }
    // From below the floor the light does not arrive.
    let sampler = LightSampler::new(&scene);
    let sample = sampler
        .sample_light(&scene, 0, Vec3::ZERO, (0.5, 0.5))
        .unwrap();
    assert!(sample.is_delta && !sample.reachable_by_bsdf && sample.distance.is_infinite());
    assert_eq!(sample.direction, -travel);
}

// ---- point -------------------------------------------------------------------------------

/// Mitsuba's point light: intensity / r² arrives, whatever the direction.
#[test]
fn point_light_sends_intensity_over_distance_squared() {
    let intensity = Color::new(5.0, 4.0, 3.0);
    let position = Vec3::new(1.0, 2.0, 3.0);
    let scene = floor_scene(
        vec![Light::Point {
            position,
            intensity,
        }],
        PhysicalParts::default(),
        vec![],
    );
    let sampler = LightSampler::new(&scene);
    for reference in [Vec3::ZERO, Vec3::new(-4.0, 0.5, 1.0)] {
        let r2 = (position - reference).length_squared();
        let s = sampler
            .sample_light(&scene, 0, reference, (0.3, 0.7))
            .unwrap();
        assert!(close(s.radiance, intensity * (1.0 / r2), 1e-6));
        // Negative control: no falloff (the course's point light) is rejected.
        assert!(!close(s.radiance, intensity, 1e-6));
        assert!(s.is_delta && s.pdf == 1.0);
    }
}

// ---- spot --------------------------------------------------------------------------------

/// Mitsuba's falloff for a spot of `cutoff` and `beam` (degrees) at angle `theta` from its
/// axis: 1 inside the beam, linear in the angle to 0 at the cutoff.
fn mitsuba_falloff(theta: f64, cutoff: f64, beam: f64) -> f64 {
    if theta >= cutoff {
        0.0
    } else if theta <= beam {
        1.0
    } else {
        (cutoff - theta) / (cutoff - beam)
    }
}

/// The spot's radiance from points at angles `thetas` (degrees) off its axis and distance 2,
/// against `falloff`.
fn spot_check(
    scene: &Scene,
    origin: Vec3,
    to_world: &Transform,
    intensity: Color,
    falloff: &dyn Fn(f64) -> f64,
) -> Result<(), String> {
    let sampler = LightSampler::new(scene);
    for theta in [0.0f64, 10.0, 15.5, 22.5, 27.0, 29.5, 30.5, 60.0, 120.0] {
        let (s, c) = theta.to_radians().sin_cos();
        let local = Vec3::new(0.6 * s as f32, 0.8 * s as f32, c as f32);
        let distance = 2.0;
        let reference = origin + to_world.vector_to_world(local) * distance;
        let want = intensity * (falloff(theta) as f32 / (distance * distance));
        let got = sampler
            .sample_light(scene, 0, reference, (0.5, 0.5))
            .map_or(Color::ZERO, |s| s.radiance);
        if !close(got, want, 1e-4) {
            return Err(format!("θ = {theta}°: got {got:?}, want {want:?}"));
        }
    }
    Ok(())
}

#[test]
fn spot_light_falloff_is_mitsubas() {
    let origin = Vec3::new(0.5, 3.0, -1.0);
    let to_world = look_at(origin, Vec3::new(0.0, 0.0, 0.0), Vec3::Z);
    let intensity = Color::new(15.0, 10.0, 5.0);
    let scene = floor_scene(
        vec![Light::Spot {
            to_world,
            intensity,
            cutoff_angle: 30.0,
            beam_width: 15.0,
            texture: None,
        }],
        PhysicalParts::default(),
        vec![],
    );
    spot_check(&scene, origin, &to_world, intensity, &|t| {
        mitsuba_falloff(t, 30.0, 15.0)
    })
    .unwrap();
    // Negative control: pbrt's smoothstep in cos θ gives other values in the falloff.
    let smoothstep = |t: f64| {
        let (c, c0, c1) = (
            t.to_radians().cos(),
            30f64.to_radians().cos(),
            15f64.to_radians().cos(),
        );
        let x = ((c - c0) / (c1 - c0)).clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    };
    assert!(spot_check(&scene, origin, &to_world, intensity, &smoothstep).is_err());
    // A spot is a delta light: selection probability 1, pdf 1.
    let s = LightSampler::new(&scene)
        .sample(&scene, origin + Vec3::new(0.0, -2.0, 0.5), (0.4, 0.6))
        .unwrap();
    assert!(s.is_delta && s.pdf == 1.0 && !s.reachable_by_bsdf);
}

/// A 2 x 2 texture of four colours, nearest texels, as Mitsuba's `bitmap` with
/// `filter_type=nearest`.
fn quadrant_texture() -> (PhysicalParts, Vec<Image>) {
    let image = Image {
        width: 2,
        height: 2,
        texels: vec![
            Color::new(1.0, 0.0, 0.0),
            Color::new(0.0, 1.0, 0.0),
            Color::new(0.0, 0.0, 1.0),
            Color::new(1.0, 1.0, 1.0),
        ],
    };
    let physical = PhysicalParts {
        textures: vec![TextureNode {
            kind: TextureKind::Bitmap {
                image: 0,
                filter: TexelFilter::Nearest,
                wrap: [Wrap::Repeat; 2],
            },
            to_uv: IDENTITY_UV,
            uv_set: 0,
        }],
        ..PhysicalParts::default()
    };
    (physical, vec![image])
}

/// Which quadrant texel lights the point `local` (the light's frame) through a spot or
/// projector, by Mitsuba's uv: `u_sign`, `v_sign` say which way local +x and +y move u and v.
fn quadrant(local: Vec3, u_sign: f32, v_sign: f32) -> Color {
    let (u, v) = (0.5 + u_sign * local.x, 0.5 + v_sign * local.y);
    let image = quadrant_texture().1.remove(0);
    image.texel((u * 2.0) as u32, (v * 2.0) as u32)
}

fn textured_check(
    scene: &Scene,
    to_world: &Transform,
    u_sign: f32,
    v_sign: f32,
) -> Result<(), String> {
    let sampler = LightSampler::new(scene);
    for (x, y) in [(0.1f32, 0.1f32), (-0.1, 0.1), (0.1, -0.1), (-0.1, -0.1)] {
        let local = Vec3::new(x, y, 1.0);
        let reference = to_world.point_to_world(local * 1.5);
        let got = sampler
            .sample_light(scene, 0, reference, (0.5, 0.5))
            .map_or(Color::ZERO, |s| s.radiance);
        let want = quadrant(local, u_sign, v_sign);
        // Only the texel's colour is compared: the scale is the other tests' business.
        let got = got * (1.0 / got.max_component().max(1e-12));
        if !close(got, want, 1e-4) {
            return Err(format!("local ({x}, {y}): got {got:?}, want {want:?}"));
        }
    }
    Ok(())
}

/// Mitsuba's spot reads its texture at u = ½ + ½ x / (z tan cutoff), v likewise from y: local
/// +x and +y move up the texture's u and v (v = 0 is the top row).
#[test]
fn spot_light_texture_orientation() {
    let origin = Vec3::new(0.0, 3.0, 0.0);
    let to_world = look_at(origin, Vec3::ZERO, Vec3::Z);
    let (physical, textures) = quadrant_texture();
    let scene = floor_scene(
        vec![Light::Spot {
            to_world,
            intensity: Color::ONE,
            cutoff_angle: 30.0,
            beam_width: 20.0,
            texture: Some(0),
        }],
        physical,
        textures,
    );
    textured_check(&scene, &to_world, 1.0, 1.0).unwrap();
    // Negative control: a texture flipped in v.
    assert!(textured_check(&scene, &to_world, 1.0, -1.0).is_err());
}

// ---- projector ---------------------------------------------------------------------------

/// The floor (albedo 0.6) lit from 1 above by a projector looking straight down: Mitsuba's
/// projector gives radiance ρ/π · π · scale · E there, the same everywhere inside the
/// frustum (a constant texture projects to a constant irradiance on a plane at z = 1), and
/// nothing outside it.
#[test]
fn projector_irradiance_and_frustum() {
    let origin = Vec3::new(0.2, -0.3, 1.0);
    let to_world = look_at(origin, origin - Vec3::Z, Vec3::Y);
    let mut physical = PhysicalParts::default();
    physical.textures.push(TextureNode {
        kind: TextureKind::Checkerboard {
            color0: Color::new(0.5, 1.0, 2.0),
            color1: Color::new(0.5, 1.0, 2.0),
        },
        to_uv: IDENTITY_UV,
        uv_set: 0,
    });
    let scale = 3.0;
    let fov = 60.0f32;
    let scene = floor_scene(
        vec![Light::Projector {
            to_world,
            irradiance: 0,
            scale,
            fov,
        }],
        physical,
        vec![],
    );
    let integrator = PathIntegrator::new(&scene, PathSettings::default());
    let right = Color::new(0.5, 1.0, 2.0) * (0.6 * scale);
    // Negative control: the documented irradiance (no factor π).
    let wrong = right * (1.0 / std::f32::consts::PI);
    let half_width = (0.5 * fov).to_radians().tan();
    for (x, y) in [(0.0, 0.0), (0.9, 0.3), (-0.5, -0.9), (0.1, 0.95)] {
        let p = origin - Vec3::Z + Vec3::new(x * half_width, y * half_width, 0.0);
        let got = radiance_at(&scene, &integrator, p, 4);
        println!("projector at {p:?}: got {got:?}, want {right:?}");
        assert!(close(got, right, 1e-4));
        assert!(!close(got, wrong, 1e-4));
    }
    // Outside the frustum (the texture's aspect is 1: as wide as high) nothing arrives.
    for (x, y) in [(1.05, 0.0), (0.0, -1.05), (3.0, 3.0)] {
        let p = origin - Vec3::Z + Vec3::new(x * half_width, y * half_width, 0.0);
        assert_eq!(radiance_at(&scene, &integrator, p, 4), Color::ZERO, "{p:?}");
    }
}

/// Mitsuba's projector maps local +x (the camera's left) to smaller u and +y to smaller v
/// (towards the top row): the image appears upright seen from behind the projector.
#[test]
fn projector_texture_orientation() {
    let origin = Vec3::new(0.0, 3.0, 0.0);
    let to_world = look_at(origin, Vec3::ZERO, Vec3::Z);
    let (physical, textures) = quadrant_texture();
    let scene = floor_scene(
        vec![Light::Projector {
            to_world,
            irradiance: 0,
            scale: 1.0,
            fov: 60.0,
        }],
        physical,
        textures,
    );
    textured_check(&scene, &to_world, -1.0, -1.0).unwrap();
    // Negative control: the spot's orientation.
    assert!(textured_check(&scene, &to_world, 1.0, 1.0).is_err());
}

/// A non-square texture narrows the frustum in y by its aspect: with a 4 x 2 image, points at
/// 0.6 of the half-width up are outside, 0.4 inside.
#[test]
fn projector_frustum_follows_the_texture_aspect() {
    let origin = Vec3::new(0.0, 0.0, 1.0);
    let to_world = look_at(origin, Vec3::ZERO, Vec3::Y);
    let image = Image {
        width: 4,
        height: 2,
        texels: vec![Color::ONE; 8],
    };
    let physical = PhysicalParts {
        textures: vec![TextureNode {
            kind: TextureKind::Bitmap {
                image: 0,
                filter: TexelFilter::Bilinear,
                wrap: [Wrap::Clamp; 2],
            },
            to_uv: IDENTITY_UV,
            uv_set: 0,
        }],
        ..PhysicalParts::default()
    };
    let scene = floor_scene(
        vec![Light::Projector {
            to_world,
            irradiance: 0,
            scale: 1.0,
            fov: 90.0,
        }],
        physical,
        vec![image],
    );
    let sampler = LightSampler::new(&scene);
    let lit = |x: f32, y: f32| {
        sampler
            .sample_light(&scene, 0, Vec3::new(x, y, 0.0), (0.5, 0.5))
            .is_some()
    };
    assert!(lit(0.9, 0.0) && lit(-0.9, 0.4) && lit(0.0, -0.45));
    assert!(!lit(0.0, 0.6) && !lit(0.3, -0.55) && !lit(1.1, 0.0));
}
