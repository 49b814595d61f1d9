//! Perspective and orthographic cameras of the course (slide001 pp.18-25, FORMAT.md 1.2).

use crate::math::{Frame, Vec3};
use crate::ray::Ray;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    Perspective,
    Orthographic,
}

/// A course camera: position e, frame (U, V, W) from the gaze and up = (0,1,0), focal length
/// f and image-plane width w. The image-plane height is w · ny / nx (square pixels,
/// FORMAT.md A2) unless an aspect ratio is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub projection: Projection,
    pub position: Vec3,
    pub basis: Frame,
    pub focal_length: f32,
    pub image_plane_width: f32,
}

impl Camera {
    pub fn new(
        projection: Projection,
        position: Vec3,
        gaze: Vec3,
        focal_length: f32,
        image_plane_width: f32,
    ) -> Camera {
        Camera {
            projection,
            position,
            basis: Frame::from_two(gaze, Vec3::Y),
            focal_length,
            image_plane_width,
        }
    }

    /// The ray through image-plane point (px, py) in pixel units, where (0,0) is the bottom-left
    /// corner of the image and (nx, ny) the top-right (the lecture's j runs bottom to top).
    /// `aspect` is nx/ny unless the user overrode it.
    #[inline]
    pub fn ray(&self, px: f32, py: f32, nx: u32, ny: u32, aspect: f32) -> Ray {
        let w = self.image_plane_width;
        let h = w / aspect;
        let u = -0.5 * w + w * px / nx as f32;
        let v = -0.5 * h + h * py / ny as f32;
        let b = &self.basis;
        match self.projection {
            Projection::Perspective => {
                Ray::new(self.position, b.w * -self.focal_length + b.u * u + b.v * v)
            }
            Projection::Orthographic => Ray::new(self.position + b.u * u + b.v * v, -b.w),
        }
    }
}
