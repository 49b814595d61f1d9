//! Mitsuba's `sdfgrid` shape, from its `.vol` grid file, as a triangle mesh.
//!
//! A `.vol` file (Mitsuba's volume grid, version 3), little-endian: the bytes `VOL`, a `u8`
//! version 3, an `i32` encoding (1, float32, the only one Mitsuba 3 reads), `i32` resolutions
//! x, y, z, an `i32` channel count, a bounding box as six f32 (min, max), then
//! `x · y · z · channels` f32 with x varying fastest and the channels innermost.
//!
//! `sdfgrid` takes one channel of signed distances, negative inside, and places sample
//! `(i, j, k)` at `(i / (x − 1), j / (y − 1), k / (z − 1))` of the unit cube, whatever the
//! file's bounding box says; between samples the distance is the trilinear interpolant.
//! Mitsuba intersects that interpolant's zero set exactly. Glint renders triangles, so
//! [`sdfgrid_mesh`] triangulates it by marching cubes: every vertex lies exactly on the zero
//! set (the interpolant is linear along a cell edge), and inside a cell the flat triangles
//! depart from the curved zero set by a fraction of the cell (for a sphere of radius r sampled
//! every h, about h² / 8r). Ambiguous cell faces are resolved by the asymptotic decider, which
//! both cells sharing the face agree on, so the mesh has no cracks; the rare cells whose
//! interior is ambiguous get the face-consistent topology rather than the interpolant's own.
//! Normals are the gradient of the grid (central differences, one-sided at the border)
//! interpolated along the edge, the continuous field that Mitsuba's default `smooth` normals
//! also interpolate; Mitsuba's `analytic` normals, the per-cell gradient, jump between cells.

use std::collections::HashMap;

use glint_render::Vec3;

use super::shapes::{ShapeError, ShapeMesh};
use crate::limits::{format_bytes, Limits};

/// Bytes before a `.vol` file's data.
pub const VOL_HEADER_BYTES: usize = 48;

/// A `.vol` grid as Mitsuba reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    /// Resolution along x, y and z (each at least 1).
    pub size: [u32; 3],
    /// Values per sample.
    pub channels: u32,
    /// The bounding box the file gives (which `sdfgrid` ignores).
    pub bbox_min: Vec3,
    /// See `bbox_min`.
    pub bbox_max: Vec3,
    /// `size[0] · size[1] · size[2] · channels` finite values, x fastest, channels innermost.
    pub data: Vec<f32>,
}

/// Reads a `.vol` file under `limits.max_file_bytes`. The header's resolution times its channels
/// times four bytes must be exactly the data present; nothing is allocated before that holds.
pub fn read_vol(bytes: &[u8], limits: &Limits) -> Result<VolGrid, ShapeError> {
    if bytes.len() as u64 > limits.max_file_bytes {
        return Err(ShapeError::new(format!(
            "the file is {}, over the limit of {}",
            format_bytes(bytes.len() as u64),
            format_bytes(limits.max_file_bytes)
        )));
    }
    if bytes.len() < VOL_HEADER_BYTES {
        return Err(ShapeError::at(
            bytes.len() as u64,
            format!(
                "the file ends inside a .vol header ({} of its {VOL_HEADER_BYTES} bytes)",
                bytes.len()
            ),
        ));
    }
    if &bytes[..3] != b"VOL" {
        return Err(ShapeError::at(
            0,
            "not a .vol grid: it does not start with 'VOL'",
        ));
    }
    if bytes[3] != 3 {
        return Err(ShapeError::at(
            3,
            format!(".vol version {} is not read (only version 3 is)", bytes[3]),
        ));
    }
    let i32_at = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let f32_at = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let encoding = i32_at(4);
    if encoding != 1 {
        return Err(ShapeError::at(
            4,
            format!(".vol encoding {encoding} is not read (only 1, float32, is)"),
        ));
    }
    let mut counts = [0u32; 4];
    let names = [
        "x resolution",
        "y resolution",
        "z resolution",
        "channel count",
    ];
    for (k, name) in names.iter().enumerate() {
        let value = i32_at(8 + 4 * k);
        if value < 1 {
            return Err(ShapeError::at(
                8 + 4 * k as u64,
                format!("the .vol {name} is {value}; it must be at least 1"),
            ));
        }
        counts[k] = value as u32;
    }
    // Four factors below 2^31 and four bytes each: checked, as u64 overflows past 2^64.
    let data_bytes = counts
        .iter()
        .try_fold(4u64, |acc, &c| acc.checked_mul(u64::from(c)));
    let present = (bytes.len() - VOL_HEADER_BYTES) as u64;
    if data_bytes != Some(present) {
        let claim = match data_bytes {
            Some(n) => format!("{n} bytes"),
            None => "more than 2^64 bytes".to_string(),
        };
        return Err(ShapeError::at(
            VOL_HEADER_BYTES as u64,
            format!(
                "the .vol header ({} × {} × {} samples × {} channels) promises {claim} of data, \
                 but {present} follow it",
                counts[0], counts[1], counts[2], counts[3]
            ),
        ));
    }
    let mut data = Vec::with_capacity(present as usize / 4);
    for (i, raw) in bytes[VOL_HEADER_BYTES..].chunks_exact(4).enumerate() {
        let value = f32::from_le_bytes(raw.try_into().expect("4 bytes"));
        if !value.is_finite() {
            return Err(ShapeError::at(
                (VOL_HEADER_BYTES + 4 * i) as u64,
                format!(".vol value {i} is {value}"),
            ));
        }
        data.push(value);
    }
    Ok(VolGrid {
        size: [counts[0], counts[1], counts[2]],
        channels: counts[3],
        bbox_min: Vec3::new(f32_at(24), f32_at(28), f32_at(32)),
        bbox_max: Vec3::new(f32_at(36), f32_at(40), f32_at(44)),
        data,
    })
}

/// Reads a `.vol` file and triangulates its zero level set: [`read_vol`] then [`sdfgrid_mesh`].
pub fn read_sdfgrid(bytes: &[u8], limits: &Limits) -> Result<ShapeMesh, ShapeError> {
    sdfgrid_mesh(&read_vol(bytes, limits)?, limits)
}

/// The zero level set of a one-channel grid as a mesh in Mitsuba's unit-cube object space (see
/// the module's documentation for how close it is). The grid's cells, and the triangles made,
/// are each held to `limits.max_triangles`. Errors have no file offset; the header's fields
/// are at bytes 8 to 23.
pub fn sdfgrid_mesh(grid: &VolGrid, limits: &Limits) -> Result<ShapeMesh, ShapeError> {
    if grid.channels != 1 {
        return Err(ShapeError::at(
            20,
            format!("an sdfgrid has one channel, not {}", grid.channels),
        ));
    }
    let [nx, ny, nz] = grid.size.map(u64::from);
    if nx < 2 || ny < 2 || nz < 2 {
        return Err(ShapeError::at(
            8,
            format!("an sdfgrid needs at least 2 samples along each axis, not {nx} × {ny} × {nz}"),
        ));
    }
    if grid.data.len() as u64 != nx * ny * nz {
        return Err(ShapeError::new(format!(
            "the grid holds {} values, not {nx} × {ny} × {nz}",
            grid.data.len()
        )));
    }
    let cells = (nx - 1) * (ny - 1) * (nz - 1);
    if cells > limits.max_triangles {
        return Err(ShapeError::at(
            8,
            format!(
                "the sdfgrid has {cells} cells, over the limit of {} (the triangle limit)",
                limits.max_triangles
            ),
        ));
    }
    let field = Field {
        data: &grid.data,
        n: [nx as usize, ny as usize, nz as usize],
    };
    let mut mesher = Mesher {
        field,
        vertices: HashMap::new(),
        mesh: ShapeMesh {
            normals: Some(Vec::new()),
            ..ShapeMesh::default()
        },
        max_triangles: limits.max_triangles,
    };
    for k in 0..field.n[2] - 1 {
        for j in 0..field.n[1] - 1 {
            for i in 0..field.n[0] - 1 {
                mesher.cell([i, j, k])?;
            }
        }
    }
    Ok(mesher.mesh)
}

/// The grid's samples, indexed x fastest.
#[derive(Clone, Copy)]
struct Field<'a> {
    data: &'a [f32],
    n: [usize; 3],
}

impl Field<'_> {
    fn at(&self, [i, j, k]: [usize; 3]) -> f32 {
        self.data[(k * self.n[1] + j) * self.n[0] + i]
    }

    fn position(&self, p: [usize; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| p[a] as f64 / (self.n[a] - 1) as f64)
    }

    /// The gradient at a sample, in object-space units.
    fn gradient(&self, p: [usize; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| {
            let (mut lo, mut hi) = (p, p);
            lo[a] = p[a].saturating_sub(1);
            hi[a] = (p[a] + 1).min(self.n[a] - 1);
            let steps = (hi[a] - lo[a]) as f64;
            (f64::from(self.at(hi)) - f64::from(self.at(lo))) * (self.n[a] - 1) as f64 / steps
        })
    }
}

/// A cube corner `c` is offset by bit 0 in x, bit 1 in y, bit 2 in z.
const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// Each face's corners, counter-clockwise seen from outside the cube.
const FACES: [[usize; 4]; 6] = [
    [0, 2, 3, 1],
    [0, 1, 5, 4],
    [0, 4, 6, 2],
    [4, 5, 7, 6],
    [2, 6, 7, 3],
    [1, 3, 7, 5],
];

fn edge_index(a: usize, b: usize) -> usize {
    EDGES
        .iter()
        .position(|&(p, q)| (p, q) == (a.min(b), a.max(b)))
        .expect("adjacent corners")
}

struct Mesher<'a> {
    field: Field<'a>,
    /// Vertex index of each grid edge already cut, keyed by (its lower sample, its axis).
    vertices: HashMap<u64, u32>,
    mesh: ShapeMesh,
    max_triangles: u64,
}

impl Mesher<'_> {
    fn cell(&mut self, base: [usize; 3]) -> Result<(), ShapeError> {
        let corner = |c: usize| {
            [
                base[0] + (c & 1),
                base[1] + (c >> 1 & 1),
                base[2] + (c >> 2),
            ]
        };
        let values: [f32; 8] = std::array::from_fn(|c| self.field.at(corner(c)));
        // Negative is inside; zero counts as outside, the same in every cell.
        let inside = values.map(|v| v < 0.0);
        if inside.iter().all(|&b| b) || inside.iter().all(|&b| !b) {
            return Ok(());
        }
        // Walking each face counter-clockwise from outside, an edge entering the inside starts
        // a segment of the zero set and the edge where it leaves ends it; chained, the segments
        // make loops wound so that their triangles face the outside (positive distances).
        let mut next = [usize::MAX; 12];
        for face in FACES {
            let mut crossings = Vec::with_capacity(4);
            for k in 0..4 {
                let (a, b) = (face[k], face[(k + 1) % 4]);
                if inside[a] != inside[b] {
                    crossings.push((edge_index(a, b), inside[b]));
                }
            }
            match crossings.len() {
                2 => {
                    let (entry, exit) = if crossings[0].1 {
                        (crossings[0].0, crossings[1].0)
                    } else {
                        (crossings[1].0, crossings[0].0)
                    };
                    next[entry] = exit;
                }
                4 => {
                    // The asymptotic decider: the bilinear interpolant's saddle value says
                    // whether the inside corners connect across the face.
                    let f = face.map(|c| f64::from(values[c]));
                    let denominator = f[0] + f[2] - f[1] - f[3];
                    let saddle = if denominator != 0.0 {
                        (f[0] * f[2] - f[1] * f[3]) / denominator
                    } else {
                        0.0
                    };
                    let inside_connected = saddle < 0.0;
                    for m in 0..4 {
                        let (edge, is_entry) = crossings[m];
                        if is_entry {
                            let exit = if inside_connected {
                                crossings[(m + 3) % 4].0
                            } else {
                                crossings[(m + 1) % 4].0
                            };
                            next[edge] = exit;
                        }
                    }
                }
                _ => {}
            }
        }
        let mut visited = [false; 12];
        let mut corners = Vec::with_capacity(12);
        for start in 0..12 {
            if next[start] == usize::MAX || visited[start] {
                continue;
            }
            corners.clear();
            let mut edge = start;
            while edge != usize::MAX && !visited[edge] {
                visited[edge] = true;
                corners.push(self.vertex(base, edge));
                edge = next[edge];
            }
            for k in 1..corners.len().saturating_sub(1) {
                self.triangle([corners[0], corners[k], corners[k + 1]])?;
            }
        }
        Ok(())
    }

    /// The vertex where the zero set cuts the cell's edge, made once per grid edge.
    fn vertex(&mut self, base: [usize; 3], edge: usize) -> u32 {
        let (a, b) = EDGES[edge];
        let axis = (a ^ b).trailing_zeros() as usize;
        let pa = [
            base[0] + (a & 1),
            base[1] + (a >> 1 & 1),
            base[2] + (a >> 2),
        ];
        let mut pb = pa;
        pb[axis] += 1;
        let key = (((pa[2] * self.field.n[1] + pa[1]) * self.field.n[0] + pa[0]) * 3 + axis) as u64;
        if let Some(&index) = self.vertices.get(&key) {
            return index;
        }
        let (fa, fb) = (f64::from(self.field.at(pa)), f64::from(self.field.at(pb)));
        // The signs differ, so the denominator is not zero; exact along the edge, where the
        // trilinear interpolant is linear.
        let t = fa / (fa - fb);
        let (xa, xb) = (self.field.position(pa), self.field.position(pb));
        let (ga, gb) = (self.field.gradient(pa), self.field.gradient(pb));
        let lerp = |u: [f64; 3], v: [f64; 3]| [0, 1, 2].map(|c| u[c] + t * (v[c] - u[c]));
        let p = lerp(xa, xb);
        let g = lerp(ga, gb);
        let mut normal = Vec3::new(g[0] as f32, g[1] as f32, g[2] as f32).normalized();
        if normal == Vec3::ZERO {
            // A flat spot in the samples: the edge's own direction of increase.
            let mut n = [0.0; 3];
            n[axis] = (fb - fa).signum() as f32;
            normal = Vec3::from_array(n);
        }
        let index = self.mesh.positions.len() as u32;
        self.mesh
            .positions
            .push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32));
        if let Some(normals) = self.mesh.normals.as_mut() {
            normals.push(normal);
        }
        self.vertices.insert(key, index);
        index
    }

    fn triangle(&mut self, t: [u32; 3]) -> Result<(), ShapeError> {
        // A zero sample puts several edges' vertices on one corner; such slivers have no area.
        let p = t.map(|i| self.mesh.positions[i as usize]);
        if t[0] == t[1]
            || t[1] == t[2]
            || t[0] == t[2]
            || (p[1] - p[0]).cross(p[2] - p[0]) == Vec3::ZERO
        {
            return Ok(());
        }
        if self.mesh.triangles.len() as u64 >= self.max_triangles {
            return Err(ShapeError::new(format!(
                "the sdfgrid's surface makes more than {} triangles, the limit",
                self.max_triangles
            )));
        }
        self.mesh.triangles.push(t);
        Ok(())
    }
}
