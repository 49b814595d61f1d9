//! The 8-wide BVH (AVX2 and scalar kernels), the reference binary BVH and brute force return the
//! same closest hit (t and primitive) and the same occlusion answer, on random rays over random
//! and real meshes; and whole scenes with spheres, boxes, triangles and instances agree between
//! the wide and the binary bottom level.

use glint_render::bench::{workload, AccelKind, SurfaceNeeds};
use glint_render::testing::*;
use glint_render::{Aabb, GeometryDesc, Instance, Matrix4, Ray, Scene, Shape, Transform, Vec3};

fn bounds_of(tris: &[Tri]) -> Aabb {
    tris.iter()
        .flatten()
        .fold(Aabb::EMPTY, |b, p| b.grow(Vec3::from_array(*p)))
}

/// Every engine gives the same (t, primitive) and occlusion on every ray; returns the hits.
fn check_all(tris: &[Tri], rays: &[Ray], brute_every: usize) -> usize {
    let shapes = shapes_of(tris);
    let wides = wide_variants(&shapes);
    let binary = BinaryReference::new(tris);
    let mut hits = 0;
    for (k, ray) in rays.iter().enumerate() {
        let reference = binary.closest(ray);
        if k % brute_every == 0 {
            assert_eq!(
                brute_force(tris, ray),
                reference,
                "brute force vs binary, ray {k}: {ray:?}"
            );
        }
        for wide in &wides {
            assert_eq!(
                wide_closest(wide, ray),
                reference,
                "{:?} wide vs binary, ray {k}: {ray:?}",
                wide.isa()
            );
            assert_eq!(
                wide.occluded(ray),
                reference.is_some(),
                "{:?} occlusion, ray {k}: {ray:?}",
                wide.isa()
            );
        }
        assert_eq!(binary.occluded(ray), reference.is_some());
        hits += reference.is_some() as usize;
    }
    hits
}

#[test]
fn random_soups_agree() {
    let mut r = rng(1);
    for (count, seed) in [(1, 2), (3, 3), (7, 4), (60, 5), (3000, 6)] {
        let mut r2 = rng(seed);
        let tris = random_soup(&mut r2, count);
        let rays = random_rays(&mut r, bounds_of(&tris), 3000);
        let hits = check_all(&tris, &rays, 1);
        if count >= 60 {
            assert!(hits > 150, "{count} triangles: only {hits} hits");
        }
    }
}

#[test]
fn degenerate_soups_agree() {
    let mut r = rng(7);
    // Many copies of one triangle (all centroids equal: median splits), zero-area triangles,
    // collinear points, and triangles far from the origin.
    let one = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut tris = vec![one; 200];
    tris.extend((0..50).map(|k| [[k as f32, 0.0, 1.0]; 3]));
    tris.extend((0..50).map(|k| {
        [
            [0.0, k as f32, 2.0],
            [1.0, k as f32, 2.0],
            [2.0, k as f32, 2.0],
        ]
    }));
    tris.extend((0..50).map(|k| {
        let c = 1.0e4 + k as f32;
        [[c, c, c], [c + 1.0, c, c], [c, c + 1.0, c]]
    }));
    let rays = random_rays(&mut r, bounds_of(&tris[..250]), 2000);
    check_all(&tris, &rays, 1);
    let rays = random_rays(&mut r, bounds_of(&tris[350..]), 500);
    check_all(&tris, &rays, 1);
}

#[test]
fn nan_and_infinite_rays_do_not_crash() {
    let mut r = rng(9);
    let tris = random_soup(&mut r, 500);
    let shapes = shapes_of(&tris);
    let n = f32::NAN;
    let i = f32::INFINITY;
    let o = Vec3::ZERO;
    let bad = [
        Ray::new(Vec3::new(n, 0.0, 0.0), Vec3::X),
        Ray::new(o, Vec3::new(n, n, n)),
        Ray::new(o, Vec3::new(i, 0.0, 1.0)),
        Ray::new(Vec3::new(-i, 0.0, 0.0), Vec3::X),
        Ray::new(o, Vec3::ZERO),
        Ray::new(o, Vec3::new(1e-38, -1e-38, 1e-39)),
        Ray::new(o, Vec3::new(1e38, 3e38, -2e38)),
        Ray {
            t_min: n,
            ..Ray::new(o, Vec3::X)
        },
        Ray {
            t_max: n,
            ..Ray::new(o, Vec3::X)
        },
        Ray {
            t_min: 2.0,
            t_max: 1.0,
            ..Ray::new(o, Vec3::X)
        },
        Ray {
            t_min: -i,
            t_max: i,
            ..Ray::new(o, Vec3::X)
        },
    ];
    let binary = BinaryReference::new(&tris);
    for wide in wide_variants(&shapes) {
        for ray in &bad {
            // No crash, and whatever a bad ray hits, the engines agree on it.
            let hit = wide_closest(&wide, ray);
            assert_eq!(
                hit,
                binary.closest(ray),
                "{:?} vs binary: {ray:?}",
                wide.isa()
            );
            assert_eq!(
                wide.occluded(ray),
                hit.is_some(),
                "{:?}: {ray:?}",
                wide.isa()
            );
        }
        for ray in &bad[..5] {
            assert!(wide.intersect(ray).is_none(), "{ray:?}");
            assert!(!wide.occluded(ray), "{ray:?}");
        }
    }
    // And the whole scene, both bottom levels.
    let [wide, binary] = [AccelKind::Wide, AccelKind::Binary].map(|accel| {
        Scene::with_accel(
            workload::mesh_scene_parts(GeometryDesc {
                materials: vec![0; shapes.len()],
                shapes: shapes.clone(),
            }),
            accel,
        )
    });
    for ray in &bad {
        let (a, b) = (wide.intersect(ray), binary.intersect(ray));
        assert_eq!(
            a.map(|h| (h.t, wide.instances().source_primitive(&h))),
            b.map(|h| (h.t, binary.instances().source_primitive(&h))),
            "{ray:?}"
        );
        assert_eq!(wide.occluded(ray), binary.occluded(ray), "{ray:?}");
        assert_eq!(wide.occluded(ray), a.is_some(), "{ray:?}");
    }
}

#[test]
fn empty_and_tiny_geometries() {
    let wide = glint_render::bench::build(&[]);
    assert!(wide.intersect(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
    assert!(!wide.occluded(&Ray::new(Vec3::ZERO, Vec3::X)));
    let tri = [[[0.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0]]];
    let ray = Ray::new(Vec3::new(0.2, 0.2, 0.0), -Vec3::Z);
    for wide in wide_variants(&shapes_of(&tri)) {
        let h = wide.intersect(&ray).expect("single triangle");
        assert_eq!(h.t, 1.0);
        assert!(
            (h.b1 - 0.2).abs() < 1e-6 && (h.b2 - 0.2).abs() < 1e-6,
            "{h:?}"
        );
    }
}

#[test]
fn the_bunny_agrees() {
    let path = shared_models().join("stanford-bunny.obj");
    let mesh = glint_io::load_mesh(&path).expect("../shared/models/stanford-bunny.obj");
    let tris = triangles(&mesh.shapes());
    let mut r = rng(11);
    let bounds = bounds_of(&tris);
    let mut rays = random_rays(&mut r, bounds, 6000);
    // Coherent camera rays too, and bounce rays from their hits (the benchmark's workloads).
    let scene = Scene::new(workload::mesh_scene_parts(mesh.geometry()));
    let camera = workload::framing_camera(bounds);
    let primary = workload::primary_rays(&camera, 64, 64);
    let (bounce, shadow) =
        workload::secondary_rays(&scene, &primary, workload::default_light(bounds), 3);
    rays.extend(primary.iter().chain(&bounce).chain(&shadow).copied());
    let hits = check_all(&tris, &rays, 97);
    assert!(hits > 3000, "only {hits} hits");
}

/// A small course-like scene: spheres, boxes and triangles in the plain geometry, and a mesh
/// placed three times with transforms (one without shadows).
fn mixed_parts(seed: u64) -> glint_render::SceneParts {
    let mut r = rng(seed);
    let mut shapes = Vec::new();
    for k in 0..300 {
        let c = Vec3::new(
            uniform(&mut r, -8.0, 8.0),
            uniform(&mut r, -8.0, 8.0),
            uniform(&mut r, -8.0, 8.0),
        );
        let s = uniform(&mut r, 0.1, 1.0);
        shapes.push(match k % 3 {
            0 => Shape::Sphere {
                center: c,
                radius: s,
            },
            1 => Shape::Box {
                min: c - Vec3::splat(s),
                max: c + Vec3::new(s, 0.5 * s, 2.0 * s),
            },
            _ => Shape::Triangle {
                vertices: [c, c + random_unit(&mut r) * s, c + random_unit(&mut r) * s],
            },
        });
    }
    let plain = GeometryDesc {
        materials: (0..shapes.len() as u32).map(|k| k % 2).collect(),
        shapes,
    };
    let sphere_mesh = shapes_of(&icosphere(2, 1.0));
    let mesh = GeometryDesc {
        materials: vec![0; sphere_mesh.len()],
        shapes: sphere_mesh,
    };
    let mut parts = workload::mesh_scene_parts(plain);
    parts.materials.push(parts.materials[0]);
    parts.geometries.push(mesh);
    for (k, m) in [
        Matrix4::translate(Vec3::new(0.0, 0.0, 12.0)),
        Matrix4::translate(Vec3::new(3.0, 1.0, -12.0))
            .mul(&Matrix4::rotate(0, 30.0))
            .mul(&Matrix4::scale(Vec3::new(2.0, 0.5, 1.0))),
        Matrix4::translate(Vec3::new(-12.0, 0.0, 0.0)).mul(&Matrix4::scale(Vec3::splat(3.0))),
    ]
    .iter()
    .enumerate()
    {
        parts.instances.push(Instance {
            geometry: 1,
            transform: Transform::from_matrix(m),
            material: Some(1),
            casts_shadow: k != 2,
        });
    }
    parts
}

#[test]
fn mixed_scenes_agree_between_bottom_levels() {
    let wide = Scene::with_accel(mixed_parts(21), AccelKind::Wide);
    let binary = Scene::with_accel(mixed_parts(21), AccelKind::Binary);
    assert_eq!(
        wide.instances().unique_primitive_count(),
        binary.instances().unique_primitive_count()
    );
    let mut r = rng(22);
    let bounds = wide.bounds();
    let mut hits = 0;
    let mut mismatches = 0;
    let rays = random_rays(&mut r, bounds, 6000);
    for ray in &rays {
        assert_eq!(wide.occluded(ray), binary.occluded(ray), "{ray:?}");
        match (wide.intersect(ray), binary.intersect(ray)) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                // Triangles: watertight test vs Möller-Trumbore, so t to rounding only.
                assert!(
                    (a.t - b.t).abs() <= 1e-5 * a.t.abs().max(1.0),
                    "{ray:?}: {a:?} vs {b:?}"
                );
                let (sa, sb) = (
                    wide.surface(ray, &a, SurfaceNeeds::Uv),
                    binary.surface(ray, &b, SurfaceNeeds::Uv),
                );
                if (wide.instances().source_primitive(&a), sa.material)
                    != (binary.instances().source_primitive(&b), sb.material)
                {
                    mismatches += 1;
                } else {
                    // The same primitive: the same normal, on every such ray (not only until
                    // the first mismatch).
                    assert!(
                        (sa.normal - sb.normal).length() < 1e-3,
                        "{ray:?}: normal {:?} vs {:?}",
                        sa.normal,
                        sb.normal
                    );
                }
            }
            (a, b) => panic!("{ray:?}: wide {a:?}, binary {b:?}"),
        }
    }
    assert!(hits > 1500, "only {hits} hits");
    // Different primitives only where two surfaces meet at the same t (touching shapes).
    assert!(
        mismatches <= 2,
        "{mismatches} rays hit different primitives"
    );
}

/// The wide BVH's build runs subtrees in parallel on the current rayon pool; the structure it
/// builds (every node, block, shape and index) is the same on 1, 2 and 4 threads, so images
/// cannot depend on the thread count through it. Enough triangles that the parallel paths run.
#[test]
fn build_is_independent_of_the_thread_count() {
    let mut r = rng(31);
    let tris = random_soup(&mut r, 60_000);
    let shapes = shapes_of(&tris);
    let build_on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(|| glint_render::bench::build(&shapes))
    };
    let one = build_on(1);
    for threads in [2, 4] {
        let many = build_on(threads);
        assert!(
            one.nodes() == many.nodes(),
            "the nodes built on {threads} threads differ"
        );
        // Debug shows every field, bit for bit where it matters (the NaN padding of triangle
        // blocks never compares equal with `==`): blocks, bounds, shapes, source indices.
        assert!(
            format!("{one:?}") == format!("{many:?}"),
            "the structure built on {threads} threads differs"
        );
    }
    // Negative control: the comparison sees a different structure (another triangle order).
    let mut reversed = shapes.clone();
    reversed.reverse();
    let other = glint_render::bench::build(&reversed);
    assert!(format!("{one:?}") != format!("{other:?}"));
}
