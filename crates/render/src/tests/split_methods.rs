//! Every split method (`-s`) builds a tree that finds the same closest hit as brute force, ties
//! in t included (duplicated triangles, coinciding spheres), and answers occlusion alike; the
//! counting traversal of `--stats` finds what the rendering one finds; and the methods build
//! the trees they say (median leaves hold one block, the SAH tree is the cheapest by its own
//! measure on a clustered mesh).

use crate::accel::build::{build_with, SplitMethod};
use crate::accel::wide::WalkCounts;
use crate::accel::Isa;
use crate::testing::*;
use crate::{Aabb, Shape, Vec3};

fn bounds_of(shapes: &[Shape]) -> Aabb {
    shapes.iter().fold(Aabb::EMPTY, |b, s| b.union(s.bounds()))
}

/// A soup with every fifth triangle repeated (exact ties in t between different indices) and
/// a clump of identical triangles (coinciding centroids, which no median can separate).
fn soup_with_ties(seed: u64, count: usize) -> Vec<Tri> {
    let mut r = rng(seed);
    let mut tris = random_soup(&mut r, count);
    let repeated: Vec<Tri> = tris.iter().step_by(5).copied().collect();
    tris.extend(repeated);
    let clump = tris[count - 1];
    tris.extend(std::iter::repeat_n(clump, 11));
    tris
}

#[test]
fn every_method_finds_the_brute_force_hit_ties_included() {
    for (seed, count) in [(11, 9), (12, 40), (13, 200), (14, 5000)] {
        let tris = soup_with_ties(seed, count);
        let shapes = shapes_of(&tris);
        let mut r = rng(seed + 100);
        let rays = random_rays(&mut r, bounds_of(&shapes), 2000);
        for method in SplitMethod::ALL {
            let mut bvh = build_with(&shapes, method);
            for isa in [Isa::Scalar, Isa::detect()] {
                bvh.set_isa(isa);
                let mut hits = 0;
                for (k, ray) in rays.iter().enumerate() {
                    let expected = brute_force(&tris, ray);
                    assert_eq!(
                        wide_closest(&bvh, ray),
                        expected,
                        "{} ({isa:?}), {count} triangles, ray {k}",
                        method.name()
                    );
                    assert_eq!(bvh.occluded(ray), expected.is_some());
                    let mut counts = WalkCounts::default();
                    let counted = bvh
                        .count_closest(ray, &mut counts)
                        .map(|h| (h.t, bvh.source_index(h.primitive)));
                    assert_eq!(counted, expected, "counting walk, ray {k}");
                    hits += expected.is_some() as usize;
                }
                assert!(hits > 0, "{count} triangles: no ray hit anything");
            }
        }
    }
}

#[test]
fn every_method_agrees_on_spheres_and_boxes_with_coinciding_centres() {
    let mut r = rng(21);
    let mut shapes = Vec::new();
    for i in 0..400 {
        let center = Vec3::new(
            uniform(&mut r, -5.0, 5.0),
            uniform(&mut r, -5.0, 5.0),
            uniform(&mut r, -5.0, 5.0),
        );
        shapes.push(Shape::Sphere {
            center,
            radius: uniform(&mut r, 0.05, 0.6),
        });
        if i % 7 == 0 {
            // The same sphere again, and a box around the same centre.
            shapes.push(shapes[shapes.len() - 1]);
            shapes.push(Shape::Box {
                min: center - Vec3::splat(0.3),
                max: center + Vec3::splat(0.3),
            });
        }
    }
    let rays = random_rays(&mut r, bounds_of(&shapes), 3000);
    let trees: Vec<_> = SplitMethod::ALL
        .into_iter()
        .map(|m| (m, build_with(&shapes, m)))
        .collect();
    let mut hits = 0;
    for (k, ray) in rays.iter().enumerate() {
        let answer = |bvh: &crate::accel::WideBvh| {
            bvh.intersect(ray)
                .map(|h| (h.t, bvh.source_index(h.primitive), h.b1, h.b2))
        };
        let reference = answer(&trees[2].1);
        for (method, bvh) in &trees {
            assert_eq!(answer(bvh), reference, "{}, ray {k}", method.name());
            assert_eq!(bvh.occluded(ray), reference.is_some());
        }
        hits += reference.is_some() as usize;
    }
    assert!(hits > 100, "only {hits} rays hit");
}

#[test]
fn methods_build_the_trees_they_describe() {
    // A clustered mesh: a finely tessellated sphere beside a few large triangles, where the
    // median rules cut through the cluster and the SAH does not.
    let mut tris = icosphere(5, 1.0);
    let far: Tri = [[40.0, 0.0, 0.0], [41.0, 0.0, 0.0], [40.0, 1.0, 0.0]];
    tris.extend(std::iter::repeat_n(far, 3));
    let shapes = shapes_of(&tris);
    let stats: Vec<_> = SplitMethod::ALL
        .into_iter()
        .map(|m| (m, build_with(&shapes, m)))
        .map(|(m, bvh)| {
            // Median leaves hold at most one block of four triangles.
            if m != SplitMethod::Sah {
                for node in bvh.nodes() {
                    for &child in &node.children {
                        let child = crate::accel::wide::ChildRef(child);
                        if child.is_leaf() && child != crate::accel::wide::ChildRef::EMPTY {
                            assert_eq!(child.range().1, 1, "{}: a leaf of blocks", m.name());
                        }
                    }
                }
            }
            (m, bvh.tree_stats())
        })
        .collect();
    let n = tris.len() as f64;
    for (m, s) in &stats {
        assert!(
            s.nodes > 0 && s.leaves > 0 && s.depth > 0,
            "{}: {s:?}",
            m.name()
        );
        // Every tree is at least as deep as a full 8-wide tree over one-block leaves could be.
        let least_depth = (n / 32.0).log(8.0).ceil() as usize;
        assert!(s.depth >= least_depth, "{}: {s:?}", m.name());
    }
    // Object median halves by count: a balanced tree, log₈ of the leaves deep (plus one level
    // where the last split leaves fewer than eight children).
    let object = &stats[0].1;
    let balanced = ((n / 4.0).log2() / 3.0).ceil() as usize + 1;
    assert!(object.depth <= balanced, "object median: {object:?}");
    let sah = stats[2].1.sah_cost;
    for (m, s) in &stats[..2] {
        assert!(
            sah < s.sah_cost,
            "the SAH tree ({sah}) should cost less than {}'s ({})",
            m.name(),
            s.sah_cost
        );
    }
}

#[test]
fn spatial_median_depth_stays_bounded_on_geometric_clusters() {
    // Point-sized boxes at 2.1^-k on the x, y and z axes in turn: each spatial split, on the
    // axis of its level, peels off exactly one of them (the next on that axis lies below the
    // middle), so without a bound the wide tree would be some 60 levels deep, past what the
    // traversal stack holds (`MAX_DEPTH`).
    let shapes: Vec<Shape> = (0..420)
        .map(|i| {
            let mut p = [0.0f32; 3];
            p[i % 3] = 2.1f32.powi(-((i / 3) as i32));
            let p = Vec3::from_array(p);
            Shape::Box { min: p, max: p }
        })
        .collect();
    for method in SplitMethod::ALL {
        let bvh = build_with(&shapes, method);
        let stats = bvh.tree_stats();
        assert!(
            stats.depth <= crate::accel::wide::MAX_DEPTH,
            "{}: {stats:?}",
            method.name()
        );
    }
}

/// `--stats` prints the build phases of the tree with the most primitives: here the second
/// of three geometries, each instanced once.
#[test]
fn the_build_phases_shown_are_the_largest_trees() {
    use crate::sampling::Rng;
    use crate::{
        Background, Camera, ColorSource, GeometryDesc, Instance, Material, Projection, Scene,
        SceneParts,
    };
    let mut r = rng(21);
    let geometry = |count: usize, r: &mut Rng| {
        let shapes = shapes_of(&random_soup(r, count));
        GeometryDesc {
            materials: vec![0; shapes.len()],
            shapes,
        }
    };
    let scene = Scene::new(SceneParts {
        physical: Default::default(),
        camera: Camera::new(Projection::Perspective, Vec3::Z, -Vec3::Z, 1.0, 1.0),
        materials: vec![Material::Lambertian {
            diffuse: ColorSource::constant(Vec3::splat(0.5)),
        }],
        textures: vec![],
        lights: vec![],
        background: Background::Color(Vec3::ZERO),
        geometries: vec![
            geometry(40, &mut r),
            geometry(700, &mut r),
            geometry(300, &mut r),
        ],
        instances: (0..3)
            .map(|geometry| Instance {
                geometry,
                transform: None,
                material: None,
                casts_shadow: true,
            })
            .collect(),
    });
    let stats = scene.bvh_stats();
    assert_eq!(stats.trees, 3);
    let (primitives, phases) = stats.largest.expect("wide trees");
    assert_eq!(primitives, 700);
    assert!(
        phases.subtrees + phases.pack > std::time::Duration::ZERO,
        "{phases:?}"
    );
}
