//! Depth of field (`-d`): every lens ray passes through the point of the plane in focus that
//! the pinhole ray meets, and a checkerboard on the plane in focus renders as sharp as without
//! a lens while the same board out of focus blurs. (That a camera without a lens renders
//! exactly as before is `scripts/same-images.sh`; the path tracer's blur is checked against
//! Mitsuba 3 in glint-io's `path_thinlens.rs`.)

use crate::sampling::Rng;
use crate::{
    render, Background, Camera, Color, GeometryDesc, Instance, IntegratorKind, Light, Material,
    Projection, RenderSettings, Scene, SceneParts, Shape, ThinLens, Vec3,
};

#[test]
fn lens_rays_meet_the_pinhole_ray_on_the_plane_in_focus() {
    let mut rng = Rng::new(5, 1);
    for projection in [Projection::Perspective, Projection::Orthographic] {
        let mut camera = Camera::new(
            projection,
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-0.3, -0.2, -1.0),
            1.5,
            1.0,
        );
        let focus_distance = 7.0;
        camera.lens = Some(ThinLens {
            focus_distance,
            radius: 0.4,
        });
        let view = -camera.basis.w;
        for _ in 0..1000 {
            let (px, py) = (rng.next_f32() * 64.0, rng.next_f32() * 48.0);
            let pinhole = camera.ray(px, py, 64, 48, 4.0 / 3.0);
            let lens = (rng.next_f32(), rng.next_f32());
            let ray = camera.lens_ray(px, py, 64, 48, 4.0 / 3.0, lens);
            // Same component along the view direction, and a different origin on the lens.
            assert!((ray.direction.dot(view) - pinhole.direction.dot(view)).abs() < 1e-5);
            let offset = ray.origin - camera_origin(&camera, &pinhole);
            assert!(offset.dot(view).abs() < 1e-5 && offset.length() <= 0.4 + 1e-5);
            // Both reach the plane in focus at the same point.
            let at_focus = |r: &crate::Ray| {
                let t = (focus_distance - (r.origin - camera.position).dot(view))
                    / r.direction.dot(view);
                r.at(t)
            };
            let miss = (at_focus(&ray) - at_focus(&pinhole)).length();
            assert!(miss < 1e-4 * focus_distance, "{projection:?}: {miss}");
        }
        // Lens samples spread over the whole disk.
        let far = camera.lens_ray(32.0, 24.0, 64, 48, 4.0 / 3.0, (0.999, 0.5));
        let centre = camera.ray(32.0, 24.0, 64, 48, 4.0 / 3.0);
        assert!((far.origin - centre.origin).length() > 0.39);
    }
}

fn camera_origin(camera: &Camera, pinhole: &crate::Ray) -> Vec3 {
    match camera.projection {
        Projection::Perspective => camera.position,
        Projection::Orthographic => pinhole.origin,
    }
}

/// A camera at the origin looking down -z at a checkerboard of boxes (cells `cell` wide) in
/// the plane z = -`distance`, lit by a point light at the camera.
fn checkerboard(distance: f32, lens: Option<ThinLens>) -> Scene {
    let mut camera = Camera::new(Projection::Perspective, Vec3::ZERO, -Vec3::Z, 1.0, 1.0);
    camera.lens = lens;
    let half = 0.5 * distance; // the board fills the view
    let cell = half / 6.0;
    let mut shapes = Vec::new();
    let mut materials = Vec::new();
    for i in 0..12 {
        for j in 0..12 {
            let min = Vec3::new(-half + i as f32 * cell, -half + j as f32 * cell, -distance);
            shapes.push(Shape::Box {
                min: min - Vec3::new(0.0, 0.0, 0.01 * cell),
                max: min + Vec3::new(cell, cell, 0.0),
            });
            materials.push(((i + j) % 2) as u32);
        }
    }
    let lambertian = |c: f32| Material::Lambertian {
        diffuse: Color::splat(c).into(),
    };
    Scene::new(SceneParts {
        physical: Default::default(),
        camera,
        materials: vec![lambertian(0.9), lambertian(0.1)],
        textures: vec![],
        lights: vec![Light::Point {
            position: Vec3::ZERO,
            intensity: Color::ONE,
        }],
        background: Background::Color(Color::ZERO),
        geometries: vec![GeometryDesc { shapes, materials }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    })
}

/// Mean absolute difference per channel between two renders of the same size.
fn mean_difference(a: &[Color], b: &[Color]) -> f32 {
    let sum: f32 = a
        .iter()
        .zip(b)
        .map(|(p, q)| (*p - *q).to_array().iter().map(|c| c.abs()).sum::<f32>())
        .sum();
    sum / (3 * a.len()) as f32
}

#[test]
fn the_plane_in_focus_stays_sharp_and_a_nearer_one_blurs() {
    let settings = RenderSettings {
        width: 48,
        height: 48,
        samples_per_pixel: 16,
        seed: 2,
        integrator: IntegratorKind::Course,
        ..RenderSettings::default()
    };
    let image = |scene: &Scene| {
        render(scene, &settings, &|_| true)
            .expect("renders")
            .0
            .pixels
    };
    let lens = |focus_distance: f32| ThinLens {
        focus_distance,
        radius: 0.5,
    };
    let pinhole = image(&checkerboard(10.0, None));
    // Focused on the board: the same picture up to rounding where a ray grazes a cell edge.
    let focused = image(&checkerboard(10.0, Some(lens(10.0))));
    let sharp = mean_difference(&pinhole, &focused);
    // Focused at half the distance: a lens of radius 0.5 blurs the board's cells (0.83 wide)
    // over a disk of diameter 1, mixing black and white.
    let defocused = image(&checkerboard(10.0, Some(lens(5.0))));
    let blurred = mean_difference(&pinhole, &defocused);
    println!("checkerboard: mean difference to the pinhole in focus {sharp:.2e}, out of focus {blurred:.3}");
    assert!(sharp < 2e-3, "in focus: mean difference {sharp}");
    assert!(blurred > 0.1, "out of focus: mean difference {blurred}");
}
