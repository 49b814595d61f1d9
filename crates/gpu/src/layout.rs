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
    Background, Camera, Color, ColorSource, CubeDistribution, FilterSampler, Image,
    LatLongDistribution, Light, LightSelection, Material, PixelFilter, Projection, SceneParts,
    Shape, Transform, Vec3,
};

pub use crate::words::{bits, NONE};

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
/// Mitsuba's `spot`: [kind, texture node | NONE, 0, 0], [position, cos cutoff],
/// [object_from_world row 0, cos beam], [row 1, cutoff], [row 2, 1 / (cutoff − beam)],
/// [intensity, tan cutoff].
pub const LIGHT_SPOT: u32 = 5;
/// Mitsuba's `directional`: [kind, ..], [direction the light travels (unit), 0], ..,
/// [irradiance].
pub const LIGHT_DIRECTIONAL: u32 = 6;
/// Mitsuba's `projector`: [kind, texture node, aspect, 0], [position, scale],
/// [object_from_world row 0], [row 1], [row 2] (with translations), [axis, cot(fov / 2)].
pub const LIGHT_PROJECTOR: u32 = 7;
/// vec4s per light: [kind, first triangle, triangle count, reachable by BSDF sampling],
/// [position | centre, area | radius], [u edge, 1/area], [v edge], [normal], [radiance];
/// textured triangles: [texture node, first uv entry in `tables`, 0, 0] in place of the
/// normal (6 floats per triangle there: the corners' uvs).
pub const LIGHT_STRIDE: usize = 6;
/// vec4s per emitting triangle, after the lights: [v0, cumulative area share], [edge1],
/// [edge2], [unit normal].
pub const LIGHT_TRIANGLE_STRIDE: usize = 4;

/// `Params::background_kind`: a colour, a cube map, Mitsuba's latitude-longitude `envmap`.
pub const BACKGROUND_COLOR: u32 = 0;
pub const BACKGROUND_CUBE: u32 = 1;
pub const BACKGROUND_LATLONG: u32 = 2;
/// Floats of the envmap's block in `tables` (at `Params::first_row`): object_from_world
/// (3x3, rows), world_from_object (3x3, rows), scale, cells across, cells down (bits).
pub const LATLONG_INFO: usize = 21;

/// `Params::render_flags`: camera rays pass through emitters and see no environment.
pub const RENDER_HIDE_EMITTERS: u32 = 1;
/// `Params::filter_kind`: box, tent, gaussian (the CPU's `PixelFilter`).
pub const FILTER_BOX: u32 = 0;
pub const FILTER_TENT: u32 = 1;
pub const FILTER_GAUSSIAN: u32 = 2;
/// Bins of the filter's table (`FilterSampler::BINS`).
pub const FILTER_BINS: u32 = FilterSampler::BINS as u32;

/// BVH leaves hold at most this many primitives (unless the depth limit forces more).
const MAX_LEAF: usize = 4;
/// Beyond this depth a node becomes a leaf whatever its size: the kernel's traversal stack
/// holds 64 entries, and a deeper tree could overflow it.
const MAX_DEPTH: u32 = 48;
const BINS: usize = 12;

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
    /// `FILTER_*`, and its radius in pixels (f32 bits: the table's half-width).
    pub filter_kind: u32,
    pub filter_param: u32,
    /// Where the filter's cumulative table (`FILTER_BINS` + 1 entries) starts in `tables`.
    pub filter_table: u32,
    pub pad2: [u32; 1],
    pub camera_position: [f32; 4],
    pub camera_u: [f32; 4],
    pub camera_v: [f32; 4],
    pub camera_w: [f32; 4],
    pub background: [f32; 4],
    /// The thin lens: aperture radius, focus distance (zero: a pinhole); the clipping
    /// planes: near, far (zero: none).
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

/// `Params::render_flags`: the texels are packed as halves (`FlatScene::pack_texels_half`).
pub const RENDER_TEXELS_HALF: u32 = 2;

impl FlatScene {
    /// Packs the texels two to a vec4, each RGB as three IEEE halves (rounded to nearest), when
    /// one vec4 a texel would take more than `max_bytes`: large images then still fit the
    /// adapter's storage-binding limit (lavapipe's is 128 MiB, four 2048² images), at a
    /// relative precision of 2^-11 and a largest value of 65504. The flag tells the kernel.
    pub fn pack_texels_half(&mut self, max_bytes: u64) {
        if (self.texels.len() as u64) * 16 <= max_bytes {
            return;
        }
        let pack = |a: f32, b: f32| {
            let (a, b) = (half::f16::from_f32(a), half::f16::from_f32(b));
            f32::from_bits(u32::from(a.to_bits()) | (u32::from(b.to_bits()) << 16))
        };
        self.texels = self
            .texels
            .chunks(2)
            .map(|pair| {
                let t0 = pair[0];
                let t1 = pair.get(1).copied().unwrap_or([0.0; 4]);
                [
                    pack(t0[0], t0[1]),
                    pack(t0[2], 0.0),
                    pack(t1[0], t1[1]),
                    pack(t1[2], 0.0),
                ]
            })
            .collect();
        self.params.render_flags |= RENDER_TEXELS_HALF;
    }
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
        let triangle_uvs = tables.len() as u32;
        tables.extend_from_slice(&lights.triangle_uvs);
        let mut light_words = lights.words;
        for &(record, first) in &lights.textured {
            light_words[record + 4][1] = bits(triangle_uvs + first);
        }

        // Textures: the material textures, then the cube map's six faces.
        let mut images: Vec<&Image> = parts.textures.iter().collect();
        let cube_first_texture = images.len() as u32;
        let background_kind = match &parts.background {
            Background::Color(_) => BACKGROUND_COLOR,
            Background::CubeMap(map) => {
                images.extend(map.faces.iter());
                BACKGROUND_CUBE
            }
            // The lat-long image is texture `cube_first_texture`.
            Background::Environment { image, .. } => {
                images.push(image);
                BACKGROUND_LATLONG
            }
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
        let (row_cdf, column_cdf, column_start, first_row) = match (&lights.cube, &parts.background)
        {
            (
                _,
                Background::Environment {
                    scale, to_world, ..
                },
            ) => {
                let first_row = tables.len() as u32;
                for matrix in [&to_world.object_from_world, &to_world.world_from_object] {
                    for row in matrix {
                        tables.extend_from_slice(&row[..3]);
                    }
                }
                tables.push(*scale);
                debug_assert_eq!(tables.len() - first_row as usize, LATLONG_INFO - 2);
                let (row_cdf, column_cdf) = match &lights.latlong {
                    Some(latlong) => {
                        let (columns, rows) = latlong.cells();
                        tables.extend([bits(columns), bits(rows)]);
                        let row_cdf = tables.len() as u32;
                        tables.extend_from_slice(latlong.row_cdf());
                        let column_cdf = tables.len() as u32;
                        tables.extend_from_slice(latlong.column_cdf());
                        (row_cdf, column_cdf)
                    }
                    // No distribution (a black map): lookups only.
                    None => {
                        tables.extend([bits(0), bits(0)]);
                        (first_row, first_row)
                    }
                };
                (row_cdf, column_cdf, first_row, first_row)
            }
            (Some(cube), _) => {
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
            (None, _) => {
                let first_row = tables.len() as u32;
                tables.extend([0.0; 8]);
                (first_row, first_row, first_row, first_row)
            }
        };

        // The reconstruction filter's table (`FilterSampler`, the CPU's own).
        let defaults = &parts.physical.defaults;
        let filter = FilterSampler::new(defaults.filter);
        let filter_table = tables.len() as u32;
        debug_assert!(filter.cdf().is_empty() || filter.cdf().len() == FILTER_BINS as usize + 1);
        tables.extend_from_slice(filter.cdf());
        let filter_kind = match defaults.filter {
            PixelFilter::Box => FILTER_BOX,
            PixelFilter::Tent { .. } => FILTER_TENT,
            PixelFilter::Gaussian { .. } => FILTER_GAUSSIAN,
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
            // `PathSettings::for_scene`: the scene's `rr_depth`, else 5.
            rr_depth: defaults.russian_roulette_depth.unwrap_or(5),
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
            render_flags: if defaults.hide_emitters {
                RENDER_HIDE_EMITTERS
            } else {
                0
            },
            filter_kind,
            filter_param: filter.radius().to_bits(),
            filter_table,
            pad2: [0; 1],
            camera_position: v4(camera.position, 0.0),
            camera_u: v4(camera.basis.u, camera.focal_length),
            camera_v: v4(camera.basis.v, camera.image_plane_width),
            camera_w: v4(camera.basis.w, 1.0),
            background,
            lens: {
                let (radius, focus) = camera
                    .lens
                    .map_or((0.0, 0.0), |l| (l.radius, l.focus_distance));
                let (near, far) = camera.clip.unwrap_or((0.0, 0.0));
                [radius, focus, near, far]
            },
        };
        FlatScene {
            nodes,
            prims,
            materials,
            lights: light_words,
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
    latlong: Option<LatLongDistribution>,
    /// The corner uvs of textured emitting triangles, six floats a triangle.
    triangle_uvs: Vec<f32>,
    /// Per textured light: the index of its first word in `words`, and where its uvs start
    /// in `triangle_uvs` (the caller adds where that goes in `tables`).
    textured: Vec<(usize, u32)>,
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
        let mut triangle_uvs = Vec::new();
        let mut textured = Vec::new();
        let mut power = Vec::new();
        // The scene's bounding radius, for the power of the lights at infinity.
        let radius = if scene_lo.x <= scene_hi.x {
            0.5 * (scene_hi - scene_lo).length()
        } else {
            1.0
        };
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
                }
                | Light::TexturedTriangles {
                    triangles: list,
                    intensity,
                    ..
                } => {
                    w[4] = [bits(NONE), 0.0, 0.0, 0.0];
                    if let Light::TexturedTriangles { uvs, texture, .. } = light {
                        textured.push((words.len(), triangle_uvs.len() as u32));
                        w[4] = [bits(*texture), 0.0, 0.0, 0.0];
                        for i in 0..list.len() {
                            let corners = uvs.get(i).copied().unwrap_or_default();
                            for (u, v) in corners {
                                triangle_uvs.extend([u, v]);
                            }
                        }
                    }
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
                Light::Spot {
                    to_world,
                    intensity,
                    cutoff_angle,
                    beam_width,
                    texture,
                } => {
                    let cutoff = cutoff_angle.to_radians();
                    let beam = beam_width.to_radians();
                    let rows = &to_world.object_from_world;
                    w[0] = [bits(LIGHT_SPOT), bits(texture.unwrap_or(NONE)), 0.0, 0.0];
                    w[1] = v4(to_world.point_to_world(Vec3::ZERO), cutoff.cos());
                    w[2] = [rows[0][0], rows[0][1], rows[0][2], beam.cos()];
                    w[3] = [rows[1][0], rows[1][1], rows[1][2], cutoff];
                    w[4] = [rows[2][0], rows[2][1], rows[2][2], 1.0 / (cutoff - beam)];
                    w[5] = v4(*intensity, cutoff.tan());
                }
                Light::Directional {
                    direction,
                    irradiance,
                } => {
                    w[0] = [bits(LIGHT_DIRECTIONAL), 0.0, 0.0, 0.0];
                    w[1] = v4(direction.normalized(), 0.0);
                    w[5] = v4(*irradiance, 0.0);
                }
                Light::Projector {
                    to_world,
                    irradiance,
                    scale,
                    fov,
                } => {
                    let rows = &to_world.object_from_world;
                    w[0] = [
                        bits(LIGHT_PROJECTOR),
                        bits(*irradiance),
                        glint_render::texture_aspect(
                            &parts.physical.textures,
                            &parts.textures,
                            *irradiance,
                        ),
                        0.0,
                    ];
                    w[1] = v4(to_world.point_to_world(Vec3::ZERO), *scale);
                    w[2] = rows[0];
                    w[3] = rows[1];
                    w[4] = rows[2];
                    w[5] = v4(
                        to_world.vector_to_world(Vec3::Z),
                        1.0 / (0.5 * fov.to_radians()).tan(),
                    );
                }
            }
            words.extend_from_slice(&w);
            // The power as `LightSampler::new` weighs each light.
            power.push(match light {
                Light::Directional { irradiance, .. } => {
                    LightSelection::environment_power(radius, mean(*irradiance))
                }
                Light::Projector {
                    irradiance,
                    scale,
                    fov,
                    ..
                } => LightSelection::projector_power(
                    *fov,
                    glint_render::texture_aspect(
                        &parts.physical.textures,
                        &parts.textures,
                        *irradiance,
                    ),
                    *scale
                        * glint_render::texture_mean(
                            &parts.physical.textures,
                            &parts.textures,
                            *irradiance,
                        ),
                ),
                Light::TexturedTriangles { texture, .. } => {
                    LightSelection::power(light, triangles_area)
                        * glint_render::texture_mean(
                            &parts.physical.textures,
                            &parts.textures,
                            *texture,
                        )
                }
                _ => LightSelection::power(light, triangles_area),
            });
        }
        let (environment_integral, cube, latlong) = match &parts.background {
            Background::Color(c) => {
                let integral = 4.0 * PI * mean(c.max(Color::ZERO));
                (
                    (integral > 0.0 && c.is_finite()).then_some(integral),
                    None,
                    None,
                )
            }
            Background::CubeMap(map) => match CubeDistribution::new(map) {
                Some((cube, integral)) => (Some(integral), Some(cube), None),
                None => (None, None, None),
            },
            Background::Environment {
                image,
                scale,
                to_world,
            } => match LatLongDistribution::new(image, *scale, to_world) {
                Some((latlong, integral)) => (Some(integral), None, Some(latlong)),
                None => (None, None, None),
            },
        };
        let mut environment = None;
        if let Some(integral) = environment_integral {
            environment = Some(power.len() as u32);
            let mut w = [[0.0f32; 4]; LIGHT_STRIDE];
            w[0] = [bits(LIGHT_ENVIRONMENT), 0.0, 0.0, 1.0];
            words.extend_from_slice(&w);
            power.push(LightSelection::environment_power(radius, integral));
        }
        let count = power.len() as u32;
        let triangles_offset = words.len() as u32;
        words.extend_from_slice(&triangles);
        // Mitsuba scenes choose every emitting light alike (`RenderDefaults`).
        if parts.physical.defaults.uniform_light_selection {
            for p in &mut power {
                *p = if *p > 0.0 { 1.0 } else { 0.0 };
            }
        }
        LightTables {
            words,
            count,
            environment,
            triangles_offset,
            selection: LightSelection::new(&power),
            cube,
            latlong,
            triangle_uvs,
            textured,
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

    /// The scene's defaults reach `Params` and the light table: `rr_depth`, hidden emitters,
    /// the filter's table, the lens, and every emitting light chosen alike when the scene
    /// asks (the directional light weighed as `LightSampler` weighs it otherwise).
    #[test]
    fn scene_defaults_reach_params_and_light_selection() {
        use glint_render::{PixelFilter, ThinLens};
        let mut parts = scene(1);
        parts.lights.push(Light::Directional {
            direction: -Vec3::Y,
            irradiance: Color::splat(2.0),
        });
        let flat = FlatScene::new(&parts);
        assert_eq!(flat.params.rr_depth, 5);
        assert_eq!(flat.params.render_flags, 0);
        assert_eq!(flat.params.filter_kind, FILTER_BOX);
        assert_eq!(flat.params.lens, [0.0; 4]);
        let cdf = &flat.tables[..4];
        // The directional light's power is the scene disk's: π r² E.
        let bounds = glint_render::Scene::new(parts.clone()).bounds();
        let radius = 0.5 * (bounds.max - bounds.min).length();
        let powers = [PI * 1.5, 4.0 * PI, PI * radius * radius * 2.0];
        let total: f32 = powers.iter().sum();
        for (i, power) in powers.iter().enumerate() {
            assert!(
                (cdf[i + 1] - cdf[i] - power / total).abs() < 1e-5,
                "{cdf:?}"
            );
        }

        parts.physical.defaults.russian_roulette_depth = Some(9);
        parts.physical.defaults.hide_emitters = true;
        parts.physical.defaults.uniform_light_selection = true;
        parts.physical.defaults.filter = PixelFilter::Tent { radius: 1.5 };
        parts.camera.lens = Some(ThinLens {
            focus_distance: 3.0,
            radius: 0.25,
        });
        let flat = FlatScene::new(&parts);
        assert_eq!(flat.params.rr_depth, 9);
        assert_eq!(flat.params.render_flags, RENDER_HIDE_EMITTERS);
        assert_eq!(flat.params.lens[..2], [0.25, 3.0]);
        assert_eq!(flat.tables[..4], [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]);
        assert_eq!(flat.params.filter_kind, FILTER_TENT);
        assert_eq!(f32::from_bits(flat.params.filter_param), 1.5);
        let table = &flat.tables[flat.params.filter_table as usize..];
        let table = &table[..FILTER_BINS as usize + 1];
        assert_eq!(
            table,
            glint_render::FilterSampler::new(PixelFilter::Tent { radius: 1.5 }).cdf()
        );
        // A tent: the middle bins weigh most.
        let bin = |i: usize| table[i + 1] - table[i];
        assert!(bin(512) > 100.0 * bin(0), "{} {}", bin(512), bin(0));
    }
}
