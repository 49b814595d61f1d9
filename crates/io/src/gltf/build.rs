//! A parsed glTF document into `SceneParts`: the chosen scene's node hierarchy walked once,
//! each mesh primitive a geometry shared by the nodes that place it, materials as
//! `BsdfNode::Gltf`, textures as `TextureNode`s over images decoded once per colour space,
//! emissive primitives as area lights, KHR_lights_punctual as Glint's point, spot and
//! directional lights, and the camera (the file's or one framing the model).

use std::collections::HashMap;
use std::path::Path;

use glint_render::{
    Aabb, Background, BsdfNode, Camera, Color, GeometryDesc, GltfAlphaMode, GltfParams, Image,
    Instance, Light, Material, MaterialId, Matrix4, Medium, MediumBoundary, MeshAttributes,
    PhaseFunction, PhysicalParts, Projection, RenderDefaults, SceneIntegrator, SceneParts, Shape,
    TexelFilter, TextureKind, TextureNode, Transform, Vec3, Wrap,
};
use gltf::accessor::Dimensions;

use crate::assets::{AssetError, Assets};
use crate::desc::Span;
use crate::diagnostic::{Diagnostics, SceneError};
use crate::gltf::accessor::Accessors;
use crate::gltf::locate::Locator;
use crate::gltf::ModelOptions;
use crate::limits::Limits;
use crate::texture_io::{check_image, TextureBudget};

/// The default image when the file's camera gives no aspect ratio: 4:3.
pub const DEFAULT_WIDTH: u32 = 800;
pub const DEFAULT_HEIGHT: u32 = 600;
/// The framing camera's vertical field of view and the direction it looks from.
pub const FRAMING_FOV_DEGREES: f32 = 40.0;
pub const FRAMING_DIRECTION: [f32; 3] = [1.0, 1.0, 2.0];
/// Lumens per watt: glTF gives punctual lights in photometric units (candela, lux); Glint's
/// radiance is radiometric, as Blender's importer converts them.
const LUMENS_PER_WATT: f32 = 683.0;

/// How an image is decoded for the texture that reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Decode {
    /// Colour: sRGB to linear.
    Srgb,
    /// Data: the stored values.
    Raw,
    /// The alpha channel, as grey.
    Alpha,
}

pub(crate) struct Builder<'a, 't> {
    document: &'a gltf::Document,
    buffers: &'a [Vec<u8>],
    folder: &'a Path,
    assets: &'a dyn Assets,
    limits: &'a Limits,
    locator: &'a Locator<'t>,
    diagnostics: &'a mut Diagnostics<'t>,
    parts: SceneParts,
    budget: TextureBudget,
    /// (image, decode) → `SceneParts::textures` index.
    images: HashMap<(usize, Decode), u32>,
    /// (texture, uv set, transform bits, decode) → `PhysicalParts::textures` index.
    nodes: HashMap<(usize, u8, [u32; 6], Decode), u32>,
    /// (material, has COLOR_0) → what `material` made of it.
    materials: HashMap<(Option<usize>, bool), BuiltMaterial>,
    /// material → the medium inside it (KHR_materials_volume's attenuation).
    media: HashMap<Option<usize>, Option<u32>>,
    /// (mesh, primitive) → its geometry and emission (radiance factor, emissive texture).
    geometries: HashMap<(usize, usize), Option<(u32, Emission)>>,
    triangles: u64,
    lit: bool,
}

/// A surface's emission: its radiance factor and its emissive texture.
type Emission = Option<(Color, Option<u32>)>;

/// A material as primitives use it: its id, its emission (radiance factor, emissive texture),
/// the medium inside it, and the uv set its normal map reads (tangents are made for it).
type BuiltMaterial = (
    MaterialId,
    Option<(Color, Option<u32>)>,
    Option<u32>,
    Option<u8>,
);

/// One primitive's triangles and corner attributes, in object space.
struct PrimitiveMesh {
    shapes: Vec<Shape>,
    attributes: MeshAttributes,
    material: MaterialId,
    emissive: Emission,
    medium: Option<u32>,
}

impl<'a, 't> Builder<'a, 't> {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        document: &'a gltf::Document,
        buffers: &'a [Vec<u8>],
        folder: &'a Path,
        assets: &'a dyn Assets,
        limits: &'a Limits,
        locator: &'a Locator<'t>,
        diagnostics: &'a mut Diagnostics<'t>,
    ) -> Builder<'a, 't> {
        Builder {
            document,
            buffers,
            folder,
            assets,
            limits,
            locator,
            diagnostics,
            parts: SceneParts {
                camera: Camera::new(
                    Projection::Perspective,
                    Vec3::ZERO,
                    Vec3::new(0.0, 0.0, -1.0),
                    1.0,
                    1.0,
                ),
                materials: Vec::new(),
                textures: Vec::new(),
                lights: Vec::new(),
                background: Background::Color(Color::ZERO),
                geometries: Vec::new(),
                instances: Vec::new(),
                physical: PhysicalParts {
                    defaults: RenderDefaults {
                        integrator: Some(SceneIntegrator::Path),
                        ..RenderDefaults::default()
                    },
                    ..PhysicalParts::default()
                },
            },
            budget: TextureBudget::new(*limits),
            images: HashMap::new(),
            nodes: HashMap::new(),
            materials: HashMap::new(),
            media: HashMap::new(),
            geometries: HashMap::new(),
            triangles: 0,
            lit: false,
        }
    }

    fn accessors(&self) -> Accessors<'_, 't> {
        Accessors {
            buffers: self.buffers,
            locator: self.locator,
            diagnostics: self.diagnostics,
            max_elements: self.limits.max_triangles.saturating_mul(3),
        }
    }

    fn span(&self, path: &str) -> Span {
        self.locator.span(path, self.diagnostics)
    }

    fn error(&self, path: &str, message: impl Into<String>) -> SceneError {
        self.diagnostics.error(self.span(path), message)
    }

    fn warn(&mut self, path: &str, message: impl Into<String>) {
        let span = self.span(path);
        self.diagnostics.warn(span, message);
    }

    pub(crate) fn build(mut self, options: &ModelOptions) -> Result<SceneParts, SceneError> {
        let roots = self.scene_roots(options)?;
        // Depth-first, children in order: the first camera met is the default one.
        let mut stack: Vec<(usize, Matrix4)> = roots
            .iter()
            .rev()
            .map(|&n| (n, Matrix4::IDENTITY))
            .collect();
        let mut seen = vec![false; self.document.nodes().len()];
        let mut cameras: Vec<(usize, Matrix4)> = Vec::new();
        let nodes: Vec<gltf::Node> = self.document.nodes().collect();
        while let Some((index, parent)) = stack.pop() {
            let node = &nodes[index];
            if std::mem::replace(&mut seen[index], true) {
                return Err(self.error(
                    &format!("nodes[{index}]"),
                    format!(
                        "node {index} is reached twice from the scene: the node hierarchy has                          a cycle or a node with two parents, which glTF forbids"
                    ),
                ));
            }
            let local = self.local_matrix(node)?;
            let world = parent.mul(&local);
            if let Some(mesh) = node.mesh() {
                self.place_mesh(index, &mesh, &world)?;
            }
            if node.camera().is_some() {
                cameras.push((index, world));
            }
            if let Some(light) = node.light() {
                self.punctual_light(index, &light, &world)?;
            }
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child.index(), world));
            }
        }
        if self.document.animations().len() > 0 {
            self.warn(
                "animations",
                "animations are ignored: the model renders in its rest pose",
            );
        }
        if self.document.skins().len() > 0 {
            self.warn(
                "skins",
                "skins are ignored: skinned meshes render in their bind pose",
            );
        }
        if self
            .document
            .meshes()
            .any(|m| m.primitives().any(|p| p.morph_targets().len() > 0))
        {
            self.warn(
                "meshes",
                "morph targets are ignored: meshes render with their base shape",
            );
        }
        if self.parts.instances.is_empty() {
            self.warn(
                "",
                "the scene has no triangles: the image shows only the background",
            );
        }
        self.choose_camera(options, &cameras)?;
        if !self.lit && !options.has_environment {
            self.parts.background = Background::Color(Color::ONE);
            self.warn(
                "",
                "the model brings no light: a uniform white sky (radiance 1) lights it (an environment map lights it instead: --env, or env= in Python)",
            );
        }
        if !self.parts.physical.media.is_empty() {
            self.parts.physical.defaults.integrator = Some(SceneIntegrator::VolPath);
        }
        Ok(self.parts)
    }

    /// The root nodes of the scene to render.
    fn scene_roots(&mut self, options: &ModelOptions) -> Result<Vec<usize>, SceneError> {
        let scenes = self.document.scenes().len();
        let scene = match options.scene {
            Some(n) if n < scenes => self.document.scenes().nth(n),
            Some(n) => {
                return Err(self.error(
                    "scenes",
                    format!(
                        "there is no scene {n}: the model has {scenes} scene{}{}",
                        if scenes == 1 { "" } else { "s" },
                        if scenes > 0 {
                            format!(" (0 to {})", scenes - 1)
                        } else {
                            String::new()
                        }
                    ),
                ))
            }
            None => match self.document.default_scene() {
                Some(scene) => Some(scene),
                None if scenes > 0 => {
                    if scenes > 1 {
                        self.warn(
                            "scenes",
                            "the model names no default scene: rendering scene 0",
                        );
                    }
                    self.document.scenes().next()
                }
                None => None,
            },
        };
        if let Some(scene) = scene {
            return Ok(scene.nodes().map(|n| n.index()).collect());
        }
        // No scenes: every node nobody names as a child.
        let mut child = vec![false; self.document.nodes().len()];
        for node in self.document.nodes() {
            for c in node.children() {
                child[c.index()] = true;
            }
        }
        let roots: Vec<usize> = (0..child.len()).filter(|&i| !child[i]).collect();
        if !roots.is_empty() {
            self.warn("", "the model has no scenes: rendering every root node");
        }
        Ok(roots)
    }

    fn local_matrix(&self, node: &gltf::Node) -> Result<Matrix4, SceneError> {
        let columns = node.transform().matrix();
        let mut m = Matrix4::IDENTITY;
        for (c, column) in columns.iter().enumerate() {
            for (r, value) in column.iter().enumerate() {
                m.m[r][c] = f64::from(*value);
            }
        }
        if m.m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(self.error(
                &format!("nodes[{}]", node.index()),
                "the node's transform is not finite",
            ));
        }
        Ok(m)
    }

    /// Instances of a mesh's primitives at `world`.
    fn place_mesh(
        &mut self,
        node: usize,
        mesh: &gltf::Mesh,
        world: &Matrix4,
    ) -> Result<(), SceneError> {
        let Some(transform) = Transform::from_matrix(world) else {
            self.warn(
                &format!("nodes[{node}]"),
                "the node's transform is singular (a zero scale): its mesh is not rendered",
            );
            return Ok(());
        };
        for primitive in mesh.primitives() {
            let key = (mesh.index(), primitive.index());
            let built = match self.geometries.get(&key) {
                Some(built) => *built,
                None => {
                    let built = self.primitive_geometry(mesh.index(), &primitive)?;
                    self.geometries.insert(key, built);
                    built
                }
            };
            let Some((geometry, emissive)) = built else {
                continue;
            };
            let mut instance = Instance {
                geometry,
                transform: Some(transform),
                material: None,
                casts_shadow: true,
            };
            if let Some((radiance, texture)) = emissive {
                instance.material = Some(self.emitter(geometry, &transform, radiance, texture));
            }
            self.parts.instances.push(instance);
        }
        Ok(())
    }

    /// An area light over one placement of an emissive geometry, and the `Emissive`
    /// material its instance shows.
    fn emitter(
        &mut self,
        geometry: u32,
        transform: &Transform,
        radiance: Color,
        texture: Option<u32>,
    ) -> MaterialId {
        let desc = &self.parts.geometries[geometry as usize];
        let surface = desc.materials.first().copied();
        let triangles: Vec<[Vec3; 3]> = desc
            .shapes
            .iter()
            .filter_map(|s| match s {
                Shape::Triangle { vertices } => Some(vertices.map(|v| transform.point_to_world(v))),
                _ => None,
            })
            .collect();
        let light = match texture {
            Some(texture) => {
                let uvs = self
                    .parts
                    .physical
                    .attributes
                    .get(geometry as usize)
                    .and_then(Option::as_ref)
                    .and_then(|a| {
                        let node = &self.parts.physical.textures[texture as usize];
                        if node.uv_set == 1 {
                            a.uvs1.clone()
                        } else {
                            a.uvs.clone()
                        }
                    })
                    .unwrap_or_else(|| vec![[(0.0, 0.0); 3]; triangles.len()]);
                Light::TexturedTriangles {
                    triangles,
                    uvs,
                    texture,
                    intensity: radiance,
                }
            }
            None => Light::Triangles {
                triangles,
                intensity: radiance,
            },
        };
        self.parts.lights.push(light);
        self.lit = true;
        self.parts.materials.push(Material::Emissive {
            radiance,
            surface,
            light: Some((self.parts.lights.len() - 1) as u32),
        });
        (self.parts.materials.len() - 1) as MaterialId
    }

    /// One primitive's geometry (object space), or `None` when it has no triangles.
    #[allow(clippy::type_complexity)]
    fn primitive_geometry(
        &mut self,
        mesh: usize,
        primitive: &gltf::Primitive,
    ) -> Result<Option<(u32, Emission)>, SceneError> {
        let Some(built) = self.primitive_mesh(mesh, primitive)? else {
            return Ok(None);
        };
        let geometry = self.parts.geometries.len() as u32;
        self.parts.geometries.push(GeometryDesc {
            materials: vec![built.material; built.shapes.len()],
            shapes: built.shapes,
        });
        let physical = &mut self.parts.physical;
        physical.attributes.resize(geometry as usize + 1, None);
        physical.attributes[geometry as usize] = Some(built.attributes);
        if let Some(medium) = built.medium {
            physical.boundaries.resize(geometry as usize + 1, None);
            physical.boundaries[geometry as usize] = Some(MediumBoundary {
                interior: Some(medium),
                exterior: None,
            });
        }
        Ok(Some((geometry, built.emissive)))
    }

    fn primitive_mesh(
        &mut self,
        mesh: usize,
        primitive: &gltf::Primitive,
    ) -> Result<Option<PrimitiveMesh>, SceneError> {
        use gltf::mesh::{Mode, Semantic};
        let at = format!("meshes[{mesh}].primitives[{}]", primitive.index());
        let mode = primitive.mode();
        if matches!(
            mode,
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
        ) {
            return Err(self.error(
                &format!("{at}.mode"),
                format!(
                    "the primitive draws {}; Glint renders triangles only (mode 4, 5 or 6)",
                    match mode {
                        Mode::Points => "points",
                        _ => "lines",
                    }
                ),
            ));
        }
        let Some(position) = primitive.get(&Semantic::Positions) else {
            return Err(self.error(&format!("{at}.attributes"), "the primitive has no POSITION"));
        };
        let accessors = self.accessors();
        let positions = accessors.floats(&position, &[Dimensions::Vec3], "POSITION")?;
        let vertex_count = positions.len() / 3;
        let corners: Vec<u32> = match primitive.indices() {
            Some(indices) => {
                let values = accessors.indices(&indices)?;
                if let Some(bad) = values.iter().find(|&&i| i as usize >= vertex_count) {
                    return Err(self.error(
                        &format!("accessors[{}]", indices.index()),
                        format!("an index {bad} is past the primitive's {vertex_count} vertices"),
                    ));
                }
                values
            }
            None => (0..vertex_count as u32).collect(),
        };
        let triangles: Vec<[u32; 3]> = match mode {
            Mode::TriangleStrip => (2..corners.len())
                .map(|i| {
                    if i % 2 == 0 {
                        [corners[i - 2], corners[i - 1], corners[i]]
                    } else {
                        [corners[i - 1], corners[i - 2], corners[i]]
                    }
                })
                .collect(),
            Mode::TriangleFan => (2..corners.len())
                .map(|i| [corners[i - 1], corners[i], corners[0]])
                .collect(),
            _ => corners
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        };
        if triangles.is_empty() {
            return Ok(None);
        }
        if self.triangles + triangles.len() as u64 > self.limits.max_triangles {
            return Err(self.error(
                &at,
                format!(
                    "the model has more than {} triangles, the limit (--max-triangles raises it)",
                    self.limits.max_triangles
                ),
            ));
        }
        fn vertex(data: &[f32], n: usize, i: u32) -> &[f32] {
            &data[i as usize * n..i as usize * n + n]
        }
        let read = |semantic: Semantic,
                    dims: &[Dimensions],
                    what: &str|
         -> Result<Option<Vec<f32>>, SceneError> {
            match primitive.get(&semantic) {
                None => Ok(None),
                Some(accessor) => {
                    let values = accessors.floats(&accessor, dims, what)?;
                    let n = values.len() / vertex_count.max(1);
                    if accessor.count() != vertex_count || n == 0 {
                        return Err(self.error(
                            &format!("accessors[{}]", accessor.index()),
                            format!(
                                "{what} has {} elements for {vertex_count} vertices",
                                accessor.count()
                            ),
                        ));
                    }
                    Ok(Some(values))
                }
            }
        };
        let normals = read(Semantic::Normals, &[Dimensions::Vec3], "NORMAL")?;
        let tangents = read(Semantic::Tangents, &[Dimensions::Vec4], "TANGENT")?;
        let uv0 = read(Semantic::TexCoords(0), &[Dimensions::Vec2], "TEXCOORD_0")?;
        let uv1 = read(Semantic::TexCoords(1), &[Dimensions::Vec2], "TEXCOORD_1")?;
        let colors = read(
            Semantic::Colors(0),
            &[Dimensions::Vec3, Dimensions::Vec4],
            "COLOR_0",
        )?;
        let color_n = colors.as_ref().map_or(3, |c| c.len() / vertex_count.max(1));
        let p = |i: u32| {
            let v = vertex(&positions, 3, i);
            Vec3::new(v[0], v[1], v[2])
        };
        if positions.iter().any(|v| !v.is_finite()) {
            return Err(self.error(
                &format!("accessors[{}]", position.index()),
                "POSITION holds a value that is not finite",
            ));
        }
        let shapes: Vec<Shape> = triangles
            .iter()
            .map(|t| Shape::Triangle { vertices: t.map(p) })
            .collect();
        let corner3 = |data: &Vec<f32>, t: &[u32; 3]| {
            t.map(|i| {
                let v = vertex(data, 3, i);
                Vec3::new(v[0], v[1], v[2])
            })
        };
        let corner2 = |data: &Vec<f32>, t: &[u32; 3]| {
            t.map(|i| {
                let v = vertex(data, 2, i);
                (v[0], v[1])
            })
        };
        let mut attributes = MeshAttributes {
            normals: normals
                .as_ref()
                .map(|n| triangles.iter().map(|t| corner3(n, t)).collect()),
            uvs: uv0
                .as_ref()
                .map(|d| triangles.iter().map(|t| corner2(d, t)).collect()),
            uvs1: uv1
                .as_ref()
                .map(|d| triangles.iter().map(|t| corner2(d, t)).collect()),
            vertex_colors: colors.as_ref().map(|d| {
                triangles
                    .iter()
                    .map(|t| {
                        t.map(|i| {
                            let v = vertex(d, color_n, i);
                            Color::new(v[0], v[1], v[2])
                        })
                    })
                    .collect()
            }),
            tangents: tangents.as_ref().map(|d| {
                triangles
                    .iter()
                    .map(|t| {
                        t.map(|i| {
                            let v = vertex(d, 4, i);
                            [v[0], v[1], v[2], v[3]]
                        })
                    })
                    .collect()
            }),
            ..MeshAttributes::default()
        };
        let has_color = colors.is_some();
        self.triangles += triangles.len() as u64;
        let (material, emissive, medium, normal_uv_set) =
            self.material(primitive.material(), has_color)?;
        if attributes.tangents.is_none() {
            if let Some(set) = normal_uv_set {
                let uvs = if set == 1 {
                    attributes.uvs1.as_ref()
                } else {
                    attributes.uvs.as_ref()
                };
                if let Some(uvs) = uvs {
                    attributes.tangents = Some(mikktspace_tangents(
                        &shapes,
                        attributes.normals.as_deref(),
                        uvs,
                    ));
                }
            }
        }
        Ok(Some(PrimitiveMesh {
            shapes,
            attributes,
            material,
            emissive,
            medium,
        }))
    }

    fn material(
        &mut self,
        material: gltf::Material,
        has_color: bool,
    ) -> Result<BuiltMaterial, SceneError> {
        let index = material.index();
        if let Some(built) = self.materials.get(&(index, has_color)) {
            return Ok(*built);
        }
        let at = index.map_or(String::new(), |i| format!("materials[{i}]"));
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, a] = pbr.base_color_factor();
        let mut p = GltfParams {
            base_color: Color::new(r, g, b),
            vertex_color: has_color,
            alpha: a,
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            double_sided: material.double_sided(),
            ..GltfParams::default()
        };
        p.alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => GltfAlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => GltfAlphaMode::Mask {
                cutoff: material.alpha_cutoff().unwrap_or(0.5),
            },
            gltf::material::AlphaMode::Blend => GltfAlphaMode::Blend,
        };
        let reads_alpha = p.alpha_mode != GltfAlphaMode::Opaque;
        if let Some(info) = pbr.base_color_texture() {
            let (texture, coord) = (info.texture(), self.tex_coord(&info, &at)?);
            let transform = transform_of(info.texture_transform());
            p.base_color_texture =
                Some(self.texture_node(&texture, coord, transform, Decode::Srgb, &at)?);
            if reads_alpha {
                p.alpha_texture =
                    Some(self.texture_node(&texture, coord, transform, Decode::Alpha, &at)?);
            }
        }
        p.metallic_roughness_texture =
            self.info_node(pbr.metallic_roughness_texture(), Decode::Raw, &at)?;
        let mut normal_set = None;
        if let Some(normal) = material.normal_texture() {
            let (coord, transform) = self.raw_info(
                normal.tex_coord(),
                normal.extension_value("KHR_texture_transform"),
                &at,
            )?;
            p.normal_texture =
                Some(self.texture_node(&normal.texture(), coord, transform, Decode::Raw, &at)?);
            p.normal_scale = normal.scale();
            normal_set = Some(coord);
        }
        if let Some(ior) = material.ior() {
            p.ior = if ior == 0.0 { 1.0e6 } else { ior };
            if !(p.ior >= 1.0 && p.ior.is_finite()) {
                return Err(self.error(
                    &format!("{at}.extensions.KHR_materials_ior.ior"),
                    format!("an index of refraction of {ior}: it must be at least 1 (or 0)"),
                ));
            }
        }
        if let Some(specular) = material.specular() {
            p.specular = specular.specular_factor();
            let [r, g, b] = specular.specular_color_factor();
            p.specular_color = Color::new(r, g, b);
            p.specular_texture = self.info_node(specular.specular_texture(), Decode::Alpha, &at)?;
            p.specular_color_texture =
                self.info_node(specular.specular_color_texture(), Decode::Srgb, &at)?;
        }
        if let Some(transmission) = material.transmission() {
            p.transmission = transmission.transmission_factor();
            p.transmission_texture =
                self.info_node(transmission.transmission_texture(), Decode::Raw, &at)?;
        }
        let mut medium = None;
        if let Some(volume) = material.volume() {
            if volume.thickness_factor() > 0.0 {
                p.thin_walled = false;
                let distance = volume.attenuation_distance();
                let [r, g, b] = volume.attenuation_color();
                if distance.is_finite() && distance > 0.0 && [r, g, b] != [1.0; 3] {
                    // Beer's law: colour c remains after `distance`.
                    let sigma = |c: f32| -(c.clamp(1e-6, 1.0)).ln() / distance;
                    self.parts.physical.media.push(Medium::Homogeneous {
                        sigma_t: Color::new(sigma(r), sigma(g), sigma(b)),
                        albedo: Color::ZERO,
                        phase: PhaseFunction::Isotropic,
                        sample_emitters: true,
                    });
                    medium = Some((self.parts.physical.media.len() - 1) as u32);
                }
            }
        }
        self.media.insert(index, medium);
        if let Some(clearcoat) = material.extension_value("KHR_materials_clearcoat") {
            let cat = format!("{at}.extensions.KHR_materials_clearcoat");
            let number = |name: &str, default: f32| {
                clearcoat
                    .get(name)
                    .and_then(|v| v.as_f64())
                    .map_or(default, |v| v as f32)
            };
            p.clearcoat = number("clearcoatFactor", 0.0).clamp(0.0, 1.0);
            p.clearcoat_roughness = number("clearcoatRoughnessFactor", 0.0).clamp(0.0, 1.0);
            for (name, slot) in [
                ("clearcoatTexture", 0usize),
                ("clearcoatRoughnessTexture", 1),
            ] {
                if let Some(info) = clearcoat.get(name) {
                    let node = self.raw_texture_info(info, &format!("{cat}.{name}"))?;
                    if slot == 0 {
                        p.clearcoat_texture = Some(node);
                    } else {
                        p.clearcoat_roughness_texture = Some(node);
                    }
                }
            }
            if clearcoat.get("clearcoatNormalTexture").is_some() {
                self.warn(
                    &format!("{cat}.clearcoatNormalTexture"),
                    "the clear coat's own normal map is ignored: the coat follows the base's \
                     shading normal",
                );
            }
        }
        for name in [
            "KHR_materials_pbrSpecularGlossiness",
            "KHR_materials_unlit",
            "KHR_materials_sheen",
            "KHR_materials_iridescence",
            "KHR_materials_anisotropy",
        ] {
            if material.extension_value(name).is_some() {
                self.warn(
                    &format!("{at}.extensions.{name}"),
                    format!("{name} is ignored"),
                );
            }
        }
        let strength = material.emissive_strength().unwrap_or(1.0);
        let [er, eg, eb] = material.emissive_factor();
        let radiance = Color::new(er, eg, eb) * strength;
        let emissive_texture = self.info_node(material.emissive_texture(), Decode::Srgb, &at)?;
        let emissive = (radiance.max_component() > 0.0 && radiance.is_finite())
            .then_some((radiance, emissive_texture));
        self.parts.physical.bsdfs.push(BsdfNode::Gltf(Box::new(p)));
        self.parts.materials.push(Material::Physical(
            (self.parts.physical.bsdfs.len() - 1) as u32,
        ));
        let id = (self.parts.materials.len() - 1) as MaterialId;
        let built = (id, emissive, medium, normal_set);
        self.materials.insert((index, has_color), built);
        Ok(built)
    }

    /// The `TextureNode` a texture info names (with its uv set and transform), if any.
    fn info_node(
        &mut self,
        info: Option<gltf::texture::Info>,
        decode: Decode,
        at: &str,
    ) -> Result<Option<u32>, SceneError> {
        let Some(info) = info else {
            return Ok(None);
        };
        let coord = self.tex_coord(&info, at)?;
        let transform = transform_of(info.texture_transform());
        self.texture_node(&info.texture(), coord, transform, decode, at)
            .map(Some)
    }

    /// A texture info's uv set, warned down to 0 or 1 (KHR_texture_transform may override
    /// it).
    fn tex_coord(&mut self, info: &gltf::texture::Info, at: &str) -> Result<u8, SceneError> {
        let coord = info
            .texture_transform()
            .and_then(|t| t.tex_coord())
            .unwrap_or(info.tex_coord());
        self.uv_set(coord, at)
    }

    fn uv_set(&mut self, coord: u32, at: &str) -> Result<u8, SceneError> {
        if coord > 1 {
            self.warn(
                at,
                format!("TEXCOORD_{coord} is not read (Glint reads TEXCOORD_0 and TEXCOORD_1): TEXCOORD_0 is used"),
            );
            return Ok(0);
        }
        Ok(coord as u8)
    }

    /// The uv set and transform of a texture info read from raw JSON (normal textures, whose
    /// transform the crate does not expose, and the clear coat's).
    fn raw_info(
        &mut self,
        tex_coord: u32,
        transform: Option<&serde_json::Value>,
        at: &str,
    ) -> Result<(u8, [f32; 6]), SceneError> {
        let mut coord = tex_coord;
        let mut matrix = IDENTITY_TRANSFORM;
        if let Some(t) = transform {
            let pair = |name: &str, default: [f32; 2]| {
                t.get(name)
                    .and_then(|v| v.as_array())
                    .filter(|a| a.len() == 2)
                    .map_or(default, |a| {
                        [
                            a[0].as_f64().unwrap_or(f64::from(default[0])) as f32,
                            a[1].as_f64().unwrap_or(f64::from(default[1])) as f32,
                        ]
                    })
            };
            let rotation = t.get("rotation").and_then(|v| v.as_f64()).unwrap_or(0.0) as f32;
            matrix = uv_matrix(
                pair("offset", [0.0, 0.0]),
                rotation,
                pair("scale", [1.0, 1.0]),
            );
            if let Some(c) = t.get("texCoord").and_then(|v| v.as_u64()) {
                coord = c.min(u64::from(u32::MAX)) as u32;
            }
        }
        Ok((self.uv_set(coord, at)?, matrix))
    }

    /// A texture info object of an extension the crate does not model (the clear coat's).
    fn raw_texture_info(&mut self, info: &serde_json::Value, at: &str) -> Result<u32, SceneError> {
        let index = info
            .get("index")
            .and_then(|v| v.as_u64())
            .ok_or_else(|| self.error(at, "a texture info needs an `index`"))?;
        let Some(texture) = usize::try_from(index)
            .ok()
            .and_then(|i| self.document.textures().nth(i))
        else {
            return Err(self.error(
                &format!("{at}.index"),
                format!(
                    "texture {index} does not exist (the model has {})",
                    self.document.textures().len()
                ),
            ));
        };
        let tex_coord = info.get("texCoord").and_then(|v| v.as_u64()).unwrap_or(0);
        let transform = info
            .get("extensions")
            .and_then(|e| e.get("KHR_texture_transform"));
        let (coord, matrix) =
            self.raw_info(tex_coord.min(u64::from(u32::MAX)) as u32, transform, at)?;
        self.texture_node(&texture, coord, matrix, Decode::Raw, at)
    }

    /// The `TextureNode` reading `texture` at uv set `coord` through `transform`.
    fn texture_node(
        &mut self,
        texture: &gltf::Texture,
        coord: u8,
        transform: [f32; 6],
        decode: Decode,
        at: &str,
    ) -> Result<u32, SceneError> {
        let key = (texture.index(), coord, transform.map(f32::to_bits), decode);
        if let Some(&node) = self.nodes.get(&key) {
            return Ok(node);
        }
        let image = self.image(
            &texture.source(),
            decode,
            &format!("textures[{}]", texture.index()),
            at,
        )?;
        let sampler = texture.sampler();
        let wrap = |mode: gltf::texture::WrappingMode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let filter = match sampler.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => TexelFilter::Nearest,
            _ => TexelFilter::Bilinear,
        };
        let [a, b, c, d, e, f] = transform;
        self.parts.physical.textures.push(TextureNode {
            kind: TextureKind::Bitmap {
                image,
                filter,
                wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
            },
            to_uv: [[a, b, c], [d, e, f]],
            uv_set: coord,
        });
        let node = (self.parts.physical.textures.len() - 1) as u32;
        self.nodes.insert(key, node);
        Ok(node)
    }

    /// The image decoded as `decode` asks, once.
    fn image(
        &mut self,
        image: &gltf::Image,
        decode: Decode,
        texture_at: &str,
        material_at: &str,
    ) -> Result<u32, SceneError> {
        if let Some(&id) = self.images.get(&(image.index(), decode)) {
            return Ok(id);
        }
        let at = format!("images[{}]", image.index());
        let bytes = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let end = view.offset().checked_add(view.length());
                match end {
                    Some(end) if end <= buffer.len() => buffer[view.offset()..end].to_vec(),
                    _ => {
                        return Err(self.error(
                            &format!("bufferViews[{}]", view.index()),
                            "the image's buffer view overruns its buffer",
                        ))
                    }
                }
            }
            gltf::image::Source::Uri { uri, .. } => {
                super::read_uri(uri, self.folder, self.assets, self.limits, "image")
                    .map_err(|message| self.error(&format!("{at}.uri"), message))?
            }
        };
        let failed = |this: &Self, error: AssetError| {
            let message = match error {
                AssetError::Refused(m) | AssetError::Failed(m) => m,
            };
            this.error(
                &at,
                format!(
                    "the image of {texture_at} (used by {}) cannot be read: {message}",
                    if material_at.is_empty() {
                        "the default material"
                    } else {
                        material_at
                    }
                ),
            )
        };
        let checked = check_image(bytes, &mut self.budget).map_err(|e| failed(self, e))?;
        let (rgb, alpha) = checked
            .decode_with_alpha(decode == Decode::Raw, decode == Decode::Alpha)
            .map_err(|e| failed(self, e))?;
        let texels: Image = match decode {
            Decode::Alpha => alpha.expect("asked for"),
            _ => rgb,
        };
        self.parts.textures.push(texels);
        let id = (self.parts.textures.len() - 1) as u32;
        self.images.insert((image.index(), decode), id);
        Ok(id)
    }

    /// A KHR_lights_punctual light at `world`.
    fn punctual_light(
        &mut self,
        node: usize,
        light: &gltf::khr_lights_punctual::Light,
        world: &Matrix4,
    ) -> Result<(), SceneError> {
        use gltf::khr_lights_punctual::Kind;
        let at = format!("extensions.KHR_lights_punctual.lights[{}]", light.index());
        let [r, g, b] = light.color();
        let value = Color::new(r, g, b) * (light.intensity() / LUMENS_PER_WATT);
        if !(value.is_finite() && value.min_component() >= 0.0) {
            return Err(self.error(
                &at,
                "the light's colour times intensity must be finite and not negative",
            ));
        }
        if light.range().is_some() {
            self.warn(&at, "the light's `range` is ignored: its light falls off with the inverse square of distance everywhere");
        }
        let position = world.transform_point(Vec3::ZERO);
        // The light shines along the node's −Z.
        let forward = -column(world, 2).normalized();
        match light.kind() {
            Kind::Directional => self.parts.lights.push(Light::Directional {
                direction: forward,
                irradiance: value,
            }),
            Kind::Point => self.parts.lights.push(Light::Point {
                position,
                intensity: value,
            }),
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                // Glint's spot shines along its +z: a rigid frame from the node's axes.
                let frame = glint_render::Transform::from_matrix(&rigid(
                    position,
                    column(world, 0),
                    forward,
                ));
                let Some(to_world) = frame else {
                    return Err(self.error(
                        &format!("nodes[{node}]"),
                        "the spot light's node transform is degenerate",
                    ));
                };
                self.parts.lights.push(Light::Spot {
                    to_world,
                    intensity: value,
                    cutoff_angle: outer_cone_angle.to_degrees(),
                    beam_width: inner_cone_angle
                        .to_degrees()
                        .min(outer_cone_angle.to_degrees()),
                    texture: None,
                });
            }
        }
        if value.max_component() > 0.0 {
            self.lit = true;
        }
        Ok(())
    }

    /// The camera `--camera` names, the first one met, or one framing the model.
    fn choose_camera(
        &mut self,
        options: &ModelOptions,
        cameras: &[(usize, Matrix4)],
    ) -> Result<(), SceneError> {
        let nodes: Vec<gltf::Node> = self.document.nodes().collect();
        let chosen = match &options.camera {
            Some(wanted) => {
                let by_index = wanted.parse::<usize>().ok();
                let found = cameras.iter().find(|(n, _)| {
                    let node = &nodes[*n];
                    let camera = node.camera().expect("collected with a camera");
                    by_index == Some(camera.index())
                        || camera.name() == Some(wanted.as_str())
                        || node.name() == Some(wanted.as_str())
                });
                match found {
                    Some(found) => Some(*found),
                    None => {
                        let names: Vec<String> = cameras
                            .iter()
                            .map(|(n, _)| {
                                let camera = nodes[*n].camera().expect("has one");
                                match camera.name().or(nodes[*n].name()) {
                                    Some(name) => format!("{} ({name})", camera.index()),
                                    None => camera.index().to_string(),
                                }
                            })
                            .collect();
                        return Err(self.error(
                            "cameras",
                            format!(
                                "the camera `{wanted}` names no camera of the scene{}",
                                if names.is_empty() {
                                    " (it has none)".to_string()
                                } else {
                                    format!("; it has {}", names.join(", "))
                                }
                            ),
                        ));
                    }
                }
            }
            None => cameras.first().copied(),
        };
        match chosen {
            Some((node, world)) => self.file_camera(&nodes[node], &world),
            None => {
                self.framing_camera();
                Ok(())
            }
        }
    }

    fn file_camera(&mut self, node: &gltf::Node, world: &Matrix4) -> Result<(), SceneError> {
        let camera = node.camera().expect("chosen for its camera");
        let at = format!("cameras[{}]", camera.index());
        let origin = world.transform_point(Vec3::ZERO);
        let (x, y, z) = (
            column(world, 0).normalized(),
            column(world, 1).normalized(),
            column(world, 2).normalized(),
        );
        if !(x.is_finite() && y.is_finite() && z.is_finite() && origin.is_finite()) {
            return Err(self.error(
                &format!("nodes[{}]", node.index()),
                "the camera's node transform is degenerate",
            ));
        }
        let defaults = &mut self.parts.physical.defaults;
        let mut result = match camera.projection() {
            gltf::camera::Projection::Perspective(p) => {
                let yfov = p.yfov();
                if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
                    return Err(self.error(
                        &format!("{at}.perspective.yfov"),
                        format!(
                            "a vertical field of view of {yfov} radians: it must lie in (0, π)"
                        ),
                    ));
                }
                let aspect = match p.aspect_ratio() {
                    Some(a) if a > 0.0 && a.is_finite() => {
                        defaults.width = Some(DEFAULT_WIDTH);
                        defaults.height = Some(((DEFAULT_WIDTH as f32 / a).round() as u32).max(1));
                        a
                    }
                    _ => {
                        defaults.width = Some(DEFAULT_WIDTH);
                        defaults.height = Some(DEFAULT_HEIGHT);
                        DEFAULT_WIDTH as f32 / DEFAULT_HEIGHT as f32
                    }
                };
                let mut c = Camera::new(
                    Projection::Perspective,
                    origin,
                    -z,
                    1.0,
                    2.0 * (0.5 * yfov).tan() * aspect,
                );
                let near = p.znear().max(0.0);
                let far = p.zfar().unwrap_or(f32::INFINITY);
                if near > 0.0 && far > near {
                    c.clip = Some((near, far));
                }
                c
            }
            gltf::camera::Projection::Orthographic(o) => {
                let (xmag, ymag) = (o.xmag().abs(), o.ymag().abs());
                if !(xmag > 0.0 && ymag > 0.0 && xmag.is_finite() && ymag.is_finite()) {
                    return Err(self.error(
                        &format!("{at}.orthographic"),
                        "xmag and ymag must be finite and not zero",
                    ));
                }
                defaults.width = Some(DEFAULT_WIDTH);
                defaults.height =
                    Some(((DEFAULT_WIDTH as f32 * ymag / xmag).round() as u32).max(1));
                Camera::new(Projection::Orthographic, origin, -z, 1.0, 2.0 * xmag)
            }
        };
        // The camera looks along the node's −Z with +X right and +Y up.
        result.basis.u = x;
        result.basis.v = y;
        result.basis.w = z;
        self.parts.camera = result;
        Ok(())
    }

    /// The framing camera (`docs/gltf.md`): from direction (1, 1, 2), fitting the bounding
    /// sphere of the model's box in a 40° vertical field of view.
    fn framing_camera(&mut self) {
        let mut bounds = Aabb::EMPTY;
        for instance in &self.parts.instances {
            let geometry = &self.parts.geometries[instance.geometry as usize];
            for shape in &geometry.shapes {
                if let Shape::Triangle { vertices } = shape {
                    for v in vertices {
                        let w = instance.transform.map_or(*v, |t| t.point_to_world(*v));
                        bounds = bounds.grow(w);
                    }
                }
            }
        }
        let (center, mut radius) = if bounds.min.x <= bounds.max.x {
            (
                (bounds.min + bounds.max) * 0.5,
                0.5 * (bounds.max - bounds.min).length(),
            )
        } else {
            (Vec3::ZERO, 1.0)
        };
        if !(radius > 0.0 && radius.is_finite()) {
            radius = 1.0;
        }
        let (width, height) = (DEFAULT_WIDTH, DEFAULT_HEIGHT);
        let aspect = width as f32 / height as f32;
        let fov = FRAMING_FOV_DEGREES.to_radians();
        let horizontal = 2.0 * ((0.5 * fov).tan() * aspect).atan();
        let theta = fov.min(horizontal);
        let distance = radius / (0.5 * theta).sin();
        let [dx, dy, dz] = FRAMING_DIRECTION;
        let eye = center + Vec3::new(dx, dy, dz).normalized() * distance;
        let camera = Camera::new(
            Projection::Perspective,
            eye,
            center - eye,
            1.0,
            2.0 * (0.5 * fov).tan() * aspect,
        );
        self.parts.camera = camera;
        self.parts.physical.defaults.width = Some(width);
        self.parts.physical.defaults.height = Some(height);
        self.warn(
            "",
            format!(
                "the model has no camera: one frames it from direction (1, 1, 2), at {} from \
                 the centre ({}, {}, {}) of its box",
                distance, center.x, center.y, center.z
            ),
        );
    }
}

/// KHR_texture_transform's identity as Glint's `to_uv` rows.
const IDENTITY_TRANSFORM: [f32; 6] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// KHR_texture_transform as `to_uv` rows: translation · rotation · scale, with the rotation
/// the extension's (u′ = cos·u − sin·v, v′ = sin·u + cos·v, its GLSL matrix read by
/// columns).
fn uv_matrix(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> [f32; 6] {
    let (sin, cos) = rotation.sin_cos();
    [
        cos * scale[0],
        -sin * scale[1],
        offset[0],
        sin * scale[0],
        cos * scale[1],
        offset[1],
    ]
}

fn transform_of(t: Option<gltf::texture::TextureTransform>) -> [f32; 6] {
    t.map_or(IDENTITY_TRANSFORM, |t| {
        uv_matrix(t.offset(), t.rotation(), t.scale())
    })
}

fn column(m: &Matrix4, c: usize) -> Vec3 {
    Vec3::new(m.m[0][c] as f32, m.m[1][c] as f32, m.m[2][c] as f32)
}

/// A rigid frame at `origin` whose +z is `forward` and whose +x is as close to `right` as
/// allowed.
fn rigid(origin: Vec3, right: Vec3, forward: Vec3) -> Matrix4 {
    let z = forward.normalized();
    let mut x = (right - z * z.dot(right)).normalized();
    if !x.is_finite() {
        let helper = if z.x.abs() < 0.9 {
            Vec3::new(1.0, 0.0, 0.0)
        } else {
            Vec3::new(0.0, 1.0, 0.0)
        };
        x = (helper - z * z.dot(helper)).normalized();
    }
    let y = z.cross(x);
    let mut m = Matrix4::IDENTITY;
    for (c, v) in [x, y, z, origin].iter().enumerate() {
        m.m[0][c] = f64::from(v.x);
        m.m[1][c] = f64::from(v.y);
        m.m[2][c] = f64::from(v.z);
    }
    m
}

/// MikkTSpace tangents at every corner (glTF's rule for normal-mapped primitives without
/// TANGENT), from the corners' positions, normals (flat where absent) and `uvs`.
fn mikktspace_tangents(
    shapes: &[Shape],
    normals: Option<&[[Vec3; 3]]>,
    uvs: &[[(f32, f32); 3]],
) -> Vec<[[f32; 4]; 3]> {
    struct Geometry<'a> {
        shapes: &'a [Shape],
        normals: Option<&'a [[Vec3; 3]]>,
        uvs: &'a [[(f32, f32); 3]],
        out: Vec<[[f32; 4]; 3]>,
    }
    impl Geometry<'_> {
        fn corners(&self, face: usize) -> [Vec3; 3] {
            match self.shapes[face] {
                Shape::Triangle { vertices } => vertices,
                _ => [Vec3::ZERO; 3],
            }
        }
    }
    impl mikktspace::Geometry for Geometry<'_> {
        fn num_faces(&self) -> usize {
            self.shapes.len()
        }
        fn num_vertices_of_face(&self, _face: usize) -> usize {
            3
        }
        fn position(&self, face: usize, vert: usize) -> [f32; 3] {
            let p = self.corners(face)[vert];
            [p.x, p.y, p.z]
        }
        fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
            let n = match self.normals {
                Some(n) => n[face][vert],
                None => {
                    let [a, b, c] = self.corners(face);
                    (b - a).cross(c - a).normalized()
                }
            };
            [n.x, n.y, n.z]
        }
        fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
            // glTF's v runs down the image; MikkTSpace's bitangent must point up it, where a
            // normal map's +y points (as the tangents Blender exports do).
            let (u, v) = self.uvs[face][vert];
            [u, 1.0 - v]
        }
        fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
            self.out[face][vert] = tangent;
        }
    }
    let mut geometry = Geometry {
        shapes,
        normals,
        uvs,
        out: vec![[[0.0; 4]; 3]; shapes.len()],
    };
    if !mikktspace::generate_tangents(&mut geometry) {
        // Degenerate input: zero tangents fall back to ∂p/∂u at the hit.
        geometry.out.iter_mut().for_each(|t| *t = [[0.0; 4]; 3]);
    }
    geometry.out
}
