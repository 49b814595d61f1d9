//! Lights of the course: point lights, rectangular area lights and shape emitters.

pub mod envmap;
pub mod sampler;

use crate::math::{Color, Frame, Transform, Vec3};

/// A light source. Emitters that are also visible geometry (shape lights, visible area lights)
/// additionally appear in the scene as shapes with `Material::Emissive`.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// `<light type="point">`: no distance falloff in the course integrator (slide001).
    Point { position: Vec3, intensity: Color },
    /// `<light type="area">`: a `width` x `length` rectangle centred at `position`, facing
    /// `normal`. Its edges lie along the one-vector basis built from the normal (slide001 p.18):
    /// `width` along U and `length` along V (FORMAT.md 4.5).
    Area {
        position: Vec3,
        normal: Vec3,
        width: f32,
        length: f32,
        intensity: Color,
    },
    /// `"_type": "shape"` (JSON): an emitting sphere, sampled by area for direct lighting.
    Sphere {
        center: Vec3,
        radius: f32,
        intensity: Color,
    },
    /// An emitting triangle, box (as its 12 triangles) or mesh: one light for the whole shape,
    /// sampled uniformly by area over its triangles.
    Triangles {
        triangles: Vec<[Vec3; 3]>,
        intensity: Color,
    },
    /// Mitsuba's `area` emitter with a textured `radiance`: emitting triangles whose
    /// radiance at a point is `PhysicalParts::textures[texture]` at its uv, interpolated
    /// from `uvs` (one entry per triangle), times `intensity`.
    TexturedTriangles {
        triangles: Vec<[Vec3; 3]>,
        uvs: Vec<[(f32, f32); 3]>,
        texture: u32,
        intensity: Color,
    },
    /// Mitsuba's `spot`: at the origin of `to_world` (a rigid transform), shining along its
    /// +z; full `intensity` inside `beam_width`, falling off smoothly to zero at
    /// `cutoff_angle` (both in degrees, half-angles), optionally modulated by a texture
    /// (`PhysicalParts::textures`) over the cone.
    Spot {
        to_world: Transform,
        intensity: Color,
        cutoff_angle: f32,
        beam_width: f32,
        texture: Option<u32>,
    },
    /// Mitsuba's `directional`: light arriving from infinitely far along `direction` (unit,
    /// the way the light travels) with `irradiance` on a surface facing it.
    Directional { direction: Vec3, irradiance: Color },
    /// Mitsuba's `projector`: a texture projected from the origin of `to_world` along its
    /// +z through a pinhole of horizontal field of view `fov` (degrees: Mitsuba's `fov`
    /// converted to the x axis by `fov_axis` and the texture's width / height), its `irradiance`
    /// (a texture of `PhysicalParts::textures`) times `scale` at unit distance.
    Projector {
        to_world: Transform,
        irradiance: u32,
        scale: f32,
        fov: f32,
    },
}

impl Light {
    /// The rectangle's edge vectors (full width along `u_edge`, full length along `v_edge`).
    pub fn area_edges(normal: Vec3, width: f32, length: f32) -> (Vec3, Vec3) {
        let basis = Frame::from_one(normal);
        (basis.u * width, basis.v * length)
    }

    pub fn intensity(&self) -> Color {
        match self {
            Light::Point { intensity, .. }
            | Light::Area { intensity, .. }
            | Light::Sphere { intensity, .. }
            | Light::Triangles { intensity, .. }
            | Light::TexturedTriangles { intensity, .. }
            | Light::Spot { intensity, .. } => *intensity,
            Light::Directional { irradiance, .. } => *irradiance,
            Light::Projector { scale, .. } => Color::splat(*scale),
        }
    }
}
