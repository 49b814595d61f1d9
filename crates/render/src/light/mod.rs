//! Lights of the course: point lights, rectangular area lights and shape emitters.

pub mod sampler;

use crate::math::{Color, Frame, Vec3};

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
            | Light::Triangles { intensity, .. } => *intensity,
        }
    }
}
