//! Mitsuba 3's shapes as triangle meshes: the type every Mitsuba shape source makes, and the
//! tessellated analytic shapes (`disk`, `cylinder`) and Mitsuba's `cube` mesh.

use glint_render::{Color, Vec3};

/// A triangle mesh as a Mitsuba shape makes it, with the per-vertex attributes Mitsuba keeps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShapeMesh {
    /// Vertex positions, in object space.
    pub positions: Vec<Vec3>,
    /// Indices into the per-vertex arrays.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex unit normals.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, in Mitsuba's convention.
    pub uvs: Option<Vec<(f32, f32)>>,
    /// Per-vertex colours (Mitsuba's `vertex_color`).
    pub colors: Option<Vec<Color>>,
}
