//! Mitsuba 3's shapes as triangle meshes: [`ShapeMesh`], the type every Mitsuba shape source
//! makes, [`ShapeError`], why a shape file was refused, and Mitsuba's `disk`, `cylinder` and
//! `cube` in object space.
//!
//! Mitsuba intersects `disk` and `cylinder` analytically; Glint renders triangles, so they are
//! tessellated here. The vertices lie on Mitsuba's surface and carry its analytic normal and
//! uv exactly; between vertices the mesh is the inscribed polygon (or prism), whose area falls
//! short of the analytic one by `1 - sin(2π/n) n / 2π` for the disk (0.040 % at
//! [`DISK_SEGMENTS`]) and `1 - sin(π/n) n / π` for the cylinder (0.010 % at
//! [`CYLINDER_SEGMENTS`]), and whose uv is interpolated linearly, as on any mesh. `cube` is a
//! mesh in Mitsuba too, and is reproduced vertex for vertex.

use std::f64::consts::TAU;
use std::fmt;

use glint_render::{Color, Vec3};

/// A triangle mesh as a Mitsuba shape makes it, with the per-vertex attributes Mitsuba keeps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShapeMesh {
    /// Vertex positions, in object space.
    pub positions: Vec<Vec3>,
    /// Indices into the per-vertex arrays.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex unit normals.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, in Mitsuba's convention.
    pub uvs: Option<Vec<(f32, f32)>>,
    /// Per-vertex colours (Mitsuba's `vertex_color`).
    pub colors: Option<Vec<Color>>,
}

impl ShapeMesh {
    /// The sum of the triangles' areas, in object-space units (f64, so that large meshes sum
    /// without drift).
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let p = |i: u32| {
                    let v = self.positions[i as usize];
                    [v.x as f64, v.y as f64, v.z as f64]
                };
                let (a, b, c) = (p(a), p(b), p(c));
                let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
            })
            .sum()
    }
}

/// Why a Mitsuba shape file or shape description was refused: what is wrong and, for files,
/// the byte offset where it was found (the reader turns it into a located diagnostic).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShapeError {
    /// Byte offset in the file, when the error has one.
    pub offset: Option<u64>,
    /// What is wrong, as a sentence fragment without the offset.
    pub message: String,
}

impl ShapeError {
    /// An error found at byte `offset` of the file.
    pub fn at(offset: u64, message: impl Into<String>) -> ShapeError {
        ShapeError {
            offset: Some(offset),
            message: message.into(),
        }
    }

    /// An error with no place in a file (a bad parameter).
    pub fn new(message: impl Into<String>) -> ShapeError {
        ShapeError {
            offset: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.offset {
            Some(offset) => write!(f, "at byte {offset}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for ShapeError {}

/// Segments around the tessellated disk: the fewest powers of two whose area error is under
/// 0.1 % are 128 (0.040 %); 64 would be 0.16 %.
pub const DISK_SEGMENTS: u32 = 128;

/// Segments around the tessellated cylinder (area error 0.010 %; 64 would give 0.040 %, but the
/// silhouette of a large cylinder shows its facets sooner than a disk does).
pub const CYLINDER_SEGMENTS: u32 = 128;

/// Mitsuba's `disk`: the unit disk in the z = 0 plane, centred on the origin, normal +z (−z with
/// `flip_normals`, which Mitsuba expresses as a mirror in z before `to_world`). Its uv is
/// Mitsuba's polar parameterisation, `(r, φ / 2π)` with φ in [0, 2π), so the mesh has a seam
/// at φ = 0 (vertices repeated with v = 0 and v = 1). The centre is the parameterisation's pole
/// (Mitsuba returns v = 0 there); each wedge gets its own centre vertex with u = 0 and v at the
/// wedge's middle angle, so that v interpolates without sweeping across the disk.
pub fn disk(flip_normals: bool) -> ShapeMesh {
    let n = DISK_SEGMENTS;
    let mut positions = Vec::with_capacity(2 * n as usize + 1);
    let mut uvs = Vec::with_capacity(positions.capacity());
    // Ring vertices 0..=n (n repeats 0 at v = 1), then centre vertices n+1..=2n.
    for i in 0..=n {
        let phi = TAU * f64::from(i % n) / f64::from(n);
        positions.push(Vec3::new(phi.cos() as f32, phi.sin() as f32, 0.0));
        uvs.push((1.0, (f64::from(i) / f64::from(n)) as f32));
    }
    for i in 0..n {
        positions.push(Vec3::ZERO);
        uvs.push((0.0, ((f64::from(i) + 0.5) / f64::from(n)) as f32));
    }
    let normal = if flip_normals { -Vec3::Z } else { Vec3::Z };
    let triangles = (0..n)
        .map(|i| {
            let (centre, a, b) = (n + 1 + i, i, i + 1);
            // Counter-clockwise about +z; Mitsuba's mirror reverses the winding.
            if flip_normals {
                [b, a, centre]
            } else {
                [centre, a, b]
            }
        })
        .collect();
    ShapeMesh {
        normals: Some(vec![normal; positions.len()]),
        positions,
        triangles,
        uvs: Some(uvs),
        colors: None,
    }
}

/// Mitsuba's `cylinder`: the open tube (no end caps) of `radius` around the segment from `p0`
/// to `p1`, in object space (Mitsuba's defaults are 1, (0, 0, 0) and (0, 0, 1)). Mitsuba maps
/// its unit cylinder (radius 1, z in [0, 1]) by `translate(p0) · to_frame(Frame(d)) ·
/// scale(r, r, |d|)`, `d = p1 − p0`, where `Frame(d)` is Duff et al.'s orthonormal basis;
/// this mesh uses the same basis, so its uv, `(φ / 2π, z)` with φ measured from the basis's
/// first axis, is Mitsuba's. Normals point outwards, inwards with `flip_normals` (which also
/// reverses the winding, as Mitsuba negates the geometric normal too).
///
/// Mitsuba also toggles `flip_normals` when `to_world` mirrors the cylinder; that belongs to
/// whoever applies `to_world`.
pub fn cylinder(
    radius: f32,
    p0: Vec3,
    p1: Vec3,
    flip_normals: bool,
) -> Result<ShapeMesh, ShapeError> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(ShapeError::new(format!(
            "the cylinder's radius must be a positive number, not {radius}"
        )));
    }
    if !(p0.is_finite() && p1.is_finite()) {
        return Err(ShapeError::new("the cylinder's end points must be finite"));
    }
    let d = p1 - p0;
    let length = d.length();
    if !(length > 0.0 && length.is_finite()) {
        return Err(ShapeError::new(
            "the cylinder's end points p0 and p1 coincide: it has no axis",
        ));
    }
    let axis = d / length;
    let (s, t) = coordinate_system(axis);
    let n = CYLINDER_SEGMENTS;
    let ring = n as usize + 1;
    let mut positions = Vec::with_capacity(2 * ring);
    let mut normals = Vec::with_capacity(2 * ring);
    let mut uvs = Vec::with_capacity(2 * ring);
    for z in [0.0f32, 1.0] {
        for i in 0..=n {
            let phi = TAU * f64::from(i % n) / f64::from(n);
            let (sin, cos) = (phi.sin() as f32, phi.cos() as f32);
            let radial = s * cos + t * sin;
            positions.push(p0 + radial * radius + d * z);
            let normal = radial.normalized();
            normals.push(if flip_normals { -normal } else { normal });
            uvs.push(((f64::from(i) / f64::from(n)) as f32, z));
        }
    }
    let mut triangles = Vec::with_capacity(2 * n as usize);
    for i in 0..n {
        let (b0, b1, t0, t1) = (i, i + 1, n + 1 + i, n + 2 + i);
        // dp/du × dp/dv points outwards for this winding.
        let quad = [[b0, b1, t1], [b0, t1, t0]];
        for [a, b, c] in quad {
            triangles.push(if flip_normals { [c, b, a] } else { [a, b, c] });
        }
    }
    Ok(ShapeMesh {
        positions,
        triangles,
        normals: Some(normals),
        uvs: Some(uvs),
        colors: None,
    })
}

/// Mitsuba's `cube`: the cube [−1, 1]³ as 24 vertices (four per face, each with the face's
/// normal and the uv corners (0, 1), (1, 1), (1, 0), (0, 0)) and 12 triangles, in Mitsuba's
/// order. `flip_normals` negates the normals and reverses the winding, as Mitsuba's meshes do.
pub fn cube(flip_normals: bool) -> ShapeMesh {
    // Face normals in Mitsuba's face order, and the corner of each face vertex; corner `c`
    // has bit k set where axis k is +1.
    const FACE_NORMALS: [[f32; 3]; 6] = [
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    const CORNERS: [u32; 24] = [
        1, 5, 4, 0, 3, 2, 6, 7, 1, 3, 7, 5, 5, 7, 6, 4, 4, 6, 2, 0, 3, 1, 0, 2,
    ];
    const FACE_UV: [(f32, f32); 4] = [(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)];
    let sign = |bit: bool| if bit { 1.0 } else { -1.0 };
    let mut mesh = ShapeMesh {
        positions: Vec::with_capacity(24),
        triangles: Vec::with_capacity(12),
        normals: Some(Vec::with_capacity(24)),
        uvs: Some(Vec::with_capacity(24)),
        colors: None,
    };
    let normal_sign = if flip_normals { -1.0 } else { 1.0 };
    for (face, normal) in FACE_NORMALS.iter().enumerate() {
        for k in 0..4 {
            let c = CORNERS[4 * face + k];
            mesh.positions.push(Vec3::new(
                sign(c & 1 != 0),
                sign(c & 2 != 0),
                sign(c & 4 != 0),
            ));
            if let Some(normals) = mesh.normals.as_mut() {
                normals.push(Vec3::from_array(*normal) * normal_sign);
            }
            if let Some(uvs) = mesh.uvs.as_mut() {
                uvs.push(FACE_UV[k]);
            }
        }
        let v = 4 * face as u32;
        for [a, b, c] in [[v, v + 1, v + 2], [v + 3, v, v + 2]] {
            mesh.triangles
                .push(if flip_normals { [c, b, a] } else { [a, b, c] });
        }
    }
    mesh
}

/// Mitsuba's `coordinate_system` (Duff et al., "Building an Orthonormal Basis, Revisited",
/// JCGT 2017): the two tangents its `Frame(n)` puts beside the unit vector `n`. The sign is
/// copysign's, so −0 counts as negative, as in Dr.Jit.
pub(crate) fn coordinate_system(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(sign * n.x * n.x * a + 1.0, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}
