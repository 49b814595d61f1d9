//! The scene flattened into the storage buffers `path.wgsl` reads. Nothing here is shared with
//! the CPU renderer's private structures: it is built from the public `SceneParts` alone, so
//! the GPU back end has its own BVHs (binary, binned SAH: one per geometry in its object space,
//! one over the instances, as glint-render's two-level structure) and its own light records
//! and triangle area shares, computed by the same formulas as `glint-render`'s
//! `light::sampler`. The table that chooses a light by power (`LightSelection`) and the cube
//! map's luminance distribution (`CubeDistribution`) are glint-render's own, public for this,
//! and uploaded as they are.
//!
//! Every buffer is an array of `vec4<f32>` (or of `f32` for `tables`); integers travel as the
//! bits of an f32 (`bits`). The strides and kinds below are repeated, by name, as constants at
//! the top of `path.wgsl`.

use std::f32::consts::PI;

use bytemuck::{Pod, Zeroable};

use crate::physical::{PhysicalBuffer, SPHERE_MITSUBA_UV};
use glint_render::{
    Background, Camera, Color, ColorSource, CubeDistribution, Image, Light, LightSelection,
    Material, Projection, SceneParts, Shape, Transform, Vec3,
};

pub const NONE: u32 = u32::MAX;

pub const PRIM_TRIANGLE: u32 = 0;
pub const PRIM_SPHERE: u32 = 1;
pub const PRIM_BOX: u32 = 2;
/// vec4s per primitive, in its geometry's object space: [v0 | centre | min, kind],
/// [v1 | (radius, ..) | max, material], [v2, a triangle's attribute record in `physical`
/// (`NONE` without) | a sphere's flags (`physical::SPHERE_MITSUBA_UV`), ..], [unit normal of
/// a triangle, 0].
pub const PRIM_STRIDE: usize = 4;
/// vec4s per instance, stored after the primitives: three rows of object_from_world (the
/// identity without a transform), then [geometry's root node, material override, flags, 0],
/// then three rows of world_from_object.
pub const INSTANCE_STRIDE: usize = 7;
/// An instance's flags: it blocks shadow rays; it has a transform.
pub const FLAG_CASTS_SHADOW: u32 = 1;
pub const FLAG_TRANSFORMED: u32 = 2;

pub const BSDF_BLACK: u32 = 0;
pub const BSDF_DIFFUSE: u32 = 1;
pub const BSDF_BLINN_PHONG: u32 = 2;
pub const BSDF_PHONG: u32 = 3;
pub const BSDF_MIRROR: u32 = 4;
pub const BSDF_GLAZE: u32 = 5;
pub const BSDF_BLINN_PHONG_MIRRORED: u32 = 6;
pub const BSDF_DIELECTRIC: u32 = 7;
/// A physically based material; its BSDF tree's id is in the exponent's place.
pub const BSDF_PHYSICAL: u32 = 8;
/// vec4s per material: [kd, kd texture], [ks, ks texture], [bsdf kind, exponent, km,
/// roughness], [η, emitter kind, light index, has attenuation], [attenuation],
/// [unsampled emitter radiance].
pub const MATERIAL_STRIDE: usize = 6;
pub const EMITTER_NONE: u32 = 0;
pub const EMITTER_LIGHT: u32 = 1;
pub const EMITTER_UNSAMPLED: u32 = 2;

pub const LIGHT_POINT: u32 = 0;
pub const LIGHT_RECTANGLE: u32 = 1;
pub const LIGHT_SPHERE: u32 = 2;
pub const LIGHT_TRIANGLES: u32 = 3;
pub const LIGHT_ENVIRONMENT: u32 = 4;
/// vec4s per light: [kind, first triangle, triangle count, reachable by BSDF sampling],
/// [position | centre, area | radius], [u edge, 1/area], [v edge], [normal], [radiance].
pub const LIGHT_STRIDE: usize = 6;
/// vec4s per emitting triangle, after the lights: [v0, cumulative area share], [edge1],
/// [edge2], [unit normal].
pub const LIGHT_TRIANGLE_STRIDE: usize = 4;

/// BVH leaves hold at most this many primitives (unless the depth limit forces more).
const MAX_LEAF: usize = 4;
/// Beyond this depth a node becomes a leaf whatever its size: the kernel's traversal stack
/// holds 64 entries, and a deeper tree could overflow it.
const MAX_DEPTH: u32 = 48;
const BINS: usize = 12;

/// An integer carried in an f32 slot.
#[inline]
pub fn bits(value: u32) -> f32 {
    f32::from_bits(value)
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

/// The uniform block of `path.wgsl` (`Params`), in the same field order.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct Params {
    pub width: u32,
    pub height: u32,
    pub first_sample: u32,
    pub samples: u32,
    pub seed_lo: u32,
    pub seed_hi: u32,
    pub max_depth: u32,
    pub rr_depth: u32,
    pub light_count: u32,
    pub environment_light: u32,
    pub material_count: u32,
    pub light_triangles: u32,
    pub background_kind: u32,
    pub cube_first_texture: u32,
    pub texture_info: u32,
    pub row_cdf: u32,
    pub column_cdf: u32,
    pub column_start: u32,
    pub first_row: u32,
    pub instances: u32,
    pub projection: u32,
    pub x0: u32,
    pub y0: u32,
    pub crop_width: u32,
    pub crop_height: u32,
    /// Always 2 (the loop-limit canary of `path.wgsl`).
    pub canary: u32,
    /// The top-level BVH's root node.
    pub tlas_root: u32,
    pub pad: u32,
    pub bsdf_index: u32,
    pub texture_nodes: u32,
    pub bsdf_count: u32,
    /// Bit 0: `RENDER_HIDE_EMITTERS`.
    pub render_flags: u32,
    /// `FILTER_*`, and its radius or standard deviation (f32 bits).
    pub filter_kind: u32,
    pub filter_param: u32,
    pub pad2: [u32; 2],
    pub camera_position: [f32; 4],
    pub camera_u: [f32; 4],
    pub camera_v: [f32; 4],
    pub camera_w: [f32; 4],
    pub background: [f32; 4],
    /// The thin lens: aperture radius, focus distance (zero: a pinhole).
    pub lens: [f32; 4],
}

/// The flattened scene: the buffers' contents and the scene-dependent part of `Params`
/// (image size, samples and seed are filled in per pass).
#[derive(Clone, Debug)]
pub struct FlatScene {
    pub nodes: Vec<[f32; 4]>,
    pub prims: Vec<[f32; 4]>,
    pub materials: Vec<[f32; 4]>,
    pub lights: Vec<[f32; 4]>,
    pub tables: Vec<f32>,
    pub texels: Vec<[f32; 4]>,
    /// Physically based materials: BSDF nodes, texture nodes, mesh attributes.
    pub physical: Vec<[f32; 4]>,
    pub params: Params,
}

/// One primitive in its geometry's object space, before the BVH orders them.
struct Primitive {
    words: [[f32; 4]; PRIM_STRIDE],
    bounds: (Vec3, Vec3),
}

fn apply_rows(m: &[[f32; 4]; 3], p: Vec3, w: f32) -> Vec3 {
    Vec3::new(
        m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3] * w,
        m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3] * w,
        m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3] * w,
    )
}

fn transformed_bounds(transform: &Transform, (min, max): (Vec3, Vec3)) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for corner in 0..8 {
        let p = Vec3::new(
            if corner & 1 == 0 { min.x } else { max.x },
            if corner & 2 == 0 { min.y } else { max.y },
            if corner & 4 == 0 { min.z } else { max.z },
        );
        let q = apply_rows(&transform.world_from_object, p, 1.0);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    (lo, hi)
}

fn shape_bounds(shape: &Shape) -> (Vec3, Vec3) {
    let b = shape.bounds();
    (b.min, b.max)
}

impl FlatScene {
    pub fn new(parts: &SceneParts) -> FlatScene {
        // Bottom level: each geometry's shapes in object space under their own BVH, stored
        // once however many instances place it (glint-render's two-level structure).
        let mut nodes: Vec<[f32; 4]> = Vec::new();
        let mut prims: Vec<[f32; 4]> = Vec::new();
        let mut roots = Vec::with_capacity(parts.geometries.len());
        let mut physical = PhysicalBuffer::new(&parts.physical, &parts.textures);
        for (g, geometry) in parts.geometries.iter().enumerate() {
            let attributes = parts.physical.attributes.get(g).and_then(Option::as_ref);
            let primitives: Vec<Primitive> = geometry
                .shapes
                .iter()
                .enumerate()
                .map(|(index, shape)| {
                    let extra = match shape {
                        Shape::Triangle { .. } => physical.triangle_attributes(attributes, index),
                        Shape::Sphere { .. } if attributes.is_some_and(|a| a.mitsuba_sphere_uv) => {
                            SPHERE_MITSUBA_UV
                        }
                        _ => 0,
                    };
                    primitive(
                        shape,
                        geometry.materials.get(index).copied().unwrap_or(NONE),
                        extra,
                    )
                })
                .collect();
            let bounds: Vec<(Vec3, Vec3)> = primitives.iter().map(|p| p.bounds).collect();
            let (mut local, order) = build_bvh(&bounds);
            let root = nodes.len() / 2;
            relocate(&mut local, root, prims.len() / PRIM_STRIDE);
            nodes.extend_from_slice(&local);
            for &index in &order {
                prims.extend_from_slice(&primitives[index].words);
            }
            let union = bounds.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
            );
            roots.push((root as u32, union, !primitives.is_empty()));
        }

        // Top level: the instances, each a transform, its geometry's root and its flags.
        let instances_offset = prims.len() as u32;
        let mut instance_words: Vec<[[f32; 4]; INSTANCE_STRIDE]> = Vec::new();
        let mut instance_bounds = Vec::new();
        let mut scene_lo = Vec3::splat(f32::INFINITY);
        let mut scene_hi = Vec3::splat(f32::NEG_INFINITY);
        for instance in &parts.instances {
            let Some(&(root, bounds, true)) = roots.get(instance.geometry as usize) else {
                continue;
            };
            let mut flags = 0;
            if instance.casts_shadow {
                flags |= FLAG_CASTS_SHADOW;
            }
            const IDENTITY: [[f32; 4]; 3] = [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ];
            let (rows, inverse) = match &instance.transform {
                Some(t) => {
                    flags |= FLAG_TRANSFORMED;
                    (t.object_from_world, t.world_from_object)
                }
                None => (IDENTITY, IDENTITY),
            };
            instance_words.push([
                rows[0],
                rows[1],
                rows[2],
                [
                    bits(root),
                    bits(instance.material.unwrap_or(NONE)),
                    bits(flags),
                    0.0,
                ],
                inverse[0],
                inverse[1],
                inverse[2],
            ]);
            let placed = placed_bounds(instance.transform.as_ref(), bounds);
            scene_lo = scene_lo.min(placed.0);
            scene_hi = scene_hi.max(placed.1);
            instance_bounds.push(placed);
        }
        let (mut top, order) = build_bvh(&instance_bounds);
        let tlas_root = nodes.len() / 2;
        relocate(&mut top, tlas_root, 0);
        nodes.extend_from_slice(&top);
        for &index in &order {
            prims.extend_from_slice(&instance_words[index]);
        }

        let materials = flatten_materials(parts);
        let mut tables = Vec::new();
        let mut texels = Vec::new();
        let lights = LightTables::new(parts, (scene_lo, scene_hi));
        tables.extend_from_slice(lights.selection.cdf());

        // Textures: the material textures, then the cube map's six faces.
        let mut images: Vec<&Image> = parts.textures.iter().collect();
        let cube_first_texture = images.len() as u32;
        let background_kind = match &parts.background {
            Background::Color(_) => 0,
            Background::CubeMap(map) => {
                images.extend(map.faces.iter());
                1
            }
            // Refused by `check_supported`.
            Background::Environment { .. } => 0,
        };
        let texture_info = tables.len() as u32;
        for image in &images {
            let usable = image.texels.len() >= (image.width as usize * image.height as usize);
            tables.push(bits(texels.len() as u32));
            if usable {
                tables.push(bits(image.width));
                tables.push(bits(image.height));
                texels.extend(
                    image.texels[..(image.width * image.height) as usize]
                        .iter()
                        .map(|c| v4(*c, 0.0)),
                );
            } else {
                tables.push(bits(0));
                tables.push(bits(0));
            }
        }
        let (row_cdf, column_cdf, column_start, first_row) = match &lights.cube {
            Some(cube) => {
                let row_cdf = tables.len() as u32;
                tables.extend_from_slice(cube.row_cdf());
                let column_cdf = tables.len() as u32;
                tables.extend_from_slice(cube.column_cdf());
                let column_start = tables.len() as u32;
                tables.extend(cube.column_start().iter().map(|&s| bits(s)));
                let first_row = tables.len() as u32;
                tables.extend(cube.first_row().iter().map(|&s| bits(s)));
                (row_cdf, column_cdf, column_start, first_row)
            }
            // No distribution: a dummy first_row of zeros keeps every read in bounds.
            None => {
                let first_row = tables.len() as u32;
                tables.extend([0.0; 8]);
                (first_row, first_row, first_row, first_row)
            }
        };

        let camera: &Camera = &parts.camera;
        let background = match &parts.background {
            Background::Color(c) => v4(*c, 0.0),
            Background::CubeMap(_) | Background::Environment { .. } => [0.0; 4],
        };
        let params = Params {
            width: 0,
            height: 0,
            first_sample: 0,
            samples: 0,
            seed_lo: 0,
            seed_hi: 0,
            max_depth: 0,
            rr_depth: 5,
            light_count: lights.count,
            environment_light: lights.environment.unwrap_or(NONE),
            material_count: (materials.len() / MATERIAL_STRIDE) as u32,
            light_triangles: lights.triangles_offset,
            background_kind,
            cube_first_texture,
            texture_info,
            row_cdf,
            column_cdf,
            column_start,
            first_row,
            instances: instances_offset,
            projection: match camera.projection {
                Projection::Perspective => 0,
                Projection::Orthographic => 1,
            },
            x0: 0,
            y0: 0,
            crop_width: 0,
            crop_height: 0,
            canary: 2,
            tlas_root: tlas_root as u32,
            pad: 0,
            bsdf_index: physical.bsdf_index,
            texture_nodes: physical.texture_nodes,
            bsdf_count: physical.bsdf_count,
            render_flags: 0,
            filter_kind: 0,
            filter_param: 0,
            pad2: [0; 2],
            camera_position: v4(camera.position, 0.0),
            camera_u: v4(camera.basis.u, camera.focal_length),
            camera_v: v4(camera.basis.v, camera.image_plane_width),
            camera_w: v4(camera.basis.w, 1.0),
            background,
            lens: [0.0; 4],
        };
        FlatScene {
            nodes,
            prims,
            materials,
            lights: lights.words,
            tables,
            texels,
            physical: physical.words,
            params,
        }
    }
}

/// One shape in its geometry's object space, with `material` (the instance may override it)
/// and `extra`: a triangle's attribute record, a sphere's flags.
fn primitive(shape: &Shape, material: u32, extra: u32) -> Primitive {
    let material = bits(material);
    match *shape {
        Shape::Triangle { vertices } => {
            let normal = (vertices[1] - vertices[0])
                .cross(vertices[2] - vertices[0])
                .normalized();
            Primitive {
                words: [
                    v4(vertices[0], bits(PRIM_TRIANGLE)),
                    v4(vertices[1], material),
                    v4(vertices[2], bits(extra)),
                    v4(normal, 0.0),
                ],
                bounds: shape_bounds(shape),
            }
        }
        Shape::Sphere { center, radius } => Primitive {
            words: [
                v4(center, bits(PRIM_SPHERE)),
                [radius, 0.0, 0.0, material],
                [bits(extra), 0.0, 0.0, 0.0],
                [0.0; 4],
            ],
            bounds: shape_bounds(shape),
        },
        Shape::Box { min, max } => Primitive {
            words: [
                v4(min, bits(PRIM_BOX)),
                v4(max, material),
                [0.0; 4],
                [0.0; 4],
            ],
            bounds: shape_bounds(shape),
        },
    }
}

/// Moves a BVH built on its own (`build_bvh`) to node `node_base` of the nodes buffer, its
/// leaves to items from `item_base`.
fn relocate(nodes: &mut [[f32; 4]], node_base: usize, item_base: usize) {
    for pair in nodes.chunks_exact_mut(2) {
        let offset = pair[0][3].to_bits() as usize;
        let base = if pair[1][3].to_bits() == 0 {
            node_base
        } else {
            item_base
        };
        pair[0][3] = bits((offset + base) as u32);
    }
}

fn placed_bounds(transform: Option<&Transform>, bounds: (Vec3, Vec3)) -> (Vec3, Vec3) {
    match transform {
        Some(t) => transformed_bounds(t, bounds),
        None => bounds,
    }
}

fn color_words(source: &ColorSource, textures: usize) -> [f32; 4] {
    let texture = source
        .texture
        .filter(|&t| (t as usize) < textures)
        .unwrap_or(NONE);
    v4(source.color, bits(texture))
}

/// One material's six vec4s: the BSDF of `plain` (an emitter's surface material, or the
/// material itself), the emitter, and the dielectric attenuation of `material`.
fn material_words(parts: &SceneParts, material: &Material) -> [[f32; 4]; MATERIAL_STRIDE] {
    let textures = parts.textures.len();
    let constant = |c: Color| color_words(&ColorSource::constant(c), textures);
    let mut words = [[0.0f32; 4]; MATERIAL_STRIDE];
    words[0] = constant(Color::ZERO);
    words[1] = constant(Color::ZERO);
    let (emitter, light, unsampled, plain) = match material {
        Material::Emissive {
            radiance,
            surface,
            light,
        } => {
            let plain = surface
                .and_then(|s| parts.materials.get(s as usize))
                .filter(|m| !matches!(m, Material::Emissive { .. }));
            match light.filter(|&l| (l as usize) < parts.lights.len()) {
                Some(l) => (EMITTER_LIGHT, l, Color::ZERO, plain),
                None => (EMITTER_UNSAMPLED, 0, *radiance, plain),
            }
        }
        other => (EMITTER_NONE, 0, Color::ZERO, Some(other)),
    };
    // [kind, exponent, km, roughness] and η.
    let (kind, exponent, km, roughness, eta) = match plain {
        Some(Material::Physical(tree)) => (BSDF_PHYSICAL, bits(*tree), 0.0, 0.0, 1.0),
        None | Some(Material::Emissive { .. }) => (BSDF_BLACK, 0.0, 0.0, 0.0, 1.0),
        Some(
            Material::Lambertian { diffuse }
            | Material::Diffuse { diffuse }
            | Material::CoolToWarm { diffuse },
        ) => {
            words[0] = color_words(diffuse, textures);
            (BSDF_DIFFUSE, 0.0, 0.0, 0.0, 1.0)
        }
        Some(Material::BlinnPhong {
            diffuse,
            specular,
            phong_exponent,
            mirror_coef,
        }) => {
            words[0] = color_words(diffuse, textures);
            words[1] = color_words(specular, textures);
            (BSDF_BLINN_PHONG, *phong_exponent, *mirror_coef, 0.0, 1.0)
        }
        Some(Material::Phong {
            diffuse,
            specular,
            phong_exponent,
        }) => {
            words[0] = color_words(diffuse, textures);
            words[1] = color_words(specular, textures);
            (BSDF_PHONG, *phong_exponent, 0.0, 0.0, 1.0)
        }
        Some(Material::Mirror { roughness }) => (BSDF_MIRROR, 0.0, 0.0, *roughness, 1.0),
        Some(Material::Glaze {
            diffuse,
            mirror_coef,
        }) => {
            words[0] = color_words(diffuse, textures);
            (BSDF_GLAZE, 0.0, *mirror_coef, 0.0, 1.0)
        }
        Some(Material::BlinnPhongMirrored {
            diffuse,
            specular,
            phong_exponent,
            mirror_coef,
            roughness,
        }) => {
            words[0] = color_words(diffuse, textures);
            words[1] = color_words(specular, textures);
            (
                BSDF_BLINN_PHONG_MIRRORED,
                *phong_exponent,
                *mirror_coef,
                *roughness,
                1.0,
            )
        }
        Some(Material::Dielectric {
            refractive_index, ..
        }) => (BSDF_DIELECTRIC, 0.0, 0.0, 0.0, *refractive_index),
    };
    let attenuation = match material {
        Material::Dielectric { attenuation, .. } => Some(*attenuation),
        _ => None,
    };
    words[2] = [bits(kind), exponent, km, roughness];
    words[3] = [
        eta,
        bits(emitter),
        bits(light),
        if attenuation.is_some() { 1.0 } else { 0.0 },
    ];
    words[4] = v4(attenuation.unwrap_or(Color::ONE), 0.0);
    words[5] = v4(unsampled, 0.0);
    words
}

/// The scene's materials, then the fallback material for ids out of range.
fn flatten_materials(parts: &SceneParts) -> Vec<[f32; 4]> {
    parts
        .materials
        .iter()
        .chain(std::iter::once(&Material::fallback()))
        .flat_map(|m| material_words(parts, m))
        .collect()
}

/// The light sampler's tables (glint-render's `light::sampler::LightSampler::new`: the same
/// light selection and cube-map distribution, the same triangle area shares).
struct LightTables {
    words: Vec<[f32; 4]>,
    count: u32,
    environment: Option<u32>,
    triangles_offset: u32,
    selection: LightSelection,
    cube: Option<CubeDistribution>,
}

fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

impl LightTables {
    fn new(parts: &SceneParts, (scene_lo, scene_hi): (Vec3, Vec3)) -> LightTables {
        let mut reachable = vec![false; parts.lights.len()];
        for material in &parts.materials {
            if let Material::Emissive {
                light: Some(index), ..
            } = material
            {
                if let Some(flag) = reachable.get_mut(*index as usize) {
                    *flag = true;
                }
            }
        }
        let mut words = Vec::new();
        let mut triangles: Vec<[f32; 4]> = Vec::new();
        let mut power = Vec::new();
        for (index, light) in parts.lights.iter().enumerate() {
            let mut w = [[0.0f32; 4]; LIGHT_STRIDE];
            let reachable = if reachable[index] { 1.0 } else { 0.0 };
            // The total area of emitting triangles, summed with their table.
            let mut triangles_area = 0.0f64;
            match light {
                Light::Point {
                    position,
                    intensity,
                } => {
                    w[0] = [bits(LIGHT_POINT), 0.0, 0.0, 0.0];
                    w[1] = v4(*position, 0.0);
                    w[5] = v4(*intensity, 0.0);
                }
                Light::Area {
                    position,
                    normal,
                    width,
                    length,
                    intensity,
                } => {
                    let (u_edge, v_edge) = Light::area_edges(*normal, *width, *length);
                    let area = u_edge.cross(v_edge).length();
                    w[0] = [bits(LIGHT_RECTANGLE), 0.0, 0.0, reachable];
                    w[1] = v4(*position, area);
                    w[2] = v4(u_edge, 1.0 / area);
                    w[3] = v4(v_edge, 0.0);
                    w[4] = v4(normal.normalized(), 0.0);
                    w[5] = v4(*intensity, 0.0);
                }
                Light::Sphere {
                    center,
                    radius,
                    intensity,
                } => {
                    let radius = radius.abs();
                    w[0] = [bits(LIGHT_SPHERE), 0.0, 0.0, reachable];
                    w[1] = v4(*center, radius);
                    w[5] = v4(*intensity, 0.0);
                }
                Light::Triangles {
                    triangles: list,
                    intensity,
                } => {
                    let first = triangles.len() / LIGHT_TRIANGLE_STRIDE;
                    let mut total = 0.0f64;
                    let mut cumulative = Vec::with_capacity(list.len());
                    for &[v0, v1, v2] in list {
                        let cross = (v1 - v0).cross(v2 - v0);
                        total += 0.5 * cross.length() as f64;
                        cumulative.push(total);
                        triangles.push(v4(v0, 0.0));
                        triangles.push(v4(v1 - v0, 0.0));
                        triangles.push(v4(v2 - v0, 0.0));
                        triangles.push(v4(cross.normalized(), 0.0));
                    }
                    for (i, c) in cumulative.iter().enumerate() {
                        let share = if i + 1 == list.len() {
                            1.0
                        } else if total > 0.0 {
                            (c / total) as f32
                        } else {
                            0.0
                        };
                        triangles[(first + i) * LIGHT_TRIANGLE_STRIDE][3] = share;
                    }
                    w[0] = [
                        bits(LIGHT_TRIANGLES),
                        bits(first as u32),
                        bits(list.len() as u32),
                        reachable,
                    ];
                    w[1] = [0.0, 0.0, 0.0, total as f32];
                    w[2] = [0.0, 0.0, 0.0, 1.0 / total as f32];
                    w[5] = v4(*intensity, 0.0);
                    triangles_area = total;
                }
                // Refused by `check_supported`: they stay zero words, which emit nothing.
                Light::Spot { .. }
                | Light::Directional { .. }
                | Light::Projector { .. }
                | Light::TexturedTriangles { .. } => {}
            }
            words.extend_from_slice(&w);
            power.push(LightSelection::power(light, triangles_area));
        }
        let (environment_integral, cube) = match &parts.background {
            Background::Color(c) => {
                let integral = 4.0 * PI * mean(c.max(Color::ZERO));
                ((integral > 0.0 && c.is_finite()).then_some(integral), None)
            }
            Background::CubeMap(map) => match CubeDistribution::new(map) {
                Some((cube, integral)) => (Some(integral), Some(cube)),
                None => (None, None),
            },
            Background::Environment { .. } => (None, None),
        };
        let mut environment = None;
        if let Some(integral) = environment_integral {
            // The scene's bounding radius, for the environment's power.
            let radius = if scene_lo.x <= scene_hi.x {
                0.5 * (scene_hi - scene_lo).length()
            } else {
                1.0
            };
            environment = Some(power.len() as u32);
            let mut w = [[0.0f32; 4]; LIGHT_STRIDE];
            w[0] = [bits(LIGHT_ENVIRONMENT), 0.0, 0.0, 1.0];
            words.extend_from_slice(&w);
            power.push(LightSelection::environment_power(radius, integral));
        }
        let count = power.len() as u32;
        let triangles_offset = words.len() as u32;
        words.extend_from_slice(&triangles);
        LightTables {
            words,
            count,
            environment,
            triangles_offset,
            selection: LightSelection::new(&power),
            cube,
        }
    }
}

/// A binary BVH over the primitives' bounds, binned SAH (pbrt-v4's `BVHAggregate` with
/// buckets), flattened depth first: node i's first child is i + 1, its second child's index
/// is stored in place of a leaf's first primitive. Returns the nodes (two vec4 each:
/// [min, first primitive | second child], [max, primitive count (0 for interior nodes)]) and
/// the primitive order the leaves index.
fn build_bvh(primitives: &[(Vec3, Vec3)]) -> (Vec<[f32; 4]>, Vec<usize>) {
    let mut order: Vec<usize> = (0..primitives.len()).collect();
    let centroids: Vec<Vec3> = primitives
        .iter()
        .map(|p| {
            let c = (p.0 + p.1) * 0.5;
            if c.is_finite() {
                c
            } else {
                Vec3::ZERO
            }
        })
        .collect();
    let mut nodes = Vec::new();
    if primitives.is_empty() {
        // One empty leaf whose box no ray enters.
        nodes.push([f32::MAX, f32::MAX, f32::MAX, bits(0)]);
        nodes.push([-f32::MAX, -f32::MAX, -f32::MAX, bits(0)]);
        return (nodes, order);
    }
    build_node(primitives, &centroids, &mut order, 0, 0, &mut nodes);
    (nodes, order)
}

fn surface_area(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

fn build_node(
    primitives: &[(Vec3, Vec3)],
    centroids: &[Vec3],
    order: &mut [usize],
    first: usize,
    depth: u32,
    nodes: &mut Vec<[f32; 4]>,
) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut centroid_lo = Vec3::splat(f32::INFINITY);
    let mut centroid_hi = Vec3::splat(f32::NEG_INFINITY);
    for &p in order.iter() {
        lo = lo.min(primitives[p].0);
        hi = hi.max(primitives[p].1);
        centroid_lo = centroid_lo.min(centroids[p]);
        centroid_hi = centroid_hi.max(centroids[p]);
    }
    // Non-finite bounds (a degenerate primitive) must not prune: make the box all of space.
    if !lo.is_finite() || !hi.is_finite() {
        lo = Vec3::splat(-f32::MAX);
        hi = Vec3::splat(f32::MAX);
    }
    let here = nodes.len();
    nodes.push(v4(lo, bits(first as u32)));
    nodes.push(v4(hi, bits(order.len() as u32)));
    let count = order.len();
    let extent = centroid_hi - centroid_lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let spread = extent[axis];
    if count <= MAX_LEAF || depth >= MAX_DEPTH || spread.is_nan() || spread <= 0.0 {
        return;
    }
    // Binned SAH along the widest centroid axis.
    let bin_of = |p: usize| -> usize {
        let f = (centroids[p][axis] - centroid_lo[axis]) / extent[axis];
        ((f * BINS as f32) as usize).min(BINS - 1)
    };
    let mut bin_count = [0usize; BINS];
    let mut bin_lo = [Vec3::splat(f32::INFINITY); BINS];
    let mut bin_hi = [Vec3::splat(f32::NEG_INFINITY); BINS];
    for &p in order.iter() {
        let b = bin_of(p);
        bin_count[b] += 1;
        bin_lo[b] = bin_lo[b].min(primitives[p].0);
        bin_hi[b] = bin_hi[b].max(primitives[p].1);
    }
    let mut best = (f32::INFINITY, BINS / 2);
    for split in 1..BINS {
        let (mut l_lo, mut l_hi, mut l_n) = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0,
        );
        let (mut r_lo, mut r_hi, mut r_n) = (
            Vec3::splat(f32::INFINITY),
            Vec3::splat(f32::NEG_INFINITY),
            0,
        );
        for b in 0..BINS {
            if bin_count[b] == 0 {
                continue;
            }
            if b < split {
                l_lo = l_lo.min(bin_lo[b]);
                l_hi = l_hi.max(bin_hi[b]);
                l_n += bin_count[b];
            } else {
                r_lo = r_lo.min(bin_lo[b]);
                r_hi = r_hi.max(bin_hi[b]);
                r_n += bin_count[b];
            }
        }
        if l_n == 0 || r_n == 0 {
            continue;
        }
        let cost = surface_area(l_lo, l_hi) * l_n as f32 + surface_area(r_lo, r_hi) * r_n as f32;
        if cost < best.0 {
            best = (cost, split);
        }
    }
    let split = best.1;
    // Partition in place: primitives in bins below `split` first.
    let mut left = 0;
    for i in 0..count {
        if bin_of(order[i]) < split {
            order.swap(i, left);
            left += 1;
        }
    }
    if left == 0 || left == count {
        left = count / 2;
    }
    // An interior node: count 0; the second child's index goes where a leaf's first
    // primitive would be.
    nodes[here + 1][3] = bits(0);
    let (left_order, right_order) = order.split_at_mut(left);
    build_node(primitives, centroids, left_order, first, depth + 1, nodes);
    let second = nodes.len() / 2;
    nodes[here][3] = bits(second as u32);
    build_node(
        primitives,
        centroids,
        right_order,
        first + left,
        depth + 1,
        nodes,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_render::{GeometryDesc, Instance, Matrix4, Projection};

    fn unbits(value: f32) -> u32 {
        value.to_bits()
    }

    /// Pseudo-random numbers in [0, 1) for test scenes.
    fn uniform(state: &mut u32) -> f32 {
        *state = state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        (*state >> 8) as f32 / (1u32 << 24) as f32
    }

    fn scene(triangles: usize) -> SceneParts {
        let mut state = 7;
        let mut point = || {
            Vec3::new(
                uniform(&mut state) * 10.0,
                uniform(&mut state) * 10.0,
                uniform(&mut state) * 10.0,
            )
        };
        let mut shapes: Vec<Shape> = (0..triangles)
            .map(|_| {
                let a = point();
                Shape::Triangle {
                    vertices: [a, a + point() * 0.05, a + point() * 0.05],
                }
            })
            .collect();
        shapes.push(Shape::Sphere {
            center: Vec3::splat(5.0),
            radius: 0.5,
        });
        let count = shapes.len();
        SceneParts {
            physical: Default::default(),
            camera: Camera::new(Projection::Perspective, Vec3::ZERO, -Vec3::Z, 1.0, 1.0),
            materials: vec![],
            textures: vec![],
            lights: vec![
                Light::Triangles {
                    triangles: vec![
                        [Vec3::ZERO, Vec3::X, Vec3::Y],
                        [Vec3::ZERO, Vec3::X * 2.0, Vec3::Y],
                    ],
                    intensity: Color::ONE,
                },
                Light::Point {
                    position: Vec3::ONE,
                    intensity: Color::ONE,
                },
            ],
            background: Background::Color(Color::ZERO),
            geometries: vec![
                GeometryDesc {
                    shapes,
                    materials: vec![0; count],
                },
                GeometryDesc {
                    shapes: vec![Shape::Box {
                        min: Vec3::ZERO,
                        max: Vec3::ONE,
                    }],
                    materials: vec![0],
                },
            ],
            instances: vec![
                Instance {
                    geometry: 0,
                    transform: None,
                    material: None,
                    casts_shadow: true,
                },
                Instance {
                    geometry: 1,
                    transform: Transform::from_matrix(&Matrix4::translate(Vec3::splat(20.0))),
                    material: Some(3),
                    casts_shadow: false,
                },
            ],
        }
    }

    /// Walks the BVH from `root`: every node inside its parent, triangles inside their
    /// leaf's box, depth within the kernel's stack. Returns the leaves' item ranges.
    fn walk(flat: &FlatScene, root: usize, triangles: bool) -> Vec<(usize, usize)> {
        let node = |i: usize| (flat.nodes[2 * i], flat.nodes[2 * i + 1]);
        let mut leaves = Vec::new();
        // (node, parent box, depth)
        let mut stack = vec![(root, None::<([f32; 4], [f32; 4])>, 0u32)];
        while let Some((index, parent, depth)) = stack.pop() {
            assert!(depth < 64, "depth {depth} overflows the kernel's stack");
            let (lo, hi) = node(index);
            if let Some((plo, phi)) = parent {
                for a in 0..3 {
                    assert!(
                        lo[a] >= plo[a] && hi[a] <= phi[a],
                        "node {index} leaves its parent"
                    );
                }
            }
            let count = unbits(hi[3]) as usize;
            let offset = unbits(lo[3]) as usize;
            if count == 0 {
                stack.push((index + 1, Some((lo, hi)), depth + 1));
                stack.push((offset, Some((lo, hi)), depth + 1));
                continue;
            }
            leaves.push((offset, count));
            if triangles {
                for primitive in offset..offset + count {
                    let words = &flat.prims[primitive * PRIM_STRIDE..][..PRIM_STRIDE];
                    if unbits(words[0][3]) == PRIM_TRIANGLE {
                        for vertex in &words[..3] {
                            for a in 0..3 {
                                assert!(vertex[a] >= lo[a] && vertex[a] <= hi[a]);
                            }
                        }
                    }
                }
            }
        }
        leaves
    }

    /// Each item index in `leaves` exactly once, and together exactly `0..count` from `first`.
    fn assert_covers(leaves: &[(usize, usize)], first: usize, count: usize) {
        let mut seen = vec![0u32; count];
        for &(offset, n) in leaves {
            for item in offset..offset + n {
                seen[item - first] += 1;
            }
        }
        assert!(
            seen.iter().all(|&n| n == 1),
            "an item is missing or repeated"
        );
    }

    /// The two levels: the top covers every instance once, each instance's geometry every
    /// one of its primitives once; the instances carry their transform, material override and
    /// shadow flag.
    #[test]
    fn both_bvh_levels_cover_everything_once_within_bounds() {
        let flat = FlatScene::new(&scene(2000));
        let instances = flat.params.instances as usize;
        assert_eq!(
            instances / PRIM_STRIDE,
            2002,
            "the instances follow the primitives"
        );
        let top = walk(&flat, flat.params.tlas_root as usize, false);
        assert_covers(&top, 0, 2);
        let record = |i: usize| &flat.prims[instances + i * INSTANCE_STRIDE..][..INSTANCE_STRIDE];
        let (plain, boxed) = if unbits(record(0)[3][2]) & FLAG_TRANSFORMED == 0 {
            (record(0), record(1))
        } else {
            (record(1), record(0))
        };
        assert_covers(&walk(&flat, unbits(plain[3][0]) as usize, true), 0, 2001);
        assert_covers(&walk(&flat, unbits(boxed[3][0]) as usize, true), 2001, 1);
        assert_eq!(unbits(plain[3][1]), NONE);
        assert_eq!(unbits(plain[3][2]), FLAG_CASTS_SHADOW);
        assert_eq!(unbits(boxed[3][1]), 3);
        assert_eq!(unbits(boxed[3][2]), FLAG_TRANSFORMED);
        // object_from_world of a translation by 20: the last column is -20.
        assert_eq!(boxed[0][3], -20.0);
        assert_eq!(unbits(flat.prims[2001 * PRIM_STRIDE][3]), PRIM_BOX);
    }

    /// The light tables: selection by power (π·area·L for the triangles, 4π·I for the point
    /// light), the triangles' area CDF, and no environment for a black background.
    #[test]
    fn light_tables_follow_power_and_area() {
        let flat = FlatScene::new(&scene(1));
        assert_eq!(flat.params.light_count, 2);
        assert_eq!(flat.params.environment_light, NONE);
        let triangles_power = PI * 1.5;
        let point_power = 4.0 * PI;
        let cdf = &flat.tables[..3];
        assert_eq!(cdf[0], 0.0);
        assert!((cdf[1] - triangles_power / (triangles_power + point_power)).abs() < 1e-6);
        assert_eq!(cdf[2], 1.0);
        let first = flat.params.light_triangles as usize;
        // Areas 0.5 and 1: the first triangle holds a third of the light.
        assert!((flat.lights[first][3] - 1.0 / 3.0).abs() < 1e-6);
        assert_eq!(flat.lights[first + LIGHT_TRIANGLE_STRIDE][3], 1.0);
        // Its 1/area for the pdf.
        assert!((flat.lights[2][3] - 1.0 / 1.5).abs() < 1e-6);
    }
}
