//! The one pipeline: a crop window renders exactly the whole render's pixels, a sample range
//! that covers every sample is the whole render, a frame of the beauty alone is a full
//! frame's, `-k` reaches the path tracer, every integrator makes feature layers, and
//! non-finite samples never reach a pixel.

use crate::{
    render, Background, Camera, Color, GeometryDesc, Instance, IntegratorKind, Light, Material,
    PixelBounds, Projection, RenderSettings, Scene, SceneParts, Shape, Vec3,
};

/// A red Lambertian sphere on a grey floor, a point light, a grey background.
pub(super) fn scene(sphere: Material) -> Scene {
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(
            Projection::Perspective,
            Vec3::new(0.0, 0.5, 4.0),
            -Vec3::Z,
            1.0,
            1.0,
        ),
        materials: vec![
            sphere,
            Material::Lambertian {
                diffuse: Color::splat(0.5).into(),
            },
        ],
        textures: vec![],
        lights: vec![Light::Point {
            position: Vec3::new(2.0, 3.0, 3.0),
            intensity: Color::ONE,
        }],
        background: Background::Color(Color::splat(0.2)),
        geometries: vec![GeometryDesc {
            shapes: vec![
                Shape::Sphere {
                    center: Vec3::new(0.0, 0.5, 0.0),
                    radius: 1.0,
                },
                Shape::Box {
                    min: Vec3::new(-5.0, -1.0, -5.0),
                    max: Vec3::new(5.0, -0.5, 5.0),
                },
            ],
            materials: vec![0, 1],
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    })
}

pub(super) fn red() -> Material {
    Material::Lambertian {
        diffuse: Color::new(0.8, 0.1, 0.1).into(),
    }
}

fn settings(integrator: IntegratorKind) -> RenderSettings {
    RenderSettings {
        width: 37,
        height: 29,
        samples_per_pixel: 9,
        seed: 5,
        integrator,
        features: true,
        ..RenderSettings::default()
    }
}

fn bits(c: Color) -> [u32; 3] {
    c.to_array().map(f32::to_bits)
}

#[test]
fn a_crop_window_renders_exactly_the_whole_renders_pixels() {
    let scene = scene(red());
    for integrator in IntegratorKind::ALL {
        let whole = settings(integrator);
        let (full, _) = render(&scene, &whole, &|_| true).unwrap();
        let bounds = PixelBounds {
            x0: 5,
            x1: 30,
            y0: 3,
            y1: 20,
        };
        let crop = RenderSettings {
            pixel_bounds: Some(bounds),
            ..whole.clone()
        };
        let (part, _) = render(&scene, &crop, &|_| true).unwrap();
        assert_eq!((part.width, part.height), (25, 17));
        assert_eq!(part.origin, (5, 3));
        assert_eq!(part.full_size, (37, 29));
        for y in 0..part.height {
            for x in 0..part.width {
                let (fx, fy) = (x + bounds.x0, y + bounds.y0);
                assert_eq!(
                    bits(part.pixel(x, y)),
                    bits(full.pixel(fx, fy)),
                    "{integrator:?} pixel ({fx}, {fy})"
                );
                let k = (y * part.width + x) as usize;
                let fk = (fy * full.width + fx) as usize;
                let (pf, ff) = (
                    part.features.as_ref().unwrap(),
                    full.features.as_ref().unwrap(),
                );
                assert_eq!(bits(pf.albedo[k]), bits(ff.albedo[fk]));
                assert_eq!(pf.depth[k].to_bits(), ff.depth[fk].to_bits());
            }
        }
    }
}

#[test]
fn a_sample_range_of_every_sample_is_the_whole_render() {
    let scene = scene(red());
    for integrator in [IntegratorKind::Path, IntegratorKind::Course] {
        let whole = settings(integrator);
        let (full, _) = render(&scene, &whole, &|_| true).unwrap();
        let ranged = RenderSettings {
            sample_range: Some(0..9),
            ..whole.clone()
        };
        let (same, _) = render(&scene, &ranged, &|_| true).unwrap();
        assert_eq!(full.pixels, same.pixels, "{integrator:?}");
        assert_eq!(full.features, same.features, "{integrator:?}");
        // Only a sample range keeps the sums; each pixel is its sum over its count.
        assert!(full.sums.is_none());
        let sums = same.sums.as_ref().expect("a sample range keeps its sums");
        for ((pixel, sum), count) in same.pixels.iter().zip(&sums.radiance).zip(&sums.counts) {
            assert_eq!(*count, 9, "{integrator:?}");
            assert_eq!(*pixel, *sum / *count as f32, "{integrator:?}");
        }
        // A partial range is a different, valid estimate; an empty one is refused.
        let part = RenderSettings {
            sample_range: Some(3..7),
            ..whole.clone()
        };
        let (partial, _) = render(&scene, &part, &|_| true).unwrap();
        assert_ne!(partial.pixels, full.pixels);
        let empty = RenderSettings {
            sample_range: Some(4..4),
            ..whole
        };
        assert!(render(&scene, &empty, &|_| true).is_err());
    }
}

#[test]
fn max_depth_reaches_the_path_tracer() {
    let scene = scene(red());
    let mean = |max_depth| {
        let s = RenderSettings {
            max_depth,
            features: false,
            ..settings(IntegratorKind::Path)
        };
        let (film, _) = render(&scene, &s, &|_| true).unwrap();
        film.pixels.iter().map(|c| c.x as f64).sum::<f64>() / film.pixels.len() as f64
    };
    // Depth 0: only what the camera sees emitting (the background); lit surfaces are black.
    let direct_view = mean(Some(0));
    let lit = mean(None);
    assert!(lit > direct_view * 1.5, "{lit} vs {direct_view}");
    assert_ne!(mean(Some(1)), lit);
}

#[test]
fn every_integrator_makes_feature_layers() {
    let scene = scene(red());
    for integrator in IntegratorKind::ALL {
        let (film, _) = render(&scene, &settings(integrator), &|_| true).unwrap();
        let features = film.features.expect("features were asked for");
        // The centre pixel sees the red sphere: its albedo, a normal facing the camera, and a
        // depth of about 3 (camera at z = 4, sphere's front at z = 1).
        let k = (14 * 37 + 18) as usize;
        assert!(
            (features.albedo[k] - Color::new(0.8, 0.1, 0.1))
                .abs()
                .max_component()
                < 1e-5
        );
        assert!(features.normal[k].z > 0.9, "{:?}", features.normal[k]);
        assert!(
            (features.depth[k] - 3.0).abs() < 0.1,
            "{}",
            features.depth[k]
        );
        // The top row sees the background: its albedo, no normal, no depth.
        assert!(
            (features.albedo[3] - Color::splat(0.2))
                .abs()
                .max_component()
                < 1e-6
        );
        assert_eq!(features.depth[3], 0.0);
    }
}

/// A frame without feature layers or sample sums keeps only its beauty while it renders: the
/// same pixels, bit for bit, as the frame with everything.
#[test]
fn a_beauty_only_frame_is_the_beauty_of_a_full_one() {
    let scene = scene(red());
    for integrator in IntegratorKind::ALL {
        let full = settings(integrator);
        let (everything, _) = render(&scene, &full, &|_| true).unwrap();
        let beauty = RenderSettings {
            features: false,
            ..full.clone()
        };
        let (alone, _) = render(&scene, &beauty, &|_| true).unwrap();
        assert!(alone.features.is_none() && alone.sums.is_none());
        assert_eq!(
            (alone.width, alone.height, alone.origin, alone.full_size),
            (
                everything.width,
                everything.height,
                everything.origin,
                everything.full_size
            )
        );
        let bits_of = |film: &crate::Film| film.pixels.iter().map(|&c| bits(c)).collect::<Vec<_>>();
        assert_eq!(bits_of(&alone), bits_of(&everything), "{integrator:?}");
        assert!(alone.pixels.iter().any(|c| c.max_component() > 0.0));
    }
}

#[test]
fn non_finite_samples_are_dropped_and_counted() {
    // A sphere that emits infinite radiance: every sample that sees it is infinite or NaN.
    let scene = scene(Material::Emissive {
        radiance: Color::splat(f32::INFINITY),
        surface: None,
        light: None,
    });
    for integrator in [IntegratorKind::Course, IntegratorKind::Path] {
        let s = RenderSettings {
            features: false,
            ..settings(integrator)
        };
        let (film, stats) = render(&scene, &s, &|_| true).unwrap();
        assert!(film.pixels.iter().all(|c| c.is_finite()), "{integrator:?}");
        assert!(stats.nonfinite_samples > 0, "{integrator:?}");
        let (x, y) = stats.first_nonfinite_pixel.expect("a first pixel");
        assert!(x < 37 && y < 29);
    }
}

#[test]
fn finite_samples_whose_sum_overflows_are_dropped_and_counted() {
    // Each sample is finite (3e38), but 16 of them sum to infinity: the pixel must not be
    // infinite, and the samples are counted. The feature layers stay finite too.
    let scene = scene(Material::Emissive {
        radiance: Color::splat(3e38),
        surface: None,
        light: None,
    });
    for integrator in [IntegratorKind::Course, IntegratorKind::Path] {
        let s = RenderSettings {
            samples_per_pixel: 16,
            ..settings(integrator)
        };
        let (film, stats) = render(&scene, &s, &|_| true).unwrap();
        assert!(film.pixels.iter().all(|c| c.is_finite()), "{integrator:?}");
        let features = film.features.as_ref().expect("features were asked for");
        assert!(features.albedo.iter().all(|c| c.is_finite()));
        assert!(features.normal.iter().all(|n| n.is_finite()));
        assert!(stats.nonfinite_samples > 0, "{integrator:?}");
        assert!(stats.first_nonfinite_pixel.is_some(), "{integrator:?}");
    }
}

#[test]
fn cancelling_stops_the_render() {
    let scene = scene(red());
    let result = render(&scene, &settings(IntegratorKind::Course), &|p| {
        p.tiles_done < 2
    });
    assert_eq!(result.unwrap_err(), crate::RenderError::Cancelled);
}

/// The one rule every front end settles a scene's defaults by: asked values win, then the
/// scene's, then the course's; the scene's depth only for the path tracer.
#[test]
fn requested_settings_settle_over_the_scenes_defaults() {
    use crate::{RenderDefaults, RequestedSettings, SceneIntegrator};
    let course = RequestedSettings::default().settle(&RenderDefaults::default());
    assert_eq!(course, RenderSettings::default());
    let scene = RenderDefaults {
        width: Some(12),
        height: Some(8),
        samples_per_pixel: Some(4),
        integrator: Some(SceneIntegrator::Path),
        max_depth: Some(2),
        ..RenderDefaults::default()
    };
    let settled = RequestedSettings::default().settle(&scene);
    assert_eq!(
        (settled.width, settled.height, settled.samples_per_pixel),
        (12, 8, 4)
    );
    assert_eq!(
        (settled.integrator, settled.max_depth),
        (IntegratorKind::Path, Some(2))
    );
    let asked = RequestedSettings {
        width: Some(6),
        samples_per_pixel: Some(9),
        integrator: Some(IntegratorKind::Normals),
        ..RequestedSettings::default()
    }
    .settle(&scene);
    assert_eq!(
        (asked.width, asked.height, asked.samples_per_pixel),
        (6, 8, 9)
    );
    // The scene's depth counts the path tracer's scattering events: not the normals view's.
    assert_eq!(
        (asked.integrator, asked.max_depth),
        (IntegratorKind::Normals, None)
    );
    let direct = RenderDefaults {
        integrator: Some(SceneIntegrator::Direct),
        ..RenderDefaults::default()
    };
    let settled = RequestedSettings::default().settle(&direct);
    assert_eq!(
        (settled.integrator, settled.max_depth),
        (IntegratorKind::Path, Some(1))
    );
    let deeper = RequestedSettings {
        max_depth: Some(5),
        ..RequestedSettings::default()
    };
    assert_eq!(deeper.settle(&direct).max_depth, Some(5));
}
