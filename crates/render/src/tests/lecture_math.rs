//! Unit tests of the course's lecture math (FORMAT.md 1.2, 2.8, 4.1-4.3) against the public
//! API of `glint-render`: bases, camera rays, ray-primitive intersection, transforms,
//! reflection/refraction, spawned-ray offsets and scene-level closest-hit queries.
//!
//! Expected values are computed by hand from the lecture formulas (or from an independent
//! geometric argument), never copied from the implementation's output.

use crate::geometry::{
    intersect_box, intersect_sphere, intersect_triangle, slab_interval, PrimitiveHit,
};
use crate::integrator::course::{reflect, refract, schlick};
use crate::math::Frame;
use crate::ray::SPAWN_EPSILON;
use crate::sampling::{sample_uniform_sphere, Rng};
use crate::scene::SurfaceNeeds;
use crate::{
    Background, Camera, GeometryDesc, Instance, Material, Matrix4, Projection, Ray, Scene,
    SceneParts, Shape, Transform, Vec3,
};

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

#[track_caller]
fn assert_close(actual: f32, expected: f32, tol: f32, what: &str) {
    assert!(
        (actual - expected).abs() <= tol,
        "{what}: expected {expected}, got {actual} (|diff| = {} > {tol})",
        (actual - expected).abs()
    );
}

#[track_caller]
fn assert_vec_close(actual: Vec3, expected: Vec3, tol: f32, what: &str) {
    let d = actual - expected;
    assert!(
        d.x.abs() <= tol && d.y.abs() <= tol && d.z.abs() <= tol,
        "{what}: expected {expected:?}, got {actual:?} (tol {tol})"
    );
}

/// |U| = |V| = |W| = 1, pairwise orthogonal, U x V = W (right-handed), all finite.
#[track_caller]
fn assert_orthonormal_right_handed(b: &Frame, what: &str) {
    assert!(
        b.u.is_finite() && b.v.is_finite() && b.w.is_finite(),
        "{what}: non-finite basis {b:?}"
    );
    assert_close(b.u.length(), 1.0, 1e-6, &format!("{what}: |U|"));
    assert_close(b.v.length(), 1.0, 1e-6, &format!("{what}: |V|"));
    assert_close(b.w.length(), 1.0, 1e-6, &format!("{what}: |W|"));
    assert_close(b.u.dot(b.v), 0.0, 1e-6, &format!("{what}: U.V"));
    assert_close(b.v.dot(b.w), 0.0, 1e-6, &format!("{what}: V.W"));
    assert_close(b.w.dot(b.u), 0.0, 1e-6, &format!("{what}: W.U"));
    assert_vec_close(b.u.cross(b.v), b.w, 1e-6, &format!("{what}: U x V = W"));
    assert_vec_close(b.v.cross(b.w), b.u, 1e-6, &format!("{what}: V x W = U"));
}

fn rng(stream: u64) -> Rng {
    Rng::new(0x5eed_1ec7, stream)
}

/// A uniformly random unit vector.
fn random_unit(r: &mut Rng) -> Vec3 {
    let (a, b) = (r.next_f32(), r.next_f32());
    sample_uniform_sphere(a, b)
}

/// A uniformly random point in the ball of radius `radius` around `center`.
fn random_in_ball(r: &mut Rng, center: Vec3, radius: f32) -> Vec3 {
    center + random_unit(r) * (radius * r.next_f32().cbrt())
}

/// A random unit vector perpendicular to unit `n`.
fn random_perpendicular(r: &mut Rng, n: Vec3) -> Vec3 {
    loop {
        let t = random_unit(r);
        let p = t - n * t.dot(n);
        if p.length() > 0.1 {
            return p.normalized();
        }
    }
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

fn ray_window(origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> Ray {
    Ray {
        origin,
        direction,
        t_min,
        t_max,
    }
}

fn any_camera() -> Camera {
    Camera::new(
        Projection::Perspective,
        v(0.0, 0.0, 10.0),
        v(0.0, 0.0, -1.0),
        1.0,
        0.5,
    )
}

fn scene_from(geometries: Vec<GeometryDesc>, instances: Vec<Instance>) -> Scene {
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: any_camera(),
        materials: vec![Material::fallback()],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Vec3::ZERO),
        geometries,
        instances,
    })
}

fn identity_instance(geometry: u32) -> Instance {
    Instance {
        geometry,
        transform: None,
        material: None,
        casts_shadow: true,
    }
}

/// A scene holding `shapes` in one geometry, placed once without a transform.
fn plain_scene(shapes: Vec<Shape>) -> Scene {
    let materials = vec![0; shapes.len()];
    scene_from(
        vec![GeometryDesc { shapes, materials }],
        vec![identity_instance(0)],
    )
}

fn matrix_close(a: &Matrix4, b: &Matrix4, tol: f64) -> bool {
    (0..4).all(|i| (0..4).all(|j| (a.m[i][j] - b.m[i][j]).abs() <= tol))
}

// ---------------------------------------------------------------------------------------------
// 1. Bases (slide001 pp.18-20, FORMAT.md 1.2, 4.2, A1)
// ---------------------------------------------------------------------------------------------

#[test]
fn basis_from_two_default_gaze_is_the_world_frame() {
    let b = Frame::from_two(v(0.0, 0.0, -1.0), Vec3::Y);
    assert_vec_close(b.u, v(1.0, 0.0, 0.0), 1e-7, "U");
    assert_vec_close(b.v, v(0.0, 1.0, 0.0), 1e-7, "V");
    assert_vec_close(b.w, v(0.0, 0.0, 1.0), 1e-7, "W");
}

#[test]
fn basis_from_two_hand_computed_tilted_and_sideways_gazes() {
    // Camera at (0,3,4) looking at the origin: W = (0,3,4)/5, U = Y x W / |Y x W| = (1,0,0),
    // V = W x U = (0, 0.8, -0.6).
    let b = Frame::from_two(v(0.0, -3.0, -4.0), Vec3::Y);
    assert_vec_close(b.w, v(0.0, 0.6, 0.8), 1e-6, "tilted W");
    assert_vec_close(b.u, v(1.0, 0.0, 0.0), 1e-6, "tilted U");
    assert_vec_close(b.v, v(0.0, 0.8, -0.6), 1e-6, "tilted V");

    // Looking along +X with up +Y: W = (-1,0,0), U = Y x W = (0,0,1), V = (0,1,0).
    let b = Frame::from_two(v(2.0, 0.0, 0.0), Vec3::Y);
    assert_vec_close(b.w, v(-1.0, 0.0, 0.0), 1e-7, "+X gaze W");
    assert_vec_close(b.u, v(0.0, 0.0, 1.0), 1e-7, "+X gaze U");
    assert_vec_close(b.v, v(0.0, 1.0, 0.0), 1e-7, "+X gaze V");
}

#[test]
fn basis_from_two_is_orthonormal_right_handed_with_w_against_gaze() {
    let mut gazes = vec![
        v(0.0, 0.0, -1.0),
        v(0.0, 0.0, 1.0),
        v(1.0, 0.0, 0.0),
        v(-1.0, 0.0, 0.0),
        v(0.0, -3.0, -4.0),
        v(0.1871, 0.6359, -0.7488), // boxSphereTest.xml's viewDir
        v(-2.0, -1.0, 3.5),
        v(1e-3, -1.0, 0.0), // almost straight down
        v(0.0, 7.0, 1e-4),  // almost straight up, not unit
    ];
    let mut r = rng(1);
    for _ in 0..200 {
        gazes.push(random_unit(&mut r) * lerp(0.01, 100.0, r.next_f32()));
    }
    for g in gazes {
        let b = Frame::from_two(g, Vec3::Y);
        let what = format!("from_two({g:?})");
        assert_orthonormal_right_handed(&b, &what);
        assert_vec_close(b.w, -g / g.length(), 1e-6, &format!("{what}: W = -g/|g|"));
        // Lecture: U is perpendicular to up (b x W is), so the horizon stays level; unless the
        // gaze is (nearly) vertical, U has no Y component and V points "up" (V.Y > 0).
        let horiz = (g.x * g.x + g.z * g.z).sqrt() / g.length();
        if horiz > 1e-3 {
            assert_close(b.u.y, 0.0, 1e-6, &format!("{what}: U.y"));
            assert!(b.v.y > 0.0, "{what}: V should point up, got {:?}", b.v);
        }
    }
}

#[test]
fn basis_from_two_degenerate_gaze_parallel_to_up() {
    // A1: when the gaze is parallel to b = (0,1,0) the implementation documents KV's choice,
    // b = (1,0,0): U = X x W / |X x W|, V = W x U.
    //
    // Gaze (0,-1,0) (StanfordBunny.json): W = (0,1,0), X x W = (0,0,1), so U = (0,0,1) and
    // V = W x U = (1,0,0): image-right is +Z, image-up is +X.
    for g in [v(0.0, -1.0, 0.0), v(0.0, -5.0, 0.0)] {
        let b = Frame::from_two(g, Vec3::Y);
        let what = format!("from_two({g:?})");
        assert_orthonormal_right_handed(&b, &what);
        assert_vec_close(b.w, v(0.0, 1.0, 0.0), 1e-7, &format!("{what}: W"));
        assert_vec_close(b.u, v(0.0, 0.0, 1.0), 1e-7, &format!("{what}: U = X x W"));
        assert_vec_close(b.v, v(1.0, 0.0, 0.0), 1e-7, &format!("{what}: V = W x U"));
    }
    // Gaze (0,1,0): W = (0,-1,0), U = X x W = (0,0,-1), V = W x U = (1,0,0).
    let b = Frame::from_two(v(0.0, 1.0, 0.0), Vec3::Y);
    assert_orthonormal_right_handed(&b, "from_two((0,1,0))");
    assert_vec_close(b.w, v(0.0, -1.0, 0.0), 1e-7, "up gaze W");
    assert_vec_close(b.u, v(0.0, 0.0, -1.0), 1e-7, "up gaze U = X x W");
    assert_vec_close(b.v, v(1.0, 0.0, 0.0), 1e-7, "up gaze V");
}

#[test]
fn basis_from_one_hand_computed() {
    // slide001 p.18: a = (0,0,-1): W = (0,0,1); smallest |component| of W is x (first of the
    // ties), so t = (1,0,1); U = t x W / |t x W| = (0,-1,0); V = W x U = (1,0,0).
    let b = Frame::from_one(v(0.0, 0.0, -1.0));
    assert_vec_close(b.w, v(0.0, 0.0, 1.0), 1e-7, "W");
    assert_vec_close(b.u, v(0.0, -1.0, 0.0), 1e-7, "U");
    assert_vec_close(b.v, v(1.0, 0.0, 0.0), 1e-7, "V");
}

#[test]
fn basis_from_one_is_orthonormal_right_handed_with_w_against_a() {
    let mut dirs = vec![
        v(1.0, 0.0, 0.0),
        v(-1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
        v(0.0, -1.0, 0.0), // an area light facing down
        v(0.0, 0.0, 1.0),
        v(0.0, 0.0, -1.0),
        v(1.0, 1.0, 1.0),
        v(-3.0, 0.5, 0.25),
        v(0.0, -2.0, 1e-5),
    ];
    let mut r = rng(2);
    for _ in 0..200 {
        dirs.push(random_unit(&mut r) * lerp(0.01, 50.0, r.next_f32()));
    }
    for a in dirs {
        let b = Frame::from_one(a);
        let what = format!("from_one({a:?})");
        assert_orthonormal_right_handed(&b, &what);
        assert_vec_close(b.w, -a / a.length(), 1e-6, &format!("{what}: W = -a/|a|"));
    }
}

// ---------------------------------------------------------------------------------------------
// 2. Camera (FORMAT.md 1.2)
// ---------------------------------------------------------------------------------------------

#[test]
fn perspective_camera_pixel_centres_follow_the_lecture_mapping() {
    let cam = Camera::new(
        Projection::Perspective,
        Vec3::ZERO,
        v(0.0, 0.0, -1.0),
        1.0,
        0.5,
    );
    let (nx, ny) = (250u32, 250u32);
    // u = l + (r-l)(i+0.5)/nx with l = -0.25, r = 0.25; v likewise (square image).
    let uv = |i: u32| -0.25 + 0.5 * (i as f32 + 0.5) / 250.0;
    for (i, j) in [
        (0, 0),
        (249, 249),
        (0, 249),
        (249, 0),
        (125, 125),
        (124, 124),
        (37, 200),
    ] {
        let ray = cam.ray(i as f32 + 0.5, j as f32 + 0.5, nx, ny, 1.0);
        let what = format!("pixel ({i},{j})");
        assert_vec_close(ray.origin, Vec3::ZERO, 0.0, &format!("{what} origin"));
        assert_vec_close(
            ray.direction,
            v(uv(i), uv(j), -1.0),
            1e-6,
            &format!("{what} direction"),
        );
        assert_eq!(ray.t_min, 0.0, "{what}: camera rays start at t = 0");
        assert_eq!(
            ray.t_max,
            f32::INFINITY,
            "{what}: camera rays are unbounded"
        );
    }
    // Hand values for the corner pixels: -0.25 + 0.5 * 0.5 / 250 = -0.249.
    let ray = cam.ray(0.5, 0.5, nx, ny, 1.0);
    assert_vec_close(ray.direction, v(-0.249, -0.249, -1.0), 1e-6, "bottom-left");
    let ray = cam.ray(249.5, 249.5, nx, ny, 1.0);
    assert_vec_close(ray.direction, v(0.249, 0.249, -1.0), 1e-6, "top-right");
    // The exact centre of the image plane looks straight down the gaze.
    let ray = cam.ray(125.0, 125.0, nx, ny, 1.0);
    assert_vec_close(ray.direction, v(0.0, 0.0, -1.0), 1e-6, "image centre");
    // Image-plane corners (pixel units (0,0) and (nx,ny)) are (l,b) and (r,t).
    let ray = cam.ray(0.0, 0.0, nx, ny, 1.0);
    assert_vec_close(
        ray.direction,
        v(-0.25, -0.25, -1.0),
        1e-6,
        "plane corner (l,b)",
    );
    let ray = cam.ray(250.0, 250.0, nx, ny, 1.0);
    assert_vec_close(
        ray.direction,
        v(0.25, 0.25, -1.0),
        1e-6,
        "plane corner (r,t)",
    );
}

#[test]
fn perspective_camera_uses_position_focal_length_and_basis() {
    // Camera at (1,2,3) gazing along +X: W = (-1,0,0), U = (0,0,1), V = (0,1,0).
    // Direction = -f W + u U + v V = (f, v, u).
    let cam = Camera::new(
        Projection::Perspective,
        v(1.0, 2.0, 3.0),
        v(4.0, 0.0, 0.0),
        2.0,
        1.0,
    );
    let ray = cam.ray(0.5, 99.5, 100, 100, 1.0);
    let (u, vv) = (-0.5 + 0.5 / 100.0, -0.5 + 99.5 / 100.0);
    assert_vec_close(ray.origin, v(1.0, 2.0, 3.0), 0.0, "origin = e");
    assert_vec_close(ray.direction, v(2.0, vv, u), 1e-6, "direction");
    // Camera at (0,3,4) looking at the origin, f = 2: the centre ray is -2W = (0,-1.2,-1.6).
    let cam = Camera::new(
        Projection::Perspective,
        v(0.0, 3.0, 4.0),
        v(0.0, -3.0, -4.0),
        2.0,
        0.5,
    );
    let ray = cam.ray(50.0, 50.0, 100, 100, 1.0);
    assert_vec_close(ray.direction, v(0.0, -1.2, -1.6), 1e-6, "tilted centre ray");
    // Moving up the image moves along V = (0, 0.8, -0.6): top edge is v = +0.25.
    let ray = cam.ray(50.0, 100.0, 100, 100, 1.0);
    assert_vec_close(
        ray.direction,
        v(0.0, -1.2 + 0.25 * 0.8, -1.6 - 0.25 * 0.6),
        1e-6,
        "tilted top-centre ray",
    );
}

#[test]
fn orthographic_camera_rays_are_parallel_and_spread_over_the_image_plane() {
    let e = v(1.0, 2.0, 3.0);
    let make = |f: f32| Camera::new(Projection::Orthographic, e, v(0.0, 0.0, -1.0), f, 16.0);
    let cam = make(1.0);
    let other_f = make(5.0);
    let (nx, ny) = (250u32, 250u32);
    let uv = |i: u32| -8.0 + 16.0 * (i as f32 + 0.5) / 250.0;
    let mut origins = Vec::new();
    for (i, j) in [(0, 0), (249, 249), (0, 249), (125, 3), (60, 190)] {
        let ray = cam.ray(i as f32 + 0.5, j as f32 + 0.5, nx, ny, 1.0);
        let what = format!("ortho pixel ({i},{j})");
        // Direction is -W = the gaze, for every pixel.
        assert_vec_close(ray.direction, v(0.0, 0.0, -1.0), 1e-7, &what);
        // Origin is e + u U + v V on the plane through e perpendicular to the gaze.
        assert_vec_close(
            ray.origin,
            e + v(uv(i), uv(j), 0.0),
            1e-5,
            &format!("{what} origin"),
        );
        // Focal length is ignored by the orthographic camera.
        let ray_f = other_f.ray(i as f32 + 0.5, j as f32 + 0.5, nx, ny, 1.0);
        assert_vec_close(
            ray_f.origin,
            ray.origin,
            1e-6,
            &format!("{what}: f ignored"),
        );
        assert_vec_close(
            ray_f.direction,
            ray.direction,
            1e-7,
            &format!("{what}: f ignored"),
        );
        origins.push(ray.origin);
    }
    // Hand value: bottom-left pixel centre at u = v = -8 + 16 * 0.5 / 250 = -7.968.
    assert_vec_close(origins[0], v(1.0 - 7.968, 2.0 - 7.968, 3.0), 1e-5, "corner");
    // The origins are spread, not all at e: opposite corners are 2 * 7.968 apart per axis.
    assert_close(origins[1].x - origins[0].x, 15.936, 1e-4, "spread x");
    assert_close(origins[1].y - origins[0].y, 15.936, 1e-4, "spread y");

    // A tilted orthographic camera: direction is still -W for all pixels.
    let tilted = Camera::new(
        Projection::Orthographic,
        Vec3::ZERO,
        v(0.0, -3.0, -4.0),
        1.0,
        2.0,
    );
    for (px, py) in [(0.5, 0.5), (99.5, 0.5), (42.0, 77.0)] {
        let ray = tilted.ray(px, py, 100, 100, 1.0);
        assert_vec_close(ray.direction, v(0.0, -0.6, -0.8), 1e-6, "tilted ortho dir");
        // Origins lie in the plane through e perpendicular to W.
        assert_close(
            ray.origin.dot(v(0.0, 0.6, 0.8)),
            0.0,
            1e-6,
            "origin in plane",
        );
    }
}

#[test]
fn non_square_image_has_height_w_over_aspect_and_square_pixels() {
    let cam = Camera::new(
        Projection::Perspective,
        Vec3::ZERO,
        v(0.0, 0.0, -1.0),
        1.0,
        0.5,
    );
    let (nx, ny) = (200u32, 100u32);
    let aspect = nx as f32 / ny as f32;
    // Height = w * ny / nx = 0.25: corners at (+-0.25, +-0.125).
    let ray = cam.ray(0.0, 0.0, nx, ny, aspect);
    assert_vec_close(ray.direction, v(-0.25, -0.125, -1.0), 1e-6, "(l,b)");
    let ray = cam.ray(200.0, 100.0, nx, ny, aspect);
    assert_vec_close(ray.direction, v(0.25, 0.125, -1.0), 1e-6, "(r,t)");
    // Top-right pixel centre: u = -0.25 + 0.5 * 199.5/200, v = -0.125 + 0.25 * 99.5/100.
    let ray = cam.ray(199.5, 99.5, nx, ny, aspect);
    assert_vec_close(
        ray.direction,
        v(0.24875, 0.12375, -1.0),
        1e-6,
        "top-right pixel",
    );
    // Square pixels: one pixel step moves u and v by the same amount (0.0025).
    let a = cam.ray(10.5, 10.5, nx, ny, aspect).direction;
    let b = cam.ray(11.5, 10.5, nx, ny, aspect).direction;
    let c = cam.ray(10.5, 11.5, nx, ny, aspect).direction;
    assert_close(b.x - a.x, 0.0025, 1e-6, "du per pixel");
    assert_close(c.y - a.y, 0.0025, 1e-6, "dv per pixel");
    // A portrait image (100x200): height = 1.0 for w = 0.5.
    let ray = cam.ray(100.0, 200.0, 100, 200, 0.5);
    assert_vec_close(ray.direction, v(0.25, 0.5, -1.0), 1e-6, "portrait (r,t)");
}

// ---------------------------------------------------------------------------------------------
// 3. Ray-sphere (slide001 quadratic)
// ---------------------------------------------------------------------------------------------

const SPHERE_C: Vec3 = Vec3::new(0.0, 0.0, -5.0);

#[test]
fn sphere_two_roots_returns_the_nearer() {
    let h = intersect_sphere(&Ray::new(Vec3::ZERO, v(0.0, 0.0, -1.0)), SPHERE_C, 1.0)
        .expect("ray through the centre hits");
    assert_close(h.t, 4.0, 1e-6, "near root");
    // An off-centre chord: origin (0.6,0,0): roots where z = -5 -+ 0.8, near t = 4.2.
    let h = intersect_sphere(
        &Ray::new(v(0.6, 0.0, 0.0), v(0.0, 0.0, -1.0)),
        SPHERE_C,
        1.0,
    )
    .expect("off-centre chord hits");
    assert_close(h.t, 4.2, 1e-5, "off-centre near root");
    // A diagonal ray from (3,0,-5+... ): origin (-3,-3,-5) along (1,1,0)/sqrt2 meets the sphere
    // at distance 3 sqrt2 - 1.
    let d = v(1.0, 1.0, 0.0).normalized();
    let h = intersect_sphere(&Ray::new(v(-3.0, -3.0, -5.0), d), SPHERE_C, 1.0).expect("diag");
    assert_close(h.t, 3.0 * 2f32.sqrt() - 1.0, 1e-5, "diagonal near root");
    // A farther sphere: centre 100 units away, t = 99 exactly.
    let h = intersect_sphere(
        &Ray::new(Vec3::ZERO, v(0.0, 0.0, -1.0)),
        v(0.0, 0.0, -100.0),
        1.0,
    )
    .expect("far sphere hits");
    assert_close(h.t, 99.0, 1e-4, "far sphere");
}

#[test]
fn sphere_tangent_ray_hits_once_at_the_tangent_point() {
    // Origin (1,0,0) along -Z touches the unit sphere at (1,0,-5): discriminant 0.
    let ray = Ray::new(v(1.0, 0.0, 0.0), v(0.0, 0.0, -1.0));
    let h = intersect_sphere(&ray, SPHERE_C, 1.0).expect("tangent ray touches");
    assert_close(h.t, 5.0, 1e-5, "tangent t");
    assert_vec_close(ray.at(h.t), v(1.0, 0.0, -5.0), 1e-5, "tangent point");
    // Slightly further out: a miss.
    let ray = Ray::new(v(1.001, 0.0, 0.0), v(0.0, 0.0, -1.0));
    assert!(
        intersect_sphere(&ray, SPHERE_C, 1.0).is_none(),
        "just outside the tangent"
    );
}

#[test]
fn sphere_origin_inside_returns_the_far_positive_root() {
    let h = intersect_sphere(&Ray::new(SPHERE_C, v(0.0, 0.0, -1.0)), SPHERE_C, 1.0)
        .expect("from the centre");
    assert_close(h.t, 1.0, 1e-6, "centre to surface");
    // From (0,0,-4.5) towards +Z: roots -1.5 (behind) and 0.5.
    let h = intersect_sphere(
        &Ray::new(v(0.0, 0.0, -4.5), v(0.0, 0.0, 1.0)),
        SPHERE_C,
        1.0,
    )
    .expect("from inside");
    assert_close(h.t, 0.5, 1e-6, "inside, far root");
    assert!(h.t > 0.0);
}

#[test]
fn sphere_miss_and_behind() {
    // Closest approach of this line to the centre is sqrt(12.5) > 1.
    let ray = Ray::new(Vec3::ZERO, v(0.0, 1.0, -1.0));
    assert!(intersect_sphere(&ray, SPHERE_C, 1.0).is_none(), "miss");
    // Sphere behind the ray: roots -6 and -4.
    let ray = Ray::new(Vec3::ZERO, v(0.0, 0.0, 1.0));
    assert!(intersect_sphere(&ray, SPHERE_C, 1.0).is_none(), "behind");
    // Zero direction never hits.
    let ray = Ray::new(Vec3::ZERO, Vec3::ZERO);
    assert!(
        intersect_sphere(&ray, SPHERE_C, 1.0).is_none(),
        "zero direction"
    );
}

#[test]
fn sphere_respects_the_t_window() {
    let d = v(0.0, 0.0, -1.0);
    // Roots 4 and 6.
    let none = intersect_sphere(&ray_window(Vec3::ZERO, d, 0.0, 3.9), SPHERE_C, 1.0);
    assert!(none.is_none(), "t_max before the near root: {none:?}");
    let h = intersect_sphere(&ray_window(Vec3::ZERO, d, 0.0, 4.5), SPHERE_C, 1.0).unwrap();
    assert_close(h.t, 4.0, 1e-6, "t_max between roots keeps the near root");
    let h = intersect_sphere(
        &ray_window(Vec3::ZERO, d, 5.0, f32::INFINITY),
        SPHERE_C,
        1.0,
    )
    .expect("t_min between the roots gives the far root");
    assert_close(h.t, 6.0, 1e-6, "far root");
    let none = intersect_sphere(&ray_window(Vec3::ZERO, d, 4.5, 5.5), SPHERE_C, 1.0);
    assert!(
        none.is_none(),
        "window strictly between the roots: {none:?}"
    );
    let none = intersect_sphere(&ray_window(Vec3::ZERO, d, 6.5, 100.0), SPHERE_C, 1.0);
    assert!(none.is_none(), "window after both roots: {none:?}");
}

#[test]
fn sphere_t_scales_inversely_with_direction_length() {
    for k in [0.25f32, 0.5, 2.0, 3.0, 10.0] {
        let ray = Ray::new(Vec3::ZERO, v(0.0, 0.0, -k));
        let h = intersect_sphere(&ray, SPHERE_C, 1.0).expect("hit");
        assert_close(h.t, 4.0 / k, 1e-5 * (4.0 / k), &format!("|d| = {k}"));
        // The hit point itself does not depend on the scale.
        assert_vec_close(ray.at(h.t), v(0.0, 0.0, -4.0), 1e-5, "hit point");
    }
    // A diagonal, non-unit direction: the point at t lies on the sphere.
    let mut r = rng(3);
    for _ in 0..100 {
        let target = random_in_ball(&mut r, SPHERE_C, 0.9);
        let origin = SPHERE_C + random_unit(&mut r) * lerp(2.0, 20.0, r.next_f32());
        let k = lerp(0.1, 10.0, r.next_f32());
        let ray = Ray::new(origin, (target - origin).normalized() * k);
        let h = intersect_sphere(&ray, SPHERE_C, 1.0).expect("aimed inside the sphere");
        assert_close(
            (ray.at(h.t) - SPHERE_C).length(),
            1.0,
            1e-4,
            "point on sphere",
        );
        // The near hit lies between the origin and the target.
        let t_target = (target - origin).length() / k;
        assert!(
            h.t > 0.0 && h.t < t_target,
            "t {} not in (0, {t_target})",
            h.t
        );
    }
}

// ---------------------------------------------------------------------------------------------
// 4. Ray-triangle
// ---------------------------------------------------------------------------------------------

/// Right triangle in the plane z = -2: v0 = (0,0), v1 = (2,0), v2 = (0,2).
const TRI: [Vec3; 3] = [
    Vec3::new(0.0, 0.0, -2.0),
    Vec3::new(2.0, 0.0, -2.0),
    Vec3::new(0.0, 2.0, -2.0),
];

fn tri_ray(x: f32, y: f32) -> Ray {
    Ray::new(v(x, y, 0.0), v(0.0, 0.0, -1.0))
}

#[test]
fn triangle_inside_hit_t_and_barycentrics() {
    // (0.5, 0.25) = v0 + b1 (v1 - v0) + b2 (v2 - v0) with b1 = 0.25, b2 = 0.125.
    let h = intersect_triangle(&tri_ray(0.5, 0.25), &TRI).expect("inside");
    assert_close(h.t, 2.0, 1e-6, "t");
    assert_close(h.b1, 0.25, 1e-6, "b1 (weight of v1)");
    assert_close(h.b2, 0.125, 1e-6, "b2 (weight of v2)");
    // A general triangle: v0 = X, v1 = Y, v2 = Z, ray from the origin along (1,1,1) hits the
    // centroid at t = 1/3, b1 = b2 = 1/3.
    let tri = [Vec3::X, Vec3::Y, Vec3::Z];
    let h = intersect_triangle(&Ray::new(Vec3::ZERO, v(1.0, 1.0, 1.0)), &tri).expect("centroid");
    assert_close(h.t, 1.0 / 3.0, 1e-6, "centroid t");
    assert_close(h.b1, 1.0 / 3.0, 1e-6, "centroid b1");
    assert_close(h.b2, 1.0 / 3.0, 1e-6, "centroid b2");
    // Non-unit direction: t scales inversely.
    let h = intersect_triangle(&Ray::new(v(0.5, 0.25, 0.0), v(0.0, 0.0, -4.0)), &TRI).unwrap();
    assert_close(h.t, 0.5, 1e-6, "t with |d| = 4");
}

#[test]
fn triangle_edges_and_vertices_count_as_inside() {
    // Edge v0-v1 (b2 = 0), edge v0-v2 (b1 = 0), edge v1-v2 (b1 + b2 = 1).
    for (x, y, b1, b2, what) in [
        (1.0, 0.0, 0.5, 0.0, "edge v0-v1"),
        (0.0, 1.0, 0.0, 0.5, "edge v0-v2"),
        (1.0, 1.0, 0.5, 0.5, "edge v1-v2"),
        (0.0, 0.0, 0.0, 0.0, "vertex v0"),
        (2.0, 0.0, 1.0, 0.0, "vertex v1"),
        (0.0, 2.0, 0.0, 1.0, "vertex v2"),
    ] {
        let h = intersect_triangle(&tri_ray(x, y), &TRI)
            .unwrap_or_else(|| panic!("{what}: a point on the boundary must hit"));
        assert_close(h.t, 2.0, 1e-6, &format!("{what}: t"));
        assert_close(h.b1, b1, 1e-6, &format!("{what}: b1"));
        assert_close(h.b2, b2, 1e-6, &format!("{what}: b2"));
    }
}

#[test]
fn triangle_just_outside_edge_v0_v1_misses() {
    assert!(intersect_triangle(&tri_ray(1.0, -1e-3), &TRI).is_none());
    assert!(
        intersect_triangle(&tri_ray(1.0, 1e-3), &TRI).is_some(),
        "control"
    );
}

#[test]
fn triangle_just_outside_edge_v0_v2_misses() {
    assert!(intersect_triangle(&tri_ray(-1e-3, 1.0), &TRI).is_none());
    assert!(
        intersect_triangle(&tri_ray(1e-3, 1.0), &TRI).is_some(),
        "control"
    );
}

#[test]
fn triangle_just_outside_edge_v1_v2_misses() {
    assert!(intersect_triangle(&tri_ray(1.001, 1.0), &TRI).is_none());
    assert!(
        intersect_triangle(&tri_ray(0.999, 1.0), &TRI).is_some(),
        "control"
    );
}

#[test]
fn triangle_just_outside_vertices_misses() {
    for (x, y) in [(-1e-3, -1e-3), (2.001, 0.0), (0.0, 2.001), (2.0, -1e-3)] {
        assert!(
            intersect_triangle(&tri_ray(x, y), &TRI).is_none(),
            "({x},{y}) is outside"
        );
    }
}

#[test]
fn triangle_parallel_ray_misses() {
    // Parallel to the plane, off it.
    let ray = Ray::new(v(-1.0, 0.5, 0.0), v(1.0, 0.0, 0.0));
    assert!(
        intersect_triangle(&ray, &TRI).is_none(),
        "parallel, off the plane"
    );
    // Parallel and lying in the plane (degenerate): no hit.
    let ray = Ray::new(v(-1.0, 0.5, -2.0), v(1.0, 0.0, 0.0));
    assert!(intersect_triangle(&ray, &TRI).is_none(), "in the plane");
}

#[test]
fn triangle_behind_origin_misses() {
    let ray = Ray::new(v(0.5, 0.25, -3.0), v(0.0, 0.0, -1.0));
    assert!(intersect_triangle(&ray, &TRI).is_none(), "triangle behind");
    // The window also applies: t = 2 is outside [0, 1.5] and [2.5, inf].
    let d = v(0.0, 0.0, -1.0);
    let o = v(0.5, 0.25, 0.0);
    assert!(intersect_triangle(&ray_window(o, d, 0.0, 1.5), &TRI).is_none());
    assert!(intersect_triangle(&ray_window(o, d, 2.5, f32::INFINITY), &TRI).is_none());
    assert!(intersect_triangle(&ray_window(o, d, 1.5, 2.5), &TRI).is_some());
}

#[test]
fn triangle_both_windings_hit() {
    let flipped = [TRI[0], TRI[2], TRI[1]];
    let a = intersect_triangle(&tri_ray(0.5, 0.25), &TRI).expect("ccw");
    let b = intersect_triangle(&tri_ray(0.5, 0.25), &flipped).expect("cw");
    assert_close(b.t, 2.0, 1e-6, "cw t");
    // Swapping v1 and v2 swaps the barycentrics.
    assert_close(b.b1, a.b2, 1e-6, "cw b1");
    assert_close(b.b2, a.b1, 1e-6, "cw b2");
    // And from the other side (origin below the plane, looking up).
    let ray = Ray::new(v(0.5, 0.25, -5.0), v(0.0, 0.0, 1.0));
    assert_close(
        intersect_triangle(&ray, &TRI).expect("back").t,
        3.0,
        1e-6,
        "back t",
    );
    assert_close(
        intersect_triangle(&ray, &flipped).expect("back cw").t,
        3.0,
        1e-6,
        "back cw t",
    );
    // The geometric normal follows the winding: (v1-v0) x (v2-v0).
    let up = Shape::Triangle { vertices: TRI };
    let down = Shape::Triangle { vertices: flipped };
    let hit = PrimitiveHit {
        t: 2.0,
        b1: 0.25,
        b2: 0.125,
    };
    assert_vec_close(
        up.normal(v(0.5, 0.25, -2.0), &hit),
        Vec3::Z,
        1e-7,
        "ccw normal",
    );
    assert_vec_close(
        down.normal(v(0.5, 0.25, -2.0), &hit),
        -Vec3::Z,
        1e-7,
        "cw normal",
    );
}

// ---------------------------------------------------------------------------------------------
// 5. Box slabs
// ---------------------------------------------------------------------------------------------

const BMIN: Vec3 = Vec3::new(-1.0, -1.0, -1.0);
const BMAX: Vec3 = Vec3::new(1.0, 1.0, 1.0);

#[test]
fn box_hit_from_outside_along_each_axis() {
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let mut o = [0.0f32; 3];
            o[axis] = -5.0 * sign;
            let mut d = [0.0f32; 3];
            d[axis] = sign;
            let ray = Ray::new(Vec3::from_array(o), Vec3::from_array(d));
            let h = intersect_box(&ray, BMIN, BMAX).expect("axis ray hits the box");
            let what = format!("axis {axis}, sign {sign}");
            assert_close(h.t, 4.0, 1e-6, &format!("{what}: entry t"));
            let (t0, t1) = slab_interval(ray.origin, ray.direction, BMIN, BMAX).unwrap();
            assert_close(t0, 4.0, 1e-6, &format!("{what}: slab near"));
            assert_close(t1, 6.0, 1e-6, &format!("{what}: slab far"));
            // The entry face's outward normal faces the ray.
            let n = Shape::Box {
                min: BMIN,
                max: BMAX,
            }
            .normal(ray.at(h.t), &h);
            let mut expected = [0.0f32; 3];
            expected[axis] = -sign;
            assert_vec_close(
                n,
                Vec3::from_array(expected),
                0.0,
                &format!("{what}: normal"),
            );
        }
    }
    // Non-unit direction: origin (0,0,3) along (0,0,-2) enters at z = 1, t = 1.
    let h = intersect_box(&Ray::new(v(0.0, 0.0, 3.0), v(0.0, 0.0, -2.0)), BMIN, BMAX).unwrap();
    assert_close(h.t, 1.0, 1e-6, "non-unit direction");
    // Diagonal: (-3,-3,-3) along (1,1,1) is inside for t in [2, 4].
    let (t0, t1) = slab_interval(v(-3.0, -3.0, -3.0), v(1.0, 1.0, 1.0), BMIN, BMAX).unwrap();
    assert_close(t0, 2.0, 1e-6, "diagonal near");
    assert_close(t1, 4.0, 1e-6, "diagonal far");
    // Asymmetric box and an oblique ray: box [1,3]x[0,1]x[-2,2], origin (0,0.5,0) along
    // (1,0.1,0): x-slab t in [1,3], y-slab t in [-5,5] -> entry 1.
    let h = intersect_box(
        &Ray::new(v(0.0, 0.5, 0.0), v(1.0, 0.1, 0.0)),
        v(1.0, 0.0, -2.0),
        v(3.0, 1.0, 2.0),
    )
    .unwrap();
    assert_close(h.t, 1.0, 1e-6, "asymmetric box entry");
}

#[test]
fn box_origin_inside_returns_exit_t() {
    let h = intersect_box(&Ray::new(Vec3::ZERO, v(0.0, 0.5, 0.0)), BMIN, BMAX).expect("inside");
    assert_close(h.t, 2.0, 1e-6, "exit t with |d| = 0.5");
    let h = intersect_box(&Ray::new(v(0.5, 0.0, 0.0), v(-1.0, 0.0, 0.0)), BMIN, BMAX).unwrap();
    assert_close(h.t, 1.5, 1e-6, "exit through -X");
    // A t_min past the entry also yields the exit.
    let ray = ray_window(v(-5.0, 0.0, 0.0), v(1.0, 0.0, 0.0), 4.5, f32::INFINITY);
    assert_close(
        intersect_box(&ray, BMIN, BMAX).unwrap().t,
        6.0,
        1e-6,
        "t_min > entry",
    );
    // A window strictly between entry and exit: no surface in it.
    let ray = ray_window(v(-5.0, 0.0, 0.0), v(1.0, 0.0, 0.0), 4.5, 5.5);
    assert!(
        intersect_box(&ray, BMIN, BMAX).is_none(),
        "window inside the box"
    );
}

#[test]
fn box_miss_and_behind() {
    // Passes beside the box.
    let ray = Ray::new(v(-5.0, 0.0, 0.0), v(1.0, 1.0, 0.0));
    assert!(intersect_box(&ray, BMIN, BMAX).is_none(), "oblique miss");
    assert!(slab_interval(ray.origin, ray.direction, BMIN, BMAX).is_none());
    // Box behind the ray.
    let ray = Ray::new(v(5.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
    assert!(intersect_box(&ray, BMIN, BMAX).is_none(), "behind");
}

#[test]
fn box_axis_parallel_ray_grazing_the_slab() {
    // Along +X at y = 1 (on the top face's plane): within the closed y-slab, hits at x = -1.
    let h = intersect_box(&Ray::new(v(-5.0, 1.0, 0.0), v(1.0, 0.0, 0.0)), BMIN, BMAX)
        .expect("grazing on the slab boundary counts as inside");
    assert_close(h.t, 4.0, 1e-6, "grazing t");
    // Just inside the slab: hit; just outside: miss.
    assert!(intersect_box(&Ray::new(v(-5.0, 0.9999, 0.0), Vec3::X), BMIN, BMAX).is_some());
    assert!(intersect_box(&Ray::new(v(-5.0, 1.0001, 0.0), Vec3::X), BMIN, BMAX).is_none());
    assert!(intersect_box(&Ray::new(v(-5.0, -1.0001, 0.0), Vec3::X), BMIN, BMAX).is_none());
}

#[test]
fn box_zero_direction_component_outside_the_slab_misses() {
    // d.z = 0 and z = 2 outside [-1,1]: the ray never enters, whatever x and y do.
    // Origins both outside and inside the x and y slabs: z alone must reject them.
    for o in [v(-5.0, 0.0, 2.0), v(0.0, 0.0, 2.0), v(0.0, -5.0, 2.0)] {
        for d in [
            v(1.0, 0.0, 0.0),
            v(1.0, 0.3, 0.0),
            v(-0.0, 1.0, 0.0),
            v(1.0, -0.0, -0.0),
        ] {
            let what = format!("o = {o:?}, d = {d:?}");
            assert!(
                intersect_box(&Ray::new(o, d), BMIN, BMAX).is_none(),
                "{what}"
            );
            assert!(slab_interval(o, d, BMIN, BMAX).is_none(), "slab, {what}");
        }
    }
    // Control: the same rays one unit lower (z = 1, on the face plane) do hit.
    assert!(intersect_box(&Ray::new(v(-5.0, 0.0, 1.0), Vec3::X), BMIN, BMAX).is_some());
    // Negative zero inside the slab behaves like zero: still a hit.
    let h = intersect_box(&Ray::new(v(-5.0, 0.0, 0.0), v(1.0, -0.0, -0.0)), BMIN, BMAX);
    assert_close(h.expect("-0 components").t, 4.0, 1e-6, "-0 components");
}

// ---------------------------------------------------------------------------------------------
// 6. Transforms (FORMAT.md 2.8)
// ---------------------------------------------------------------------------------------------

#[test]
fn transform_order_matches_the_slide_example() {
    let m = Matrix4::translate(v(0.0, 1.5, -4.0)).mul(&Matrix4::scale(v(0.5, 1.5, 1.0)));
    let expected = Matrix4 {
        m: [
            [0.5, 0.0, 0.0, 0.0],
            [0.0, 1.5, 0.0, 1.5],
            [0.0, 0.0, 1.0, -4.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    };
    assert!(matrix_close(&m, &expected, 1e-12), "T*S = {m:?}");
    // Scale is applied first: the object point (1,1,1) goes to (0.5, 1.5+1.5, 1-4).
    assert_vec_close(
        m.transform_point(v(1.0, 1.0, 1.0)),
        v(0.5, 3.0, -3.0),
        1e-6,
        "T*S p",
    );
    // The other order is a different matrix: S*T translates by S t = (0, 2.25, -4).
    let st = Matrix4::scale(v(0.5, 1.5, 1.0)).mul(&Matrix4::translate(v(0.0, 1.5, -4.0)));
    assert_close(st.m[1][3] as f32, 2.25, 1e-12, "S*T translation y");
    assert!(!matrix_close(&m, &st, 1e-3), "order matters");
    // Vectors ignore the translation.
    assert_vec_close(
        m.transform_vector(v(1.0, 1.0, 1.0)),
        v(0.5, 1.5, 1.0),
        1e-6,
        "vector",
    );
}

#[test]
fn rotations_are_right_handed() {
    let rz = Matrix4::rotate(2, 90.0);
    assert_vec_close(rz.transform_vector(Vec3::X), Vec3::Y, 1e-7, "Rz(90) X -> Y");
    assert_vec_close(
        rz.transform_vector(Vec3::Y),
        -Vec3::X,
        1e-7,
        "Rz(90) Y -> -X",
    );
    assert_vec_close(
        rz.transform_vector(Vec3::Z),
        Vec3::Z,
        1e-7,
        "Rz(90) Z fixed",
    );
    let rx = Matrix4::rotate(0, 90.0);
    assert_vec_close(rx.transform_vector(Vec3::Y), Vec3::Z, 1e-7, "Rx(90) Y -> Z");
    assert_vec_close(
        rx.transform_vector(Vec3::Z),
        -Vec3::Y,
        1e-7,
        "Rx(90) Z -> -Y",
    );
    let ry = Matrix4::rotate(1, 90.0);
    assert_vec_close(ry.transform_vector(Vec3::Z), Vec3::X, 1e-7, "Ry(90) Z -> X");
    assert_vec_close(
        ry.transform_vector(Vec3::X),
        -Vec3::Z,
        1e-7,
        "Ry(90) X -> -Z",
    );
    // 30 degrees about Z: X -> (cos 30, sin 30, 0).
    let r30 = Matrix4::rotate(2, 30.0);
    assert_vec_close(
        r30.transform_vector(Vec3::X),
        v(0.75f32.sqrt(), 0.5, 0.0),
        1e-7,
        "Rz(30) X",
    );
    // Rotations compose by adding angles.
    let r = Matrix4::rotate(1, 31.7).mul(&Matrix4::rotate(1, -58.3));
    assert!(
        matrix_close(&r, &Matrix4::rotate(1, -26.6), 1e-12),
        "Ry adds"
    );
}

#[test]
fn composite_times_inverse_is_identity() {
    // The slide's "rotation, then scale, then rotation, then translation".
    let m = Matrix4::translate(v(0.0, 1.5, -4.0))
        .mul(&Matrix4::rotate(2, -58.3))
        .mul(&Matrix4::scale(v(0.5, 1.5, 1.0)))
        .mul(&Matrix4::rotate(2, 31.7));
    let inv = m.inverse().expect("invertible");
    assert!(
        matrix_close(&m.mul(&inv), &Matrix4::IDENTITY, 1e-12),
        "M M^-1"
    );
    assert!(
        matrix_close(&inv.mul(&m), &Matrix4::IDENTITY, 1e-12),
        "M^-1 M"
    );
    // A matrix whose first pivot is zero (needs row exchange): a 90-degree rotation about X
    // and a translation.
    let m2 = Matrix4::translate(v(3.0, -2.0, 7.0))
        .mul(&Matrix4::rotate(0, 90.0))
        .mul(&Matrix4::scale(v(2.0, 3.0, 0.25)));
    let inv2 = m2.inverse().expect("invertible");
    assert!(
        matrix_close(&m2.mul(&inv2), &Matrix4::IDENTITY, 1e-12),
        "M2 M2^-1"
    );
    // Transform keeps the pair consistent in f32: world -> object -> world round trips.
    let xf = Transform::from_matrix(&m).expect("invertible");
    let mut r = rng(6);
    for _ in 0..100 {
        let p = random_in_ball(&mut r, Vec3::ZERO, 10.0);
        let w = xf.point_to_world(p);
        assert_vec_close(w, m.transform_point(p), 1e-5, "point_to_world = M p");
        assert_vec_close(xf.point_to_object(w), p, 1e-4, "round trip");
        let d = random_unit(&mut r);
        assert_vec_close(
            xf.vector_to_object(xf.vector_to_world(d)),
            d,
            1e-5,
            "vector trip",
        );
    }
}

#[test]
fn singular_matrix_has_no_transform() {
    let zero_y = Matrix4::scale(v(1.0, 0.0, 1.0));
    assert!(zero_y.inverse().is_none(), "inverse of a zero scale");
    assert!(
        Transform::from_matrix(&zero_y).is_none(),
        "Transform of a zero scale"
    );
    let composite = Matrix4::translate(v(1.0, 2.0, 3.0))
        .mul(&Matrix4::rotate(1, 45.0))
        .mul(&Matrix4::scale(v(2.0, 2.0, 0.0)));
    assert!(
        Transform::from_matrix(&composite).is_none(),
        "composite with zero scale"
    );
    assert!(Transform::from_matrix(&Matrix4::scale(v(1e-3, 1.0, 1.0))).is_some());
}

#[test]
fn normal_to_world_stays_perpendicular_to_transformed_tangents() {
    let scale = v(2.0, 1.0, 0.5);
    let matrices = [
        Matrix4::scale(scale),
        Matrix4::translate(v(1.0, -2.0, 3.0))
            .mul(&Matrix4::rotate(2, 30.0))
            .mul(&Matrix4::scale(scale))
            .mul(&Matrix4::rotate(0, -70.0)),
    ];
    let mut r = rng(7);
    for (k, m) in matrices.iter().enumerate() {
        let xf = Transform::from_matrix(m).unwrap();
        for _ in 0..200 {
            // On the unit sphere the object normal at p is p itself.
            let p = random_unit(&mut r);
            let t1 = random_perpendicular(&mut r, p);
            let t2 = p.cross(t1);
            let n = xf.normal_to_world(p).normalized();
            for t in [t1, t2] {
                let tw = xf.vector_to_world(t).normalized();
                assert_close(n.dot(tw), 0.0, 1e-5, &format!("matrix {k}: n . M t"));
            }
            // The normal is outward: it points away from the ellipsoid's centre.
            let centre = xf.point_to_world(Vec3::ZERO);
            assert!(n.dot(xf.point_to_world(p) - centre) > 0.0, "outward");
        }
    }
    // Pure scale: the ellipsoid x^2/4 + y^2 + z^2/0.25 = 1 has gradient (x/4, y, 4z) at q.
    let xf = Transform::from_matrix(&matrices[0]).unwrap();
    for _ in 0..100 {
        let p = random_unit(&mut r);
        let q = xf.point_to_world(p);
        let grad = v(q.x / 4.0, q.y, q.z / 0.25).normalized();
        assert_vec_close(
            xf.normal_to_world(p).normalized(),
            grad,
            1e-5,
            "ellipsoid grad",
        );
    }
    // Without the inverse transpose the normal would be wrong: (1,1,0)/sqrt2 under scale
    // (2,1,0.5) must become ∝ (1/2, 1, 0), not ∝ (2, 1, 0).
    let n = xf.normal_to_world(v(1.0, 1.0, 0.0)).normalized();
    assert_vec_close(n, v(0.5, 1.0, 0.0).normalized(), 1e-6, "inverse transpose");
}

// ---------------------------------------------------------------------------------------------
// 7. Reflection, refraction, Schlick (FORMAT.md 4.2, 4.3)
// ---------------------------------------------------------------------------------------------

#[test]
fn reflect_hand_values() {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let r = reflect(v(s, -s, 0.0), Vec3::Y);
    assert_vec_close(r, v(s, s, 0.0), 1e-7, "45-degree mirror");
    // Non-unit d keeps its length: (3,-4,0) -> (3,4,0).
    let r = reflect(v(3.0, -4.0, 0.0), Vec3::Y);
    assert_vec_close(r, v(3.0, 4.0, 0.0), 1e-6, "non-unit d");
    // Normal incidence bounces straight back.
    assert_vec_close(reflect(-Vec3::Z, Vec3::Z), Vec3::Z, 0.0, "normal incidence");
    // The normal's sign does not matter.
    assert_vec_close(
        reflect(v(s, -s, 0.0), -Vec3::Y),
        v(s, s, 0.0),
        1e-7,
        "flipped n",
    );
}

#[test]
fn reflect_preserves_length_and_angle() {
    let mut r = rng(8);
    for _ in 0..500 {
        let n = random_unit(&mut r);
        let d = random_unit(&mut r) * lerp(0.1, 5.0, r.next_f32());
        let out = reflect(d, n);
        assert_close(out.length(), d.length(), 1e-5 * d.length(), "|r| = |d|");
        // Angle of incidence = angle of reflection, on the other side of the tangent plane.
        assert_close(out.dot(n), -d.dot(n), 1e-5 * d.length(), "r.n = -d.n");
        // The tangential component is unchanged (coplanar with d and n).
        let tan_d = d - n * d.dot(n);
        let tan_r = out - n * out.dot(n);
        assert_vec_close(tan_r, tan_d, 1e-5 * d.length(), "tangential part");
        // Reflecting twice is the identity.
        assert_vec_close(reflect(out, n), d, 1e-5 * d.length(), "involution");
    }
}

/// A unit direction at angle `theta` (radians) from -n, with its tangential part along `t`.
fn incident(n: Vec3, t: Vec3, theta: f32) -> Vec3 {
    -n * theta.cos() + t * theta.sin()
}

#[test]
fn refract_hand_value_at_30_degrees() {
    // 30 degrees from air into glass: sin(theta2) = 0.5 / 1.5 = 1/3, cos = sqrt(8/9).
    let d = incident(Vec3::Y, Vec3::X, 30f32.to_radians());
    let t = refract(d, Vec3::Y, 1.0, 1.5).expect("no TIR entering glass");
    assert_vec_close(
        t,
        v(1.0 / 3.0, -(8.0f32 / 9.0).sqrt(), 0.0),
        1e-6,
        "refracted",
    );
}

#[test]
fn refract_obeys_snell_and_stays_in_the_plane_of_incidence() {
    let n = v(0.3, 1.0, -0.2).normalized();
    let mut r = rng(9);
    for (n1, n2) in [(1.0f32, 1.5f32), (1.5, 1.0), (1.0, 1.333), (1.8, 1.01)] {
        let critical = if n1 > n2 {
            (n2 / n1).asin()
        } else {
            f32::INFINITY
        };
        for deg in [0.0f32, 5.0, 10.0, 20.0, 30.0, 40.0, 45.0, 60.0, 80.0, 89.0] {
            let theta1 = deg.to_radians();
            if theta1 >= critical - 1e-3 {
                continue;
            }
            let tan = random_perpendicular(&mut r, n);
            let d = incident(n, tan, theta1);
            let what = format!("{n1}->{n2} at {deg} deg");
            let t = refract(d, n, n1, n2).unwrap_or_else(|| panic!("{what}: unexpected TIR"));
            assert_close(t.length(), 1.0, 1e-5, &format!("{what}: |t|"));
            assert!(
                t.dot(n) < 0.0,
                "{what}: transmitted ray must cross the surface"
            );
            let sin2 = t.cross(n).length();
            assert_close(
                n1 * theta1.sin(),
                n2 * sin2,
                1e-5,
                &format!("{what}: Snell"),
            );
            // Coplanar with d and n, and bent towards the same side as d.
            assert_close(t.dot(d.cross(n)), 0.0, 1e-5, &format!("{what}: coplanar"));
            if deg > 0.0 {
                assert!(t.dot(tan) > 0.0, "{what}: tangential direction kept");
            }
            // Towards the normal when entering a denser medium, away when leaving it.
            let theta2 = sin2.clamp(0.0, 1.0).asin();
            if deg > 0.0 && n1 < n2 {
                assert!(theta2 < theta1, "{what}: bends towards the normal");
            } else if deg > 0.0 && n1 > n2 {
                assert!(theta2 > theta1, "{what}: bends away from the normal");
            }
        }
    }
}

#[test]
fn refract_normal_incidence_passes_straight_through() {
    for (n1, n2) in [(1.0, 1.5), (1.5, 1.0), (1.33, 1.33)] {
        let t = refract(-Vec3::Y, Vec3::Y, n1, n2).expect("normal incidence never TIRs");
        assert_vec_close(t, -Vec3::Y, 1e-7, &format!("{n1}->{n2}"));
    }
    // Equal indices: no bending at any angle.
    let d = incident(Vec3::Y, Vec3::X, 1.0);
    assert_vec_close(
        refract(d, Vec3::Y, 1.2, 1.2).unwrap(),
        d,
        1e-6,
        "matched indices",
    );
}

#[test]
fn refract_total_internal_reflection_beyond_the_critical_angle() {
    let critical = (1.0f32 / 1.5).asin(); // 41.81 degrees
    let just_above = incident(Vec3::Y, Vec3::X, critical + 0.5f32.to_radians());
    assert!(
        refract(just_above, Vec3::Y, 1.5, 1.0).is_none(),
        "beyond the critical angle: TIR"
    );
    let grazing = incident(Vec3::Y, Vec3::X, 85f32.to_radians());
    assert!(
        refract(grazing, Vec3::Y, 1.5, 1.0).is_none(),
        "grazing inside glass: TIR"
    );
    let just_below = incident(Vec3::Y, Vec3::X, critical - 0.5f32.to_radians());
    let t = refract(just_below, Vec3::Y, 1.5, 1.0).expect("below the critical angle");
    // Close to the critical angle the transmitted ray is nearly tangent.
    assert!(
        t.cross(Vec3::Y).length() > 0.99,
        "nearly grazing, got {t:?}"
    );
    // From the thin side there is never TIR, even at 89 degrees.
    let steep = incident(Vec3::Y, Vec3::X, 89f32.to_radians());
    assert!(refract(steep, Vec3::Y, 1.0, 1.5).is_some(), "air to glass");
}

#[test]
fn schlick_values() {
    assert_close(schlick(1.0, 1.5), 0.04, 1e-7, "R0 for glass");
    assert_close(schlick(0.0, 1.5), 1.0, 1e-7, "grazing");
    assert_close(schlick(0.5, 1.5), 0.04 + 0.96 / 32.0, 1e-7, "cos = 0.5");
    assert_close(schlick(1.0, 2.0), 1.0 / 9.0, 1e-7, "R0 for n = 2");
    assert_close(schlick(1.0, 1.0), 0.0, 1e-7, "matched index");
    // Monotone: more reflection towards grazing.
    let mut prev = schlick(1.0, 1.5);
    for i in (0..100).rev() {
        let cur = schlick(i as f32 / 100.0, 1.5);
        assert!(
            cur >= prev,
            "schlick not monotone at cos = {}",
            i as f32 / 100.0
        );
        prev = cur;
    }
}

// ---------------------------------------------------------------------------------------------
// 8. Spawned rays never find their own surface (FORMAT.md 4.1: tmin = 1e-3)
// ---------------------------------------------------------------------------------------------

const TRI_Y: f32 = -2.0;
const BOX_MIN: Vec3 = Vec3::new(3.0, -1.0, -1.0);
const BOX_MAX: Vec3 = Vec3::new(5.0, 1.0, 1.0);

fn ground_triangle() -> Shape {
    // Normal (v1-v0) x (v2-v0) = (20,0,0) x (10,0,-20) ∝ +Y.
    Shape::Triangle {
        vertices: [
            v(-10.0, TRI_Y, 10.0),
            v(10.0, TRI_Y, 10.0),
            v(0.0, TRI_Y, -10.0),
        ],
    }
}

fn three_shapes() -> Vec<Shape> {
    vec![
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        ground_triangle(),
        Shape::Box {
            min: BOX_MIN,
            max: BOX_MAX,
        },
    ]
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Sphere,
    Triangle,
    Box,
}

/// Which of `three_shapes` the world point lies on.
fn classify(p: Vec3) -> Kind {
    if (p.length() - 1.0).abs() < 1e-4 {
        Kind::Sphere
    } else if (p.y - TRI_Y).abs() < 1e-4 {
        Kind::Triangle
    } else {
        let inside = (0..3).all(|a| p[a] >= BOX_MIN[a] - 1e-4 && p[a] <= BOX_MAX[a] + 1e-4);
        assert!(inside, "{p:?} is on none of the shapes");
        Kind::Box
    }
}

/// A random point on or inside shape `kind` of `three_shapes`.
fn random_target(r: &mut Rng, kind: Kind) -> Vec3 {
    match kind {
        Kind::Sphere => random_in_ball(r, Vec3::ZERO, 0.999),
        Kind::Triangle => {
            let Shape::Triangle {
                vertices: [a, b, c],
            } = ground_triangle()
            else {
                unreachable!()
            };
            let (mut u, mut w) = (r.next_f32(), r.next_f32());
            if u + w > 1.0 {
                (u, w) = (1.0 - u, 1.0 - w);
            }
            a + (b - a) * u + (c - a) * w
        }
        Kind::Box => v(
            lerp(BOX_MIN.x, BOX_MAX.x, r.next_f32()),
            lerp(BOX_MIN.y, BOX_MAX.y, r.next_f32()),
            lerp(BOX_MIN.z, BOX_MAX.z, r.next_f32()),
        ),
    }
}

/// Camera-like rays from random points 12 units around the scene towards random points on
/// each shape; yields (ray, hit) for every ray that hits something.
fn random_hits(
    scene: &Scene,
    seed: u64,
    per_kind: usize,
) -> Vec<(Ray, crate::accel::instances::Hit)> {
    let mut r = rng(seed);
    let mut out = Vec::new();
    for kind in [Kind::Sphere, Kind::Triangle, Kind::Box] {
        for _ in 0..per_kind {
            let origin = v(1.0, 0.0, 0.0) + random_unit(&mut r) * 12.0;
            let target = random_target(&mut r, kind);
            let ray = Ray::new(origin, target - origin);
            let hit = scene
                .intersect(&ray)
                .unwrap_or_else(|| panic!("ray {ray:?} aimed at a {kind:?} hit nothing"));
            assert!(hit.t > 0.0 && hit.t <= 1.0 + 1e-5, "hit beyond the target");
            out.push((ray, hit));
        }
    }
    out
}

#[test]
fn reflected_rays_never_hit_their_own_primitive() {
    let scene = plain_scene(three_shapes());
    let mut counts = [0usize; 3];
    let mut failures = Vec::new();
    for (ray, hit) in random_hits(&scene, 10, 4000) {
        let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
        let kind = classify(si.point);
        counts[kind as usize] += 1;
        assert_close(si.normal.length(), 1.0, 1e-5, "unit normal");
        let d = ray.direction.normalized();
        let cos_i = d.dot(si.normal);
        let refl = reflect(d, si.normal);
        // Reflection stays on the incoming side of the surface.
        assert!(refl.dot(si.normal) * cos_i <= 0.0);
        let spawned = Ray::spawn(si.point, refl);
        assert_eq!(spawned.t_min, SPAWN_EPSILON);
        if let Some(h2) = scene.intersect(&spawned) {
            // Sphere and box are convex and hit from outside, the triangle is flat: a ray
            // leaving into the outer half-space can never meet the same primitive again.
            if h2.instance == hit.instance && h2.primitive == hit.primitive {
                failures.push((kind, cos_i, h2.t, si.point, refl));
            }
        }
    }
    assert!(
        counts.iter().all(|&c| c >= 1000),
        "too few hits per shape: {counts:?}"
    );
    assert!(
        failures.is_empty(),
        "{} of {} reflected rays re-hit their own primitive; first few \
         (kind, cos incidence, t, point, reflected dir): {:?}",
        failures.len(),
        counts.iter().sum::<usize>(),
        &failures[..failures.len().min(5)]
    );
}

#[test]
fn refracted_ray_into_a_sphere_hits_its_far_side() {
    // The spawned ray must skip the entry point but still find the same sphere at the chord
    // length 2 R cos(theta_t) = -2 R (t . n).
    let scene = plain_scene(vec![Shape::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    }]);
    let mut r = rng(11);
    for _ in 0..2000 {
        let origin = random_unit(&mut r) * 10.0;
        let target = random_in_ball(&mut r, Vec3::ZERO, 0.999);
        let ray = Ray::new(origin, target - origin);
        let hit = scene.intersect(&ray).expect("aimed at the sphere");
        let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
        let t = refract(ray.direction.normalized(), si.normal, 1.0, 1.5).expect("no TIR");
        let inner = Ray::spawn(si.point, t);
        let h2 = scene
            .intersect(&inner)
            .expect("refracted ray must exit the sphere");
        assert_eq!(h2.primitive, hit.primitive);
        assert_close(h2.t, -2.0 * t.dot(si.normal), 1e-4, "chord length");
    }
}

#[test]
fn shadow_rays_towards_a_light_on_the_same_side_are_not_occluded() {
    for (name, shape) in [
        (
            "sphere",
            Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            },
        ),
        ("triangle", ground_triangle()),
        (
            "box",
            Shape::Box {
                min: BOX_MIN,
                max: BOX_MAX,
            },
        ),
    ] {
        let scene = plain_scene(vec![shape]);
        let mut r = rng(12);
        let centre = shape.bounds().centroid();
        let mut tested = 0;
        for _ in 0..3000 {
            let origin = centre + random_unit(&mut r) * 12.0;
            let target = match shape {
                Shape::Triangle { .. } => random_target(&mut r, Kind::Triangle),
                Shape::Sphere { .. } => random_in_ball(&mut r, Vec3::ZERO, 0.999),
                Shape::Box { .. } => random_target(&mut r, Kind::Box),
            };
            let ray = Ray::new(origin, target - origin);
            let Some(hit) = scene.intersect(&ray) else {
                panic!("{name}: ray aimed at the shape missed");
            };
            let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
            // The side the ray came from.
            let n = if si.normal.dot(ray.direction) > 0.0 {
                -si.normal
            } else {
                si.normal
            };
            // A light at 1..30 units, at most ~87 degrees from the normal.
            let cos_a = lerp(0.05, 1.0, r.next_f32());
            let sin_a = (1.0 - cos_a * cos_a).sqrt();
            let l = n * cos_a + random_perpendicular(&mut r, n) * sin_a;
            let light = si.point + l * lerp(1.0, 30.0, r.next_f32());
            let shadow = Ray::spawn_to(si.point, light);
            assert_vec_close(
                shadow.direction,
                light - si.point,
                0.0,
                "spawn_to direction",
            );
            assert!(
                !scene.occluded(&shadow),
                "{name}: self-shadowed at {:?} (n {n:?}) towards light {light:?}",
                si.point
            );
            tested += 1;
        }
        assert_eq!(tested, 3000);
    }
}

#[test]
fn shadow_rays_are_blocked_only_between_point_and_light() {
    let scene = plain_scene(three_shapes());
    // Ground point under the sphere, light above it: the sphere blocks.
    let p = v(0.0, TRI_Y, 0.0);
    assert!(
        scene.occluded(&Ray::spawn_to(p, v(0.0, 5.0, 0.0))),
        "sphere shadows ground"
    );
    // Same point, light off to the side with a clear line: lit.
    assert!(
        !scene.occluded(&Ray::spawn_to(p, v(-6.0, 5.0, 0.0))),
        "clear line"
    );
    // Ground point under the box with the light between ground and box: the box lies beyond
    // the light (t > 1) and must not block.
    let q = v(4.0, TRI_Y, 0.0);
    assert!(
        !scene.occluded(&Ray::spawn_to(q, v(4.0, -1.5, 0.0))),
        "box beyond the light"
    );
    assert!(
        scene.occluded(&Ray::spawn_to(q, v(4.0, 3.0, 0.0))),
        "box between"
    );
    // A point on the far side of the sphere from the light is shadowed by the sphere itself.
    assert!(scene.occluded(&Ray::spawn_to(v(0.0, 0.0, -1.0), v(0.0, 0.0, 5.0))));
    // Light below the ground triangle: the triangle blocks the top of the sphere.
    assert!(scene.occluded(&Ray::spawn_to(v(0.0, 1.0, 0.0), v(0.0, -5.0, 3.0))));
}

// ---------------------------------------------------------------------------------------------
// 9. Scene queries: closest hit, t window, instances
// ---------------------------------------------------------------------------------------------

#[test]
fn scene_returns_the_closest_of_overlapping_shapes() {
    // The farther sphere is listed first, so "first found" would be wrong.
    let scene = plain_scene(vec![
        Shape::Sphere {
            center: v(0.0, 0.0, -10.0),
            radius: 1.0,
        },
        Shape::Sphere {
            center: v(0.0, 0.0, -5.0),
            radius: 1.0,
        },
    ]);
    let d = v(0.0, 0.0, -1.0);
    let at = |t_min: f32, t_max: f32| {
        let ray = ray_window(Vec3::ZERO, d, t_min, t_max);
        scene.intersect(&ray).map(|h| {
            let si = scene.surface(&ray, &h, SurfaceNeeds::Uv);
            (h.t, si.point, si.normal)
        })
    };
    let (t, p, n) = at(0.0, f32::INFINITY).expect("hit");
    assert_close(t, 4.0, 1e-6, "nearer sphere");
    assert_vec_close(p, v(0.0, 0.0, -4.0), 1e-6, "point on nearer sphere");
    assert_vec_close(n, Vec3::Z, 1e-6, "its outward normal");
    let (t, _, n) = at(4.5, f32::INFINITY).expect("hit");
    assert_close(t, 6.0, 1e-6, "t_min past the near sphere's front: its back");
    assert_vec_close(n, -Vec3::Z, 1e-6, "back normal");
    let (t, ..) = at(6.5, f32::INFINITY).expect("hit");
    assert_close(t, 9.0, 1e-6, "past the first sphere: the second");
    let (t, ..) = at(9.5, 100.0).expect("hit");
    assert_close(t, 11.0, 1e-6, "second sphere's back");
    assert!(at(0.0, 3.9).is_none(), "t_max before everything");
    assert!(at(4.5, 5.9).is_none(), "window between surfaces");
    assert!(at(11.5, f32::INFINITY).is_none(), "past everything");

    // Interpenetrating spheres: the front surface of the union wins.
    let scene = plain_scene(vec![
        Shape::Sphere {
            center: v(0.0, 0.0, -5.5),
            radius: 1.0,
        },
        Shape::Sphere {
            center: v(0.0, 0.0, -5.0),
            radius: 1.0,
        },
    ]);
    let h = scene.intersect(&Ray::new(Vec3::ZERO, d)).unwrap();
    assert_close(h.t, 4.0, 1e-6, "overlapping spheres");
}

#[test]
fn scene_closest_hit_matches_brute_force() {
    let mut r = rng(13);
    let mut shapes = Vec::new();
    for i in 0..150 {
        let c = v(
            lerp(-8.0, 8.0, r.next_f32()),
            lerp(-8.0, 8.0, r.next_f32()),
            lerp(-8.0, 8.0, r.next_f32()),
        );
        let s = lerp(0.2, 1.5, r.next_f32());
        shapes.push(match i % 3 {
            0 => Shape::Sphere {
                center: c,
                radius: s,
            },
            1 => Shape::Triangle {
                vertices: [
                    c + random_unit(&mut r) * s,
                    c + random_unit(&mut r) * s,
                    c + random_unit(&mut r) * s,
                ],
            },
            _ => Shape::Box {
                min: c - v(s, 0.5 * s, 0.7 * s),
                max: c + v(0.3 * s, s, 0.7 * s),
            },
        });
    }
    let scene = plain_scene(shapes.clone());
    let mut hits = 0;
    for _ in 0..3000 {
        let origin = random_unit(&mut r) * 20.0;
        let target = random_in_ball(&mut r, Vec3::ZERO, 8.0);
        let t_min = if r.next_f32() < 0.3 { 5.0 } else { 0.0 };
        let ray = ray_window(origin, target - origin, t_min, f32::INFINITY);
        let brute = shapes
            .iter()
            .filter_map(|s| s.intersect(&ray).map(|h| h.t))
            .min_by(f32::total_cmp);
        let got = scene.intersect(&ray).map(|h| h.t);
        match (brute, got) {
            (None, None) => {}
            (Some(b), Some(g)) => {
                hits += 1;
                assert_close(g, b, 1e-6 * b.max(1.0), "closest t");
            }
            _ => panic!("ray {ray:?}: brute force {brute:?}, scene {got:?}"),
        }
    }
    assert!(
        hits > 1000,
        "only {hits} hits: the test scene is too sparse"
    );
}

/// A unit sphere at the origin placed by `m`.
fn instanced_sphere_scene(m: &Matrix4) -> Scene {
    scene_from(
        vec![GeometryDesc {
            shapes: vec![Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            }],
            materials: vec![0],
        }],
        vec![Instance {
            transform: Some(Transform::from_matrix(m).unwrap()),
            ..identity_instance(0)
        }],
    )
}

#[test]
fn instanced_ellipsoid_hit_point_and_normal() {
    // Unit sphere scaled by (1,2,0.5), then moved to (2,1,-6): the ellipsoid
    // (x-2)^2 + (y-1)^2/4 + (z+6)^2/0.25 = 1.
    let centre = v(2.0, 1.0, -6.0);
    let radii = v(1.0, 2.0, 0.5);
    let m = Matrix4::translate(centre).mul(&Matrix4::scale(radii));
    let scene = instanced_sphere_scene(&m);

    // Straight down -Z through the centre: front at z = -6 + 0.5, so t = 5.5 from z = 0.
    let ray = Ray::new(v(2.0, 1.0, 0.0), v(0.0, 0.0, -1.0));
    let hit = scene.intersect(&ray).expect("hit the ellipsoid");
    assert_close(
        hit.t,
        5.5,
        1e-5,
        "axial t (world-space t, not object-space)",
    );
    let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
    assert_vec_close(si.point, v(2.0, 1.0, -5.5), 1e-5, "axial point");
    assert_vec_close(si.normal, Vec3::Z, 1e-5, "axial normal");
    // Along +Y from below: bottom at y = 1 - 2 = -1, t = 4 from y = -5.
    let ray = Ray::new(v(2.0, -5.0, -6.0), v(0.0, 1.0, 0.0));
    assert_close(scene.intersect(&ray).unwrap().t, 4.0, 1e-5, "vertical t");
    // Misses where the unit sphere would have been hit but the squashed one is not.
    // From inside at z = -5.8 ((0.2)^2/0.25 = 0.16): exits at x = 2 + sqrt(0.84).
    let ray = Ray::new(v(2.0, 1.0, -5.8), v(1.0, 0.0, 0.0));
    let h = scene.intersect(&ray).expect("from inside: hits the wall");
    assert_close(h.t, 0.84f32.sqrt(), 1e-5, "exit t from inside");
    let ray = Ray::new(v(0.0, 1.0, -6.7), v(1.0, 0.0, 0.0));
    assert!(
        scene.intersect(&ray).is_none(),
        "z = -6.7 is outside the squashed sphere"
    );

    // Random visible points: aim at a point q on the ellipsoid from a viewpoint e in q's
    // outer half-space (so q is the first hit of the convex ellipsoid) and check t and the
    // analytic normal ∝ ((x-cx)/a^2, (y-cy)/b^2, (z-cz)/c^2).
    let mut r = rng(14);
    let mut checked = 0;
    while checked < 500 {
        let q = centre + random_unit(&mut r).mul_elem(radii);
        let rel = q - centre;
        let grad = v(
            rel.x / (radii.x * radii.x),
            rel.y / (radii.y * radii.y),
            rel.z / (radii.z * radii.z),
        )
        .normalized();
        let e = centre + random_unit(&mut r) * 4.0;
        if grad.dot((e - q).normalized()) < 0.1 {
            continue;
        }
        let k = lerp(0.2, 3.0, r.next_f32());
        let ray = Ray::new(e, (q - e) * k);
        let hit = scene.intersect(&ray).expect("visible point");
        assert_close(hit.t * k, 1.0, 2e-5, "t of the aimed point (relative)");
        let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
        assert_vec_close(si.point, q, 1e-4, "world hit point");
        assert_close(si.normal.length(), 1.0, 1e-5, "unit world normal");
        assert_vec_close(si.normal, grad, 5e-4, "analytic normal at the aimed point");
        // At the actual hit point the analytic normal must agree much more tightly.
        let rel = si.point - centre;
        let grad_hit = v(
            rel.x / (radii.x * radii.x),
            rel.y / (radii.y * radii.y),
            rel.z / (radii.z * radii.z),
        )
        .normalized();
        assert_vec_close(
            si.normal,
            grad_hit,
            2e-5,
            "analytic normal at the hit point",
        );
        checked += 1;
    }
}

#[test]
fn instanced_rotated_box_normal_and_shadow_flag() {
    // Box [-1,1]x[-0.5,0.5]x[-0.25,0.25] turned 90 degrees about Y (object X -> world -Z)
    // and moved to z = -5: world z-extent [-6,-4].
    let m = Matrix4::translate(v(0.0, 0.0, -5.0)).mul(&Matrix4::rotate(1, 90.0));
    let geometry = GeometryDesc {
        shapes: vec![Shape::Box {
            min: v(-1.0, -0.5, -0.25),
            max: v(1.0, 0.5, 0.25),
        }],
        materials: vec![0],
    };
    let placed = Instance {
        transform: Some(Transform::from_matrix(&m).unwrap()),
        ..identity_instance(0)
    };
    let scene = scene_from(vec![geometry.clone()], vec![placed]);
    let ray = Ray::new(Vec3::ZERO, v(0.0, 0.0, -1.0));
    let hit = scene.intersect(&ray).expect("hit the rotated box");
    assert_close(hit.t, 4.0, 1e-5, "front face at z = -4");
    let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
    assert_vec_close(
        si.normal,
        Vec3::Z,
        1e-5,
        "world normal of the object -X face",
    );
    // Along +X the box is only 0.5 wide (object z-extent): from x = -3, t = 2.75.
    let ray = Ray::new(v(-3.0, 0.0, -5.0), Vec3::X);
    assert_close(
        scene.intersect(&ray).unwrap().t,
        2.75,
        1e-5,
        "x-extent 0.25",
    );

    // The same instance with casts_shadow = false is still hit by rays but never occludes.
    let ghost = Instance {
        casts_shadow: false,
        ..placed
    };
    let scene = scene_from(vec![geometry], vec![ghost]);
    assert!(scene
        .intersect(&Ray::new(Vec3::ZERO, v(0.0, 0.0, -1.0)))
        .is_some());
    assert!(!scene.occluded(&Ray::spawn_to(Vec3::ZERO, v(0.0, 0.0, -10.0))));
}

#[test]
fn scene_hits_rays_whose_direction_has_negative_zero_components() {
    // -0.0 == 0.0: a direction (-0, -0, -1) (e.g. `-Vec3::Z`) is the same ray as (0, 0, -1)
    // and must hit the same sphere at t = 4. Primitive-level tests handle it (the slab test
    // of `intersect_box` too); the scene's BVH must as well.
    let scene = plain_scene(vec![Shape::Sphere {
        center: v(0.0, 0.0, -5.0),
        radius: 1.0,
    }]);
    let plus = Ray::new(Vec3::ZERO, v(0.0, 0.0, -1.0));
    let minus = Ray::new(Vec3::ZERO, -Vec3::Z);
    assert!(
        minus.direction.x.is_sign_negative(),
        "the test needs a -0.0 component"
    );
    assert_close(
        intersect_sphere(&minus, v(0.0, 0.0, -5.0), 1.0).unwrap().t,
        4.0,
        1e-6,
        "prim",
    );
    assert_close(
        scene.intersect(&plus).expect("+0 ray").t,
        4.0,
        1e-6,
        "+0 ray",
    );
    let h = scene.intersect(&minus);
    assert!(
        h.is_some(),
        "ray with direction {:?} misses the sphere",
        minus.direction
    );
    assert_close(h.unwrap().t, 4.0, 1e-6, "-0 ray");
    // Shadow rays go through the same traversal.
    let shadow = Ray {
        t_max: 10.0,
        ..minus
    };
    assert!(
        scene.occluded(&shadow),
        "sphere between origin and z = -10 occludes"
    );
}

#[test]
fn far_sphere_hit_points_are_accurate_enough_for_the_spawn_epsilon() {
    // marbles01.json: camera at (-140, 80, -140), spheres of radius 1.5 .. 15 hundreds of
    // units away. The hit point must lie within a small fraction of SPAWN_EPSILON of the
    // sphere, or rays spawned there find their own sphere again (surface acne). An f32
    // quadratic with discriminant b^2 - ac loses ~D^2 eps / R to cancellation (b^2 ~ D^2);
    // the perpendicular-distance form of the discriminant (Ray Tracing Gems ch. 7) or f64
    // arithmetic keeps the error near D eps (~7e-5 at D = 300).
    let mut problems = Vec::new();
    for (dist, radius) in [(30.0f32, 0.1f32), (100.0, 1.0), (300.0, 1.5), (300.0, 5.0)] {
        let centre = v(0.0, 0.0, -dist);
        let scene = plain_scene(vec![Shape::Sphere {
            center: centre,
            radius,
        }]);
        let mut r = rng(15);
        let (mut max_err, mut self_hits, mut tested) = (0.0f32, 0, 0);
        for _ in 0..5000 {
            let target = random_in_ball(&mut r, centre, 0.999 * radius);
            let origin = v(r.next_f32(), r.next_f32(), 0.0);
            let ray = Ray::new(origin, (target - origin).normalized());
            let hit = scene.intersect(&ray).expect("aimed at the sphere");
            let si = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
            max_err = max_err.max(((si.point - centre).length() - radius).abs());
            // Non-grazing reflections only (|cos| > 0.1): a point off the surface by delta
            // re-hits at ~delta / cos, which must stay below SPAWN_EPSILON.
            if ray.direction.dot(si.normal).abs() > 0.1 {
                tested += 1;
                let refl = reflect(ray.direction, si.normal);
                if scene.intersect(&Ray::spawn(si.point, refl)).is_some() {
                    self_hits += 1;
                }
            }
        }
        if max_err > 0.2 * SPAWN_EPSILON || self_hits > 0 {
            problems.push(format!(
                "sphere R = {radius} at distance {dist}: max |p - c| - R = {max_err:e}, \
                 {self_hits}/{tested} reflected rays re-hit the sphere"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
