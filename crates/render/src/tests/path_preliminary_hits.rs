//! The path tracer's split of a hit into what traversal finds and what shading asks for:
//! `Scene::intersect_preliminary` finds exactly the t, instance and primitive `intersect`
//! finds, `Scene::complete` adds exactly its barycentrics, and `Scene::surface_without_uv`
//! is `Scene::surface` without texture coordinates (its normals read from the per-triangle
//! table built with the scene). On one instance and on several, with transforms, with every
//! shape, on both bottom-level structures. And the path tracer, which builds the BSDF of an
//! untextured material once per render, still reads a textured one's texture at each hit.

use crate::accel::instances::AccelKind;
use crate::scene::SurfaceNeeds;
use crate::testing::{random_rays, random_soup, rng, shapes_of};
use crate::{
    render, Background, Camera, Color, ColorSource, GeometryDesc, Image, Instance, IntegratorKind,
    Light, Material, Matrix4, Projection, RenderSettings, Scene, SceneParts, Shape, Transform,
    Vec3,
};

fn scene(instances: usize, accel: AccelKind) -> Scene {
    let mut r = rng(17);
    let mut shapes = shapes_of(&random_soup(&mut r, 300));
    shapes.extend([
        Shape::Sphere {
            center: Vec3::new(0.2, 0.1, -0.3),
            radius: 0.4,
        },
        Shape::Box {
            min: Vec3::new(-0.8, -0.9, 0.2),
            max: Vec3::new(-0.2, -0.1, 0.9),
        },
        // Degenerate: no normal, never hit.
        Shape::Triangle {
            vertices: [Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        },
    ]);
    let materials = (0..shapes.len() as u32).map(|i| i % 3).collect();
    let placed = |k: usize| {
        let transform = (k % 2 == 1).then(|| {
            let m = Matrix4::translate(Vec3::new(1.5 * k as f32, 0.2, -0.4))
                .mul(&Matrix4::rotate(1, 30.0 * k as f64))
                .mul(&Matrix4::scale(Vec3::new(1.0, 0.7, 1.3)));
            Transform::from_matrix(&m).unwrap()
        });
        Instance {
            geometry: 0,
            transform,
            material: None,
            casts_shadow: true,
        }
    };
    Scene::with_accel(
        SceneParts {
            physical: Default::default(),
            camera: Camera::new(Projection::Perspective, Vec3::Z * 4.0, -Vec3::Z, 1.0, 1.0),
            materials: vec![],
            textures: vec![],
            lights: vec![],
            background: Background::Color(Vec3::ZERO),
            geometries: vec![GeometryDesc { shapes, materials }],
            instances: (0..instances).map(placed).collect(),
        },
        accel,
    )
}

#[test]
fn preliminary_hits_complete_to_the_hits_of_intersect() {
    for accel in [AccelKind::Wide, AccelKind::Binary] {
        for instances in [1, 3] {
            let scene = scene(instances, accel);
            let mut r = rng(5);
            let mut hits = 0;
            for ray in random_rays(&mut r, scene.bounds(), 4000) {
                let hit = scene.intersect(&ray);
                let preliminary = scene.intersect_preliminary(&ray);
                assert_eq!(
                    preliminary.map(|p| (p.t, p.instance, p.primitive)),
                    hit.map(|h| (h.t, h.instance, h.primitive)),
                    "{accel:?}, {instances} instances, {ray:?}"
                );
                let (Some(hit), Some(preliminary)) = (hit, preliminary) else {
                    continue;
                };
                hits += 1;
                assert_eq!(scene.accel.complete(&ray, &preliminary), hit, "{ray:?}");
                // A preliminary hit completes to the surface of the full hit, uv included.
                let surface = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
                assert_eq!(
                    scene.surface(&ray, &preliminary, SurfaceNeeds::Uv),
                    surface,
                    "{ray:?}"
                );
                let mut without_uv = surface;
                without_uv.uv = (0.0, 0.0);
                assert_eq!(
                    scene.surface(&ray, &preliminary, SurfaceNeeds::Geometry),
                    without_uv,
                    "{ray:?}"
                );
            }
            assert!(hits > 500, "{hits}");
        }
    }
}

/// `SurfaceNeeds::Shading`, the course integrator's: the surface `Uv` gives where the hit's
/// material reads texture coordinates, and without them (as `Geometry`) where it does not; on
/// triangles, spheres and boxes, placed once and three times.
#[test]
fn shading_surfaces_have_uv_where_the_material_reads_it() {
    let textured = ColorSource {
        color: Color::ONE,
        texture: Some(0),
    };
    let plain = ColorSource::constant(Color::splat(0.5));
    for instances in [1, 3] {
        let mut scene = scene(instances, AccelKind::Wide);
        // Shapes take materials 0, 1, 2 in turn (the sphere 0, the box 1).
        scene.materials = vec![
            Material::Lambertian { diffuse: textured },
            Material::Mirror { roughness: 0.0 },
            Material::Phong {
                diffuse: plain,
                specular: textured,
                phong_exponent: 8.0,
            },
        ];
        let mut r = rng(9);
        let (mut with, mut without) = (0, 0);
        for ray in random_rays(&mut r, scene.bounds(), 4000) {
            let Some(hit) = scene.intersect(&ray) else {
                continue;
            };
            let full = scene.surface(&ray, &hit, SurfaceNeeds::Uv);
            let mut expect = full;
            if full.material == 1 {
                expect.uv = (0.0, 0.0);
                without += 1;
            } else {
                with += 1;
            }
            assert_eq!(
                scene.surface(&ray, &hit, SurfaceNeeds::Shading),
                expect,
                "{ray:?}"
            );
        }
        assert!(with > 300 && without > 150, "{with} {without}");
    }
}

/// A square facing the camera, lit by a point light, with material `material` of `materials`.
fn textured_scene(materials: Vec<Material>, textures: Vec<Image>, material: u32) -> Scene {
    let (a, b, c, d) = (
        Vec3::new(-4.0, -4.0, 0.0),
        Vec3::new(4.0, -4.0, 0.0),
        Vec3::new(4.0, 4.0, 0.0),
        Vec3::new(-4.0, 4.0, 0.0),
    );
    Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(Projection::Perspective, Vec3::Z * 3.0, -Vec3::Z, 1.0, 1.0),
        materials,
        textures,
        lights: vec![Light::Point {
            position: Vec3::new(0.3, 0.2, 2.0),
            intensity: Color::splat(4.0),
        }],
        background: Background::Color(Vec3::ZERO),
        geometries: vec![GeometryDesc {
            shapes: vec![
                Shape::Triangle {
                    vertices: [a, b, c],
                },
                Shape::Triangle {
                    vertices: [a, c, d],
                },
            ],
            materials: vec![material; 2],
        }],
        instances: vec![Instance {
            geometry: 0,
            transform: None,
            material: None,
            casts_shadow: true,
        }],
    })
}

fn render_path(scene: &Scene) -> Vec<Color> {
    let settings = RenderSettings {
        width: 24,
        height: 24,
        samples_per_pixel: 4,
        seed: 3,
        integrator: IntegratorKind::Path,
        ..Default::default()
    };
    render(scene, &settings, &|_| true).unwrap().0.pixels
}

#[test]
fn textured_materials_read_their_texture_at_each_hit() {
    let materials = vec![
        // Black where the barycentric b1 is below 1/2, white above.
        Material::Diffuse {
            diffuse: ColorSource {
                color: Color::ONE,
                texture: Some(0),
            },
        },
        // A white texture under a grey colour, and the same grey untextured.
        Material::Diffuse {
            diffuse: ColorSource {
                color: Color::splat(0.5),
                texture: Some(1),
            },
        },
        Material::Diffuse {
            diffuse: Color::splat(0.5).into(),
        },
    ];
    let textures = vec![
        Image {
            width: 2,
            height: 1,
            texels: vec![Color::ZERO, Color::ONE],
        },
        Image {
            width: 1,
            height: 1,
            texels: vec![Color::ONE],
        },
    ];
    let scene = |material| textured_scene(materials.clone(), textures.clone(), material);
    // The texture multiplies by exactly one: the same image as without it, bit for bit.
    assert_eq!(render_path(&scene(1)), render_path(&scene(2)));
    // The two-texel texture leaves parts of the square black (nothing reflects there) and
    // parts lit.
    let image = render_path(&scene(0));
    let black = image.iter().filter(|c| **c == Color::ZERO).count();
    let lit = image.iter().filter(|c| c.x > 0.01).count();
    assert!(black > 50 && lit > 50, "{black} black, {lit} lit");
}
