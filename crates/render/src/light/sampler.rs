//! Lights as physical emitters, prepared once per render for the path tracer: which light to
//! sample (by emitted power, O(log n)), where on it, with what density per unit solid angle,
//! and how much radiance it sends.
//!
//! - Area lights (rectangles), emitting triangles and spheres emit radiance `intensity`, on one
//!   side only: along an area light's `normal`, along a triangle's geometric normal
//!   (v1 − v0) × (v2 − v0), outward from a sphere. Rectangles and triangles are sampled
//!   uniformly by area and converted to solid angle (pdf_area · r² / cos θ_light); spheres by
//!   the cone they subtend (uniform in solid angle, pbrt's `Sphere::Sample(ctx)`).
//! - Point lights are Dirac deltas of intensity I: radiance I / r² arrives (Mitsuba's `point`).
//! - Mitsuba's delta emitters, as its 3.9 plugins define them: a `spot` sends I · falloff ·
//!   texture / r², the falloff linear in the angle from the beam width to the cutoff; a
//!   `directional` light sends E from infinitely far; a `projector` sends
//!   π · scale · E(uv) / (z² cos θ) inside its frustum, so that E · π is the irradiance at
//!   z = 1 (Mitsuba's factor π included).
//! - The background is an infinite light: a constant colour sampled uniformly over the sphere,
//!   a cube map (six faces or a vertical cross cut into faces by the loader) sampled in
//!   proportion to luminance × texel solid angle with a row/column piecewise-constant
//!   distribution (pbrt's `PiecewiseConstant2D`, here over the cube's texels), or Mitsuba's
//!   latitude-longitude `envmap` (`light::envmap`) by luminance × sin θ over its texel grid.

#[cfg(test)]
use crate::geometry::intersect_triangle;
use crate::light::envmap::{direction_to_uv, uv_to_direction, LatLongMap};
use crate::light::Light;
use crate::material::Material;
use crate::math::{Color, Transform, Vec3};
#[cfg(test)]
use crate::ray::Ray;
use crate::sampling::warp::{
    sample_uniform_cone, sample_uniform_sphere, sample_uniform_triangle, uniform_cone_pdf,
    uniform_sphere_pdf,
};
use crate::scene::{Background, Scene};
use crate::texture::CubeMap;
use crate::texture::{Image, TextureNode, TexturePoint};
use rayon::prelude::*;

use std::f32::consts::PI;

/// A point chosen on a light for one shadow ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Radiance arriving at the reference point from the light along `direction` (for a point
    /// light I / r²), before visibility.
    pub radiance: Color,
    /// Unit direction from the reference point towards the light.
    pub direction: Vec3,
    /// The point on the light (meaningless for the environment: see `distance`).
    pub position: Vec3,
    /// Distance to `position`; infinite for the environment.
    pub distance: f32,
    /// Density per unit solid angle (for a point light: 1), times the probability of having
    /// chosen this light when it comes from `LightSampler::sample`.
    pub pdf: f32,
    /// Point lights: no BSDF sample can find them, so no MIS weight.
    pub is_delta: bool,
    /// Whether a BSDF-sampled ray can hit this light (it has emissive geometry or is the
    /// environment); if not, light sampling is the only estimator and takes the full weight.
    pub reachable_by_bsdf: bool,
}

/// A point on an emitter, by area: what the course integrator asks of a light, and what the
/// path tracer's area sampling converts to a `LightSample` per unit solid angle (pbrt-v4's
/// `ShapeSample` beside its `LightLiSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LightPoint {
    pub position: Vec3,
    /// Unit normal of the emitter at `position` (`None` for point lights).
    pub normal: Option<Vec3>,
    /// Density of `position` per unit area (1 for point lights, 0 for no point).
    pub pdf_area: f32,
}

/// The course integrator's point on light `index` (`light`) for shading point `p`, with the
/// course's conventions: an area light's rectangle and emitting triangles by area (triangles
/// from the prepared table of `lights`), a sphere light on the hemisphere facing `p`, a point
/// light itself. `u` is the sample; `None` asks for the deterministic point of one ray per
/// pixel (the rectangle's centre, the sphere's point nearest `p`, the centroid of the triangle
/// at the middle of the area table: FORMAT.md 4.5).
pub(crate) fn course_light_point(
    lights: Option<&LightSampler>,
    light: &Light,
    index: usize,
    p: Vec3,
    u: Option<(f32, f32)>,
) -> LightPoint {
    match light {
        Light::Point { position, .. } => LightPoint {
            position: *position,
            normal: None,
            pdf_area: 1.0,
        },
        // Mitsuba's lights have no course counterpart: the course integrator treats them as
        // points at their origin (a directional light as a point far against its direction).
        Light::Spot { to_world, .. } | Light::Projector { to_world, .. } => LightPoint {
            position: to_world.point_to_world(Vec3::ZERO),
            normal: None,
            pdf_area: 1.0,
        },
        Light::Directional { direction, .. } => LightPoint {
            position: p - *direction * 1.0e6,
            normal: None,
            pdf_area: 1.0,
        },
        Light::Area {
            position,
            normal,
            width,
            length,
            ..
        } => {
            let (u_edge, v_edge) = Light::area_edges(*normal, *width, *length);
            let (u1, u2) = u.unwrap_or((0.5, 0.5));
            let area = (width * length).abs().max(f32::MIN_POSITIVE);
            LightPoint {
                position: *position + u_edge * (u1 - 0.5) + v_edge * (u2 - 0.5),
                normal: Some(normal.normalized()),
                pdf_area: 1.0 / area,
            }
        }
        Light::Sphere { center, radius, .. } => {
            // Uniform on the hemisphere facing p: the far side cannot light p.
            let to_p = (p - *center).normalized();
            let dir = match u {
                None => to_p,
                Some((u1, u2)) => {
                    let d = sample_uniform_sphere(u1, u2);
                    if d.dot(to_p) < 0.0 {
                        -d
                    } else {
                        d
                    }
                }
            };
            let area = 2.0 * PI * radius * radius;
            LightPoint {
                position: *center + dir * radius.abs(),
                normal: Some(dir),
                pdf_area: 1.0 / area.max(f32::MIN_POSITIVE),
            }
        }
        Light::Triangles { .. } | Light::TexturedTriangles { .. } => {
            let point = lights.and_then(|lights| {
                lights.triangle_point(index, u.unwrap_or((0.5, 1.0 / 3.0)), u.is_none())
            });
            match point {
                Some((point, _, _)) => point,
                None => LightPoint {
                    position: p,
                    normal: None,
                    pdf_area: 0.0,
                },
            }
        }
    }
}

#[derive(Clone, Debug)]
enum PreparedLight {
    Point {
        position: Vec3,
        intensity: Color,
    },
    Rectangle {
        center: Vec3,
        u_edge: Vec3,
        v_edge: Vec3,
        normal: Vec3,
        area: f32,
        radiance: Color,
    },
    Sphere {
        center: Vec3,
        radius: f32,
        radiance: Color,
    },
    Triangles {
        /// Range in `LightSampler::triangles`.
        first: u32,
        count: u32,
        area: f32,
        /// 1 / area: the density per unit area of a point sampled on the light.
        inverse_area: f32,
        radiance: Color,
        /// A textured radiance: the texture node, and where the triangles' uvs start in
        /// `LightSampler::triangle_uvs`; the radiance is `radiance` times the texture.
        texture: Option<(u32, u32)>,
    },
    Environment,
    /// Mitsuba's `spot`: intensity × falloff(θ) × texture(uv) / r², θ from the local +z.
    Spot {
        position: Vec3,
        to_world: Transform,
        intensity: Color,
        cos_cutoff: f32,
        cos_beam: f32,
        cutoff: f32,
        /// 1 / (cutoff − beam width), radians: the falloff's slope.
        inverse_transition: f32,
        /// tan(cutoff): the texture spans the cutoff cone.
        uv_factor: f32,
        texture: Option<u32>,
    },
    /// Mitsuba's `directional`: `irradiance` arriving against `direction` (unit, the way the
    /// light travels) from infinitely far.
    Directional {
        direction: Vec3,
        irradiance: Color,
    },
    /// Mitsuba's `projector`: π · scale · E(uv) / (z² cos θ) from its pinhole.
    Projector {
        position: Vec3,
        to_world: Transform,
        /// to_world · (0, 0, 1), not normalised (Mitsuba's `ds.n`).
        axis: Vec3,
        irradiance: u32,
        scale: f32,
        /// cot(fov / 2) and the texture's width / height.
        cot: f32,
        aspect: f32,
    },
}

#[derive(Clone, Copy, Debug)]
struct PreparedTriangle {
    v0: Vec3,
    edge1: Vec3,
    edge2: Vec3,
    /// Unit geometric normal, (v1 − v0) × (v2 − v0) normalised.
    normal: Vec3,
    /// Cumulative share of the light's area up to and including this triangle.
    cumulative: f32,
}

/// The lights of a scene, prepared for sampling. Build it once per render
/// (`LightSampler::new`); sampling then neither allocates nor loops over lights.
#[derive(Clone, Debug)]
pub struct LightSampler {
    lights: Vec<PreparedLight>,
    /// Whether BSDF sampling can reach each light.
    reachable: Vec<bool>,
    selection: LightSelection,
    triangles: Vec<PreparedTriangle>,
    /// The corner uvs of textured emitting triangles (`PreparedLight::Triangles::texture`).
    triangle_uvs: Vec<[(f32, f32); 3]>,
    environment: Option<EnvironmentDistribution>,
}

impl LightSampler {
    /// Prepares the scene's lights (index i here is `scene.lights[i]`) and, when the background
    /// is not black, the environment as one more light at index `scene.lights.len()`.
    pub fn new(scene: &Scene) -> LightSampler {
        LightSampler::prepare(scene, true)
    }

    /// The scene's lights alone, as `new` prepares them for a black background: for the course
    /// integrator, which takes points on its lights one light at a time (`course_light_point`)
    /// and gathers the background by cosine rays, so never samples the environment. An
    /// environment map's distribution is a pass over every texel (6 M for the course's reef
    /// cube map: a tenth of a second on one thread before the first pixel).
    pub fn without_environment(scene: &Scene) -> LightSampler {
        LightSampler::prepare(scene, false)
    }

    fn prepare(scene: &Scene, with_environment: bool) -> LightSampler {
        let mut lights = Vec::with_capacity(scene.lights.len() + 1);
        let mut triangles = Vec::new();
        let mut triangle_uvs = Vec::new();
        let mut power = Vec::with_capacity(scene.lights.len() + 1);
        let mut reachable = vec![false; scene.lights.len()];
        for material in &scene.materials {
            if let Material::Emissive {
                light: Some(index), ..
            } = material
            {
                if let Some(flag) = reachable.get_mut(*index as usize) {
                    *flag = true;
                }
            }
        }
        // The scene's bounding radius, for the power of the lights at infinity.
        let bounds = scene.bounds();
        let radius = if bounds.is_empty() {
            1.0
        } else {
            0.5 * (bounds.max - bounds.min).length()
        };
        for light in &scene.lights {
            // The total area of emitting triangles, summed with their table.
            let mut triangles_area = 0.0f64;
            let prepared = match light {
                Light::Point {
                    position,
                    intensity,
                } => PreparedLight::Point {
                    position: *position,
                    intensity: *intensity,
                },
                Light::Area {
                    position,
                    normal,
                    width,
                    length,
                    intensity,
                } => {
                    let (u_edge, v_edge) = Light::area_edges(*normal, *width, *length);
                    PreparedLight::Rectangle {
                        center: *position,
                        u_edge,
                        v_edge,
                        normal: normal.normalized(),
                        area: u_edge.cross(v_edge).length(),
                        radiance: *intensity,
                    }
                }
                Light::Sphere {
                    center,
                    radius,
                    intensity,
                } => PreparedLight::Sphere {
                    center: *center,
                    radius: radius.abs(),
                    radiance: *intensity,
                },
                Light::Triangles {
                    triangles: list,
                    intensity,
                }
                | Light::TexturedTriangles {
                    triangles: list,
                    intensity,
                    ..
                } => {
                    let texture = match light {
                        Light::TexturedTriangles { uvs, texture, .. } => {
                            let uv_first = triangle_uvs.len() as u32;
                            triangle_uvs.extend(
                                (0..list.len()).map(|i| uvs.get(i).copied().unwrap_or_default()),
                            );
                            Some((*texture, uv_first))
                        }
                        _ => None,
                    };
                    let first = triangles.len() as u32;
                    let mut total = 0.0f64;
                    for &[v0, v1, v2] in list {
                        let cross = (v1 - v0).cross(v2 - v0);
                        let area = 0.5 * cross.length();
                        total += area as f64;
                        triangles.push(PreparedTriangle {
                            v0,
                            edge1: v1 - v0,
                            edge2: v2 - v0,
                            normal: cross.normalized(),
                            cumulative: total as f32,
                        });
                    }
                    let added = &mut triangles[first as usize..];
                    for triangle in added.iter_mut() {
                        triangle.cumulative = if total > 0.0 {
                            (triangle.cumulative as f64 / total) as f32
                        } else {
                            0.0
                        };
                    }
                    if let Some(last) = added.last_mut() {
                        last.cumulative = 1.0;
                    }
                    triangles_area = total;
                    PreparedLight::Triangles {
                        first,
                        count: list.len() as u32,
                        area: total as f32,
                        inverse_area: 1.0 / total as f32,
                        radiance: *intensity,
                        texture,
                    }
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
                    PreparedLight::Spot {
                        position: to_world.point_to_world(Vec3::ZERO),
                        to_world: *to_world,
                        intensity: *intensity,
                        cos_cutoff: cutoff.cos(),
                        cos_beam: beam.cos(),
                        cutoff,
                        inverse_transition: 1.0 / (cutoff - beam),
                        uv_factor: cutoff.tan(),
                        texture: *texture,
                    }
                }
                Light::Directional {
                    direction,
                    irradiance,
                } => PreparedLight::Directional {
                    direction: direction.normalized(),
                    irradiance: *irradiance,
                },
                Light::Projector {
                    to_world,
                    irradiance,
                    scale,
                    fov,
                } => PreparedLight::Projector {
                    position: to_world.point_to_world(Vec3::ZERO),
                    to_world: *to_world,
                    axis: to_world.vector_to_world(Vec3::Z),
                    irradiance: *irradiance,
                    scale: *scale,
                    cot: 1.0 / (0.5 * fov.to_radians()).tan(),
                    aspect: texture_aspect(&scene.physical.textures, &scene.textures, *irradiance),
                },
            };
            lights.push(prepared);
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
                    texture_aspect(&scene.physical.textures, &scene.textures, *irradiance),
                    *scale * texture_mean(&scene.physical.textures, &scene.textures, *irradiance),
                ),
                Light::TexturedTriangles { texture, .. } => {
                    LightSelection::power(light, triangles_area)
                        * texture_mean(&scene.physical.textures, &scene.textures, *texture)
                }
                _ => LightSelection::power(light, triangles_area),
            });
        }
        let environment = with_environment
            .then(|| EnvironmentDistribution::new(&scene.background))
            .flatten();
        if let Some(env) = &environment {
            lights.push(PreparedLight::Environment);
            reachable.push(true);
            power.push(LightSelection::environment_power(radius, env.integral));
        }
        LightSampler {
            lights,
            reachable,
            selection: if scene.physical.defaults.uniform_light_selection {
                let uniform: Vec<f32> = power
                    .iter()
                    .map(|&p| if p > 0.0 { 1.0 } else { 0.0 })
                    .collect();
                LightSelection::new(&uniform)
            } else {
                LightSelection::new(&power)
            },
            triangles,
            triangle_uvs,
            environment,
        }
    }

    /// Index of the environment light, if the background emits.
    pub fn environment_index(&self) -> Option<usize> {
        self.environment.as_ref().map(|_| self.lights.len() - 1)
    }

    /// Probability that `sample` chooses light `index`.
    pub fn selection_probability(&self, index: usize) -> f32 {
        self.selection.probability(index)
    }

    /// Whether BSDF-sampled rays can hit light `index`.
    pub fn reachable_by_bsdf(&self, index: usize) -> bool {
        self.reachable.get(index).copied().unwrap_or(false)
    }

    /// Chooses a light by power with `u.0`, then a point on it with `u.0` remapped to [0, 1)
    /// within the chosen light's share, and `u.1`, as seen from `reference`. Reusing `u.0`
    /// keeps a stratified `u` stratified over the union of the lights (the two triangles of a
    /// quad light are sampled as one quad), at the cost of log2(lights) bits of its precision.
    /// `None` when nothing can arrive (no lights, or the reference is behind the chosen
    /// one-sided emitter).
    #[inline(always)]
    pub fn sample(&self, scene: &Scene, reference: Vec3, u: (f32, f32)) -> Option<LightSample> {
        let (index, probability, remapped) = self.selection.sample(u.0)?;
        let u = (remapped, u.1);
        // Shape emitters, the commonest lights, inline; the others out of line.
        let mut sample = match self.lights.get(index)? {
            PreparedLight::Triangles { .. } => self.sample_triangles(scene, index, reference, u)?,
            _ => self.sample_light(scene, index, reference, u)?,
        };
        sample.pdf *= probability;
        Some(sample)
    }

    /// `sample_light` for light `index`, a `PreparedLight::Triangles`: a triangle chosen by
    /// area with `u.0`, which is then remapped to pick the point on it.
    #[inline]
    fn sample_triangles(
        &self,
        scene: &Scene,
        index: usize,
        reference: Vec3,
        u: (f32, f32),
    ) -> Option<LightSample> {
        let (point, mut radiance, (slot, b1, b2)) = self.triangle_point(index, u, false)?;
        if let Some(PreparedLight::Triangles {
            first,
            texture: Some((texture, uv_first)),
            ..
        }) = self.lights.get(index)
        {
            let uvs = self
                .triangle_uvs
                .get((*uv_first as usize) + slot - *first as usize)?;
            radiance = radiance.mul_elem(textured_radiance(scene, *texture, uvs, b1, b2));
        }
        let mut sample = area_sample(reference, point, radiance)?;
        sample.reachable_by_bsdf = self.reachable_by_bsdf(index);
        Some(sample)
    }

    /// A point on light `index` when it is a set of emitting triangles: the triangle chosen by
    /// area with `u.0` (binary search in the prepared table, O(log n)), the point uniform on it
    /// with the rest of `u.0` and `u.1`, or its centroid when `centroid` (the course's one ray
    /// per pixel). Returns the point (with the triangle's unit normal and the density per unit
    /// area of the whole light) and the light's radiance.
    pub(crate) fn triangle_point(
        &self,
        index: usize,
        u: (f32, f32),
        centroid: bool,
    ) -> Option<(LightPoint, Color, (usize, f32, f32))> {
        let PreparedLight::Triangles {
            first,
            count,
            inverse_area,
            radiance,
            ..
        } = *self.lights.get(index)?
        else {
            return None;
        };
        let list = &self.triangles[first as usize..(first + count) as usize];
        let (chosen, u0) = match list {
            [] => return None,
            // One triangle (a shape light): all of u.0 is its own.
            [_] => (0, u.0),
            _ => {
                let chosen = list
                    .partition_point(|t| t.cumulative <= u.0)
                    .min(list.len() - 1);
                let start = if chosen == 0 {
                    0.0
                } else {
                    list[chosen - 1].cumulative
                };
                let width = list[chosen].cumulative - start;
                if width <= 0.0 {
                    return None;
                }
                (chosen, ((u.0 - start) / width).clamp(0.0, 1.0))
            }
        };
        let triangle = &list[chosen];
        let (b1, b2) = if centroid {
            (1.0 / 3.0, 1.0 / 3.0)
        } else {
            sample_uniform_triangle(u0, u.1)
        };
        let point = LightPoint {
            position: triangle.v0 + triangle.edge1 * b1 + triangle.edge2 * b2,
            normal: Some(triangle.normal),
            pdf_area: inverse_area,
        };
        Some((point, radiance, (first as usize + chosen, b1, b2)))
    }

    /// The texture of light `index`'s radiance when it is textured (`Light::TexturedTriangles`):
    /// an emitter hit multiplies `emission_towards` by it at the hit's uv.
    #[inline]
    pub fn radiance_texture(&self, index: usize) -> Option<u32> {
        match self.lights.get(index) {
            Some(PreparedLight::Triangles {
                texture: Some((texture, _)),
                ..
            }) => Some(*texture),
            _ => None,
        }
    }

    /// A point on light `index` as seen from `reference`; the pdf is per unit solid angle of
    /// this light alone (no selection probability).
    pub fn sample_light(
        &self,
        scene: &Scene,
        index: usize,
        reference: Vec3,
        u: (f32, f32),
    ) -> Option<LightSample> {
        let reachable_by_bsdf = self.reachable_by_bsdf(index);
        match self.lights.get(index)? {
            PreparedLight::Point {
                position,
                intensity,
            } => {
                let to_light = *position - reference;
                let distance_squared = to_light.length_squared();
                if distance_squared <= 0.0 {
                    return None;
                }
                let distance = distance_squared.sqrt();
                Some(LightSample {
                    radiance: *intensity / distance_squared,
                    direction: to_light / distance,
                    position: *position,
                    distance,
                    pdf: 1.0,
                    is_delta: true,
                    reachable_by_bsdf: false,
                })
            }
            PreparedLight::Rectangle {
                center,
                u_edge,
                v_edge,
                normal,
                area,
                radiance,
            } => {
                let point = LightPoint {
                    position: *center + *u_edge * (u.0 - 0.5) + *v_edge * (u.1 - 0.5),
                    normal: Some(*normal),
                    pdf_area: 1.0 / area,
                };
                area_sample(reference, point, *radiance).map(|s| LightSample {
                    reachable_by_bsdf,
                    ..s
                })
            }
            PreparedLight::Triangles { .. } => self.sample_triangles(scene, index, reference, u),
            PreparedLight::Sphere {
                center,
                radius,
                radiance,
            } => {
                let cone = SphereCone::new(reference, *center, *radius)?;
                let local = sample_uniform_cone(u.0, u.1, cone.cos_theta_max);
                let direction = cone.frame_to_world(local);
                // Distance to the near intersection along the sampled direction; the square
                // root is clamped so rounding at the cone's rim cannot produce NaN.
                let cos_theta = local.z;
                let sin2_theta = (1.0 - cos_theta * cos_theta).max(0.0);
                let distance = cone.distance * cos_theta
                    - (radius * radius - cone.distance * cone.distance * sin2_theta)
                        .max(0.0)
                        .sqrt();
                let position = reference + direction * distance;
                Some(LightSample {
                    radiance: *radiance,
                    direction,
                    position,
                    distance,
                    pdf: uniform_cone_pdf(cone.cos_theta_max),
                    is_delta: false,
                    reachable_by_bsdf,
                })
            }
            PreparedLight::Spot {
                position,
                to_world,
                intensity,
                cos_cutoff,
                cos_beam,
                cutoff,
                inverse_transition,
                uv_factor,
                texture,
            } => {
                let (direction, distance_squared) = towards(reference, *position)?;
                let local = to_world.vector_to_object(-direction).normalized();
                let cos_theta = local.z;
                // Mitsuba's falloff: linear in the angle from the beam width to the cutoff.
                let falloff = if cos_theta <= *cos_cutoff {
                    return None;
                } else if cos_theta >= *cos_beam {
                    1.0
                } else {
                    (cutoff - cos_theta.clamp(-1.0, 1.0).acos()) * inverse_transition
                };
                let mut radiance = *intensity * (falloff / distance_squared);
                if let Some(texture) = texture {
                    // Mitsuba's uv over the cutoff cone, v = 0 on its image's top row.
                    let uv = (
                        0.5 + 0.5 * local.x / (local.z * uv_factor),
                        0.5 + 0.5 * local.y / (local.z * uv_factor),
                    );
                    radiance = radiance.mul_elem(texture_value(scene, *texture, uv));
                }
                Some(delta_sample(
                    *position,
                    direction,
                    distance_squared,
                    radiance,
                ))
            }
            PreparedLight::Directional {
                direction,
                irradiance,
            } => Some(LightSample {
                radiance: *irradiance,
                direction: -*direction,
                position: reference - *direction,
                distance: f32::INFINITY,
                pdf: 1.0,
                is_delta: true,
                reachable_by_bsdf: false,
            }),
            PreparedLight::Projector {
                position,
                to_world,
                axis,
                irradiance,
                scale,
                cot,
                aspect,
            } => {
                let local = to_world.point_to_object(reference);
                if local.z.is_nan() || local.z <= 0.0 {
                    return None;
                }
                // Mitsuba's perspective projection onto its texture's uv (v = 0 on the top
                // row); nothing outside the frustum.
                let uv = (
                    0.5 - 0.5 * cot * local.x / local.z,
                    0.5 - 0.5 * aspect * cot * local.y / local.z,
                );
                if !(0.0..=1.0).contains(&uv.0) || !(0.0..=1.0).contains(&uv.1) {
                    return None;
                }
                let (direction, distance_squared) = towards(reference, *position)?;
                // So that the irradiance at z = 1 is the texture's (times π, as Mitsuba
                // has it): dist² cos³θ = z² cos θ.
                let cos_theta = -axis.dot(direction);
                let factor = PI * scale / (local.z * local.z * cos_theta);
                if !(factor > 0.0 && factor.is_finite()) {
                    return None;
                }
                let radiance = texture_value(scene, *irradiance, uv) * factor;
                Some(delta_sample(
                    *position,
                    direction,
                    distance_squared,
                    radiance,
                ))
            }
            PreparedLight::Environment => {
                let env = self.environment.as_ref()?;
                let (direction, pdf) = env.sample(u)?;
                Some(LightSample {
                    radiance: scene.background_radiance(direction),
                    direction,
                    position: reference + direction,
                    distance: f32::INFINITY,
                    pdf,
                    is_delta: false,
                    reachable_by_bsdf: true,
                })
            }
        }
    }

    /// Density per unit solid angle with which `sample_light(index, reference, ..)` returns
    /// `direction` (unit). Intersects the light's own geometry, so it costs O(triangles) for
    /// meshes: for tests; the integrator uses `pdf_emitter_hit`.
    #[cfg(test)]
    pub fn pdf_light_direction(&self, index: usize, reference: Vec3, direction: Vec3) -> f32 {
        match self.lights.get(index) {
            None
            | Some(
                PreparedLight::Point { .. }
                | PreparedLight::Spot { .. }
                | PreparedLight::Directional { .. }
                | PreparedLight::Projector { .. },
            ) => 0.0,
            Some(PreparedLight::Rectangle {
                center,
                u_edge,
                v_edge,
                normal,
                area,
                ..
            }) => {
                let cos_light = -direction.dot(*normal);
                if cos_light <= 0.0 {
                    return 0.0;
                }
                let distance = (*center - reference).dot(*normal) / direction.dot(*normal);
                if distance <= 0.0 || !distance.is_finite() {
                    return 0.0;
                }
                let offset = reference + direction * distance - *center;
                let s = offset.dot(*u_edge) / u_edge.length_squared();
                let t = offset.dot(*v_edge) / v_edge.length_squared();
                if s.abs() > 0.5 || t.abs() > 0.5 {
                    return 0.0;
                }
                distance * distance / (cos_light * area)
            }
            Some(PreparedLight::Triangles {
                first, count, area, ..
            }) => {
                let list = &self.triangles[*first as usize..(*first + *count) as usize];
                list.iter()
                    .filter_map(|triangle| {
                        let cos_light = -direction.dot(triangle.normal);
                        if cos_light <= 0.0 {
                            return None;
                        }
                        let vertices = [
                            triangle.v0,
                            triangle.v0 + triangle.edge1,
                            triangle.v0 + triangle.edge2,
                        ];
                        let ray = Ray {
                            t_min: f32::MIN_POSITIVE,
                            ..Ray::new(reference, direction)
                        };
                        let distance = intersect_triangle(&ray, &vertices)?.t;
                        Some(distance * distance / (cos_light * area))
                    })
                    .sum()
            }
            Some(PreparedLight::Sphere { center, radius, .. }) => {
                match SphereCone::new(reference, *center, *radius) {
                    Some(cone) if direction.dot(cone.axis) >= cone.cos_theta_max => {
                        uniform_cone_pdf(cone.cos_theta_max)
                    }
                    _ => 0.0,
                }
            }
            Some(PreparedLight::Environment) => self
                .environment
                .as_ref()
                .map_or(0.0, |env| env.pdf(direction)),
        }
    }

    /// Density per unit solid angle, selection included, with which `sample` would have chosen
    /// the point `hit_point` (surface normal `hit_normal`) on light `index` from `reference`:
    /// the light-sampling side of the MIS weight when a BSDF sample hits an emitter.
    #[inline]
    pub fn pdf_emitter_hit(
        &self,
        index: usize,
        reference: Vec3,
        hit_point: Vec3,
        hit_normal: Vec3,
    ) -> f32 {
        let probability = self.selection_probability(index);
        if probability <= 0.0 {
            return 0.0;
        }
        let to_hit = hit_point - reference;
        let distance_squared = to_hit.length_squared();
        let direction = to_hit / distance_squared.sqrt();
        let pdf = match &self.lights[index] {
            PreparedLight::Rectangle { normal, area, .. } => {
                let cos_light = direction.dot(*normal).abs();
                distance_squared / (cos_light * area)
            }
            PreparedLight::Triangles { area, .. } => {
                let cos_light = direction.dot(hit_normal).abs();
                distance_squared / (cos_light * area)
            }
            PreparedLight::Sphere { center, radius, .. } => {
                match SphereCone::new(reference, *center, *radius) {
                    Some(cone) => uniform_cone_pdf(cone.cos_theta_max),
                    None => 0.0,
                }
            }
            PreparedLight::Point { .. }
            | PreparedLight::Spot { .. }
            | PreparedLight::Directional { .. }
            | PreparedLight::Projector { .. }
            | PreparedLight::Environment => 0.0,
        };
        if pdf.is_finite() {
            pdf * probability
        } else {
            0.0
        }
    }

    /// Density per unit solid angle, selection included, with which `sample` picks `direction`
    /// (unit) on the environment.
    #[inline]
    pub fn pdf_environment(&self, direction: Vec3) -> f32 {
        match (&self.environment, self.environment_index()) {
            (Some(env), Some(index)) => env.pdf(direction) * self.selection_probability(index),
            _ => 0.0,
        }
    }

    /// What light `index` emits from a surface point with normal `surface_normal` along the
    /// ray direction `travel` that hit it: `Some(intensity)` on its emitting side, `None`
    /// behind it (one-sided emitters).
    #[inline]
    pub fn emission_towards(
        &self,
        index: usize,
        travel: Vec3,
        surface_normal: Vec3,
    ) -> Option<Color> {
        match self.lights.get(index) {
            Some(PreparedLight::Rectangle {
                normal, radiance, ..
            }) => (travel.dot(*normal) < 0.0).then_some(*radiance),
            Some(
                PreparedLight::Triangles { radiance, .. } | PreparedLight::Sphere { radiance, .. },
            ) => (travel.dot(surface_normal) < 0.0).then_some(*radiance),
            // Not emitters with a surface: nothing to add, nothing to hide.
            _ => Some(Color::ZERO),
        }
    }
}

/// The table that chooses a light: each light (the environment last, when it emits) with a
/// probability in proportion to its power Φ, by one uniform number and a binary search of the
/// cumulative distribution, O(log n). The renderer's `LightSampler` samples with it, and the
/// GPU back end uploads its `cdf` as it is, so the two back ends choose lights alike.
#[derive(Clone, Debug, PartialEq)]
pub struct LightSelection {
    /// `probability[i]` is the probability of choosing light `i`.
    probability: Vec<f32>,
    /// `cdf[i]` is the probability of choosing a light before `i`; one more entry than
    /// lights, the last 1 (all 0 when no light emits).
    cdf: Vec<f32>,
}

impl LightSelection {
    /// The table for the lights' powers, in order: [`LightSelection::power`] of each light,
    /// then [`LightSelection::environment_power`] where the background emits. Light i is
    /// chosen with probability power[i] / Σ power, summed in f64; no light at all when the sum
    /// is 0.
    pub fn new(power: &[f32]) -> LightSelection {
        let total: f64 = power.iter().map(|&p| p as f64).sum();
        let probability: Vec<f32> = power
            .iter()
            .map(|&p| {
                if total > 0.0 {
                    (p as f64 / total) as f32
                } else {
                    0.0
                }
            })
            .collect();
        let mut cdf = Vec::with_capacity(power.len() + 1);
        let mut running = 0.0f64;
        cdf.push(0.0);
        for &p in power {
            running += p as f64;
            cdf.push(if total > 0.0 {
                (running / total) as f32
            } else {
                0.0
            });
        }
        if total > 0.0 {
            if let Some(last) = cdf.last_mut() {
                *last = 1.0;
            }
        }
        LightSelection { probability, cdf }
    }

    /// Φ of `light`, by which the table weighs it, each colour by its channel mean: 4π I for a
    /// point light, π A L for the one-sided area emitters (a rectangle; emitting triangles of
    /// total area `triangles_area`, as the caller summed it with its triangle table), π 4π r² L
    /// for a sphere. 0 where that is not a finite positive number.
    pub fn power(light: &Light, triangles_area: f64) -> f32 {
        let phi = match light {
            Light::Point { intensity, .. } => 4.0 * PI * mean(*intensity),
            // pbrt-v4's spot light power: the full cone to the beam width, half of the
            // falloff's ring (Mitsuba gives none).
            Light::Spot {
                intensity,
                cutoff_angle,
                beam_width,
                ..
            } => {
                let cos_cutoff = cutoff_angle.to_radians().cos();
                let cos_beam = beam_width.to_radians().cos();
                2.0 * PI * ((1.0 - cos_beam) + 0.5 * (cos_beam - cos_cutoff)) * mean(*intensity)
            }
            // Their power needs the scene (its size, the projector's texture):
            // `LightSampler::new` weighs them with `environment_power` and `projector_power`.
            Light::Directional { .. } | Light::Projector { .. } => 0.0,
            Light::Area {
                normal,
                width,
                length,
                intensity,
                ..
            } => {
                let (u_edge, v_edge) = Light::area_edges(*normal, *width, *length);
                let area = u_edge.cross(v_edge).length();
                PI * area * mean(*intensity)
            }
            Light::Sphere {
                radius, intensity, ..
            } => {
                let radius = radius.abs();
                PI * 4.0 * PI * radius * radius * mean(*intensity)
            }
            Light::Triangles { intensity, .. } | Light::TexturedTriangles { intensity, .. } => {
                PI * triangles_area as f32 * mean(*intensity)
            }
        };
        if phi.is_finite() {
            phi.max(0.0)
        } else {
            0.0
        }
    }

    /// Φ of an emitting background, pbrt-v4's power of an infinite light: what it sends
    /// through a disk the size of the scene, π r² ∫ L dω, for the scene's bounding radius
    /// `scene_radius` and `integral` = ∫ L dω (channel mean).
    pub fn environment_power(scene_radius: f32, integral: f32) -> f32 {
        PI * scene_radius * scene_radius * integral
    }

    /// Φ of a projector of horizontal field of view `fov` (degrees) and image aspect `aspect`
    /// whose texture's mean irradiance times its scale is `irradiance`: what Mitsuba's
    /// `projector` sends, π · E · the image's area on the plane at unit distance.
    pub fn projector_power(fov: f32, aspect: f32, irradiance: f32) -> f32 {
        let half = (0.5 * fov.to_radians()).tan();
        let phi = PI * irradiance * (2.0 * half) * (2.0 * half / aspect);
        if phi.is_finite() {
            phi.max(0.0)
        } else {
            0.0
        }
    }

    /// The cumulative distribution: entry i is the probability of choosing a light before i,
    /// one more entry than lights.
    pub fn cdf(&self) -> &[f32] {
        &self.cdf
    }

    /// The probability of choosing light `index` (0 for no light).
    #[inline]
    pub fn probability(&self, index: usize) -> f32 {
        self.probability.get(index).copied().unwrap_or(0.0)
    }

    /// The light `u` chooses, with its probability and `u` remapped to [0, 1) within its
    /// share; `None` when no light emits.
    #[inline(always)]
    fn sample(&self, u: f32) -> Option<(usize, f32, f32)> {
        sample_cdf(&self.cdf, u)
    }
}

#[inline]
fn mean(c: Color) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// The unit direction from `reference` to `position`, and the squared distance; `None` when
/// they coincide.
#[inline]
fn towards(reference: Vec3, position: Vec3) -> Option<(Vec3, f32)> {
    let to_light = position - reference;
    let distance_squared = to_light.length_squared();
    (distance_squared > 0.0).then(|| (to_light / distance_squared.sqrt(), distance_squared))
}

/// The sample of a light at a point (a spot, a projector): no BSDF sample finds it.
#[inline]
fn delta_sample(
    position: Vec3,
    direction: Vec3,
    distance_squared: f32,
    radiance: Color,
) -> LightSample {
    LightSample {
        radiance,
        direction,
        position,
        distance: distance_squared.sqrt(),
        pdf: 1.0,
        is_delta: true,
        reachable_by_bsdf: false,
    }
}

/// Texture `node` of `PhysicalParts::textures` at (u, v) in Mitsuba's texture space, where
/// v = 0 is the image's top row (a spot's and a projector's uv are computed there, as
/// `TextureNode::eval` reads them); black for a node out of range.
#[inline]
fn texture_value(scene: &Scene, node: u32, uv: (f32, f32)) -> Color {
    node_value(&scene.physical.textures, &scene.textures, node, uv)
}

#[inline]
fn node_value(nodes: &[TextureNode], images: &[Image], node: u32, uv: (f32, f32)) -> Color {
    match nodes.get(node as usize) {
        Some(texture) => texture.eval(
            images,
            &TexturePoint {
                uv,
                ..TexturePoint::default()
            },
        ),
        None => Color::ZERO,
    }
}

/// Width / height of texture `node` of `nodes` (over `images`), as Mitsuba's
/// `Texture::resolution` gives it: the image's for a bitmap, 1 for the others. Public for the
/// GPU back end, which sets up projectors with it.
pub fn texture_aspect(nodes: &[TextureNode], images: &[Image], node: u32) -> f32 {
    use crate::texture::TextureKind;
    match nodes.get(node as usize).map(|t| &t.kind) {
        Some(TextureKind::Bitmap { image, .. }) => match images.get(*image as usize) {
            Some(image) if image.width > 0 && image.height > 0 => {
                image.width as f32 / image.height as f32
            }
            _ => 1.0,
        },
        _ => 1.0,
    }
}

/// Texture `node`'s mean over its uv square (channel mean), for the power of a light that
/// reads it. Public for the GPU back end, whose light selection must be the CPU's.
pub fn texture_mean(nodes: &[TextureNode], images: &[Image], node: u32) -> f32 {
    const N: usize = 16;
    let mut sum = 0.0f64;
    for i in 0..N {
        for j in 0..N {
            let uv = ((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
            sum += mean(node_value(nodes, images, node, uv).max(Color::ZERO)) as f64;
        }
    }
    (sum / (N * N) as f64) as f32
}

/// A point sampled by area on a one-sided planar emitter, converted to solid angle.
#[inline]
fn area_sample(reference: Vec3, point: LightPoint, radiance: Color) -> Option<LightSample> {
    let LightPoint {
        position,
        normal,
        pdf_area,
    } = point;
    let normal = normal?;
    let to_light = position - reference;
    let distance_squared = to_light.length_squared();
    if distance_squared <= 0.0 {
        return None;
    }
    let distance = distance_squared.sqrt();
    let direction = to_light / distance;
    let cos_light = -direction.dot(normal);
    if cos_light <= 0.0 {
        return None;
    }
    let pdf = pdf_area * distance_squared / cos_light;
    if !pdf.is_finite() {
        return None;
    }
    Some(LightSample {
        radiance,
        direction,
        position,
        distance,
        pdf,
        is_delta: false,
        reachable_by_bsdf: false,
    })
}

/// The cone of directions under which a sphere is seen from outside it.
struct SphereCone {
    axis: Vec3,
    distance: f32,
    cos_theta_max: f32,
}

impl SphereCone {
    /// `None` from inside the sphere (or on it), where its outward emission cannot arrive.
    #[inline]
    fn new(reference: Vec3, center: Vec3, radius: f32) -> Option<SphereCone> {
        let to_center = center - reference;
        let distance_squared = to_center.length_squared();
        if distance_squared <= radius * radius {
            return None;
        }
        let distance = distance_squared.sqrt();
        let sin2_theta_max = radius * radius / distance_squared;
        Some(SphereCone {
            axis: to_center / distance,
            distance,
            cos_theta_max: (1.0 - sin2_theta_max).max(0.0).sqrt(),
        })
    }

    #[inline]
    fn frame_to_world(&self, local: Vec3) -> Vec3 {
        crate::math::Frame::from_normal(self.axis).to_world(local)
    }
}

/// Face index, and (s, t) in [0, 1]² on it, that `CubeMap::lookup` reads for direction `d`.
#[inline]
pub fn cube_face_coordinates(d: Vec3) -> Option<(usize, f32, f32)> {
    CubeMap::face_coordinates(d)
}

/// The (unnormalised) direction through point (s, t) of cube face `face`: the inverse of
/// `cube_face_coordinates`.
#[inline]
pub fn cube_face_direction(face: usize, s: f32, t: f32) -> Vec3 {
    let sc = 2.0 * s - 1.0;
    let tc = 2.0 * t - 1.0;
    match face {
        0 => Vec3::new(1.0, -tc, -sc),
        1 => Vec3::new(-1.0, -tc, sc),
        2 => Vec3::new(sc, 1.0, tc),
        3 => Vec3::new(sc, -1.0, -tc),
        4 => Vec3::new(sc, -tc, 1.0),
        _ => Vec3::new(-sc, -tc, -1.0),
    }
}

/// Solid angle per unit (s, t) area at a point of a cube face: the face is the square
/// [−1, 1]² at distance 1, so dω = 4 ds dt / (1 + a² + b²)^{3/2} with a = 2s − 1, b = 2t − 1.
#[inline]
fn cube_solid_angle_per_area(s: f32, t: f32) -> f32 {
    let a = 2.0 * s - 1.0;
    let b = 2.0 * t - 1.0;
    let r2 = 1.0 + a * a + b * b;
    4.0 / (r2 * r2.sqrt())
}

/// The environment's sampling distribution.
#[derive(Clone, Debug)]
struct EnvironmentDistribution {
    /// ∫ L dω by channel mean, for choosing between lights by power.
    integral: f32,
    shape: EnvironmentShape,
}

/// How the environment's directions are drawn.
#[derive(Clone, Debug)]
enum EnvironmentShape {
    /// A constant colour: uniformly over the sphere.
    Uniform,
    Cube(CubeDistribution),
    LatLong(LatLongDistribution),
}

/// A cube map's importance-sampling distribution, by luminance times each texel's solid angle:
/// rows of all six faces stacked (face 0's rows first), each row a piecewise-constant
/// distribution over its texels. Public so that the GPU back end uploads these tables instead
/// of computing its own.
#[derive(Clone, Debug)]
pub struct CubeDistribution {
    /// Face sizes (width, height); empty faces have no rows.
    sizes: [(u32, u32); 6],
    /// Index of each face's first row; entry 6 is the row count.
    first_row: [u32; 7],
    /// Cumulative probability of the rows before row r; rows + 1 entries.
    row_cdf: Vec<f32>,
    /// Per row: width + 1 cumulative probabilities within the row; row r starts at
    /// `column_start[r]`.
    column_cdf: Vec<f32>,
    column_start: Vec<u32>,
}

impl EnvironmentDistribution {
    fn new(background: &Background) -> Option<EnvironmentDistribution> {
        match background {
            Background::Color(c) => {
                let integral = 4.0 * PI * mean(c.max(Color::ZERO));
                (integral > 0.0 && c.is_finite()).then_some(EnvironmentDistribution {
                    integral,
                    shape: EnvironmentShape::Uniform,
                })
            }
            Background::CubeMap(map) => {
                CubeDistribution::new(map).map(|(cube, integral)| EnvironmentDistribution {
                    integral,
                    shape: EnvironmentShape::Cube(cube),
                })
            }
            Background::Environment {
                image,
                scale,
                to_world,
            } => LatLongDistribution::new(image, *scale, to_world).map(|(latlong, integral)| {
                EnvironmentDistribution {
                    integral,
                    shape: EnvironmentShape::LatLong(latlong),
                }
            }),
        }
    }

    #[inline]
    fn sample(&self, u: (f32, f32)) -> Option<(Vec3, f32)> {
        match &self.shape {
            EnvironmentShape::Uniform => {
                Some((sample_uniform_sphere(u.0, u.1), uniform_sphere_pdf()))
            }
            EnvironmentShape::Cube(cube) => cube.sample(u),
            EnvironmentShape::LatLong(latlong) => latlong.sample(u),
        }
    }

    #[inline]
    fn pdf(&self, direction: Vec3) -> f32 {
        match &self.shape {
            EnvironmentShape::Uniform => uniform_sphere_pdf(),
            EnvironmentShape::Cube(cube) => cube.pdf(direction),
            EnvironmentShape::LatLong(latlong) => latlong.pdf(direction),
        }
    }
}

/// Mitsuba's smallest sin θ in the envmap's solid-angle Jacobian (its `Epsilon`, 2⁻²⁴): the
/// pdf at the poles is large and finite instead of infinite.
const POLE_SIN_THETA: f32 = 5.960_464_5e-8;

/// A latitude-longitude environment's importance-sampling distribution (`light::envmap`).
///
/// Mitsuba's `envmap` samples a piecewise-bilinear density over the (W + 1) x H grid of its
/// texels' luminance times sin θ; this is the piecewise-constant version over the same grid:
/// one cell between each two neighbouring texel centres in u (W cells, the last wrapping
/// round to column 0) and each two rows in v (H − 1 cells, rows at v = y / (H − 1) as the
/// lookup places them), weighted by the mean luminance of its four corner texels times
/// ∫ sin θ dθ over the cell. The bilinear lookup is positive only inside cells with a
/// positive corner, so the density covers every direction that sends light. Rows of cells
/// are stacked with their column distributions as `CubeDistribution` stacks them. Which
/// density samples changes only the variance: the estimate's expectation is Mitsuba's.
#[derive(Clone, Debug)]
pub struct LatLongDistribution {
    to_world: Transform,
    /// Cells across (the padded map's columns) and down (its rows − 1).
    columns: u32,
    rows: u32,
    /// Cumulative probability of the rows of cells before row r; rows + 1 entries.
    row_cdf: Vec<f32>,
    /// Per row of cells, columns + 1 cumulative probabilities, one row after another.
    column_cdf: Vec<f32>,
}

impl LatLongDistribution {
    /// The distribution for `image` (times `scale`, turned by `to_world`) and ∫ L dω by
    /// channel mean; `None` for a black map.
    pub fn new(
        image: &Image,
        scale: f32,
        to_world: &Transform,
    ) -> Option<(LatLongDistribution, f32)> {
        let map = LatLongMap::new(image)?;
        if !(scale > 0.0 && scale.is_finite()) {
            return None;
        }
        let (columns, rows) = (map.width, map.height - 1);
        let stride = columns as usize + 1;
        let mut column_cdf = vec![0.0f32; rows as usize * stride];
        let delta_phi = 2.0 * std::f64::consts::PI / columns as f64;
        let clean = |c: Color| {
            let c = c.max(Color::ZERO);
            if c.is_finite() {
                c
            } else {
                Color::ZERO
            }
        };
        // Per row of cells: its weight (luminance) and ∫ L dω over it (channel mean).
        let sums: Vec<(f64, f64)> = column_cdf
            .par_chunks_mut(stride)
            .enumerate()
            .map(|(row, cdf)| {
                let theta = |y: usize| std::f64::consts::PI * y as f64 / rows as f64;
                // ∫ sin θ dθ over the row: the solid angle of its cells over Δφ.
                let band = theta(row).cos() - theta(row + 1).cos();
                let (top, bottom) = (row as u32, row as u32 + 1);
                let (mut running, mut integral) = (0.0f64, 0.0f64);
                for x in 0..columns {
                    let next = (x + 1) % columns;
                    let corners = clean(map.texel(x, top))
                        + clean(map.texel(next, top))
                        + clean(map.texel(x, bottom))
                        + clean(map.texel(next, bottom));
                    let corners = corners * 0.25;
                    running += corners.luminance() as f64 * band;
                    integral += mean(corners) as f64 * band * delta_phi;
                    cdf[x as usize + 1] = running as f32;
                }
                if running > 0.0 {
                    for c in cdf.iter_mut() {
                        *c = (*c as f64 / running) as f32;
                    }
                    cdf[columns as usize] = 1.0;
                }
                (running, integral)
            })
            .collect();
        let total: f64 = sums.iter().map(|s| s.0).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let integral: f64 = sums.iter().map(|s| s.1).sum::<f64>() * scale as f64;
        let mut row_cdf = Vec::with_capacity(rows as usize + 1);
        row_cdf.push(0.0f32);
        let mut running = 0.0f64;
        for (weight, _) in &sums {
            running += weight;
            row_cdf.push((running / total) as f32);
        }
        row_cdf[rows as usize] = 1.0;
        Some((
            LatLongDistribution {
                to_world: *to_world,
                columns,
                rows,
                row_cdf,
                column_cdf,
            },
            integral as f32,
        ))
    }

    /// Cells across (the padded map's columns) and down (its rows − 1).
    pub fn cells(&self) -> (u32, u32) {
        (self.columns, self.rows)
    }

    /// Cumulative probability of the rows of cells before row r (rows + 1 entries, the last
    /// 1).
    pub fn row_cdf(&self) -> &[f32] {
        &self.row_cdf
    }

    /// Per row of cells, columns + 1 cumulative probabilities, one row after another.
    pub fn column_cdf(&self) -> &[f32] {
        &self.column_cdf
    }

    fn row_columns(&self, row: usize) -> &[f32] {
        let stride = self.columns as usize + 1;
        &self.column_cdf[row * stride..(row + 1) * stride]
    }

    /// Density per unit (u, v) area of cell (column, row).
    #[inline]
    fn cell_density(&self, column: usize, row: usize) -> f32 {
        let row_probability = self.row_cdf[row + 1] - self.row_cdf[row];
        let columns = self.row_columns(row);
        let column_probability = columns[column + 1] - columns[column];
        row_probability * column_probability * (self.columns * self.rows) as f32
    }

    #[inline]
    fn sample(&self, u: (f32, f32)) -> Option<(Vec3, f32)> {
        let (row, row_probability, v_offset) = sample_cdf(&self.row_cdf, u.0)?;
        let (column, column_probability, u_offset) = sample_cdf(self.row_columns(row), u.1)?;
        // Cells start at texel centres: half a texel on in u.
        let map_u = (column as f32 + 0.5 + u_offset) / self.columns as f32;
        let map_v = (row as f32 + v_offset) / self.rows as f32;
        let local = uv_to_direction(map_u, map_v).0;
        let direction = self.to_world.vector_to_world(local).normalized();
        let density = row_probability * column_probability * (self.columns * self.rows) as f32;
        // sin θ of the direction as `pdf` computes it: near the poles a few ulps of rounding
        // in the turn are a large share of sin θ, and both must give the same density.
        let back = self.to_world.vector_to_object(direction).normalized();
        let sin_theta = (back.x * back.x + back.z * back.z).sqrt();
        let pdf = density / (2.0 * PI * PI * sin_theta.max(POLE_SIN_THETA));
        (pdf > 0.0 && pdf.is_finite() && direction.is_finite()).then_some((direction, pdf))
    }

    #[inline]
    fn pdf(&self, direction: Vec3) -> f32 {
        let local = self.to_world.vector_to_object(direction).normalized();
        if !local.is_finite() {
            return 0.0;
        }
        let (u, v) = direction_to_uv(local);
        let x = (u - u.floor()) * self.columns as f32 - 0.5;
        let column = (x.floor() as i64).rem_euclid(self.columns as i64) as usize;
        let row = ((v * self.rows as f32) as usize).min(self.rows as usize - 1);
        let sin_theta = (local.x * local.x + local.z * local.z).sqrt();
        self.cell_density(column, row) / (2.0 * PI * PI * sin_theta.max(POLE_SIN_THETA))
    }
}

/// Finds the bin of `u` in a cumulative table (`cdf[0] = 0`, increasing) and returns it with
/// its probability and `u` remapped to [0, 1) within it.
#[inline]
fn sample_cdf(cdf: &[f32], u: f32) -> Option<(usize, f32, f32)> {
    let bins = cdf.len().checked_sub(1)?;
    if bins == 0 {
        return None;
    }
    let index = cdf[1..].partition_point(|&c| c <= u).min(bins - 1);
    let probability = cdf[index + 1] - cdf[index];
    if probability <= 0.0 {
        return None;
    }
    let remapped = ((u - cdf[index]) / probability).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
    Some((index, probability, remapped))
}

impl CubeDistribution {
    /// The distribution and ∫ L dω (channel mean); `None` for a black map.
    pub fn new(map: &CubeMap) -> Option<(CubeDistribution, f32)> {
        let mut sizes = [(0u32, 0u32); 6];
        let mut first_row = [0u32; 7];
        for (face, image) in map.faces.iter().enumerate() {
            let usable = image.width > 0
                && image.height > 0
                && image.texels.len() >= (image.width * image.height) as usize;
            sizes[face] = if usable {
                (image.width, image.height)
            } else {
                (0, 0)
            };
            first_row[face + 1] = first_row[face] + sizes[face].1;
        }
        let rows = first_row[6] as usize;
        // Each row's distribution is its own (rows in parallel, a block of them at a time);
        // ∫ L dω is one running sum over every texel in order, so each block's terms are made
        // in parallel and then added in order (the same sum, bit for bit, as one loop).
        const BLOCK_ROWS: usize = 64;
        let mut column_start = Vec::with_capacity(rows);
        let mut column_cdf = Vec::new();
        let mut row_weight = Vec::with_capacity(rows);
        let mut integral = 0.0f64;
        let mut terms = Vec::new();
        for (face, image) in map.faces.iter().enumerate() {
            let (width, height) = sizes[face];
            if height == 0 {
                continue;
            }
            let stride = width as usize + 1;
            let start = column_cdf.len();
            column_start.extend((0..height as usize).map(|y| (start + y * stride) as u32));
            column_cdf.resize(start + height as usize * stride, 0.0f32);
            terms.resize(BLOCK_ROWS * width as usize, 0.0f64);
            let texels = width as f64 * height as f64;
            for (block, cdf) in column_cdf[start..]
                .chunks_mut(BLOCK_ROWS * stride)
                .enumerate()
            {
                let terms = &mut terms[..cdf.len() / stride * width as usize];
                let weights: Vec<f64> = cdf
                    .par_chunks_mut(stride)
                    .zip(terms.par_chunks_mut(width as usize))
                    .enumerate()
                    .map(|(i, (row, terms))| {
                        let y = (block * BLOCK_ROWS + i) as u32;
                        let mut running = 0.0f64;
                        for x in 0..width {
                            let s = (x as f32 + 0.5) / width as f32;
                            let t = (y as f32 + 0.5) / height as f32;
                            let texel = image.texels[(y * width + x) as usize];
                            let luminance = texel.luminance();
                            let luminance = if luminance.is_finite() {
                                luminance.max(0.0)
                            } else {
                                0.0
                            };
                            let per_area = cube_solid_angle_per_area(s, t) as f64;
                            // Luminance times the texel's solid angle: the share of light
                            // it sends.
                            running += luminance as f64 * per_area / texels;
                            row[x as usize + 1] = running as f32;
                            terms[x as usize] =
                                mean(texel.max(Color::ZERO)) as f64 * per_area / texels;
                        }
                        if running > 0.0 {
                            for c in row.iter_mut() {
                                *c = (*c as f64 / running) as f32;
                            }
                            if let Some(last) = row.last_mut() {
                                *last = 1.0;
                            }
                        }
                        running
                    })
                    .collect();
                row_weight.extend(weights);
                for &term in terms.iter() {
                    integral += term;
                }
            }
        }
        let total: f64 = row_weight.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut row_cdf = Vec::with_capacity(rows + 1);
        row_cdf.push(0.0f32);
        let mut running = 0.0f64;
        for w in &row_weight {
            running += w;
            row_cdf.push((running / total) as f32);
        }
        if let Some(last) = row_cdf.last_mut() {
            *last = 1.0;
        }
        Some((
            CubeDistribution {
                sizes,
                first_row,
                row_cdf,
                column_cdf,
                column_start,
            },
            integral as f32,
        ))
    }

    /// Cumulative probability of the rows before row r (rows + 1 entries, the last 1).
    pub fn row_cdf(&self) -> &[f32] {
        &self.row_cdf
    }

    /// Every row's width + 1 cumulative probabilities within the row, one row after another.
    pub fn column_cdf(&self) -> &[f32] {
        &self.column_cdf
    }

    /// Where row r's entries start in `column_cdf`.
    pub fn column_start(&self) -> &[u32] {
        &self.column_start
    }

    /// Each face's first row; entry 6 is the row count (faces without texels have no rows).
    pub fn first_row(&self) -> &[u32; 7] {
        &self.first_row
    }

    fn row_columns(&self, row: usize, width: u32) -> &[f32] {
        let start = self.column_start[row] as usize;
        &self.column_cdf[start..start + width as usize + 1]
    }

    #[inline]
    fn sample(&self, u: (f32, f32)) -> Option<(Vec3, f32)> {
        let (row, row_probability, t_offset) = sample_cdf(&self.row_cdf, u.0)?;
        let face = self.first_row[1..].partition_point(|&first| first as usize <= row);
        let (width, height) = *self.sizes.get(face)?;
        let y = row as u32 - self.first_row[face];
        let (x, column_probability, s_offset) = sample_cdf(self.row_columns(row, width), u.1)?;
        let s = (x as f32 + s_offset) / width as f32;
        let t = (y as f32 + t_offset) / height as f32;
        let direction = cube_face_direction(face, s, t).normalized();
        let pdf_area = row_probability * column_probability * (width * height) as f32;
        let pdf = pdf_area / cube_solid_angle_per_area(s, t);
        (pdf > 0.0 && pdf.is_finite()).then_some((direction, pdf))
    }

    #[inline]
    fn pdf(&self, direction: Vec3) -> f32 {
        let Some((face, s, t)) = cube_face_coordinates(direction) else {
            return 0.0;
        };
        let (width, height) = self.sizes[face];
        if width == 0 || height == 0 {
            return 0.0;
        }
        // The texel `CubeMap::lookup` reads (its truncation and clamping).
        let x = ((s * width as f32) as u32).min(width - 1);
        let y = ((t * height as f32) as u32).min(height - 1);
        let row = (self.first_row[face] + y) as usize;
        let row_probability = self.row_cdf[row + 1] - self.row_cdf[row];
        let columns = self.row_columns(row, width);
        let column_probability = columns[x as usize + 1] - columns[x as usize];
        row_probability * column_probability * (width * height) as f32
            / cube_solid_angle_per_area(s, t)
    }
}

/// Radiance texture `texture` at barycentrics (b1, b2) of a triangle with corner uvs `uvs`.
fn textured_radiance(
    scene: &Scene,
    texture: u32,
    uvs: &[(f32, f32); 3],
    b1: f32,
    b2: f32,
) -> Color {
    let b0 = 1.0 - b1 - b2;
    let uv = (
        uvs[0].0 * b0 + uvs[1].0 * b1 + uvs[2].0 * b2,
        uvs[0].1 * b0 + uvs[1].1 * b1 + uvs[2].1 * b2,
    );
    texture_value(scene, texture, uv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Image;

    fn distinct_cube(size: u32) -> CubeMap {
        let face = |f: u32| Image {
            width: size,
            height: size,
            texels: (0..size * size)
                .map(|i| Vec3::new(f as f32, (i % size) as f32, (i / size) as f32))
                .collect(),
        };
        CubeMap {
            faces: [face(0), face(1), face(2), face(3), face(4), face(5)],
        }
    }

    #[test]
    fn cube_coordinates_match_cube_map_lookup() {
        let size = 7;
        let map = distinct_cube(size);
        let mut rng = crate::sampling::Rng::new(3, 1);
        for _ in 0..20_000 {
            let d = sample_uniform_sphere(rng.next_f32(), rng.next_f32());
            let (face, s, t) = cube_face_coordinates(d).unwrap();
            let x = ((s * size as f32) as u32).min(size - 1);
            let y = ((t * size as f32) as u32).min(size - 1);
            assert_eq!(
                map.lookup(d),
                Vec3::new(face as f32, x as f32, y as f32),
                "{d:?}"
            );
            // And the inverse map returns the direction.
            let back = cube_face_direction(face, s, t).normalized();
            assert!((back - d).length() < 1e-5, "{d:?} {back:?}");
        }
    }

    /// Faces of 1 to 130 rows (the distribution is made in blocks of 64 rows, in parallel):
    /// each texel's probability (row times column) is its luminance times its solid angle over
    /// the whole map's, and the integral is every texel's mean times its solid angle.
    #[test]
    fn cube_distribution_weighs_every_texel() {
        let sizes = [(3, 1), (5, 64), (4, 65), (2, 130), (9, 7), (1, 129)];
        let mut rng = crate::sampling::Rng::new(8, 2);
        let faces = sizes.map(|(width, height)| Image {
            width,
            height,
            texels: (0..width * height)
                .map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()))
                .collect(),
        });
        let map = CubeMap { faces };
        let (cube, integral) = CubeDistribution::new(&map).unwrap();
        let weight = |face: usize, x: u32, y: u32| {
            let (w, h) = sizes[face];
            let texel = map.faces[face].texels[(y * w + x) as usize];
            let per_area =
                cube_solid_angle_per_area((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32)
                    as f64
                    / (w as f64 * h as f64);
            (
                texel.luminance() as f64 * per_area,
                mean(texel) as f64 * per_area,
            )
        };
        let (mut total, mut want_integral) = (0.0, 0.0);
        for (face, &(w, h)) in sizes.iter().enumerate() {
            for y in 0..h {
                for x in 0..w {
                    total += weight(face, x, y).0;
                    want_integral += weight(face, x, y).1;
                }
            }
        }
        assert!(((integral as f64) / want_integral - 1.0).abs() < 1e-6);
        for (face, &(w, h)) in sizes.iter().enumerate() {
            for y in 0..h {
                let row = (cube.first_row[face] + y) as usize;
                let row_p = (cube.row_cdf[row + 1] - cube.row_cdf[row]) as f64;
                let columns = cube.row_columns(row, w);
                for x in 0..w as usize {
                    let p = row_p * (columns[x + 1] - columns[x]) as f64;
                    let want = weight(face, x as u32, y).0 / total;
                    assert!((p / want - 1.0).abs() < 2e-3, "{face} {x} {y}: {p} {want}");
                }
            }
        }
    }

    #[test]
    fn cube_face_solid_angles_sum_to_sphere() {
        let n = 200;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let s = (i as f32 + 0.5) / n as f32;
                let t = (j as f32 + 0.5) / n as f32;
                sum += cube_solid_angle_per_area(s, t) as f64 / (n * n) as f64;
            }
        }
        assert!(
            (6.0 * sum - 4.0 * std::f64::consts::PI).abs() < 1e-3,
            "{sum}"
        );
    }
}
