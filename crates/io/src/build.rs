//! `SceneDesc` into the renderer's `SceneParts`: names resolved to indices, assets loaded,
//! transforms composed, emitters turned into lights plus visible geometry. Problems the user
//! can live with (a dangling reference) become warnings at the place they were written, and the
//! scene still builds with a visible fallback. A file that cannot be read is an error, reported
//! with every other such file of the scene (`Limits::allow_missing_assets` makes it a warning,
//! as the course renderer had it).
//!
//! Geometry layout:
//! * every plain sphere, triangle and box of the scene (and of shape lights) goes into one
//!   world-space `GeometryDesc`, placed by one instance without a transform;
//! * each instance definition that is used becomes one `GeometryDesc`, shared by every
//!   instance shape that places it: a mesh is never copied per instance;
//! * a mesh used directly as a shape gets its own `GeometryDesc` (one per OBJ file, shared if
//!   the file is named again); every OBJ file is read once;
//! * each visible area light adds a two-triangle emissive rectangle that casts no shadow.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use rayon::prelude::*;

use glint_render::{
    Background, Camera, Color, ColorSource, CubeMap, GeometryDesc, Image, Instance, Light,
    Material, MaterialId, Matrix4, SceneParts, Shape, TextureId, Transform, Vec3,
};

use crate::assets::{AssetError, Assets};
use crate::desc::{
    ColorDesc, LightKindDesc, Located, SceneDesc, ShaderKindDesc, ShapeDesc, ShapeKindDesc, Span,
    TextureDesc, TransformOperation, TransformStep,
};
use crate::diagnostic::{did_you_mean, Diagnostics, SceneError};
use crate::limits::Limits;
use crate::obj::load_triangles;
use crate::texture_io::{load_cube_map, load_image, read_image, Checked, TextureBudget};

pub(crate) fn build(
    desc: &SceneDesc,
    base_directory: &Path,
    assets: &dyn Assets,
    limits: &Limits,
    diagnostics: &mut Diagnostics,
) -> Result<SceneParts, SceneError> {
    let mut builder = Builder::new(desc, base_directory, assets, limits, diagnostics);
    builder.declare_textures();
    builder.prefetch_textures();
    builder.create_materials()?;
    builder.declare_definitions();
    for shape in &desc.shapes {
        builder.add_shape(shape)?;
    }
    for light in &desc.lights {
        builder.add_light(&light.kind)?;
    }
    let camera = builder.camera();
    let background = builder.background()?;
    Ok(builder.finish(camera, background))
}

/// Texture files held at once, read and waiting for their decode (`prefetch_textures`): 64 MiB,
/// some twenty of the course's largest.
const PREFETCH_BYTES: u64 = 64 << 20;

/// The mesh cache: every OBJ file is read once; `None` records a failure already reported.
type MeshCache = HashMap<PathBuf, Option<Rc<Vec<[Vec3; 3]>>>>;

struct Builder<'desc, 'diagnostics, 'text> {
    desc: &'desc SceneDesc,
    base_directory: &'desc Path,
    /// Where meshes, textures and environment maps are read from.
    assets: &'desc dyn Assets,
    diagnostics: &'diagnostics mut Diagnostics<'text>,
    materials: Vec<Material>,
    material_by_name: HashMap<&'desc str, MaterialId>,
    fallback_material: Option<MaterialId>,
    texture_by_name: HashMap<&'desc str, &'desc TextureDesc>,
    /// Loaded textures by name; `None` when loading failed (reported once).
    loaded_textures: HashMap<&'desc str, Option<TextureId>>,
    /// Loaded textures by file: texture entries naming the same image share one copy.
    textures_by_path: HashMap<PathBuf, Option<TextureId>>,
    textures: Vec<Image>,
    /// The shaders' texture images by file, read and decoded ahead (`prefetch_textures`),
    /// taken by `texture` as it first asks for each.
    prefetched: HashMap<PathBuf, Result<Image, AssetError>>,
    limits: Limits,
    /// Texture memory taken so far, checked against the limits before each decode.
    texture_budget: TextureBudget,
    definition_by_name: HashMap<&'desc str, usize>,
    /// Definitions whose own shader is needed: some instance shape places them without a
    /// shader of its own.
    definition_needs_shader: Vec<bool>,
    definition_geometry: HashMap<usize, Option<u32>>,
    direct_mesh_geometry: HashMap<PathBuf, Option<u32>>,
    meshes: MeshCache,
    /// All plain shapes, world space; becomes geometry 0.
    plain: GeometryDesc,
    geometries: Vec<GeometryDesc>,
    instances: Vec<Instance>,
    lights: Vec<Light>,
}

impl<'desc, 'diagnostics, 'text> Builder<'desc, 'diagnostics, 'text> {
    fn new(
        desc: &'desc SceneDesc,
        base_directory: &'desc Path,
        assets: &'desc dyn Assets,
        limits: &Limits,
        diagnostics: &'diagnostics mut Diagnostics<'text>,
    ) -> Self {
        Builder {
            desc,
            base_directory,
            assets,
            diagnostics,
            materials: Vec::new(),
            material_by_name: HashMap::new(),
            fallback_material: None,
            texture_by_name: HashMap::new(),
            loaded_textures: HashMap::new(),
            textures_by_path: HashMap::new(),
            textures: Vec::new(),
            prefetched: HashMap::new(),
            limits: *limits,
            texture_budget: TextureBudget::new(*limits),
            definition_by_name: HashMap::new(),
            definition_needs_shader: vec![false; desc.instance_definitions.len()],
            definition_geometry: HashMap::new(),
            direct_mesh_geometry: HashMap::new(),
            meshes: HashMap::new(),
            plain: GeometryDesc::default(),
            // Slot 0 is kept for the plain shapes, filled in `finish`.
            geometries: vec![GeometryDesc::default()],
            instances: Vec::new(),
            lights: Vec::new(),
        }
    }

    /// A file the scene names that cannot be read: an error, or with `allow_missing_assets`
    /// a warning saying what is used instead.
    fn missing_asset(&mut self, span: Span, message: String, fallback: &str) {
        let allowed = self.limits.allow_missing_assets;
        self.diagnostics
            .missing_asset(span, message, fallback, allowed);
    }

    fn resolve_path(&self, relative: &str) -> PathBuf {
        self.base_directory.join(relative)
    }

    fn camera(&self) -> Camera {
        // FORMAT.md 1.2: the first camera is used (the others were reported while reading).
        let camera = &self.desc.cameras[0];
        // FORMAT.md 1.2: lookatPoint wins over viewDir when both are given.
        let gaze = match (&camera.lookat_point, &camera.view_dir) {
            (Some(lookat_point), _) => lookat_point.value - camera.position,
            (None, Some(view_dir)) => view_dir.value,
            (None, None) => -Vec3::Z,
        };
        Camera::new(
            camera.projection,
            camera.position,
            gaze,
            camera.focal_length,
            camera.image_plane_width,
        )
    }

    // ---- materials and textures ----------------------------------------------------------

    fn declare_textures(&mut self) {
        for texture in &self.desc.textures {
            let name = texture.name.value.as_str();
            if let Some(earlier) = self.texture_by_name.insert(name, texture) {
                self.diagnostics.warn(
                    texture.name.span,
                    format!(
                        "texture `{name}` was already defined at line {}; this later definition \
                         is used",
                        earlier.span.line
                    ),
                );
            }
        }
    }

    /// Reads the texture images the shaders name in the order `create_materials` asks for them
    /// (each file once; the texture budget charged in that order, up to the first image it
    /// refuses), then decodes them in parallel for `texture` to take: one after the other,
    /// the decodes were most of a textured scene's load (ten 2048 x 1024 images, 190 ms of
    /// the solar system's 240). What `texture` then reports, and in which order, is what
    /// reading and decoding each image as it was first asked for gave. The files read and not
    /// yet decoded are held to `PREFETCH_BYTES` together (or the limit on one file's size,
    /// when lower): past it they are decoded before more are read, so that a load holds at
    /// most that much more file data than one file at a time did. (Their decoded images are
    /// charged to the texture budget before they are decoded, `BYTES_PER_TEXEL` covering
    /// the decoder's own buffers, so decoding them together takes no more than the budget.)
    fn prefetch_textures(&mut self) {
        let mut read: Vec<(PathBuf, Checked)> = Vec::new();
        let mut seen: HashSet<PathBuf> = HashSet::new();
        let mut held = 0u64;
        let decode =
            |read: &mut Vec<(PathBuf, Checked)>,
             prefetched: &mut HashMap<PathBuf, Result<Image, AssetError>>| {
                let decoded: Vec<_> = std::mem::take(read)
                    .into_par_iter()
                    .map(|(path, image)| (path, image.decode()))
                    .collect();
                prefetched.extend(decoded);
            };
        let colors = self
            .desc
            .shaders
            .iter()
            .filter(|shader| shader.name.is_some())
            .flat_map(|shader| shader.kind.colors());
        for color in colors {
            let Some(name) = &color.texture else { continue };
            let Some(declaration) = self.texture_by_name.get(name.value.as_str()) else {
                continue;
            };
            let path = self.resolve_path(&declaration.source_file.value);
            if !seen.insert(path.clone()) {
                continue;
            }
            match read_image(&path, self.assets, &mut self.texture_budget) {
                Ok(image) => {
                    held += image.file_bytes();
                    read.push((path, image));
                    if held > PREFETCH_BYTES.min(self.limits.max_file_bytes) {
                        decode(&mut read, &mut self.prefetched);
                        held = 0;
                    }
                }
                Err(error) => {
                    let refused = matches!(error, AssetError::Refused(_));
                    self.prefetched.insert(path, Err(error));
                    if refused {
                        // `texture` stops the load there.
                        break;
                    }
                }
            }
        }
        decode(&mut read, &mut self.prefetched);
    }

    fn create_materials(&mut self) -> Result<(), SceneError> {
        for shader in &self.desc.shaders {
            let Some(name) = &shader.name else { continue };
            let material = match &shader.kind {
                ShaderKindDesc::Unknown { .. } => None,
                kind => Some(self.material(kind)?),
            };
            let id = match material {
                Some(material) => self.push_material(material),
                // Reported while reading; shapes that use it get the fallback.
                None => self.fallback_material(),
            };
            if self.material_by_name.insert(&name.value, id).is_some() {
                // As the instructor's parser stores shaders in a map, a later definition
                // replaces an earlier one of the same name.
                self.diagnostics.warn(
                    name.span,
                    format!(
                        "shader `{}` is defined again; this later definition replaces the \
                         earlier one",
                        name.value
                    ),
                );
            }
        }
        Ok(())
    }

    fn push_material(&mut self, material: Material) -> MaterialId {
        self.materials.push(material);
        (self.materials.len() - 1) as MaterialId
    }

    /// FORMAT.md A16: dangling references and unknown shader types get a visible grey
    /// Lambertian instead of failing the load.
    fn fallback_material(&mut self) -> MaterialId {
        if let Some(id) = self.fallback_material {
            return id;
        }
        let id = self.push_material(Material::fallback());
        self.fallback_material = Some(id);
        id
    }

    fn material(&mut self, kind: &'desc ShaderKindDesc) -> Result<Material, SceneError> {
        // The colours resolved in `ShaderKindDesc::colors` order (diffuse, then specular): the
        // order `prefetch_textures` read their textures in.
        let mut resolved = [ColorSource::constant(Vec3::ZERO); 2];
        for (slot, color) in resolved.iter_mut().zip(kind.colors()) {
            *slot = self.color(color)?;
        }
        let [diffuse, specular] = resolved;
        Ok(match kind {
            ShaderKindDesc::Lambertian { .. } => Material::Lambertian { diffuse },
            ShaderKindDesc::BlinnPhong {
                phong_exp,
                mirror_coef,
                ..
            } => Material::BlinnPhong {
                diffuse,
                specular,
                phong_exponent: *phong_exp,
                mirror_coef: *mirror_coef,
            },
            ShaderKindDesc::Phong { phong_exp, .. } => Material::Phong {
                diffuse,
                specular,
                phong_exponent: *phong_exp,
            },
            ShaderKindDesc::Mirror { roughness } => Material::Mirror {
                roughness: *roughness,
            },
            ShaderKindDesc::Glaze { mirror_coef, .. } => Material::Glaze {
                diffuse,
                mirror_coef: *mirror_coef,
            },
            ShaderKindDesc::BlinnPhongMirrored {
                phong_exp,
                mirror_coef,
                roughness,
                ..
            } => Material::BlinnPhongMirrored {
                diffuse,
                specular,
                phong_exponent: *phong_exp,
                mirror_coef: *mirror_coef,
                roughness: *roughness,
            },
            ShaderKindDesc::Dielectric {
                refractive_index,
                attenuation_coef,
            } => Material::Dielectric {
                refractive_index: *refractive_index,
                attenuation: *attenuation_coef,
            },
            ShaderKindDesc::CoolToWarm { .. } => Material::CoolToWarm { diffuse },
            ShaderKindDesc::Diffuse { .. } => Material::Diffuse { diffuse },
            ShaderKindDesc::Unknown { .. } => Material::fallback(),
        })
    }

    /// A colour parameter with its texture loaded. FORMAT.md A17: a texture that is not
    /// defined or cannot be read leaves the plain colour.
    fn color(&mut self, color: &'desc ColorDesc) -> Result<ColorSource, SceneError> {
        let Some(texture_name) = &color.texture else {
            return Ok(ColorSource::constant(color.color));
        };
        let texture = self.texture(texture_name)?;
        Ok(ColorSource {
            color: color.color,
            texture,
        })
    }

    fn texture(&mut self, name: &'desc Located<String>) -> Result<Option<TextureId>, SceneError> {
        let Some(declaration) = self.texture_by_name.get(name.value.as_str()).copied() else {
            let suggestion = did_you_mean(&name.value, self.texture_by_name.keys().copied());
            self.diagnostics.warn(
                name.span,
                format!(
                    "texture `{}` is not defined{suggestion}; the plain colour is used",
                    name.value
                ),
            );
            return Ok(None);
        };
        let key = declaration.name.value.as_str();
        if let Some(loaded) = self.loaded_textures.get(key) {
            return Ok(*loaded);
        }
        let source = &declaration.source_file;
        let path = self.resolve_path(&source.value);
        if let Some(&shared) = self.textures_by_path.get(&path) {
            self.loaded_textures.insert(key, shared);
            return Ok(shared);
        }
        // Read and decoded by `prefetch_textures` (in this order), unless asked for otherwise.
        let outcome = match self.prefetched.remove(&path) {
            Some(outcome) => outcome,
            None => load_image(&path, self.assets, &mut self.texture_budget),
        };
        let loaded = match outcome {
            Ok(image) => {
                self.textures.push(image);
                Some((self.textures.len() - 1) as TextureId)
            }
            Err(AssetError::Refused(why)) => {
                return Err(self.diagnostics.error(
                    source.span,
                    format!(
                        "texture image `{}` ({}) is refused: {why}",
                        source.value,
                        path.display()
                    ),
                ))
            }
            Err(AssetError::Failed(error)) => {
                let message = format!(
                    "cannot read texture image `{}` (tried {}): {error}",
                    source.value,
                    self.assets.tried(&path).display()
                );
                let fallback = format!("shaders using texture `{key}` show their plain colour");
                self.missing_asset(source.span, message, &fallback);
                None
            }
        };
        self.loaded_textures.insert(key, loaded);
        self.textures_by_path.insert(path, loaded);
        Ok(loaded)
    }

    /// The material of a shader reference. A missing reference on a plain shape, or one that
    /// names no shader, gets the fallback (FORMAT.md A16).
    fn shader(
        &mut self,
        reference: Option<&'desc Located<String>>,
        owner_span: Span,
    ) -> MaterialId {
        let Some(reference) = reference else {
            self.diagnostics.warn(
                owner_span,
                "the shape has no shader; it gets a grey fallback material",
            );
            return self.fallback_material();
        };
        if let Some(&id) = self.material_by_name.get(reference.value.as_str()) {
            return id;
        }
        let suggestion = did_you_mean(&reference.value, self.material_by_name.keys().copied());
        self.diagnostics.warn(
            reference.span,
            format!(
                "shader `{}` is not defined{suggestion}; a grey fallback material is used",
                reference.value
            ),
        );
        self.fallback_material()
    }

    // ---- shapes and instances ------------------------------------------------------------

    fn declare_definitions(&mut self) {
        for (index, definition) in self.desc.instance_definitions.iter().enumerate() {
            let Some(name) = &definition.name else {
                self.diagnostics.warn(
                    definition.span,
                    "the instance definition has no `name`, so no shape can place it",
                );
                continue;
            };
            if self.definition_by_name.insert(name, index).is_some() {
                self.diagnostics.warn(
                    definition.span,
                    format!(
                        "instance `{name}` is defined again; this later definition replaces the \
                         earlier one"
                    ),
                );
            }
        }
        // FORMAT.md A15: an instance shape without a shader uses its definition's. Knowing
        // which definitions are placed that way lets a dangling shader in a definition that
        // every placement overrides (instructor files do this, A16) be reported as harmless.
        // Shape lights always draw with their emissive material, so only scene shapes count.
        for shape in &self.desc.shapes {
            if let ShapeKindDesc::Instance { id, .. } = &shape.kind {
                if shape.shader.is_none() {
                    if let Some(&index) = self.definition_by_name.get(id.value.as_str()) {
                        self.definition_needs_shader[index] = true;
                    }
                }
            }
        }
    }

    fn add_shape(&mut self, shape: &'desc ShapeDesc) -> Result<(), SceneError> {
        match &shape.kind {
            ShapeKindDesc::Sphere { .. }
            | ShapeKindDesc::Triangle { .. }
            | ShapeKindDesc::Box { .. } => {
                let material = self.shader(shape.shader.as_ref(), shape.span);
                self.add_plain(shape, material);
            }
            ShapeKindDesc::Mesh { file } => {
                let material = self.shader(shape.shader.as_ref(), shape.span);
                if let Some(geometry) = self.direct_mesh(file, material)? {
                    self.instances.push(Instance {
                        geometry,
                        transform: None,
                        material: Some(material),
                        casts_shadow: true,
                    });
                }
            }
            ShapeKindDesc::Instance { id, transform } => {
                let Some((geometry, _)) = self.placed_definition(id)? else {
                    return Ok(());
                };
                // FORMAT.md A15: without a shader of its own the instance keeps its
                // definition's (the geometry's materials).
                let material = shape
                    .shader
                    .as_ref()
                    .map(|reference| self.shader(Some(reference), shape.span));
                let transform = self.transform(transform)?;
                self.instances.push(Instance {
                    geometry,
                    transform: transform.map(|(transform, _)| transform),
                    material,
                    casts_shadow: true,
                });
            }
        }
        Ok(())
    }

    /// Adds a sphere, triangle or box to the world-space group.
    fn add_plain(&mut self, shape: &ShapeDesc, material: MaterialId) {
        if let Some(primitive) = primitive(&shape.kind) {
            self.plain.shapes.push(primitive);
            self.plain.materials.push(material);
        }
    }

    /// The OBJ triangles of `file`, read once per path.
    fn mesh(&mut self, file: &Located<String>) -> Result<Option<Rc<Vec<[Vec3; 3]>>>, SceneError> {
        let path = self.resolve_path(&file.value);
        if let Some(cached) = self.meshes.get(&path) {
            return Ok(cached.clone());
        }
        let loaded = match load_triangles(&path, self.assets, &self.limits) {
            Ok(triangles) if triangles.is_empty() => {
                self.diagnostics.warn(
                    file.span,
                    format!(
                        "OBJ file `{}` ({}) has no faces; the mesh is omitted",
                        file.value,
                        path.display()
                    ),
                );
                None
            }
            Ok(triangles) => Some(Rc::new(triangles)),
            Err(AssetError::Refused(why)) => {
                return Err(self.diagnostics.error(
                    file.span,
                    format!(
                        "OBJ file `{}` ({}) is refused: {why}",
                        file.value,
                        path.display()
                    ),
                ))
            }
            Err(AssetError::Failed(error)) => {
                // FORMAT.md A17: instructor files name meshes that exist nowhere; the course
                // renderer went on without them, which `allow_missing_assets` keeps.
                let message = format!(
                    "cannot read mesh `{}` (tried {}): {error}",
                    file.value,
                    self.assets.tried(&path).display()
                );
                self.missing_asset(file.span, message, "the mesh is omitted");
                None
            }
        };
        self.meshes.insert(path, loaded.clone());
        Ok(loaded)
    }

    fn push_geometry(&mut self, geometry: GeometryDesc) -> u32 {
        self.geometries.push(geometry);
        (self.geometries.len() - 1) as u32
    }

    fn mesh_geometry(
        &mut self,
        file: &Located<String>,
        material: MaterialId,
    ) -> Result<Option<u32>, SceneError> {
        let Some(triangles) = self.mesh(file)? else {
            return Ok(None);
        };
        let shapes: Vec<Shape> = triangles
            .par_iter()
            .with_min_len(4096)
            .map(|&vertices| Shape::Triangle { vertices })
            .collect();
        let materials = vec![material; shapes.len()];
        Ok(Some(self.push_geometry(GeometryDesc { shapes, materials })))
    }

    /// The geometry of a mesh used directly as a shape, shared by every shape naming the same
    /// file (each placement carries its own material).
    fn direct_mesh(
        &mut self,
        file: &Located<String>,
        material: MaterialId,
    ) -> Result<Option<u32>, SceneError> {
        let path = self.resolve_path(&file.value);
        if let Some(&geometry) = self.direct_mesh_geometry.get(&path) {
            return Ok(geometry);
        }
        let geometry = self.mesh_geometry(file, material)?;
        self.direct_mesh_geometry.insert(path, geometry);
        Ok(geometry)
    }

    /// The geometry of the definition an instance shape names, built on first use, and the
    /// definition itself.
    fn placed_definition(
        &mut self,
        id: &Located<String>,
    ) -> Result<Option<(u32, &'desc ShapeDesc)>, SceneError> {
        let Some(&index) = self.definition_by_name.get(id.value.as_str()) else {
            let suggestion = did_you_mean(&id.value, self.definition_by_name.keys().copied());
            self.diagnostics.warn(
                id.span,
                format!(
                    "instance `{}` is not defined{suggestion}; the shape is omitted",
                    id.value
                ),
            );
            return Ok(None);
        };
        let definitions = &self.desc.instance_definitions;
        let definition = &definitions[index];
        if let Some(&geometry) = self.definition_geometry.get(&index) {
            return Ok(geometry.map(|geometry| (geometry, definition)));
        }
        let material = self.definition_material(index);
        let geometry = match &definition.kind {
            ShapeKindDesc::Mesh { file } => self.mesh_geometry(file, material)?,
            kind => primitive(kind).map(|primitive| {
                self.push_geometry(GeometryDesc {
                    shapes: vec![primitive],
                    materials: vec![material],
                })
            }),
        };
        self.definition_geometry.insert(index, geometry);
        Ok(geometry.map(|geometry| (geometry, definition)))
    }

    /// A definition's own shader. FORMAT.md A16: instructor files give definitions shaders
    /// that do not exist and override them in every placement; that is reported but noted as
    /// harmless.
    fn definition_material(&mut self, index: usize) -> MaterialId {
        let definition = &self.desc.instance_definitions[index];
        let needed = self.definition_needs_shader[index];
        match &definition.shader {
            Some(reference) => {
                if let Some(&id) = self.material_by_name.get(reference.value.as_str()) {
                    return id;
                }
                let suggestion =
                    did_you_mean(&reference.value, self.material_by_name.keys().copied());
                let consequence = if needed {
                    "instances that do not set their own shader get a grey fallback material"
                } else {
                    "harmless here, as every instance of it sets its own shader"
                };
                self.diagnostics.warn(
                    reference.span,
                    format!(
                        "shader `{}` is not defined{suggestion}; {consequence}",
                        reference.value
                    ),
                );
            }
            None if needed => self.diagnostics.warn(
                definition.span,
                "the instance definition has no shader, and an instance of it sets none either; \
                 it gets a grey fallback material",
            ),
            None => {}
        }
        self.fallback_material()
    }

    /// The composed transform M = T1·T2·…·Tn of the listed steps (FORMAT.md 2.8, A5: the last
    /// listed applies to the object first), or `None` for an empty list.
    fn transform(
        &self,
        steps: &[TransformStep],
    ) -> Result<Option<(Transform, Matrix4)>, SceneError> {
        let Some(first) = steps.first() else {
            return Ok(None);
        };
        let matrix = compose(steps);
        let finite = matrix.m.iter().flatten().all(|value| value.is_finite());
        match Transform::from_matrix(&matrix).filter(|_| finite) {
            Some(transform) => Ok(Some((transform, matrix))),
            None => Err(self.diagnostics.error(
                first.span,
                "this transform cannot be inverted (a scale of zero?), so the instance cannot be \
                 placed",
            )),
        }
    }

    // ---- lights --------------------------------------------------------------------------

    fn add_light(&mut self, light: &'desc LightKindDesc) -> Result<(), SceneError> {
        match light {
            LightKindDesc::Point {
                position,
                intensity,
            } => self.lights.push(Light::Point {
                position: *position,
                intensity: *intensity,
            }),
            LightKindDesc::Area {
                position,
                intensity,
                normal,
                width,
                length,
                visible,
            } => {
                let normal = normal.normalized();
                self.lights.push(Light::Area {
                    position: *position,
                    normal,
                    width: *width,
                    length: *length,
                    intensity: *intensity,
                });
                // FORMAT.md A10: the light is visible to camera rays with colour = intensity
                // and blocks no shadow ray; the student extension `"visible": 0` hides it.
                if *visible {
                    let light_index = (self.lights.len() - 1) as u32;
                    let material = self.push_material(Material::Emissive {
                        radiance: *intensity,
                        surface: None,
                        light: Some(light_index),
                    });
                    let (u_edge, v_edge) = Light::area_edges(normal, *width, *length);
                    let shapes = rectangle(*position, u_edge, v_edge, normal)
                        .map(|vertices| Shape::Triangle { vertices })
                        .to_vec();
                    let geometry = self.push_geometry(GeometryDesc {
                        materials: vec![material; shapes.len()],
                        shapes,
                    });
                    self.instances.push(Instance {
                        geometry,
                        transform: None,
                        material: None,
                        casts_shadow: false,
                    });
                }
            }
            LightKindDesc::Shape { intensity, shape } => self.add_emitter(*intensity, shape)?,
        }
        Ok(())
    }

    /// FORMAT.md A11: a shape light is the shape, drawn with an emissive material, plus a light
    /// that samples points on it. The shape's own shader stays as the emitter's surface.
    fn add_emitter(&mut self, intensity: Color, shape: &'desc ShapeDesc) -> Result<(), SceneError> {
        let surface = shape
            .shader
            .as_ref()
            .map(|reference| self.shader(Some(reference), shape.span));
        match &shape.kind {
            ShapeKindDesc::Sphere { center, radius } => {
                let light = self.push_light(Light::Sphere {
                    center: *center,
                    radius: *radius,
                    intensity,
                });
                let material = self.emissive(intensity, surface, Some(light));
                self.add_plain(shape, material);
            }
            ShapeKindDesc::Triangle { .. } | ShapeKindDesc::Box { .. } => {
                let triangles = primitive(&shape.kind).map_or_else(Vec::new, |p| triangles_of(&p));
                let light = self.push_light(Light::Triangles {
                    triangles,
                    intensity,
                });
                let material = self.emissive(intensity, surface, Some(light));
                self.add_plain(shape, material);
            }
            ShapeKindDesc::Mesh { file } => {
                let Some(triangles) = self.mesh(file)? else {
                    return Ok(());
                };
                let light = self.push_light(Light::Triangles {
                    triangles: triangles.to_vec(),
                    intensity,
                });
                let material = self.emissive(intensity, surface, Some(light));
                if let Some(geometry) = self.direct_mesh(file, material)? {
                    self.instances.push(Instance {
                        geometry,
                        transform: None,
                        material: Some(material),
                        casts_shadow: true,
                    });
                }
            }
            ShapeKindDesc::Instance { id, transform } => {
                let Some((geometry, definition)) = self.placed_definition(id)? else {
                    return Ok(());
                };
                let transform = self.transform(transform)?;
                let light =
                    match self.world_light(definition, transform.map(|(_, m)| m), intensity)? {
                        Some(light) => Some(self.push_light(light)),
                        None => {
                            self.diagnostics.warn(
                            shape.span,
                            "this emitter is a sphere scaled unevenly, which cannot be sampled as \
                             a light: it is drawn glowing but lights nothing directly",
                        );
                            None
                        }
                    };
                let material = self.emissive(intensity, surface, light);
                self.instances.push(Instance {
                    geometry,
                    transform: transform.map(|(transform, _)| transform),
                    material: Some(material),
                    casts_shadow: true,
                });
            }
        }
        Ok(())
    }

    fn push_light(&mut self, light: Light) -> u32 {
        self.lights.push(light);
        (self.lights.len() - 1) as u32
    }

    fn emissive(
        &mut self,
        radiance: Color,
        surface: Option<MaterialId>,
        light: Option<u32>,
    ) -> MaterialId {
        self.push_material(Material::Emissive {
            radiance,
            surface,
            light,
        })
    }

    /// The light for an instanced emitter, in world space; `None` for a sphere under a
    /// transform that does not keep it a sphere.
    fn world_light(
        &mut self,
        definition: &'desc ShapeDesc,
        matrix: Option<Matrix4>,
        intensity: Color,
    ) -> Result<Option<Light>, SceneError> {
        let matrix = matrix.unwrap_or(Matrix4::IDENTITY);
        Ok(match &definition.kind {
            ShapeKindDesc::Sphere { center, radius } => {
                uniform_scale(&matrix).map(|scale| Light::Sphere {
                    center: matrix.transform_point(*center),
                    radius: radius * scale,
                    intensity,
                })
            }
            ShapeKindDesc::Mesh { file } => {
                let triangles = self.mesh(file)?.map_or_else(Vec::new, |mesh| mesh.to_vec());
                Some(Light::Triangles {
                    triangles: transform_triangles(&triangles, &matrix),
                    intensity,
                })
            }
            kind => {
                let triangles = primitive(kind).map_or_else(Vec::new, |p| triangles_of(&p));
                Some(Light::Triangles {
                    triangles: transform_triangles(&triangles, &matrix),
                    intensity,
                })
            }
        })
    }

    // ---- background and result -----------------------------------------------------------

    fn background(&mut self) -> Result<Background, SceneError> {
        let background = &self.desc.background;
        // FORMAT.md A4: sceneParameters.bgColor outranks the scene's bgColor/_bgColor; black
        // when neither is given.
        let color = background
            .parameters_bg_color
            .as_ref()
            .or(background.scene_bg_color.as_ref())
            .map_or(Vec3::ZERO, |color| color.value);
        if let Some(prefix) = &background.env_map_prefix {
            match load_cube_map(
                self.base_directory,
                &prefix.value,
                self.assets,
                &mut self.texture_budget,
            ) {
                Ok(map) => return Ok(Background::CubeMap(Box::new(map))),
                Err(AssetError::Refused(why)) => {
                    return Err(self.diagnostics.error(
                        prefix.span,
                        format!("environment map `{}` is refused: {why}", prefix.value),
                    ))
                }
                // FORMAT.md 2.1, A17: `data/reef_` never existed; the course renderer drew
                // the background colour instead, which `allow_missing_assets` keeps.
                Err(AssetError::Failed(error)) => {
                    self.missing_asset(prefix.span, error, "the background colour is used instead")
                }
            }
        }
        if let Some(cross) = &background.env_map_vertical_cross {
            let path = self.resolve_path(&cross.value);
            let faces = match read_image(&path, self.assets, &mut self.texture_budget)
                .and_then(Checked::decode_cross)
            {
                Err(AssetError::Refused(why)) => {
                    return Err(self.diagnostics.error(
                        cross.span,
                        format!(
                            "environment map `{}` ({}) is refused: {why}",
                            cross.value,
                            path.display()
                        ),
                    ))
                }
                Err(AssetError::Failed(error)) => Err(format!(
                    "cannot read environment map `{}` (tried {}): {error}",
                    cross.value,
                    self.assets.tried(&path).display()
                )),
                Ok(faces) => faces,
            };
            match faces {
                Ok(faces) => return Ok(Background::CubeMap(Box::new(CubeMap { faces }))),
                Err(error) => {
                    self.missing_asset(cross.span, error, "the background colour is used instead")
                }
            }
        }
        Ok(Background::Color(color))
    }

    fn finish(mut self, camera: Camera, background: Background) -> SceneParts {
        let plain = std::mem::take(&mut self.plain);
        if plain.shapes.is_empty() {
            // No plain shapes: drop the reserved slot 0 and renumber.
            self.geometries.remove(0);
            for instance in &mut self.instances {
                instance.geometry -= 1;
            }
        } else {
            self.geometries[0] = plain;
            self.instances.insert(
                0,
                Instance {
                    geometry: 0,
                    transform: None,
                    material: None,
                    casts_shadow: true,
                },
            );
        }
        if self.instances.is_empty() {
            self.diagnostics.warn(
                self.desc.span,
                "the scene has no shapes; the image shows only the background",
            );
        }
        SceneParts {
            physical: Default::default(),
            camera,
            materials: self.materials,
            textures: self.textures,
            lights: self.lights,
            background,
            geometries: self.geometries,
            instances: self.instances,
        }
    }
}

/// The renderer's primitive for a sphere, triangle or box description.
fn primitive(kind: &ShapeKindDesc) -> Option<Shape> {
    match *kind {
        ShapeKindDesc::Sphere { center, radius } => Some(Shape::Sphere { center, radius }),
        ShapeKindDesc::Triangle { vertices } => Some(Shape::Triangle { vertices }),
        ShapeKindDesc::Box { min_pt, max_pt } => Some(Shape::Box {
            min: min_pt,
            max: max_pt,
        }),
        ShapeKindDesc::Mesh { .. } | ShapeKindDesc::Instance { .. } => None,
    }
}

pub(crate) fn compose(steps: &[TransformStep]) -> Matrix4 {
    steps.iter().fold(Matrix4::IDENTITY, |matrix, step| {
        let step_matrix = match step.operation {
            TransformOperation::Translate(offset) => Matrix4::translate(offset),
            TransformOperation::Rotate { axis, degrees } => Matrix4::rotate(axis, degrees),
            TransformOperation::Scale(factors) => Matrix4::scale(factors),
        };
        matrix.mul(&step_matrix)
    })
}

/// The scale factor when the matrix's linear part is a rotation times one uniform scale.
fn uniform_scale(matrix: &Matrix4) -> Option<f32> {
    let column = |j: usize| [matrix.m[0][j], matrix.m[1][j], matrix.m[2][j]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let columns = [column(0), column(1), column(2)];
    let squared: Vec<f64> = columns.iter().map(|&c| dot(c, c)).collect();
    let reference = squared[0];
    let tolerance = 1e-6 * reference.max(f64::MIN_POSITIVE);
    let equal_lengths = squared.iter().all(|&s| (s - reference).abs() <= tolerance);
    let orthogonal =
        (0..3).all(|i| ((i + 1)..3).all(|j| dot(columns[i], columns[j]).abs() <= tolerance));
    (equal_lengths && orthogonal && reference > 0.0).then(|| reference.sqrt() as f32)
}

fn transform_triangles(triangles: &[[Vec3; 3]], matrix: &Matrix4) -> Vec<[Vec3; 3]> {
    triangles
        .iter()
        .map(|triangle| triangle.map(|vertex| matrix.transform_point(vertex)))
        .collect()
}

/// The triangles of a triangle or box (12, facing outward), for emitters.
fn triangles_of(shape: &Shape) -> Vec<[Vec3; 3]> {
    match *shape {
        Shape::Triangle { vertices } => vec![vertices],
        Shape::Box { min, max } => box_triangles(min, max),
        Shape::Sphere { .. } => Vec::new(),
    }
}

fn box_triangles(min: Vec3, max: Vec3) -> Vec<[Vec3; 3]> {
    let corner = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { max.x } else { min.x },
            if y { max.y } else { min.y },
            if z { max.z } else { min.z },
        )
    };
    let center = (min + max) * 0.5;
    let mut triangles = Vec::with_capacity(12);
    for axis in 0..3 {
        for high in [false, true] {
            // The four corners of the face with coordinate `axis` at min or max, in order
            // around the face.
            let face: Vec<Vec3> = [(false, false), (true, false), (true, true), (false, true)]
                .iter()
                .map(|&(a, b)| match axis {
                    0 => corner(high, a, b),
                    1 => corner(b, high, a),
                    _ => corner(a, b, high),
                })
                .collect();
            let face_center = (face[0] + face[2]) * 0.5;
            for triangle in [[face[0], face[1], face[2]], [face[0], face[2], face[3]]] {
                triangles.push(facing(triangle, face_center - center));
            }
        }
    }
    triangles
}

/// The triangle wound so its geometric normal (v1−v0)×(v2−v0) points along `direction`.
fn facing(triangle: [Vec3; 3], direction: Vec3) -> [Vec3; 3] {
    let [a, b, c] = triangle;
    if (b - a).cross(c - a).dot(direction) < 0.0 {
        [a, c, b]
    } else {
        triangle
    }
}

/// The two triangles of an area light's rectangle: corners position ± u/2 ± v/2, wound to
/// face `normal`.
fn rectangle(position: Vec3, u_edge: Vec3, v_edge: Vec3, normal: Vec3) -> [[Vec3; 3]; 2] {
    let corner = |s: f32, t: f32| position + u_edge * (0.5 * s) + v_edge * (0.5 * t);
    let (p00, p10, p11, p01) = (
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    );
    [
        facing([p00, p10, p11], normal),
        facing([p00, p11, p01], normal),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_triangles_face_outward_and_cover_the_area() {
        let triangles = box_triangles(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(triangles.len(), 12);
        let center = Vec3::new(0.5, 1.0, 1.5);
        let mut area = 0.0;
        for [a, b, c] in &triangles {
            let cross = (*b - *a).cross(*c - *a);
            area += 0.5 * cross.length();
            let centroid = (*a + *b + *c) / 3.0;
            assert!(cross.dot(centroid - center) > 0.0);
        }
        assert!((area - 2.0 * (2.0 + 6.0 + 3.0)).abs() < 1e-5);
    }

    #[test]
    fn rectangle_faces_its_normal() {
        let normal = Vec3::new(0.0, -1.0, 0.0);
        let (u, v) = Light::area_edges(normal, 2.0, 4.0);
        for [a, b, c] in rectangle(Vec3::new(0.0, 5.0, 0.0), u, v, normal) {
            assert!((b - a).cross(c - a).dot(normal) > 0.0);
        }
    }

    #[test]
    fn uniform_scale_is_recognised() {
        let matrix = Matrix4::translate(Vec3::new(1.0, 2.0, 3.0))
            .mul(&Matrix4::rotate(2, 30.0))
            .mul(&Matrix4::scale(Vec3::splat(2.0)));
        assert!((uniform_scale(&matrix).unwrap() - 2.0).abs() < 1e-6);
        let uneven = Matrix4::scale(Vec3::new(1.0, 2.0, 1.0));
        assert_eq!(uniform_scale(&uneven), None);
    }
}
