//! Perspective and orthographic cameras of the course (slide001 pp.18-25, FORMAT.md 1.2),
//! with an optional thin lens for depth of field (`-d`, FORMAT.md 1.4).

use crate::math::{Frame, Vec3};
use crate::ray::Ray;
use crate::sampling::sample_uniform_disk_concentric;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    Perspective,
    Orthographic,
}

/// A course camera: position e, frame (U, V, W) from the gaze and up = (0,1,0), focal length
/// f and image-plane width w. The image-plane height is w · ny / nx (square pixels,
/// FORMAT.md A2) unless an aspect ratio is given.
#[derive(Clone, Copy, PartialEq)]
pub struct Camera {
    pub projection: Projection,
    pub position: Vec3,
    pub basis: Frame,
    pub focal_length: f32,
    pub image_plane_width: f32,
    /// Depth of field: `None` is the course's pinhole (every ray leaves from the position).
    pub lens: Option<ThinLens>,
    /// Mitsuba's `near_clip` and `far_clip`: the path tracer's camera rays see only what lies
    /// between these distances along the view direction (-W); `None` sees everything.
    pub clip: Option<(f32, f32)>,
}

/// The derived text, with `clip` only where there are clipping planes: the scene hash reads
/// a camera's `Debug` text, and course cameras (which have none) keep the digests earlier
/// builds wrote.
impl std::fmt::Debug for Camera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("Camera");
        s.field("projection", &self.projection)
            .field("position", &self.position)
            .field("basis", &self.basis)
            .field("focal_length", &self.focal_length)
            .field("image_plane_width", &self.image_plane_width)
            .field("lens", &self.lens);
        if let Some(clip) = &self.clip {
            s.field("clip", clip);
        }
        s.finish()
    }
}

/// A thin lens (pbrt's `PerspectiveCamera` lens, Mitsuba 3's `thinlens` sensor): rays leave
/// from a point of a disk of radius `radius` around the camera position, in the (U, V) plane,
/// and pass through the point of the plane in focus that the pinhole ray meets. Points on that
/// plane stay sharp; the others blur in proportion to the radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Distance from the lens to the plane in focus, along the view direction (-W).
    pub focus_distance: f32,
    /// Lens radius in scene units.
    pub radius: f32,
}

impl ThinLens {
    /// Share of the width the image covers at the focus distance that the default lens
    /// radius takes: a point far behind the plane in focus (or at half its distance) blurs
    /// into a disk of 1/25 of the image width.
    pub const DEFAULT_RADIUS_SHARE: f32 = 1.0 / 50.0;

    /// A lens focused at `focus_distance` with the default radius for `camera`:
    /// `DEFAULT_RADIUS_SHARE` of the width the image covers at that distance (the image-plane
    /// width scaled by focus distance / focal length; the image-plane width itself for an
    /// orthographic camera), so that the blur looks alike whatever the scene's scale.
    pub fn with_default_radius(camera: &Camera, focus_distance: f32) -> ThinLens {
        let covered = match camera.projection {
            Projection::Perspective => {
                camera.image_plane_width * focus_distance / camera.focal_length
            }
            Projection::Orthographic => camera.image_plane_width,
        };
        ThinLens {
            focus_distance,
            radius: covered.abs() * Self::DEFAULT_RADIUS_SHARE,
        }
    }
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
            lens: None,
            clip: None,
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

    /// A camera ray with a unit direction limited to the clipping planes: the distances along
    /// the view direction become distances along the ray.
    #[inline]
    pub fn clipped(&self, mut ray: Ray) -> Ray {
        if let Some((near, far)) = self.clip {
            let along = -ray.direction.dot(self.basis.w);
            if along > 0.0 {
                ray.t_min = near / along;
                ray.t_max = far / along;
            }
        }
        ray
    }

    /// `ray`, leaving from the point of the lens that `lens_sample` in [0, 1)² maps to (the
    /// concentric disk mapping, as Mitsuba's `thinlens` does) and passing through the point
    /// where `ray` meets the plane in focus. Its direction has the same component along the
    /// view direction as `ray`'s, so a lens of radius 0 gives `ray` back. Without a lens,
    /// `ray` itself.
    #[inline]
    pub fn lens_ray(
        &self,
        px: f32,
        py: f32,
        nx: u32,
        ny: u32,
        aspect: f32,
        lens_sample: (f32, f32),
    ) -> Ray {
        let pinhole = self.ray(px, py, nx, ny, aspect);
        let Some(lens) = self.lens else {
            return pinhole;
        };
        let b = &self.basis;
        let (dx, dy) = sample_uniform_disk_concentric(lens_sample.0, lens_sample.1);
        let offset = b.u * (dx * lens.radius) + b.v * (dy * lens.radius);
        // The pinhole ray meets the plane in focus at t = focus distance / its component along
        // the view direction; from the lens point, that point is direction · t − offset away.
        let along = -pinhole.direction.dot(b.w);
        let t_focus = lens.focus_distance / along;
        Ray::new(
            pinhole.origin + offset,
            pinhole.direction - offset * (1.0 / t_focus),
        )
    }
}

#[cfg(test)]
mod clip_tests {
    use super::*;

    /// The clipping planes are distances along the view direction: an oblique ray's window
    /// is longer by 1/cos, and a camera without planes leaves rays as they are.
    #[test]
    fn clipping_planes_are_distances_along_the_view() {
        let mut camera = Camera::new(
            Projection::Perspective,
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, -1.0),
            1.0,
            1.0,
        );
        let straight = Ray::new(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
        let oblique = Ray::new(Vec3::ZERO, Vec3::new(0.6, 0.0, -0.8));
        assert_eq!(camera.clipped(oblique), oblique);
        camera.clip = Some((1.0, 10.0));
        let s = camera.clipped(straight);
        assert_eq!((s.t_min, s.t_max), (1.0, 10.0));
        let o = camera.clipped(oblique);
        assert!((o.t_min - 1.25).abs() < 1e-6 && (o.t_max - 12.5).abs() < 1e-5);
    }
}
