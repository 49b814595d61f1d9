//! Participating media as Mitsuba 3.9.1 reads them: `homogeneous` and `heterogeneous` media,
//! the volumes they read (`constvolume`, `gridvolume`), their phase functions (`isotropic`,
//! `hg`), the media a shape bounds (`interior`, `exterior`) and the sensor's.
//!
//! A medium's `sigma_t` and `albedo` are volumes in Mitsuba; a plain float, rgb or spectrum
//! becomes a `constvolume` with an identity `to_world`, whose box is the unit cube. Only a
//! heterogeneous medium reads that box (its extinction lives inside `sigma_t`'s box); a
//! homogeneous one takes the value alone.

use glint_render::{
    Color, Matrix4, Medium, MediumBoundary, MediumId, PhaseFunction, Transform, Volume, VolumeGrid,
};

use crate::diagnostic::{did_you_mean, SceneError};
use crate::mitsuba::parse::Element;
use crate::mitsuba::props::{Property, Props, Value};
use crate::mitsuba::sdfgrid;
use crate::mitsuba::spectrum::Role;

use super::{color, determinant3};

/// A medium's `sigma_t` or `albedo` as given: a plain value, or a volume.
enum Quantity {
    /// A float, rgb or spectrum: Mitsuba's `constvolume` over the unit cube.
    Plain(Color),
    Volume(Volume),
}

/// Mitsuba's defaults for a medium's `sigma_t` and `albedo`.
const DEFAULT_SIGMA_T: f32 = 1.0;
const DEFAULT_ALBEDO: f32 = 0.75;
/// `hg`'s default asymmetry.
const DEFAULT_G: f64 = 0.8;

impl<'a> super::Builder<'a> {
    /// The `PhysicalParts::media` index of `element` (a `<medium>`), built and added the first
    /// time it is used.
    pub(super) fn medium_id(&mut self, element: &'a Element) -> Result<MediumId, SceneError> {
        if let Some(&id) = self.media.get(&element.index) {
            return Ok(id);
        }
        let medium = self.medium(element)?;
        let id = self.parts.physical.media.len() as MediumId;
        self.parts.physical.media.push(medium);
        self.media.insert(element.index, id);
        Ok(id)
    }

    /// A `<medium>`, built once per element.
    pub(super) fn medium(&mut self, element: &'a Element) -> Result<Medium, SceneError> {
        if let Some(medium) = self.built_media.get(&element.index) {
            return Ok(medium.clone());
        }
        let props = Props::read(element, self.files)?;
        let homogeneous = match props.plugin.as_str() {
            "homogeneous" => true,
            "heterogeneous" => false,
            other => {
                let hint = did_you_mean(other, ["homogeneous", "heterogeneous"]);
                return Err(self.element_error(
                    element,
                    format!("the medium `{other}` is not supported{hint}"),
                ));
            }
        };
        let scale = props.float(self.files, "scale", 1.0)?;
        if !(scale >= 0.0 && (scale as f32).is_finite()) {
            let p = props.get("scale").expect("a bad scale was given");
            return Err(self.error(
                p.file,
                p.span,
                format!("the medium's `scale` must be finite and not negative, not {scale}"),
            ));
        }
        let scale = scale as f32;
        let sample_emitters = props.boolean(self.files, "sample_emitters", true)?;
        // Whether Mitsuba's estimator treats the extinction as varying over the spectrum: a
        // choice of estimator, not of the image it converges to.
        props.boolean(self.files, "has_spectral_extinction", true)?;
        let phase = self.medium_phase(&props)?;
        let sigma_t = self.quantity(&props, "sigma_t", DEFAULT_SIGMA_T)?;
        let albedo = self.quantity(&props, "albedo", DEFAULT_ALBEDO)?;
        props.check_all_used(self.files)?;
        if let Some(negative) = self.negative_extinction(&sigma_t) {
            let p = props.get("sigma_t").expect("a default is not negative");
            return Err(self.error(
                p.file,
                p.span,
                format!(
                    "the extinction `sigma_t` holds {negative}; it must not be negative \
                     (distances are sampled in proportion to it)"
                ),
            ));
        }
        let medium = if homogeneous {
            let constant = |quantity: Quantity, name: &str| match quantity {
                Quantity::Plain(value) => Ok(value),
                Quantity::Volume(Volume::Constant { value, .. }) => Ok(value),
                Quantity::Volume(Volume::Grid { .. }) => {
                    let p = props.get(name).expect("a grid was given");
                    Err(self.error(
                        p.file,
                        p.span,
                        format!(
                            "a homogeneous medium takes a constant `{name}`, not a gridvolume \
                             (a heterogeneous medium reads grids)"
                        ),
                    ))
                }
            };
            Medium::Homogeneous {
                sigma_t: constant(sigma_t, "sigma_t")? * scale,
                albedo: constant(albedo, "albedo")?,
                phase,
                sample_emitters,
            }
        } else {
            let volume = |quantity: Quantity| match quantity {
                Quantity::Plain(value) => Volume::constant(value, &identity()),
                Quantity::Volume(volume) => volume,
            };
            Medium::Heterogeneous {
                sigma_t: volume(sigma_t),
                albedo: volume(albedo),
                scale,
                phase,
                sample_emitters,
            }
        };
        self.built_media.insert(element.index, medium.clone());
        Ok(medium)
    }

    /// The most negative value `sigma_t` holds, if any is negative.
    fn negative_extinction(&self, sigma_t: &Quantity) -> Option<f32> {
        let least = match sigma_t {
            Quantity::Plain(value) | Quantity::Volume(Volume::Constant { value, .. }) => {
                value.min_component()
            }
            Quantity::Volume(Volume::Grid { grid, .. }) => {
                grid.data.iter().copied().fold(f32::INFINITY, f32::min)
            }
        };
        (least < 0.0).then_some(least)
    }

    /// The medium's phase function: its one nested `<phase>` (under any name, as Mitsuba
    /// takes it), isotropic when there is none.
    fn medium_phase(&mut self, props: &Props<'a>) -> Result<PhaseFunction, SceneError> {
        let mut phase = None;
        for p in &props.list {
            let is_object = matches!(p.value, Value::Object(_) | Value::Ref(_));
            if !is_object || p.name == "sigma_t" || p.name == "albedo" {
                continue;
            }
            let child = self.resolve(p)?;
            if child.tag != "phase" {
                return Err(self.error(
                    p.file,
                    p.span,
                    format!(
                        "a medium takes a phase function and its `sigma_t` and `albedo`, not \
                         a <{}>",
                        child.tag
                    ),
                ));
            }
            if phase.is_some() {
                return Err(self.error(p.file, p.span, "a medium takes one phase function"));
            }
            p.queried.set(true);
            phase = Some(self.phase(child)?);
        }
        Ok(phase.unwrap_or(PhaseFunction::Isotropic))
    }

    /// A `<phase>`.
    pub(super) fn phase(&mut self, element: &'a Element) -> Result<PhaseFunction, SceneError> {
        let props = Props::read(element, self.files)?;
        let phase = match props.plugin.as_str() {
            "isotropic" => PhaseFunction::Isotropic,
            "hg" => {
                let g = props.float(self.files, "g", DEFAULT_G)?;
                // Checked in single precision, where the lobe is evaluated: 1 − 1e-9 is 1 there
                // (`g` is finite: the reader refuses other numbers).
                if (g as f32).abs() >= 1.0 {
                    let p = props.get("g").expect("the default is in range");
                    return Err(self.error(
                        p.file,
                        p.span,
                        format!("the asymmetry parameter `g` must lie in (-1, 1), not {g}"),
                    ));
                }
                PhaseFunction::HenyeyGreenstein { g: g as f32 }
            }
            other => {
                let hint = did_you_mean(other, ["isotropic", "hg"]);
                return Err(self.element_error(
                    element,
                    format!(
                        "the phase function `{other}` is not supported (Glint reads isotropic \
                         and hg){hint}"
                    ),
                ));
            }
        };
        props.check_all_used(self.files)?;
        Ok(phase)
    }

    /// `sigma_t` or `albedo` of a medium: a float, rgb or spectrum (read as Mitsuba reads a
    /// plain value for a volume: an rgb must lie in [0, 1], a spectrum is converted as a
    /// reflectance), a `<spectrum>` plugin, or a `<volume>`.
    fn quantity(
        &mut self,
        props: &Props<'a>,
        name: &str,
        default: f32,
    ) -> Result<Quantity, SceneError> {
        let Some(p) = props.get(name) else {
            return Ok(Quantity::Plain(Color::splat(default)));
        };
        let (file, span) = (p.file, p.span);
        let value = match &p.value {
            Value::Float(v) => Color::splat(*v as f32),
            Value::Rgb(rgb) => {
                if rgb.iter().any(|c| !(0.0..=1.0).contains(c)) {
                    return Err(self.error(
                        file,
                        span,
                        format!(
                            "invalid RGB value {rgb:?} for `{name}`: Mitsuba reads a plain rgb \
                             here as a reflectance, in [0, 1]; use a float, or a constvolume \
                             (whose `value` is unbounded)"
                        ),
                    ));
                }
                color(*rgb)
            }
            Value::Spectrum(spectrum) => self.spectrum(spectrum, Role::Reflectance, file, span)?,
            Value::Object(_) | Value::Ref(_) => {
                let child = self.resolve(p)?;
                match child.tag.as_str() {
                    "volume" => return Ok(Quantity::Volume(self.volume(child)?)),
                    "spectrum" => self.spectrum_plugin(child)?,
                    other => {
                        return Err(self.error(
                            file,
                            span,
                            format!(
                                "`{name}` of `{}` must be a float, rgb, spectrum or volume, \
                                 not a <{other}>",
                                props.plugin
                            ),
                        ))
                    }
                }
            }
            other => {
                return Err(self.error(
                    file,
                    span,
                    format!(
                        "`{name}` of `{}` must be a float, rgb, spectrum or volume, not {}",
                        props.plugin,
                        other.kind()
                    ),
                ))
            }
        };
        Ok(Quantity::Plain(value))
    }

    /// A `<volume>`, built once per element.
    pub(super) fn volume(&mut self, element: &'a Element) -> Result<Volume, SceneError> {
        if let Some(volume) = self.volumes.get(&element.index) {
            return Ok(volume.clone());
        }
        let props = Props::read(element, self.files)?;
        let to_world = props
            .transform(self.files, "to_world")?
            .unwrap_or(Matrix4::IDENTITY);
        let place = |builder: &Self, m: &Matrix4, why: &str| {
            Transform::from_matrix(m).ok_or_else(|| {
                let (file, span) = props
                    .get("to_world")
                    .map_or((element.file, element.span), |p| (p.file, p.span));
                builder.error(file, span, format!("the volume's to_world {why}"))
            })
        };
        let volume = match props.plugin.as_str() {
            "constvolume" => {
                let value = self.volume_value(&props)?;
                props.check_all_used(self.files)?;
                Volume::constant(value, &place(self, &to_world, "cannot be inverted")?)
            }
            "gridvolume" => {
                let (name, span, file) =
                    props.string(self.files, "filename")?.ok_or_else(|| {
                        self.element_error(element, "`gridvolume` needs a `filename` (a .vol grid)")
                    })?;
                let choice = |setting: &str, supported: &str, known: &[&str]| {
                    let Some((text, span, file)) = props.string(self.files, setting)? else {
                        return Ok(());
                    };
                    if text == supported {
                        return Ok(());
                    }
                    let why = if known.contains(&text.as_str()) {
                        format!(
                            "{setting} \"{text}\" is not supported: Glint's grids take \
                             \"{supported}\" only"
                        )
                    } else {
                        format!(
                            "invalid {setting} \"{text}\": must be one of {}",
                            known.join(", ")
                        )
                    };
                    Err(self.error(file, span, why))
                };
                choice("filter_type", "trilinear", &["trilinear", "nearest"])?;
                choice("wrap_mode", "clamp", &["clamp", "repeat", "mirror"])?;
                // `raw` only stops the spectral variants' conversion of RGB grids, and
                // `accel` chooses how Dr.Jit looks texels up: neither changes an RGB render.
                props.boolean(self.files, "raw", false)?;
                props.boolean(self.files, "accel", true)?;
                let use_grid_bbox = props.boolean(self.files, "use_grid_bbox", false)?;
                if let Some(p) = props.get("max_value") {
                    return Err(self.error(
                        p.file,
                        p.span,
                        "`max_value` is not supported: Glint's majorant is the grid's true \
                         maximum, so that null collisions never get a negative density",
                    ));
                }
                props.check_all_used(self.files)?;
                let path = self.find(&name);
                let bytes = self.read(&path, file, span, &name, "volume grid")?;
                let cannot = |why: String| {
                    self.error(
                        file,
                        span,
                        format!("cannot read \"{name}\" ({}): {why}", path.display()),
                    )
                };
                let grid = sdfgrid::read_vol(&bytes, self.limits)
                    .map_err(|error| cannot(error.to_string()))?;
                if grid.channels != 1 && grid.channels != 3 {
                    return Err(cannot(format!(
                        "it has {} channels; a volume has 1 or 3",
                        grid.channels
                    )));
                }
                // Mitsuba's `use_grid_bbox` maps the unit cube onto the file's box first.
                let (placement, why) = if use_grid_bbox {
                    let m = to_world
                        .mul(&Matrix4::translate(grid.bbox_min))
                        .mul(&Matrix4::scale(grid.bbox_max - grid.bbox_min));
                    (
                        m,
                        "with the file's bounding box cannot be inverted (a flat box?)",
                    )
                } else {
                    (to_world, "cannot be inverted")
                };
                let transform = place(self, &placement, why)?;
                Volume::grid(
                    VolumeGrid {
                        size: grid.size,
                        channels: grid.channels,
                        data: grid.data,
                    },
                    transform,
                )
            }
            other => {
                let hint = did_you_mean(other, ["constvolume", "gridvolume"]);
                return Err(self.element_error(
                    element,
                    format!("the volume `{other}` is not supported{hint}"),
                ));
            }
        };
        self.volumes.insert(element.index, volume.clone());
        Ok(volume)
    }

    /// A `constvolume`'s `value` (default 1), unbounded as Mitsuba reads it.
    fn volume_value(&mut self, props: &Props<'a>) -> Result<Color, SceneError> {
        let Some(p) = props.get("value") else {
            return Ok(Color::ONE);
        };
        let (file, span) = (p.file, p.span);
        Ok(match &p.value {
            Value::Float(v) => Color::splat(*v as f32),
            Value::Integer(v) => Color::splat(*v as f32),
            Value::Rgb(rgb) => color(*rgb),
            Value::Spectrum(spectrum) => self.spectrum(spectrum, Role::Unbounded, file, span)?,
            Value::Object(_) | Value::Ref(_) => {
                let child = self.resolve(p)?;
                if child.tag != "spectrum" {
                    return Err(self.error(
                        file,
                        span,
                        format!(
                            "a constvolume's `value` must be a float, rgb or spectrum, not a \
                             <{}>",
                            child.tag
                        ),
                    ));
                }
                self.spectrum_plugin(child)?
            }
            other => {
                return Err(self.error(
                    file,
                    span,
                    format!(
                        "a constvolume's `value` must be a float, rgb or spectrum, not {}",
                        other.kind()
                    ),
                ))
            }
        })
    }

    /// The named properties of `props` that are media (nested, or references to one), other
    /// than the unnamed ones.
    pub(super) fn named_media<'p>(&self, props: &'p Props<'a>) -> Vec<&'p Property<'a>> {
        props
            .list
            .iter()
            .filter(|p| !p.name.starts_with("_arg_"))
            .filter(|p| match &p.value {
                Value::Object(element) => element.tag == "medium",
                Value::Ref(id) => self.ids.get(id).is_some_and(|e| e.tag == "medium"),
                _ => false,
            })
            .collect()
    }

    /// An emitter's medium (under any name, as Mitsuba's endpoints take it): checked, and
    /// ignored with a warning, as Mitsuba 3.9.1's integrators read only the sensor's.
    pub(super) fn ignore_emitter_media(&mut self, props: &Props<'a>) -> Result<(), SceneError> {
        let media: Vec<&Property<'a>> = props
            .list
            .iter()
            .filter(|p| match &p.value {
                Value::Object(element) => element.tag == "medium",
                Value::Ref(id) => self.ids.get(id).is_some_and(|e| e.tag == "medium"),
                _ => false,
            })
            .collect();
        for p in media {
            p.queried.set(true);
            let element = self.resolve(p)?;
            self.medium(element)?;
            self.files.warn(
                p.file,
                p.span,
                "an emitter's medium is ignored (no integrator of Mitsuba 3.9.1 reads it)",
            );
        }
        Ok(())
    }

    /// A shape's `interior` and `exterior` media; `None` when it names neither. Media under
    /// other names are refused (Mitsuba ignores them silently).
    pub(super) fn shape_media(
        &mut self,
        props: &Props<'a>,
    ) -> Result<Option<MediumBoundary>, SceneError> {
        if let Some(p) = self
            .named_media(props)
            .into_iter()
            .find(|p| p.name != "interior" && p.name != "exterior")
        {
            return Err(self.error(
                p.file,
                p.span,
                format!(
                    "a shape's media are named `interior` or `exterior`, not `{}`",
                    p.name
                ),
            ));
        }
        let mut boundary = MediumBoundary::default();
        for name in ["interior", "exterior"] {
            let Some(p) = props.get(name) else { continue };
            let element = match &p.value {
                Value::Object(_) | Value::Ref(_) => self.resolve(p)?,
                other => {
                    return Err(self.error(
                        p.file,
                        p.span,
                        format!(
                            "`{name}` must be a medium (nested or a <ref>), not {}",
                            other.kind()
                        ),
                    ))
                }
            };
            if element.tag != "medium" {
                return Err(self.error(
                    p.file,
                    p.span,
                    format!("`{name}` must be a medium, not a <{}>", element.tag),
                ));
            }
            let id = self.medium_id(element)?;
            if name == "interior" {
                boundary.interior = Some(id);
            } else {
                boundary.exterior = Some(id);
            }
        }
        Ok((boundary != MediumBoundary::default()).then_some(boundary))
    }

    /// Records the media geometry `geometry` bounds, with its sides as Mitsuba has them.
    ///
    /// Mitsuba sends a ray crossing a surface along its geometric normal into the exterior
    /// medium; Glint's volumetric path tracer does the same with Glint's normal, the
    /// object-space normal carried to the world by the inverse transpose, which keeps the
    /// side it points to whatever `to_world` is. Mitsuba's meshes (`obj`, `ply`,
    /// `serialized`, `rectangle`, `cube`) instead take the cross product of their edges in
    /// the world, which turns to the other side under a mirroring `to_world`, and its
    /// `sphere` toggles `flip_normals` when the scale of its `to_world` is negative: under a
    /// mirror their normal is the opposite of Glint's, so their media swap sides. The
    /// `cylinder` (whose mirror the mesh already takes), `disk` and `sdfgrid` carry their
    /// normals as Glint does.
    pub(super) fn set_boundary(
        &mut self,
        geometry: u32,
        boundary: MediumBoundary,
        plugin: &str,
        to_world: &Matrix4,
    ) {
        let turned = matches!(
            plugin,
            "obj" | "ply" | "serialized" | "rectangle" | "cube" | "sphere"
        ) && determinant3(to_world) < 0.0;
        let boundary = if turned {
            MediumBoundary {
                interior: boundary.exterior,
                exterior: boundary.interior,
            }
        } else {
            boundary
        };
        let boundaries = &mut self.parts.physical.boundaries;
        if boundaries.len() <= geometry as usize {
            boundaries.resize(geometry as usize + 1, None);
        }
        boundaries[geometry as usize] = Some(boundary);
    }
}

fn identity() -> Transform {
    Transform::from_matrix(&Matrix4::IDENTITY).expect("the identity inverts")
}
