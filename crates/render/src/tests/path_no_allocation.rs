//! The path tracer's per-sample work allocates nothing (ARCHITECTURE.md invariant): every
//! material (a textured one too), every kind of light and a cube-map environment, traced through
//! a counting global allocator with the renderer's own Sobol' sampler, with the plain `Rng`, and
//! through the render loop's call (`pixel_samples`, whose camera rays go in packets). And a
//! whole render's working memory: the bytes live at once on its thread, at their peak.
//! The counts are per thread, so other tests of the binary do not reach them.

// The one unsafe item: a global allocator must implement the unsafe `GlobalAlloc` trait. It
// forwards to `System` unchanged and only counts.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use crate::integrator::path::{PathIntegrator, PathSettings};
use crate::integrator::{FirstHit, Integrator, PixelContext};
use crate::sampling::sobol::{PathSampler, SobolPixel};
use crate::sampling::Rng;
use crate::{
    render, Background, Camera, Color, ColorSource, CubeMap, GeometryDesc, Image, Instance,
    IntegratorKind, Light, Material, Projection, RenderSettings, Scene, SceneParts, Shape, Vec3,
};

struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
    /// Whether this thread's bytes are weighed (`LIVE`, `PEAK`).
    static WEIGHED: Cell<bool> = const { Cell::new(false) };
    /// Bytes allocated on this thread while weighed, less those freed on it.
    static LIVE: Cell<i64> = const { Cell::new(0) };
    /// The most `LIVE` has been.
    static PEAK: Cell<i64> = const { Cell::new(0) };
}

/// Adds `bytes` (negative: freed) to this thread's live bytes if it is weighed.
fn weigh(bytes: i64) {
    if WEIGHED.with(Cell::get) {
        let live = LIVE.with(|live| {
            live.set(live.get() + bytes);
            live.get()
        });
        PEAK.with(|peak| peak.set(peak.get().max(live)));
    }
}

unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|count| count.set(count.get() + 1));
        weigh(layout.size() as i64);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        weigh(-(layout.size() as i64));
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|count| count.set(count.get() + 1));
        weigh(new_size as i64 - layout.size() as i64);
        // SAFETY: as for `dealloc`; `new_size` is passed through.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

fn every_feature_scene() -> Scene {
    let face = |value: f32| Image {
        width: 4,
        height: 4,
        texels: (0..16)
            .map(|i| Color::splat(value + i as f32 * 0.1))
            .collect(),
    };
    let materials = vec![
        Material::Diffuse {
            diffuse: Color::splat(0.7).into(),
        },
        Material::BlinnPhong {
            diffuse: Color::splat(0.4).into(),
            specular: Color::splat(0.4).into(),
            phong_exponent: 32.0,
            mirror_coef: 0.2,
        },
        Material::Phong {
            diffuse: Color::splat(0.4).into(),
            specular: Color::splat(0.4).into(),
            phong_exponent: 16.0,
        },
        Material::Mirror { roughness: 0.2 },
        Material::Glaze {
            diffuse: Color::splat(0.5).into(),
            mirror_coef: 0.3,
        },
        Material::BlinnPhongMirrored {
            diffuse: Color::splat(0.4).into(),
            specular: Color::splat(0.3).into(),
            phong_exponent: 16.0,
            mirror_coef: 0.3,
            roughness: 0.1,
        },
        Material::Dielectric {
            refractive_index: 1.5,
            attenuation: Color::new(0.9, 0.8, 0.7),
        },
        Material::CoolToWarm {
            diffuse: Color::splat(0.5).into(),
        },
        Material::Emissive {
            radiance: Color::splat(2.0),
            surface: Some(0),
            light: Some(1),
        },
        // Textured: its BSDF is built per hit from the texel, not once per render.
        Material::BlinnPhong {
            diffuse: ColorSource {
                color: Color::splat(0.8),
                texture: Some(0),
            },
            specular: Color::splat(0.2).into(),
            phong_exponent: 8.0,
            mirror_coef: 0.0,
        },
    ];
    let spheres: Vec<Shape> = (0..8)
        .map(|i| Shape::Sphere {
            center: Vec3::new(-2.1 + 0.6 * i as f32, 0.0, 0.0),
            radius: 0.28,
        })
        .collect();
    let emitter = [
        Vec3::new(-0.5, 1.5, -0.5),
        Vec3::new(0.5, 1.5, -0.5),
        Vec3::new(0.0, 1.5, 0.5),
    ];
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(
            Projection::Perspective,
            Vec3::new(0.0, 0.5, 4.0),
            -Vec3::Z,
            1.0,
            1.2,
        ),
        materials,
        textures: vec![face(0.2)],
        lights: vec![
            Light::Point {
                position: Vec3::new(1.0, 2.0, 1.0),
                intensity: Color::splat(3.0),
            },
            Light::Triangles {
                triangles: vec![emitter],
                intensity: Color::splat(2.0),
            },
            Light::Area {
                position: Vec3::new(0.0, 2.0, 1.0),
                normal: -Vec3::Y,
                width: 0.5,
                length: 0.5,
                intensity: Color::splat(4.0),
            },
            Light::Sphere {
                center: Vec3::new(2.0, 1.5, 0.0),
                radius: 0.2,
                intensity: Color::splat(5.0),
            },
        ],
        background: Background::CubeMap(Box::new(CubeMap {
            faces: [
                face(0.1),
                face(0.2),
                face(1.0),
                face(0.0),
                face(0.3),
                face(0.4),
            ],
        })),
        geometries: vec![
            GeometryDesc {
                materials: (0..8).collect(),
                shapes: spheres,
            },
            GeometryDesc {
                shapes: vec![
                    Shape::Box {
                        min: Vec3::new(-3.0, -0.4, -2.0),
                        max: Vec3::new(3.0, -0.3, 2.0),
                    },
                    Shape::Triangle { vertices: emitter },
                ],
                // The floor is the textured material, the triangle the emitter.
                materials: vec![9, 8],
            },
        ],
        instances: vec![
            Instance {
                geometry: 0,
                transform: None,
                material: None,
                casts_shadow: true,
            },
            Instance {
                geometry: 1,
                transform: None,
                material: None,
                casts_shadow: true,
            },
        ],
    })
}

#[test]
fn tracing_paths_does_not_allocate() {
    let scene = every_feature_scene();
    let integrator = PathIntegrator::new(&scene, PathSettings::default());
    let (width, height) = (48u32, 32u32);
    let mut sum = Color::ZERO;
    let mut rays = 0;
    let before = ALLOCATIONS.with(Cell::get);
    let camera_ray = |x: u32, y: u32, (ox, oy): (f32, f32)| {
        scene.camera.ray(
            x as f32 + ox,
            y as f32 + oy,
            width,
            height,
            width as f32 / height as f32,
        )
    };
    for y in 0..height {
        for x in 0..width {
            let pixel = (y * width + x) as u64;
            // The plain random stream.
            for s in 0..4 {
                let mut rng = Rng::for_sample(1, pixel, s);
                let ray = camera_ray(x, y, (rng.next_f32(), rng.next_f32()));
                let mut first_hit = FirstHit::default();
                sum += integrator.trace(&scene, &ray, &mut rng, &mut rays, &mut first_hit);
            }
            // The renderer's sampler: scrambled Sobol' per pixel, as the pipeline uses.
            let sobol = SobolPixel::new(1, pixel, 4);
            for s in 0..4 {
                let mut sampler = sobol.sampler(s);
                let ray = camera_ray(x, y, sampler.sample_2d(0));
                let mut first_hit = FirstHit::default();
                sum += integrator.trace(&scene, &ray, &mut sampler, &mut rays, &mut first_hit);
            }
            // The render loop's own call, whose camera rays go in packets of eight (12
            // samples: a packet of eight and one of four), with the feature layers.
            let pixel = PixelContext {
                x,
                y,
                width,
                height,
                aspect: width as f32 / height as f32,
                seed: 1,
                samples_per_pixel: 12,
                max_depth: PathSettings::default().max_depth,
                features: true,
                progressive_order: false,
            };
            integrator.pixel_samples(&scene, &pixel, 0..12, &mut rays, &mut |sample| {
                sum += sample.radiance;
            });
        }
    }
    let allocations = ALLOCATIONS.with(Cell::get) - before;
    assert!(sum.is_finite() && sum.max_component() > 0.0);
    assert!(rays > (width * height * 8) as u64);
    assert_eq!(
        allocations, 0,
        "{allocations} allocations while tracing {rays} rays"
    );
    // The counter does see allocations on this thread.
    let probe = ALLOCATIONS.with(Cell::get);
    drop(std::hint::black_box(Box::new(7u64)));
    assert_eq!(ALLOCATIONS.with(Cell::get), probe + 1);
}

/// The most bytes live at once on the one thread of a pool that renders `settings`.
fn render_peak(scene: &Scene, settings: &RenderSettings) -> (i64, crate::Film) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| {
        LIVE.with(|live| live.set(0));
        PEAK.with(|peak| peak.set(0));
        WEIGHED.with(|weighed| weighed.set(true));
        let (film, _) = render(scene, settings, &|_| true).unwrap();
        WEIGHED.with(|weighed| weighed.set(false));
        (PEAK.with(Cell::get), film)
    })
}

/// A frame's pixels are held twice at most while it renders (the tiles' and the film's): a
/// beauty-only frame took 68 bytes a pixel when every tile kept the features and sums of
/// each pixel too, whether asked for or not.
#[test]
fn a_render_holds_its_pixels_twice_at_most() {
    let scene = every_feature_scene();
    for integrator in [IntegratorKind::Course, IntegratorKind::Path] {
        let settings = RenderSettings {
            width: 256,
            height: 192,
            samples_per_pixel: 1,
            integrator,
            ..RenderSettings::default()
        };
        let (peak, film) = render_peak(&scene, &settings);
        let pixels = (settings.width * settings.height) as i64;
        let image = pixels * std::mem::size_of::<Color>() as i64;
        assert!(film.pixels.iter().any(|c| c.max_component() > 0.0));
        assert!(peak >= image, "{integrator:?}: peak {peak} bytes");
        assert!(
            peak <= 2 * image + (256 << 10),
            "{integrator:?}: peak {peak} bytes, {} a pixel",
            peak / pixels
        );
        // With the feature layers, more is kept, and weighed.
        let features = RenderSettings {
            features: true,
            ..settings
        };
        let (with_features, _) = render_peak(&scene, &features);
        assert!(with_features > peak + 2 * image, "{integrator:?}");
    }
}
