//! The indexed triangle mesh that the OBJ and PLY readers make (`obj.rs`, `obj_fast.rs`,
//! `ply.rs`) and that stand-alone mesh files load into (`mesh_file.rs`). It imports no reader,
//! so that every reader can import it.

use glint_render::{GeometryDesc, Shape, Vec3};

/// An indexed triangle mesh: positions and corner indices into them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// The three corners of triangle `index`.
    pub fn triangle(&self, index: usize) -> [Vec3; 3] {
        self.triangles[index].map(|corner| self.positions[corner as usize])
    }

    /// The triangles as renderer shapes, in file order.
    pub fn shapes(&self) -> Vec<Shape> {
        (0..self.triangles.len())
            .map(|index| Shape::Triangle {
                vertices: self.triangle(index),
            })
            .collect()
    }

    /// The mesh as one geometry with material 0 on every triangle.
    pub fn geometry(&self) -> GeometryDesc {
        let shapes = self.shapes();
        GeometryDesc {
            materials: vec![0; shapes.len()],
            shapes,
        }
    }
}
