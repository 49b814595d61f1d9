//! Mitsuba 3's shape sources (glint-io's `mitsuba` module, reached through the doc(hidden)
//! `glint_io::mitsuba_shapes`): the tessellated disk, cylinder and cube against their closed
//! forms, `.serialized` files written here from the format's description, and `sdfgrid`'s
//! `.vol` files, with hostile variants of each.

use std::f64::consts::PI;

use glint_io::mitsuba_shapes::*;
use glint_render::Vec3;

/// The triangle's geometric normal (unnormalised), from its winding.
fn face_normal(mesh: &ShapeMesh, [a, b, c]: [u32; 3]) -> Vec3 {
    let p = |i: u32| mesh.positions[i as usize];
    (p(b) - p(a)).cross(p(c) - p(a))
}

/// Every per-vertex array is as long as the positions, and every index is in range.
fn assert_consistent(mesh: &ShapeMesh) {
    let n = mesh.positions.len();
    for &t in &mesh.triangles {
        assert!(
            t.iter().all(|&i| (i as usize) < n),
            "index out of range in {t:?}"
        );
    }
    if let Some(normals) = &mesh.normals {
        assert_eq!(normals.len(), n);
        for normal in normals {
            assert!(
                (normal.length() - 1.0).abs() < 1e-5,
                "normal {normal:?} is not unit"
            );
        }
    }
    if let Some(uvs) = &mesh.uvs {
        assert_eq!(uvs.len(), n);
    }
    if let Some(colors) = &mesh.colors {
        assert_eq!(colors.len(), n);
    }
}

/// Each triangle's winding agrees with its vertices' normals.
fn assert_winding_follows_normals(mesh: &ShapeMesh) {
    let normals = mesh.normals.as_ref().expect("normals");
    for &t in &mesh.triangles {
        let g = face_normal(mesh, t);
        for &i in &t {
            assert!(
                g.dot(normals[i as usize]) > 0.0,
                "triangle {t:?} faces against vertex {i}'s normal"
            );
        }
    }
}

#[test]
fn the_disk_has_the_unit_disks_area_normal_and_polar_uv() {
    for flip in [false, true] {
        let mesh = disk(flip);
        assert_consistent(&mesh);
        assert_winding_follows_normals(&mesh);
        let area = mesh.area();
        assert!((area - PI).abs() / PI < 1e-3, "area {area}");
        assert!(area < PI, "the tessellation is inscribed");
        let expected_normal = if flip { -Vec3::Z } else { Vec3::Z };
        assert!(mesh
            .normals
            .as_ref()
            .unwrap()
            .iter()
            .all(|&n| n == expected_normal));
        for (p, &(u, v)) in mesh.positions.iter().zip(mesh.uvs.as_ref().unwrap()) {
            assert_eq!(p.z, 0.0);
            assert!((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v));
            let r = (p.x as f64).hypot(p.y as f64);
            assert!((u as f64 - r).abs() < 1e-6, "u {u} at radius {r}");
            if r > 0.5 && v < 0.999 {
                let mut phi = (p.y as f64).atan2(p.x as f64);
                if phi < 0.0 {
                    phi += 2.0 * PI;
                }
                assert!(
                    (v as f64 - phi / (2.0 * PI)).abs() < 1e-5,
                    "v {v} at φ {phi}"
                );
            }
        }
    }
}

#[test]
fn mitsubas_frame_is_orthonormal_and_right_handed() {
    let axes = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::new(0.3, -0.4, 0.5).normalized(),
        Vec3::new(-0.7, 0.1, -0.2).normalized(),
    ];
    for axis in axes {
        // Through the cylinder: its first ring vertex (u = 0) lies along the frame's s.
        let mesh = cylinder(1.0, Vec3::ZERO, axis, false).unwrap();
        let s = mesh.positions[0];
        let quarter = mesh.positions[(CYLINDER_SEGMENTS / 4) as usize];
        assert!(s.dot(axis).abs() < 1e-6 && quarter.dot(axis).abs() < 1e-6);
        assert!(s.dot(quarter).abs() < 1e-6);
        assert!(
            (s.cross(quarter) - axis).length() < 1e-5,
            "{s:?} × {quarter:?} ≠ {axis:?}"
        );
    }
    // Along +z Mitsuba's frame is the identity, so φ is measured from +x towards +y.
    let mesh = cylinder(1.0, Vec3::ZERO, Vec3::Z, false).unwrap();
    assert!((mesh.positions[0] - Vec3::X).length() < 1e-6);
}

#[test]
fn the_cylinder_is_an_open_tube_with_mitsubas_area_normals_and_uv() {
    let cases = [
        (1.0, Vec3::ZERO, Vec3::Z),
        (0.25, Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 4.0)),
        (3.0, Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0)),
    ];
    for (radius, p0, p1) in cases {
        for flip in [false, true] {
            let mesh = cylinder(radius, p0, p1, flip).unwrap();
            assert_consistent(&mesh);
            assert_winding_follows_normals(&mesh);
            let length = (p1 - p0).length() as f64;
            let analytic = 2.0 * PI * radius as f64 * length;
            let area = mesh.area();
            assert!(
                (area - analytic).abs() / analytic < 1e-3,
                "area {area} vs {analytic}"
            );
            let axis = (p1 - p0).normalized();
            let normals = mesh.normals.as_ref().unwrap();
            for ((p, n), &(u, v)) in mesh
                .positions
                .iter()
                .zip(normals)
                .zip(mesh.uvs.as_ref().unwrap())
            {
                let along = (*p - p0).dot(axis);
                let radial = *p - p0 - axis * along;
                assert!((radial.length() - radius).abs() < 1e-5 * radius.max(1.0));
                let outward = radial.normalized();
                let expected = if flip { -outward } else { outward };
                assert!(
                    (*n - expected).length() < 1e-5,
                    "normal {n:?} vs {expected:?}"
                );
                assert!((0.0..=1.0).contains(&u));
                assert!((v as f64 - along as f64 / length).abs() < 1e-5, "v {v}");
            }
        }
    }
    // Open: no vertex inside the tube, so no cap.
    let mesh = cylinder(1.0, Vec3::ZERO, Vec3::Z, false).unwrap();
    assert!(mesh
        .positions
        .iter()
        .all(|p| (p.x.hypot(p.y) - 1.0).abs() < 1e-6));
}

#[test]
fn a_cylinder_without_an_axis_or_radius_is_refused() {
    assert!(cylinder(1.0, Vec3::Z, Vec3::Z, false).is_err());
    assert!(cylinder(0.0, Vec3::ZERO, Vec3::Z, false).is_err());
    assert!(cylinder(f32::NAN, Vec3::ZERO, Vec3::Z, false).is_err());
    assert!(cylinder(1.0, Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0), false).is_err());
}

#[test]
fn the_cube_is_mitsubas_24_vertex_cube() {
    for flip in [false, true] {
        let mesh = cube(flip);
        assert_consistent(&mesh);
        assert_winding_follows_normals(&mesh);
        assert_eq!(mesh.positions.len(), 24);
        assert_eq!(mesh.triangles.len(), 12);
        assert!((mesh.area() - 24.0).abs() < 1e-9);
        let normals = mesh.normals.as_ref().unwrap();
        for (p, n) in mesh.positions.iter().zip(normals) {
            assert!(p.to_array().iter().all(|c| c.abs() == 1.0));
            // A face's vertices lie on the face its normal names.
            let outward = if flip { -*n } else { *n };
            assert_eq!(p.dot(outward), 1.0, "{p:?} is not on the face of {n:?}");
        }
        let uvs = mesh.uvs.as_ref().unwrap();
        for face in 0..6 {
            let corners: Vec<_> = uvs[4 * face..4 * face + 4].to_vec();
            assert_eq!(
                corners,
                vec![(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)]
            );
        }
        // Mitsuba's first face is −y, its first triangle (0, 1, 2).
        let first = if flip { [2, 1, 0] } else { [0, 1, 2] };
        assert_eq!(mesh.triangles[0], first);
        assert_eq!(mesh.positions[0], Vec3::new(1.0, -1.0, -1.0));
    }
}
