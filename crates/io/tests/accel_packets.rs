//! Packet traversal (`accel/packet.rs`) gives every ray exactly its single-ray answer: the same
//! closest hit (t, primitive, barycentrics, bit for bit) and the same occlusion, with the AVX2
//! and the scalar packet kernels, on coherent packets (camera rays of 4x2 pixel blocks),
//! jittered same-sign packets and incoherent random ones, with some lanes left out and some
//! holding NaN or infinite rays; over random soups, an exact-grid cube, the bunny, and whole
//! scenes with spheres, boxes and transformed instances (the two-level path).

use glint_render::bench::{workload, AccelKind, Hit, LocalHit, Rng, WideBvh, ALL_LANES, PACKET};
use glint_render::testing::*;
use glint_render::{
    Aabb, GeometryDesc, Instance, Matrix4, Ray, Scene, SceneParts, Shape, Transform, Vec3,
};

fn bounds_of(tris: &[Tri]) -> Aabb {
    tris.iter()
        .flatten()
        .fold(Aabb::EMPTY, |b, p| b.grow(Vec3::from_array(*p)))
}

/// Bit-exact view of a local hit.
fn local_bits(h: Option<LocalHit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.primitive, h.b1.to_bits(), h.b2.to_bits()))
}

fn hit_bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32, u32)> {
    h.map(|h| {
        (
            h.t.to_bits(),
            h.instance,
            h.primitive,
            h.b1.to_bits(),
            h.b2.to_bits(),
        )
    })
}

/// A packet: the rays and the lanes asked for.
type Packet = ([Ray; PACKET], u8);

/// Camera rays of 4x2 pixel blocks (the render loop's packets), `size` x `size` pixels.
fn camera_packets(bounds: Aabb, size: u32) -> Vec<Packet> {
    let camera = workload::framing_camera(bounds);
    let rays = workload::primary_rays(&camera, size, size);
    let mut packets = Vec::new();
    for by in (0..size).step_by(2) {
        for bx in (0..size).step_by(4) {
            let packet: [Ray; PACKET] = std::array::from_fn(|l| {
                let (x, y) = (bx + l as u32 % 4, by + l as u32 / 4);
                rays[(y.min(size - 1) * size + x.min(size - 1)) as usize]
            });
            packets.push((packet, ALL_LANES));
        }
    }
    packets
}

/// Packets of eight rays near one random ray: same signs mostly (the interval test), and a
/// few straddling an axis.
fn jittered_packets(r: &mut Rng, bounds: Aabb, count: usize) -> Vec<Packet> {
    let size = (bounds.max - bounds.min).length().max(1e-3);
    random_rays(r, bounds, count)
        .into_iter()
        .enumerate()
        .map(|(k, base)| {
            let spread = [1e-4, 1e-2, 0.1][k % 3];
            let packet = std::array::from_fn(|_| {
                let mut ray = base;
                ray.origin += random_unit(r) * (spread * size);
                ray.direction += random_unit(r) * (spread * ray.direction.length());
                ray
            });
            (packet, ALL_LANES)
        })
        .collect()
}

/// Incoherent packets: eight unrelated random rays.
fn random_packets(r: &mut Rng, bounds: Aabb, count: usize) -> Vec<Packet> {
    let rays = random_rays(r, bounds, count * PACKET);
    rays.chunks_exact(PACKET)
        .map(|c| (std::array::from_fn(|l| c[l]), ALL_LANES))
        .collect()
}

/// Leaves some lanes out and spoils others with NaN, infinite or empty-window rays.
fn spoil(r: &mut Rng, packets: &mut [Packet]) {
    let n = f32::NAN;
    for (k, (rays, lanes)) in packets.iter_mut().enumerate() {
        match k % 5 {
            0 => *lanes = r.next_u32() as u8,
            1 => {
                let l = r.below(8) as usize;
                rays[l] = match r.below(5) {
                    0 => Ray::new(Vec3::new(n, 0.0, 0.0), rays[l].direction),
                    1 => Ray::new(rays[l].origin, Vec3::new(n, n, n)),
                    2 => Ray::new(rays[l].origin, Vec3::new(f32::INFINITY, 0.0, 1.0)),
                    3 => Ray {
                        t_min: 2.0,
                        t_max: 1.0,
                        ..rays[l]
                    },
                    _ => Ray {
                        t_max: n,
                        ..rays[l]
                    },
                };
            }
            2 => {
                // A window per ray, as shadow and spawned rays have.
                for ray in rays.iter_mut() {
                    ray.t_min = 0.5 * r.next_f32();
                    ray.t_max = 0.5 + 2.0 * r.next_f32();
                }
            }
            _ => {}
        }
    }
}

/// Every lane of every packet agrees with single-ray traversal, on every kernel; returns hits.
fn check_wide(bvh: &WideBvh, packets: &[Packet]) -> usize {
    let mut hits = 0;
    for (k, (rays, lanes)) in packets.iter().enumerate() {
        let closest = bvh.intersect_packet(rays, *lanes);
        let occluded = bvh.occluded_packet(rays, *lanes);
        for l in 0..PACKET {
            let ray = &rays[l];
            let (expect, expect_occluded) = if lanes & (1 << l) != 0 {
                (bvh.intersect(ray), bvh.occluded(ray))
            } else {
                (None, false)
            };
            assert_eq!(
                local_bits(closest[l]),
                local_bits(expect),
                "{:?} packet {k} lane {l} (lanes {lanes:#010b}): {ray:?}",
                bvh.isa()
            );
            assert_eq!(
                occluded & (1 << l) != 0,
                expect_occluded,
                "{:?} occlusion, packet {k} lane {l}: {ray:?}",
                bvh.isa()
            );
            hits += expect.is_some() as usize;
        }
    }
    hits
}

fn check_tris(tris: &[Tri], packets: &[Packet]) -> usize {
    let mut hits = 0;
    for bvh in wide_variants(&shapes_of(tris)) {
        hits = check_wide(&bvh, packets);
    }
    hits
}

fn all_kinds(r: &mut Rng, bounds: Aabb, camera: u32, count: usize) -> Vec<Packet> {
    let mut packets = camera_packets(bounds, camera);
    packets.extend(jittered_packets(r, bounds, count));
    packets.extend(random_packets(r, bounds, count));
    spoil(r, &mut packets);
    packets
}

#[test]
fn random_soups_agree() {
    let mut r = rng(31);
    for (count, seed) in [(1, 32), (5, 33), (60, 34), (3000, 35)] {
        let tris = random_soup(&mut rng(seed), count);
        let packets = all_kinds(&mut r, bounds_of(&tris), 32, 300);
        let hits = check_tris(&tris, &packets);
        if count >= 60 {
            assert!(hits > 150, "{count} triangles: only {hits} hits");
        }
    }
}

#[test]
fn exact_grid_cube_agrees() {
    // Rays along the axes through vertices and edges (zero edge functions, ties).
    let tris = grid_cube(8);
    let mut r = rng(36);
    let mut packets = all_kinds(&mut r, bounds_of(&tris), 24, 200);
    for axis in 0..3 {
        for k in 0..17 {
            let packet = std::array::from_fn(|l| {
                let mut o = [-0.75 + 0.125 * k as f32, -1.0 + 0.25 * l as f32, -4.0];
                o.rotate_right(axis);
                let mut d = [0.0, 0.0, 1.0];
                d.rotate_right(axis);
                Ray::new(Vec3::from_array(o), Vec3::from_array(d))
            });
            packets.push((packet, ALL_LANES));
        }
    }
    let hits = check_tris(&tris, &packets);
    assert!(hits > 500, "only {hits} hits");
}

#[test]
fn the_bunny_agrees() {
    let path = shared_models().join("stanford-bunny.obj");
    let mesh = glint_io::load_mesh(&path).expect("../shared/models/stanford-bunny.obj");
    let tris = triangles(&mesh.shapes());
    let bounds = bounds_of(&tris);
    let mut r = rng(37);
    let mut packets = all_kinds(&mut r, bounds, 64, 400);
    // The benchmark's bounce and shadow rays, in packets of eight consecutive rays.
    let scene = Scene::new(workload::mesh_scene_parts(mesh.geometry()));
    let camera = workload::framing_camera(bounds);
    let primary = workload::primary_rays(&camera, 48, 48);
    let (bounce, shadow) =
        workload::secondary_rays(&scene, &primary, workload::default_light(bounds), 5);
    for set in [&bounce, &shadow] {
        packets.extend(
            set.chunks_exact(PACKET)
                .map(|c| (std::array::from_fn(|l| c[l]), ALL_LANES)),
        );
    }
    let hits = check_tris(&tris, &packets);
    assert!(hits > 3500, "only {hits} hits");
}

/// Spheres, boxes and triangles in the plain geometry; an icosphere placed with transforms:
/// once, once casting no shadow, and twelve times in exactly the same place (those instances
/// tie at every hit, so the top level's visiting order decides, and being more than a leaf
/// holds with equal centroids, they are split between leaves in an order the walk follows).
fn instanced_parts(seed: u64) -> SceneParts {
    let mut r = rng(seed);
    let mut shapes = Vec::new();
    for k in 0..200 {
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
    let ball = shapes_of(&icosphere(2, 1.0));
    let mesh = GeometryDesc {
        materials: vec![0; ball.len()],
        shapes: ball,
    };
    let mut parts = workload::mesh_scene_parts(plain);
    parts.materials.push(parts.materials[0]);
    parts.geometries.push(mesh);
    let twin = Matrix4::translate(Vec3::new(3.0, 1.0, -12.0))
        .mul(&Matrix4::rotate(0, 30.0))
        .mul(&Matrix4::scale(Vec3::new(2.0, 0.5, 1.0)));
    let mut placements = vec![
        Matrix4::translate(Vec3::new(0.0, 0.0, 12.0)),
        Matrix4::translate(Vec3::new(-12.0, 0.0, 0.0)).mul(&Matrix4::scale(Vec3::splat(3.0))),
    ];
    placements.extend([twin; 12]);
    for (k, m) in placements.iter().enumerate() {
        parts.instances.push(Instance {
            geometry: 1,
            transform: Transform::from_matrix(m),
            material: Some(1),
            casts_shadow: k != 1,
        });
    }
    parts
}

fn check_scene(scene: &Scene, packets: &[Packet]) -> usize {
    let mut hits = 0;
    for (k, (rays, lanes)) in packets.iter().enumerate() {
        let closest = scene.intersect_lanes(rays, *lanes);
        let occluded = scene.occluded_lanes(rays, *lanes);
        if *lanes == ALL_LANES {
            assert_eq!(
                closest.map(hit_bits),
                scene.instances().intersect_packet(rays).map(hit_bits)
            );
            assert_eq!(
                scene.instances().occluded_packet(rays),
                std::array::from_fn(|l| occluded & (1 << l) != 0)
            );
        }
        for l in 0..PACKET {
            let ray = &rays[l];
            let (expect, expect_occluded) = if lanes & (1 << l) != 0 {
                (scene.intersect(ray), scene.occluded(ray))
            } else {
                (None, false)
            };
            assert_eq!(
                hit_bits(closest[l]),
                hit_bits(expect),
                "packet {k} lane {l} (lanes {lanes:#010b}): {ray:?}"
            );
            assert_eq!(
                occluded & (1 << l) != 0,
                expect_occluded,
                "occlusion, packet {k} lane {l}: {ray:?}"
            );
            hits += expect.is_some() as usize;
        }
    }
    hits
}

#[test]
fn instanced_scenes_agree() {
    for accel in [AccelKind::Wide, AccelKind::Binary] {
        let scene = Scene::with_accel(instanced_parts(41), accel);
        let bounds = scene.bounds();
        let mut r = rng(42);
        let mut packets = all_kinds(&mut r, bounds, 48, 600);
        // Packets aimed at the twin instances, which tie everywhere.
        let twin = Aabb {
            min: Vec3::new(0.0, -1.0, -14.0),
            max: Vec3::new(6.0, 3.0, -10.0),
        };
        packets.extend(jittered_packets(&mut r, twin, 300));
        let hits = check_scene(&scene, &packets);
        assert!(hits > 3000, "{accel:?}: only {hits} hits");
    }
}

#[test]
fn single_mesh_scenes_agree() {
    // One instance (no top level), with and without a transform.
    let tris = random_soup(&mut rng(43), 2000);
    let geometry = GeometryDesc {
        materials: vec![0; tris.len()],
        shapes: shapes_of(&tris),
    };
    let mut parts = workload::mesh_scene_parts(geometry);
    let mut r = rng(44);
    for transform in [
        None,
        Transform::from_matrix(&Matrix4::rotate(1, 40.0).mul(&Matrix4::scale(Vec3::splat(0.5)))),
    ] {
        parts.instances[0].transform = transform;
        let scene = Scene::new(parts.clone());
        let packets = all_kinds(&mut r, scene.bounds(), 32, 300);
        let hits = check_scene(&scene, &packets);
        assert!(hits > 500, "only {hits} hits");
    }
}
