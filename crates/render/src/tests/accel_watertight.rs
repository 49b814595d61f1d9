//! Watertightness: a ray through a shared edge or vertex of a closed mesh meets exactly one
//! triangle there (it neither slips through the crack nor counts the surface twice), for the
//! triangle test alone and for the wide BVH's closest hit with both kernels.

use crate::testing::*;
use crate::{Ray, Vec3};

/// From outside a convex closed mesh towards `target` on its surface: the ray enters there and
/// leaves elsewhere, so exactly two triangles are met, and the closest hit is at t = 1.
fn check_through(
    tris: &[Tri],
    wides: &[crate::accel::WideBvh],
    origin: Vec3,
    target: Vec3,
    what: &str,
) {
    let ray = Ray::new(origin, target - origin);
    assert_eq!(count_hits(tris, &ray), 2, "{what}: {ray:?}");
    // Just the entry: exactly one triangle in a thin window around t = 1.
    let entry = Ray {
        t_min: 0.999,
        t_max: 1.001,
        ..ray
    };
    assert_eq!(count_hits(tris, &entry), 1, "{what} (entry): {ray:?}");
    for wide in wides {
        let hit = wide
            .intersect(&ray)
            .unwrap_or_else(|| panic!("{:?} missed, {what}: {ray:?}", wide.isa()));
        assert!(
            (hit.t - 1.0).abs() < 1e-4,
            "{:?} {what}: t = {}",
            wide.isa(),
            hit.t
        );
        assert!(wide.occluded(&ray));
    }
}

#[test]
fn rays_through_icosphere_vertices_and_edges() {
    let tris = icosphere(3, 1.0);
    let wides = wide_variants(&shapes_of(&tris));
    let mut r = rng(31);
    let mut checked = 0;
    for (k, tri) in tris.iter().enumerate().step_by(3) {
        let [a, b, _] = tri.map(Vec3::from_array);
        for (target, what) in [
            (a, "vertex"),
            ((a + b) * 0.5, "edge midpoint"),
            (a + (b - a) * 0.25, "edge point"),
        ] {
            // From outside, within 60 degrees of the outward normal (the sphere's radius).
            let normal = target.normalized();
            let mut offset = random_unit(&mut r);
            if offset.dot(normal) < 0.5 {
                offset = (normal * 2.0 + offset).normalized();
            }
            let origin = target + offset * uniform(&mut r, 0.5, 3.0);
            check_through(
                &tris,
                &wides,
                origin,
                target,
                &format!("triangle {k} {what}"),
            );
            checked += 1;
        }
    }
    assert!(checked > 1000);
}

#[test]
fn axis_rays_exactly_through_grid_edges_and_vertices() {
    // Vertices and edges of the grid lie on exact binary fractions and the rays run along the
    // axes, so the edge functions there are exactly zero: the f64 check and the tie rule decide.
    let n = 8;
    let tris = grid_cube(n);
    let wides = wide_variants(&shapes_of(&tris));
    let step = 2.0 / n as f32;
    let mut checked = 0;
    for axis in 0..3 {
        for i in 1..n {
            for j in 1..2 * n {
                // j odd: the middle of an edge of the grid; j even: a grid vertex.
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut p = [0.0f32; 3];
                p[u] = -1.0 + step * i as f32;
                p[v] = -1.0 + 0.5 * step * j as f32;
                for (side, sign) in [(1.0f32, 1.0f32), (-1.0, -1.0)] {
                    let mut target = p;
                    target[axis] = side;
                    let mut origin = target;
                    origin[axis] = side + sign * 3.0;
                    check_through(
                        &tris,
                        &wides,
                        Vec3::from_array(origin),
                        Vec3::from_array(target),
                        "grid",
                    );
                    // And along the diagonal of the squares (the shared hypotenuse).
                    checked += 1;
                }
            }
        }
    }
    // Rays in general directions through the square diagonals (edges shared inside a face).
    for i in 0..n {
        for j in 0..n {
            let t = 0.375;
            let target = Vec3::new(
                -1.0 + step * (i as f32 + t),
                -1.0 + step * (j as f32 + t),
                1.0,
            );
            for d in [Vec3::new(0.3, -0.2, -1.0), Vec3::new(-0.7, 0.6, -1.0)] {
                check_through(&tris, &wides, target - d * 2.0, target, "diagonal");
                checked += 1;
            }
        }
    }
    assert!(checked > 300);
}

#[test]
fn camera_rays_never_leak_through_a_closed_mesh() {
    // Dense coherent rays at a finely tessellated sphere: every ray whose line passes well
    // inside the sphere must hit.
    let tris = icosphere(4, 1.0);
    let wides = wide_variants(&shapes_of(&tris));
    let origin = Vec3::new(0.1, 0.2, 4.0);
    let size = 256;
    for wide in &wides {
        let mut misses = 0;
        for y in 0..size {
            for x in 0..size {
                let d = Vec3::new(
                    -0.3 + 0.6 * (x as f32 + 0.5) / size as f32,
                    -0.3 + 0.6 * (y as f32 + 0.5) / size as f32,
                    -1.0,
                );
                let ray = Ray::new(origin, d);
                // Distance of the line from the centre, against the inscribed radius of the mesh.
                let closest = origin - d * (origin.dot(d) / d.dot(d));
                if closest.length() < 0.98 && wide.intersect(&ray).is_none() {
                    misses += 1;
                }
            }
        }
        assert_eq!(misses, 0, "{:?}", wide.isa());
    }
}

/// Rays that start on a face of the grid cube, in its plane (t_min 0), so that a hit lies at
/// t = 0 and every vertex there is at the origin's coordinate on the face's axis: each kernel
/// reports the scalar one's hit bit for bit, the sign of a zero t among it.
#[test]
fn hits_at_the_origin_are_the_scalar_kernels_bit_for_bit() {
    let n = 4;
    let tris = grid_cube(n);
    let wides = wide_variants(&shapes_of(&tris));
    let mut rng = rng(17);
    let mut zero_hits = 0;
    for _ in 0..4000 {
        let axis = (rng.next_u32() % 3) as usize;
        let side = if rng.next_u32().is_multiple_of(2) {
            -1.0f32
        } else {
            1.0
        };
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut origin = [0.0f32; 3];
        origin[axis] = side;
        // On the face, at quarter steps of the grid (on edges and vertices too).
        origin[u] = -1.0 + 0.125 * (rng.next_u32() % 17) as f32;
        origin[v] = -1.0 + 0.125 * (rng.next_u32() % 17) as f32;
        // Mostly along the face's axis (so that it is the sheared frame's), either way.
        let mut d = (random_unit(&mut rng) * 0.5).to_array();
        d[axis] = if rng.next_u32().is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let ray = Ray {
            origin: Vec3::from_array(origin),
            direction: Vec3::from_array(d),
            t_min: 0.0,
            t_max: f32::INFINITY,
        };
        let bits = |h: Option<crate::accel::wide::LocalHit>| {
            h.map(|h| (h.t.to_bits(), h.primitive, h.b1.to_bits(), h.b2.to_bits()))
        };
        let scalar = bits(wides[0].intersect(&ray));
        zero_hits += usize::from(scalar.is_some_and(|(t, ..)| f32::from_bits(t) == 0.0));
        for wide in &wides[1..] {
            assert_eq!(
                bits(wide.intersect(&ray)),
                scalar,
                "{:?}: {ray:?}",
                wide.isa()
            );
        }
    }
    assert!(zero_hits > 1000, "{zero_hits} hits at t = 0");
}
