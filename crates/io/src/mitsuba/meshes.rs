//! Triangle meshes as Mitsuba's `obj` and `ply` shapes read them: positions, per-corner
//! normals and uv, vertex and face colours, and the smooth normals Mitsuba makes when a
//! file has none.

use glint_render::{Color, Vec3};

/// A triangle mesh in object space with its attributes, per triangle corner.
#[derive(Clone, Debug, Default)]
pub(crate) struct TriMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<[Vec3; 3]>>,
    pub uvs: Option<Vec<[(f32, f32); 3]>>,
    pub vertex_colors: Option<Vec<[Color; 3]>>,
    pub face_colors: Option<Vec<Color>>,
    /// A PLY file's other scalar vertex and face properties by name, and the face each
    /// triangle was cut from, for `mesh_attribute` textures of other names.
    pub vertex_columns: Vec<(String, Vec<f32>)>,
    pub face_columns: Vec<(String, Vec<f32>)>,
    pub triangle_faces: Vec<u32>,
}

/// Reads an OBJ file the way Mitsuba's `obj` plugin does: `v`, `vt` (v flipped to 1 − v),
/// `vn`, and `f` records of `v`, `v/vt`, `v//vn` or `v/vt/vn` corners, polygons cut into
/// fans; everything else is skipped. Indices are 1-based and must exist.
pub(crate) fn read_obj(bytes: &[u8], max_triangles: u64) -> Result<TriMesh, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "the file is not UTF-8 text".to_string())?;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut texcoords: Vec<(f32, f32)> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    // Corner indices into the three lists (u32::MAX: none).
    let mut corners: Vec<[u32; 3]> = Vec::new();
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    let mut face: Vec<[u32; 3]> = Vec::new();
    let mut has_uv = false;
    let mut has_normals = false;
    for (number, line) in text.lines().enumerate() {
        let fail = |why: &str| format!("line {}: {why}", number + 1);
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let mut numbers = |count: usize| -> Result<Vec<f32>, String> {
            let values: Vec<f32> = words
                .by_ref()
                .take(count)
                .map(|word| word.parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|_| fail("could not parse a number"))?;
            if values.len() < count || !values.iter().all(|v| v.is_finite()) {
                return Err(fail("expected finite numbers"));
            }
            Ok(values)
        };
        match keyword {
            "v" => {
                let p = numbers(3)?;
                positions.push(Vec3::new(p[0], p[1], p[2]));
            }
            "vt" => {
                let t = numbers(2)?;
                texcoords.push((t[0], 1.0 - t[1]));
            }
            "vn" => {
                let n = numbers(3)?;
                normals.push(Vec3::new(n[0], n[1], n[2]));
            }
            "f" => {
                face.clear();
                for word in words {
                    let mut key = [u32::MAX; 3];
                    for (slot, part) in key.iter_mut().zip(word.split('/')) {
                        if part.is_empty() {
                            continue;
                        }
                        let index: u32 =
                            part.parse().ok().filter(|&i| i > 0).ok_or_else(|| {
                                fail(&format!("`{word}` is not a positive index"))
                            })?;
                        *slot = index - 1;
                    }
                    if key[0] == u32::MAX || key[0] as usize >= positions.len() {
                        return Err(fail(&format!("reference to invalid vertex in `{word}`")));
                    }
                    if key[1] != u32::MAX && key[1] as usize >= texcoords.len() {
                        return Err(fail(&format!(
                            "reference to invalid texture coordinate in `{word}`"
                        )));
                    }
                    if key[2] != u32::MAX && key[2] as usize >= normals.len() {
                        return Err(fail(&format!("reference to invalid normal in `{word}`")));
                    }
                    has_uv |= key[1] != u32::MAX;
                    has_normals |= key[2] != u32::MAX;
                    face.push(key);
                }
                let base = corners.len();
                corners.extend_from_slice(&face);
                for k in 1..face.len().saturating_sub(1) {
                    triangles.push([base, base + k, base + k + 1]);
                }
                if triangles.len() as u64 > max_triangles {
                    return Err(format!(
                        "its faces make more than the limit of {max_triangles} triangles \
                         (--max-triangles raises it)"
                    ));
                }
            }
            _ => {}
        }
    }
    let corner = |t: &[usize; 3], k: usize| corners[t[k]];
    let mesh_triangles: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| [corner(t, 0)[0], corner(t, 1)[0], corner(t, 2)[0]])
        .collect();
    // A corner without uv (in a file where others have them) reads (0, 0).
    let uvs = has_uv.then(|| {
        triangles
            .iter()
            .map(|t| {
                [0, 1, 2].map(|k| {
                    let i = corner(t, k)[1];
                    if i == u32::MAX {
                        (0.0, 0.0)
                    } else {
                        texcoords[i as usize]
                    }
                })
            })
            .collect()
    });
    let corner_normals = has_normals.then(|| {
        triangles
            .iter()
            .map(|t| {
                [0, 1, 2].map(|k| {
                    let i = corner(t, k)[2];
                    if i == u32::MAX {
                        Vec3::new(1.0, 0.0, 0.0)
                    } else {
                        normals[i as usize]
                    }
                })
            })
            .collect()
    });
    Ok(TriMesh {
        positions,
        triangles: mesh_triangles,
        normals: corner_normals,
        uvs,
        ..Default::default()
    })
}

/// A PLY file's attributes as Mitsuba's `ply` plugin names them: `nx ny nz` normals, `u v`
/// (or `s t`, `texture_u texture_v`) uv, and colours (`r g b`, `red green blue`,
/// `color_0..2`, `color_r..b`) as `vertex_color` and `face_color`.
pub(crate) fn from_ply(ply: crate::ply::PlyAttributes) -> TriMesh {
    let column = |columns: &[(String, Vec<f32>)], name: &str| {
        columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, values)| values.clone())
    };
    let triple = |columns: &[(String, Vec<f32>)], names: [&str; 3]| match names
        .map(|name| column(columns, name))
    {
        [Some(a), Some(b), Some(c)] => Some((a, b, c)),
        _ => None,
    };
    let colour = |columns: &[(String, Vec<f32>)]| {
        [
            ["r", "g", "b"],
            ["red", "green", "blue"],
            ["color_0", "color_1", "color_2"],
            ["color_1", "color_2", "color_3"],
            ["color_r", "color_g", "color_b"],
        ]
        .into_iter()
        .find_map(|names| triple(columns, names))
    };
    let vertices = &ply.vertex_columns;
    let positions: Vec<Vec3> = ply
        .positions
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let per_corner = |values: &(Vec<f32>, Vec<f32>, Vec<f32>), normalise: bool| {
        ply.triangles
            .iter()
            .map(|t| {
                t.map(|i| {
                    let i = i as usize;
                    let v = Vec3::new(values.0[i], values.1[i], values.2[i]);
                    if normalise {
                        v.normalized()
                    } else {
                        v
                    }
                })
            })
            .collect::<Vec<[Vec3; 3]>>()
    };
    let normals = triple(vertices, ["nx", "ny", "nz"]).map(|n| per_corner(&n, false));
    let uv_columns = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"]]
        .into_iter()
        .find_map(|[u, v]| Some((column(vertices, u)?, column(vertices, v)?)));
    let uvs = uv_columns.map(|(u, v)| {
        ply.triangles
            .iter()
            .map(|t| t.map(|i| (u[i as usize], v[i as usize])))
            .collect()
    });
    let vertex_colors = colour(vertices).map(|c| per_corner(&c, false));
    let face_colors = colour(&ply.face_columns).map(|(r, g, b)| {
        ply.triangle_faces
            .iter()
            .map(|&f| Color::new(r[f as usize], g[f as usize], b[f as usize]))
            .collect()
    });
    TriMesh {
        positions,
        triangles: ply.triangles,
        normals,
        uvs,
        vertex_colors,
        face_colors,
        vertex_columns: ply.vertex_columns,
        face_columns: ply.face_columns,
        triangle_faces: ply.triangle_faces,
    }
}

/// The columns of attribute `prefix` as Mitsuba groups them: `prefix` alone (one channel)
/// or `prefix_{x,y,z}`, `prefix_{r,g,b}`, `prefix_{0,1,2}`, `prefix_{1,2,3}` (three, or
/// one when only the first exists).
fn grouped(columns: &[(String, Vec<f32>)], prefix: &str) -> Option<[Vec<f32>; 3]> {
    let find = |name: &str| {
        columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
    };
    if let Some(single) = find(prefix) {
        return Some([single.clone(), single.clone(), single]);
    }
    for suffixes in [
        ["x", "y", "z"],
        ["r", "g", "b"],
        ["0", "1", "2"],
        ["1", "2", "3"],
    ] {
        let [a, b, c] = suffixes.map(|s| find(&format!("{prefix}_{s}")));
        match (a, b, c) {
            (Some(a), Some(b), Some(c)) => return Some([a, b, c]),
            (Some(a), None, None) => return Some([a.clone(), a.clone(), a]),
            _ => {}
        }
    }
    None
}

impl TriMesh {
    /// Fills `vertex_colors` or `face_colors` from the attribute Mitsuba calls `name`
    /// (`vertex_<prefix>` or `face_<prefix>`), a one-channel attribute as grey. Errors say
    /// why not.
    pub fn use_attribute(&mut self, name: &str) -> Result<(), String> {
        if name == "vertex_color" && self.vertex_colors.is_some()
            || name == "face_color" && self.face_colors.is_some()
        {
            return Ok(());
        }
        if let Some(prefix) = name.strip_prefix("vertex_") {
            let [r, g, b] = grouped(&self.vertex_columns, prefix)
                .ok_or_else(|| format!("the mesh has no attribute \"{name}\""))?;
            self.vertex_colors = Some(
                self.triangles
                    .iter()
                    .map(|t| t.map(|i| Color::new(r[i as usize], g[i as usize], b[i as usize])))
                    .collect(),
            );
            Ok(())
        } else if let Some(prefix) = name.strip_prefix("face_") {
            let [r, g, b] = grouped(&self.face_columns, prefix)
                .ok_or_else(|| format!("the mesh has no attribute \"{name}\""))?;
            self.face_colors = Some(
                self.triangle_faces
                    .iter()
                    .map(|&f| Color::new(r[f as usize], g[f as usize], b[f as usize]))
                    .collect(),
            );
            Ok(())
        } else {
            Err(format!(
                "a mesh attribute's name starts with vertex_ or face_, not \"{name}\""
            ))
        }
    }
}

impl TriMesh {
    /// A shape source's mesh (per-vertex attributes) with per-corner attributes; colours
    /// become `vertex_colors`.
    pub fn from_shape(mesh: super::shapes::ShapeMesh) -> TriMesh {
        fn corners<T: Copy>(triangles: &[[u32; 3]], values: &[T]) -> Vec<[T; 3]> {
            triangles
                .iter()
                .map(|t| t.map(|i| values[i as usize]))
                .collect()
        }
        TriMesh {
            normals: mesh.normals.as_deref().map(|v| corners(&mesh.triangles, v)),
            uvs: mesh.uvs.as_deref().map(|v| corners(&mesh.triangles, v)),
            vertex_colors: mesh.colors.as_deref().map(|v| corners(&mesh.triangles, v)),
            positions: mesh.positions,
            triangles: mesh.triangles,
            ..Default::default()
        }
    }

    /// Smooth normals as Mitsuba makes them for a mesh without any: each triangle's unit
    /// normal added to its corners' positions weighted by the corner's angle (Thürmer and
    /// Wüthrich), then normalised; a position no valid triangle touches gets (1, 0, 0).
    pub fn compute_vertex_normals(&mut self) {
        let mut sums = vec![[0.0f32; 3]; self.positions.len()];
        for t in &self.triangles {
            let p = t.map(|i| self.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let length_squared = n.length_squared();
            if length_squared <= 0.0 {
                continue;
            }
            let n = n / length_squared.sqrt();
            for k in 0..3 {
                let a = (p[(k + 1) % 3] - p[k]).normalized();
                let b = (p[(k + 2) % 3] - p[k]).normalized();
                let angle = unit_angle(a, b);
                let sum = &mut sums[t[k] as usize];
                sum[0] += n.x * angle;
                sum[1] += n.y * angle;
                sum[2] += n.z * angle;
            }
        }
        let unit: Vec<Vec3> = sums
            .iter()
            .map(|s| {
                let v = Vec3::new(s[0], s[1], s[2]);
                if v.length_squared() > 0.0 {
                    v.normalized()
                } else {
                    Vec3::new(1.0, 0.0, 0.0)
                }
            })
            .collect();
        self.normals = Some(
            self.triangles
                .iter()
                .map(|t| t.map(|i| unit[i as usize]))
                .collect(),
        );
    }

    /// Mitsuba's `flip_normals`: the winding reversed, and shading normals turned with it.
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(0, 2);
        }
        for list in self.normals.iter_mut() {
            for n in list.iter_mut() {
                n.swap(0, 2);
                *n = n.map(|v| -v);
            }
        }
        for list in self.uvs.iter_mut() {
            for uv in list.iter_mut() {
                uv.swap(0, 2);
            }
        }
        for list in self.vertex_colors.iter_mut() {
            for c in list.iter_mut() {
                c.swap(0, 2);
            }
        }
    }
}

/// The angle between unit vectors, accurate near 0 and π (Mitsuba's `unit_angle`).
fn unit_angle(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        std::f32::consts::PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}
