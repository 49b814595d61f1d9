//! Mitsuba 3's shape sources (glint-io's `mitsuba` module, reached through the doc(hidden)
//! `glint_io::mitsuba_shapes`): the tessellated disk, cylinder and cube against their closed
//! forms, `.serialized` files written here from the format's description, and `sdfgrid`'s
//! `.vol` files, with hostile variants of each.

use std::f64::consts::PI;

use glint_io::mitsuba_shapes::*;
use glint_io::Limits;
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

// ---- .serialized ----

/// What a test shape holds, written by [`encode_serialized`] from the format's description.
#[derive(Clone)]
struct Raw {
    flags: u32,
    name: &'static str,
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    uvs: Vec<[f64; 2]>,
    colors: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Overrides the vertex and triangle counts written (lies).
    counts: Option<(u64, u64)>,
}

const NORMALS: u32 = 0x1;
const UVS: u32 = 0x2;
const COLORS: u32 = 0x8;
const FACE_NORMALS: u32 = 0x10;
const DOUBLE: u32 = 0x2000;

fn raw_shape(flags: u32, shift: f64) -> Raw {
    let positions = vec![
        [0.0 + shift, 0.0, 0.0],
        [1.0, 0.0 + shift, 0.0],
        [0.0, 1.0, 0.5],
        [1.0, 1.0, 0.25 + shift],
    ];
    Raw {
        flags,
        name: "quad",
        normals: vec![
            [0.0, 0.0, 2.0],
            [0.0, 0.6, 0.8],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
        ],
        uvs: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.1, 0.9]],
        colors: vec![
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.5, 0.5],
        ],
        triangles: vec![[0, 1, 2], [2, 1, 3]],
        positions,
        counts: None,
    }
}

/// The uncompressed content of one shape's stream.
fn shape_content(version: u16, raw: &Raw) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend(raw.flags.to_le_bytes());
    if version == 4 {
        out.extend(raw.name.as_bytes());
        out.push(0);
    }
    let (v, f) = raw
        .counts
        .unwrap_or((raw.positions.len() as u64, raw.triangles.len() as u64));
    out.extend(v.to_le_bytes());
    out.extend(f.to_le_bytes());
    let double = raw.flags & DOUBLE != 0;
    let mut floats = |values: &mut dyn Iterator<Item = f64>| {
        for x in values {
            if double {
                out.extend(x.to_le_bytes());
            } else {
                out.extend((x as f32).to_le_bytes());
            }
        }
    };
    floats(&mut raw.positions.iter().flatten().copied());
    if raw.flags & NORMALS != 0 {
        floats(&mut raw.normals.iter().flatten().copied());
    }
    if raw.flags & UVS != 0 {
        floats(&mut raw.uvs.iter().flatten().copied());
    }
    if raw.flags & COLORS != 0 {
        floats(&mut raw.colors.iter().flatten().copied());
    }
    for t in &raw.triangles {
        for i in t {
            out.extend(i.to_le_bytes());
        }
    }
    out
}

fn zlib(content: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    encoder.write_all(content).unwrap();
    encoder.finish().unwrap()
}

/// A whole file: each shape's header and zlib stream, then the dictionary of offsets.
fn encode_serialized(version: u16, shapes: &[Raw]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for raw in shapes {
        offsets.push(out.len() as u64);
        out.extend(0x041Cu16.to_le_bytes());
        out.extend(version.to_le_bytes());
        out.extend(zlib(&shape_content(version, raw)));
    }
    for offset in offsets {
        if version == 4 {
            out.extend(offset.to_le_bytes());
        } else {
            out.extend((offset as u32).to_le_bytes());
        }
    }
    out.extend((shapes.len() as u32).to_le_bytes());
    out
}

fn assert_matches(shape: &SerializedShape, raw: &Raw, version: u16) {
    let mesh = &shape.mesh;
    assert_consistent(mesh);
    assert_eq!(shape.name, if version == 4 { raw.name } else { "" });
    assert_eq!(shape.face_normals, raw.flags & FACE_NORMALS != 0);
    let v3 = |a: &[f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
    let positions: Vec<_> = raw.positions.iter().map(v3).collect();
    assert_eq!(mesh.positions, positions);
    assert_eq!(mesh.triangles, raw.triangles);
    match &mesh.normals {
        Some(normals) => {
            assert!(raw.flags & NORMALS != 0);
            for (n, r) in normals.iter().zip(&raw.normals) {
                assert!((*n - v3(r).normalized()).length() < 1e-6);
            }
        }
        None => assert_eq!(raw.flags & NORMALS, 0),
    }
    let uvs: Option<Vec<_>> = (raw.flags & UVS != 0)
        .then(|| raw.uvs.iter().map(|a| (a[0] as f32, a[1] as f32)).collect());
    assert_eq!(mesh.uvs, uvs);
    let colors: Option<Vec<_>> =
        (raw.flags & COLORS != 0).then(|| raw.colors.iter().map(v3).collect());
    assert_eq!(mesh.colors, colors);
}

#[test]
fn serialized_files_round_trip_with_every_flag_combination() {
    let limits = Limits::default();
    for version in [3u16, 4] {
        for bits in 0..32u32 {
            let flag_of = [NORMALS, UVS, COLORS, FACE_NORMALS, DOUBLE];
            let flags = flag_of
                .iter()
                .enumerate()
                .filter(|(k, _)| bits & (1 << k) != 0)
                .fold(0, |acc, (_, f)| acc | f);
            let first = raw_shape(flags, 0.0);
            let second = raw_shape(flags ^ (NORMALS | UVS), 3.0);
            let file = encode_serialized(version, &[first.clone(), second.clone()]);
            assert_eq!(serialized_shape_count(&file).unwrap(), 2);
            let shape = read_serialized(&file, 0, &limits).unwrap();
            assert_matches(&shape, &first, version);
            let shape = read_serialized(&file, 1, &limits).unwrap();
            assert_matches(&shape, &second, version);
        }
    }
}

fn assert_refused(file: &[u8], index: u32, limits: &Limits, words: &str) -> ShapeError {
    match read_serialized(file, index, limits) {
        Ok(_) => panic!("accepted a file that should fail with '{words}'"),
        Err(error) => {
            let text = error.to_string();
            assert!(text.contains(words), "'{text}' does not say '{words}'");
            assert!(error.offset.is_some(), "'{text}' has no offset");
            error
        }
    }
}

#[test]
fn a_wrong_magic_or_version_is_refused() {
    let limits = Limits::default();
    let mut file = encode_serialized(4, &[raw_shape(NORMALS, 0.0)]);
    file[0] = 0x1D;
    let error = assert_refused(&file, 0, &limits, "magic");
    assert_eq!(error.offset, Some(0));
    for version in [0u16, 2, 5, 6, 0xFFFF] {
        let mut file = encode_serialized(4, &[raw_shape(NORMALS, 0.0)]);
        file[2..4].copy_from_slice(&version.to_le_bytes());
        let error = assert_refused(&file, 0, &limits, "version");
        assert_eq!(error.offset, Some(2));
    }
    assert_refused(&[0x1C], 0, &limits, "header");
    assert_refused(&[], 0, &limits, "header");
}

#[test]
fn corrupt_zlib_data_is_refused() {
    let limits = Limits::default();
    let file = encode_serialized(4, &[raw_shape(NORMALS | UVS, 0.0)]);
    let stream_end = file.len() - 12;
    // Garbage in the middle of the stream.
    let mut garbage = file.clone();
    for byte in &mut garbage[6..stream_end - 6] {
        *byte = 0xFF;
    }
    assert_refused(&garbage, 0, &limits, "corrupt");
    // A bad zlib header.
    let mut header = file.clone();
    header[4] = 0x00;
    assert_refused(&header, 0, &limits, "corrupt");
    // Only the checksum is wrong: the content parses, the stream does not end well.
    let mut checksum = file.clone();
    checksum[stream_end - 1] ^= 0x55;
    assert_refused(&checksum, 0, &limits, "corrupt");
}

#[test]
fn truncated_files_are_refused_at_every_length() {
    let limits = Limits::default();
    let file = encode_serialized(4, &[raw_shape(NORMALS, 0.0), raw_shape(UVS | COLORS, 1.0)]);
    let first_stream_end = {
        let one = encode_serialized(4, &[raw_shape(NORMALS, 0.0)]);
        one.len() - 12
    };
    for len in 0..file.len() {
        let cut = &file[..len];
        // Shape 0 needs its own bytes only (Mitsuba reads it without the dictionary).
        if len < first_stream_end {
            assert!(
                read_serialized(cut, 0, &limits).is_err(),
                "shape 0 read from {len} bytes"
            );
        }
        assert!(
            read_serialized(cut, 1, &limits).is_err(),
            "shape 1 read from {len} bytes"
        );
    }
}

#[test]
fn lying_counts_and_indices_are_refused() {
    let limits = Limits::default();
    let lie = |v: u64, f: u64| {
        // No normals: a normal read from the wrong bytes would be refused for its own sake.
        let mut raw = raw_shape(0, 0.0);
        raw.counts = Some((v, f));
        encode_serialized(4, &[raw])
    };
    // One vertex or triangle more than the data: the stream ends early.
    assert_refused(&lie(5, 2), 0, &limits, "ends");
    assert_refused(&lie(4, 3), 0, &limits, "ends");
    // Far more than the compressed bytes could hold, refused before allocating: with no
    // limits at all, 2^32 - 1 vertices would be 80 GB.
    assert_refused(
        &lie(u32::MAX as u64, 2),
        0,
        &Limits::none(),
        "compressed bytes",
    );
    assert_refused(&lie(4, 1 << 40), 0, &Limits::none(), "compressed bytes");
    assert_refused(&lie(u64::MAX, u64::MAX), 0, &Limits::none(), "vertices");
    // Over the limits.
    let small = Limits {
        max_triangles: 1,
        ..Limits::default()
    };
    assert_refused(&lie(4, 2), 0, &small, "over the limit");
    let tiny_file = Limits {
        max_file_bytes: 10,
        ..Limits::default()
    };
    assert!(read_serialized(&lie(4, 2), 0, &tiny_file).is_err());
    // An index past the vertices.
    let mut raw = raw_shape(0, 0.0);
    raw.triangles[1] = [2, 1, 4];
    assert_refused(&encode_serialized(4, &[raw]), 0, &limits, "vertex 4");
}

#[test]
fn non_finite_values_are_refused() {
    let limits = Limits::default();
    for double in [0, DOUBLE] {
        let mut raw = raw_shape(NORMALS | double, 0.0);
        raw.positions[2][1] = f64::NAN;
        assert_refused(&encode_serialized(4, &[raw]), 0, &limits, "NaN");
        let mut raw = raw_shape(UVS | double, 0.0);
        raw.uvs[1][0] = f64::INFINITY;
        assert_refused(&encode_serialized(4, &[raw]), 0, &limits, "inf");
        let mut raw = raw_shape(NORMALS | double, 0.0);
        raw.normals[3] = [0.0, 0.0, 0.0];
        assert_refused(&encode_serialized(4, &[raw]), 0, &limits, "normal");
    }
}

#[test]
fn the_dictionary_is_checked() {
    let limits = Limits::default();
    for version in [3u16, 4] {
        let file = encode_serialized(version, &[raw_shape(0, 0.0), raw_shape(0, 1.0)]);
        assert_refused(&file, 2, &limits, "out of range");
        // A count larger than the file.
        let mut count = file.clone();
        let n = count.len();
        count[n - 4..].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_refused(&count, 1, &limits, "dictionary");
        // An offset past the shapes.
        let mut offset = file.clone();
        let entry = if version == 4 { n - 12 } else { n - 8 };
        offset[entry..entry + 4].copy_from_slice(&0x7FFF_FFFFu32.to_le_bytes());
        assert_refused(&offset, 1, &limits, "outside");
        // An offset into the middle of shape 0.
        let mut middle = file.clone();
        middle[entry..entry + 4].copy_from_slice(&7u32.to_le_bytes());
        assert!(read_serialized(&middle, 1, &limits).is_err());
    }
}

// ---- sdfgrid and .vol ----

/// A `.vol` file from the format's description.
fn encode_vol(size: [i32; 3], channels: i32, data: &[f32]) -> Vec<u8> {
    let mut out = b"VOL".to_vec();
    out.push(3);
    out.extend(1i32.to_le_bytes());
    for n in size {
        out.extend(n.to_le_bytes());
    }
    out.extend(channels.to_le_bytes());
    for b in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        out.extend(b.to_le_bytes());
    }
    for v in data {
        out.extend(v.to_le_bytes());
    }
    out
}

/// The exact distance to a sphere of radius `r` centred in the unit cube, sampled at Mitsuba's
/// grid points `i / (n - 1)`.
fn sphere_grid(n: usize, r: f64) -> Vec<f32> {
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = [i, j, k].map(|c| c as f64 / (n - 1) as f64 - 0.5);
                data.push(((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - r) as f32);
            }
        }
    }
    data
}

#[test]
fn a_sphere_sdf_becomes_a_closed_sphere_mesh() {
    let (n, r) = (40usize, 0.3);
    let file = encode_vol([n as i32; 3], 1, &sphere_grid(n, r));
    let mesh = read_sdfgrid(&file, &Limits::default()).unwrap();
    assert_consistent(&mesh);
    assert!(mesh.triangles.len() > 1000);
    let analytic = 4.0 * PI * r * r;
    let area = mesh.area();
    assert!(
        (area - analytic).abs() / analytic < 0.01,
        "area {area} vs {analytic}"
    );
    let cell = 1.0 / (n - 1) as f64;
    let normals = mesh.normals.as_ref().unwrap();
    for (p, normal) in mesh.positions.iter().zip(normals) {
        let d = *p - Vec3::splat(0.5);
        let distance = (d.length() as f64 - r).abs();
        assert!(
            distance < cell,
            "vertex {p:?} is {distance} from the sphere"
        );
        assert!(
            normal.dot(d.normalized()) > 0.99,
            "normal {normal:?} at {p:?}"
        );
    }
    // Every triangle faces outwards, the way the gradient points.
    for &t in &mesh.triangles {
        let centre = (0..3).fold(Vec3::ZERO, |acc, k| acc + mesh.positions[t[k] as usize]) / 3.0;
        assert!(
            face_normal(&mesh, t).dot(centre - Vec3::splat(0.5)) > 0.0,
            "{t:?} faces in"
        );
    }
    // Closed: every edge is shared by exactly two triangles, in opposite directions.
    let mut edges = std::collections::HashMap::new();
    for &[a, b, c] in &mesh.triangles {
        for (u, v) in [(a, b), (b, c), (c, a)] {
            *edges.entry((u, v)).or_insert(0) += 1;
        }
    }
    for (&(u, v), &count) in &edges {
        assert_eq!(count, 1, "edge {u}-{v} used {count} times in one direction");
        assert!(edges.contains_key(&(v, u)), "edge {u}-{v} is on a crack");
    }
}

#[test]
fn ambiguous_faces_stay_crack_free() {
    // Random values: most cells and faces ambiguous somewhere. The surface may reach the grid's
    // border, so only interior edges must pair up.
    let n = 12usize;
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let data: Vec<f32> = (0..n * n * n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        })
        .collect();
    let mesh = read_sdfgrid(&encode_vol([n as i32; 3], 1, &data), &Limits::default()).unwrap();
    assert_consistent(&mesh);
    let on_border = |p: Vec3| p.to_array().iter().any(|&c| c == 0.0 || c == 1.0);
    let mut edges = std::collections::HashMap::new();
    for &[a, b, c] in &mesh.triangles {
        for (u, v) in [(a, b), (b, c), (c, a)] {
            *edges.entry((u, v)).or_insert(0) += 1;
        }
    }
    // Fan diagonals of two loops can coincide, so an edge may serve four triangles; a crack
    // would leave an edge without as many uses the other way.
    for (&(u, v), &count) in &edges {
        let both_border =
            on_border(mesh.positions[u as usize]) && on_border(mesh.positions[v as usize]);
        let back = edges.get(&(v, u)).copied().unwrap_or(0);
        assert!(
            both_border || back == count,
            "edge {u}-{v}: {count} uses, {back} back"
        );
    }
}

#[test]
fn vol_files_read_back() {
    let data: Vec<f32> = (0..2 * 3 * 4 * 2).map(|v| v as f32 - 10.0).collect();
    let grid = read_vol(&encode_vol([2, 3, 4], 2, &data), &Limits::default()).unwrap();
    assert_eq!(grid.size, [2, 3, 4]);
    assert_eq!(grid.channels, 2);
    assert_eq!(grid.data, data);
    assert_eq!(grid.bbox_max, Vec3::ONE);
}

#[test]
fn lying_vol_headers_are_refused_without_allocating() {
    let limits = Limits::default();
    let good = encode_vol([3, 3, 3], 1, &sphere_grid(3, 0.3));
    assert!(read_sdfgrid(&good, &limits).is_ok());
    let refuse = |file: &[u8], words: &str| {
        let error = read_sdfgrid(file, &limits).expect_err(words);
        assert!(
            error.to_string().contains(words),
            "'{error}' does not say '{words}'"
        );
    };
    // 2^40 samples (4 TiB) claimed over 27 floats: refused from the header alone. With no
    // size check this would try to allocate 4 TiB and abort, so passing is the proof.
    let mut huge = good.clone();
    for (k, n) in [1i32 << 14, 1 << 13, 1 << 13].iter().enumerate() {
        huge[8 + 4 * k..12 + 4 * k].copy_from_slice(&n.to_le_bytes());
    }
    refuse(&huge, "promises");
    // Products past 2^64.
    let mut overflow = good.clone();
    for k in 0..4 {
        overflow[8 + 4 * k..12 + 4 * k].copy_from_slice(&i32::MAX.to_le_bytes());
    }
    refuse(&overflow, "2^64");
    // One float short, one too many.
    refuse(&good[..good.len() - 4], "promises");
    let mut long = good.clone();
    long.extend(0f32.to_le_bytes());
    refuse(&long, "promises");
    // Negative and zero sizes, channels.
    let mut negative = good.clone();
    negative[12..16].copy_from_slice(&(-3i32).to_le_bytes());
    refuse(&negative, "at least 1");
    let mut zero = good.clone();
    zero[20..24].copy_from_slice(&0i32.to_le_bytes());
    refuse(&zero, "at least 1");
    // Magic, version, encoding, short header.
    let mut magic = good.clone();
    magic[0] = b'X';
    refuse(&magic, "VOL");
    let mut version = good.clone();
    version[3] = 4;
    refuse(&version, "version");
    let mut encoding = good.clone();
    encoding[4] = 2;
    refuse(&encoding, "encoding");
    refuse(&good[..47], "header");
    // Values and shapes sdfgrid cannot use.
    let mut nan = sphere_grid(3, 0.3);
    nan[13] = f32::NAN;
    refuse(&encode_vol([3, 3, 3], 1, &nan), "NaN");
    refuse(&encode_vol([3, 3, 1], 1, &[0.0; 9]), "at least 2");
    refuse(&encode_vol([2, 2, 2], 3, &[0.0; 24]), "one channel");
    let few_cells = Limits {
        max_triangles: 7,
        ..Limits::default()
    };
    let error = read_sdfgrid(&encode_vol([3, 3, 3], 1, &sphere_grid(3, 0.3)), &few_cells);
    assert!(error.unwrap_err().to_string().contains("cells"));
    // A checkerboard cuts every corner of its 8 cells: far more triangles than cells.
    let checker: Vec<f32> = (0..27)
        .map(|v| if v % 2 == 0 { -1.0 } else { 1.0 })
        .collect();
    let few_triangles = Limits {
        max_triangles: 8,
        ..Limits::default()
    };
    let error = read_sdfgrid(&encode_vol([3, 3, 3], 1, &checker), &few_triangles);
    assert!(error.unwrap_err().to_string().contains("triangles"));
}
