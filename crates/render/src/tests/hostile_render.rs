//! Renders that hostile settings and geometry once made endless: a stop signal heard inside a
//! pixel of many samples, the course dielectric's branching bounded per camera sample without
//! changing its expected value, exact copies of a shape kept out of the BVH, and sample counts
//! at the top of `u32`.

use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use crate::integrator::course::{shade_camera_ray, SampleContext, RAY_BUDGET};
use crate::integrator::PixelContext;
use crate::light::sampler::LightSampler;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::{
    measure_traversal, render, render_interruptible, Background, Camera, Color, GeometryDesc,
    Instance, IntegratorKind, Light, Material, ProgressiveRender, Projection, RenderError,
    RenderSettings, Scene, SceneParts, Shape, Vec3,
};

/// A camera at the origin looking down -z at a white Lambertian sphere at z = -8, lit by a
/// point light, behind `shapes` (material 1, `glass`).
fn scene_with(shapes: Vec<Shape>, glass: Material) -> Scene {
    let mut all = vec![Shape::Sphere {
        center: Vec3::new(0.0, 0.0, -8.0),
        radius: 1.0,
    }];
    let mut materials = vec![0];
    materials.extend(shapes.iter().map(|_| 1));
    all.extend(shapes);
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(Projection::Perspective, Vec3::ZERO, -Vec3::Z, 1.0, 1.0),
        materials: vec![
            Material::Lambertian {
                diffuse: Color::ONE.into(),
            },
            glass,
        ],
        textures: vec![],
        lights: vec![Light::Point {
            position: Vec3::new(0.0, 3.0, 0.0),
            intensity: Color::ONE,
        }],
        background: Background::Color(Color::new(0.2, 0.3, 0.4)),
        geometries: vec![GeometryDesc {
            shapes: all,
            materials,
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    })
}

fn glass() -> Material {
    Material::Dielectric {
        refractive_index: 1.5,
        attenuation: Color::ONE,
    }
}

/// Four glass slabs between the camera and the sphere (as `scripts/hostile-figures.py`'s
/// "glass -k 24").
fn glass_slabs() -> Scene {
    let slabs = (0..4)
        .map(|i| Shape::Box {
            min: Vec3::new(-2.0, -2.0, -3.0 - i as f32),
            max: Vec3::new(2.0, 2.0, -2.9 - i as f32),
        })
        .collect();
    scene_with(slabs, glass())
}

fn one_pixel(integrator: IntegratorKind, samples_per_pixel: u32) -> RenderSettings {
    RenderSettings {
        width: 1,
        height: 1,
        samples_per_pixel,
        integrator,
        ..RenderSettings::default()
    }
}

/// Runs `work` on its own thread and waits for it at most `limit`: a render that does not
/// stop when told would otherwise hang the test rather than fail it.
fn within<T: Send + 'static>(limit: Duration, work: impl FnOnce() -> T + Send + 'static) -> T {
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(work());
    });
    receive
        .recv_timeout(limit)
        .expect("the render did not stop when told to")
}

/// One pixel of the most samples a pixel may take (2^24) behind four glass slabs, with every
/// integrator: the stop signal, which says stop from its fourth look on, is heard inside the
/// pixel (the progress callback, heard only between tiles, never is), and the render hands
/// back no pixel. Before the stop signal was looked at inside pixels, each of these ran for
/// minutes.
#[test]
fn a_stop_signal_ends_a_pixel_of_the_most_samples() {
    for integrator in IntegratorKind::ALL {
        let looks = within(Duration::from_secs(60), move || {
            let scene = glass_slabs();
            let settings = RenderSettings {
                threads: Some(2),
                ..one_pixel(integrator, crate::MAX_SAMPLES_PER_PIXEL)
            };
            let looks = AtomicU32::new(0);
            let result = render_interruptible(&scene, &settings, &|_| true, &|| {
                looks.fetch_add(1, Ordering::Relaxed) >= 3
            });
            assert_eq!(
                result.unwrap_err(),
                RenderError::Cancelled,
                "{integrator:?}"
            );
            looks.into_inner()
        });
        assert!(looks >= 4, "{integrator:?}: stop was asked {looks} times");
    }
}

/// A progressive render's pass stopped inside its pixels leaves the render as the last
/// pass left it, bit for bit: no pixel keeps part of the stopped pass's samples.
#[test]
fn a_stopped_pass_leaves_the_render_as_it_was() {
    for integrator in [IntegratorKind::Path, IntegratorKind::VolPath] {
        let (before, after, taken) = within(Duration::from_secs(60), move || {
            let scene = glass_slabs();
            let settings = RenderSettings {
                width: 3,
                height: 2,
                ..one_pixel(integrator, crate::MAX_SAMPLES_PER_PIXEL)
            };
            let mut passes = ProgressiveRender::new(&settings).unwrap();
            passes.pass(&scene, 4, &|_| true).unwrap();
            let before = passes.film();
            let looks = AtomicU32::new(0);
            let stopped = passes.pass_interruptible(&scene, 1 << 23, &|_| true, &|| {
                looks.fetch_add(1, Ordering::Relaxed) >= 3
            });
            assert_eq!(stopped.unwrap_err(), RenderError::Cancelled);
            (before, passes.film(), passes.samples_taken())
        });
        assert_eq!(taken, 4, "{integrator:?}");
        let bits = |film: &crate::Film| -> Vec<[u32; 3]> {
            film.pixels
                .iter()
                .map(|c| c.to_array().map(f32::to_bits))
                .collect()
        };
        assert_eq!(bits(&before), bits(&after), "{integrator:?}");
        assert_eq!(before.samples, after.samples, "{integrator:?}");
    }
}

/// A stop signal that never says stop changes nothing: the pixels are those of `render`,
/// bit for bit, with every integrator (the samples are taken in chunks between the looks).
#[test]
fn an_unused_stop_signal_changes_no_pixel() {
    let scene = glass_slabs();
    for integrator in IntegratorKind::ALL {
        let settings = RenderSettings {
            width: 20,
            height: 18,
            samples_per_pixel: 36,
            max_depth: Some(6),
            features: true,
            seed: 3,
            integrator,
            ..RenderSettings::default()
        };
        let (plain, _) = render(&scene, &settings, &|_| true).unwrap();
        let (stoppable, _) = render_interruptible(&scene, &settings, &|_| true, &|| false).unwrap();
        assert_eq!(plain, stoppable, "{integrator:?}");
    }
}

/// The course integrator's sample at the pixel centre of a 1x1 image, its random stream
/// keyed by `s`, with `budget` rays before its dielectrics take one branch: (radiance, rays).
fn centre_sample(scene: &Scene, max_depth: u32, s: u32, budget: u64) -> (Color, u64) {
    let lights = LightSampler::without_environment(scene);
    let pixel = PixelContext {
        x: 0,
        y: 0,
        width: 1,
        height: 1,
        aspect: 1.0,
        seed: 11,
        samples_per_pixel: 1,
        max_depth,
        features: false,
        progressive_order: false,
    };
    let ray: Ray = pixel.camera_ray(scene, 0.5, 0.5, (0.5, 0.5));
    let mut ctx = SampleContext {
        rng: Rng::for_sample(pixel.seed, pixel.index(), s as u64),
        lights: Some(&lights),
        sample_index: 0,
        grid_size: 1,
        pixel_key: 0,
        max_depth,
        rays: 1,
        ray_budget: budget,
    };
    let c = shade_camera_ray(scene, &ray, &mut ctx);
    (c, ctx.rays)
}

/// Four glass slabs at -k 24: a camera sample takes at most the budget and then `-k` rays
/// (and a shadow ray each) for each branch left open, where both branches at every hit took
/// up to 2^25. The budget is reached, so the bound is the budget's doing.
#[test]
fn glass_slabs_at_depth_24_take_a_bounded_number_of_rays() {
    let scene = glass_slabs();
    let depth = 24;
    let settings = RenderSettings {
        max_depth: Some(depth),
        ..one_pixel(IntegratorKind::Course, 1)
    };
    let (_, stats) = render(&scene, &settings, &|_| true).unwrap();
    let k = depth as u64;
    let bound = RAY_BUDGET + 2 + k * k * 2;
    assert!(
        stats.rays > RAY_BUDGET && stats.rays <= bound,
        "{} rays for one camera sample (budget {RAY_BUDGET}, bound {bound})",
        stats.rays
    );
}

/// Under the budget nothing changes: at -k 8 every dielectric takes both branches (512 rays
/// at most), and the default budget gives the unlimited one's radiance bit for bit. Past it,
/// the one branch chosen by its Fresnel weight has the both-branch radiance as its expected
/// value: the mean of 4000 samples with no budget at all is within five standard errors of
/// the exact both-branch radiance, channel by channel, and so is that of samples whose budget
/// runs out halfway.
#[test]
fn past_the_budget_the_expected_value_is_the_both_branch_one() {
    let scene = glass_slabs();
    let depth = 8;
    let (exact, rays) = centre_sample(&scene, depth, 0, u64::MAX);
    assert!(rays > 64 && rays < RAY_BUDGET, "{rays} rays");
    let (default, _) = centre_sample(&scene, depth, 0, RAY_BUDGET);
    assert_eq!(
        exact.to_array().map(f32::to_bits),
        default.to_array().map(f32::to_bits)
    );
    for budget in [0, rays / 2] {
        let n = 4000;
        let (mut sum, mut squares) = ([0.0f64; 3], [0.0f64; 3]);
        for s in 0..n {
            let (c, _) = centre_sample(&scene, depth, s, budget);
            for (channel, v) in c.to_array().into_iter().enumerate() {
                sum[channel] += v as f64;
                squares[channel] += (v as f64).powi(2);
            }
        }
        for (channel, want) in exact.to_array().into_iter().enumerate() {
            let mean = sum[channel] / n as f64;
            let variance = (squares[channel] / n as f64 - mean * mean).max(0.0);
            let error = (variance / n as f64).sqrt();
            assert!(
                (mean - want as f64).abs() <= 5.0 * error + 1e-6,
                "budget {budget}, channel {channel}: mean {mean} ± {error}, exact {want}"
            );
        }
    }
}

/// A triangle facing the camera at z = -5, `copies` times, then another one beside it
/// `copies` times, interleaved.
fn copies_of_two_triangles(copies: usize) -> Vec<Shape> {
    let a = Shape::Triangle {
        vertices: [
            Vec3::new(-1.0, -1.0, -5.0),
            Vec3::new(1.0, -1.0, -5.0),
            Vec3::new(0.0, 1.0, -5.0),
        ],
    };
    let b = Shape::Triangle {
        vertices: [
            Vec3::new(0.5, 0.0, -4.0),
            Vec3::new(2.5, 0.0, -4.0),
            Vec3::new(1.5, 2.0, -4.0),
        ],
    };
    (0..copies).flat_map(|_| [a, b]).collect()
}

/// Exact copies of a triangle are kept out of the BVH: twenty thousand copies of two
/// triangles cost a camera ray a few block tests (it tested all ten thousand blocks a tree
/// of copies holds, whose leaves all overlap), and every hit is the one brute force finds,
/// the lowest index among the copies.
#[test]
fn exact_copies_cost_a_ray_one_test_and_hit_the_first_copy() {
    let shapes = copies_of_two_triangles(20_000);
    let tris = crate::testing::triangles(&shapes);
    for bvh in crate::testing::wide_variants(&shapes) {
        let mut rng = crate::testing::rng(7);
        let bounds = crate::Aabb {
            min: Vec3::new(-3.0, -3.0, -6.0),
            max: Vec3::new(3.0, 3.0, -3.0),
        };
        for ray in crate::testing::random_rays(&mut rng, bounds, 500) {
            let want = crate::testing::brute_force(&tris, &ray);
            let got = crate::testing::wide_closest(&bvh, &ray);
            assert_eq!(
                got.map(|(t, i)| (t.to_bits(), i)),
                want.map(|(t, i)| (t.to_bits(), i))
            );
        }
    }
    let scene = scene_with(shapes, glass());
    let settings = RenderSettings {
        width: 16,
        height: 16,
        ..RenderSettings::default()
    };
    let traversal = measure_traversal(&scene, &settings);
    assert!(traversal.hits > 0);
    assert!(
        traversal.blocks_per_ray() <= 2.0,
        "{} triangle blocks per camera ray",
        traversal.blocks_per_ray()
    );
}

/// Sample counts at the cap (`MAX_SAMPLES_PER_PIXEL`, 2^24: the course integrator's
/// 4096 x 4096 grid, the path tracers' 2^24 samples), the last samples of each through a
/// sample range, and adaptive sampling's checks at the top of `u32`, with overflow checks on
/// (a debug build): no arithmetic overflows and the samples are finite. One more sample than
/// the cap is refused.
#[test]
fn the_last_samples_of_the_most_samples_a_pixel_may_take() {
    let scene = glass_slabs();
    let most = crate::MAX_SAMPLES_PER_PIXEL;
    for integrator in IntegratorKind::ALL {
        let mut settings = one_pixel(integrator, most);
        let all = settings.samples_per_pixel();
        assert_eq!(all, most, "{integrator:?}");
        assert!(one_pixel(integrator, most + 1).validate().is_err());
        assert!(one_pixel(integrator, 0).validate().is_err());
        settings.sample_range = Some(all - 3..all);
        settings.features = true;
        let (film, stats) = render(&scene, &settings, &|_| true).unwrap();
        assert!(film.pixels[0].is_finite(), "{integrator:?}");
        assert_eq!(film.sums.as_ref().unwrap().counts[0], 3, "{integrator:?}");
        assert!(stats.rays >= 3, "{integrator:?}");
    }
    let adaptive = crate::AdaptiveSampling {
        threshold: 0.01,
        min_samples: u32::MAX - 1,
    };
    assert_eq!(adaptive.check_after(u32::MAX - 1), u32::MAX);
    assert_eq!(adaptive.check_after(u32::MAX), u32::MAX);
}
