//! Debug views on the course family's samples (the jittered grid): what the first hit is,
//! rather than the light it receives. Each is also a feature layer (`FirstHit`).

use std::ops::Range;

use crate::integrator::course::grid_samples;
use crate::integrator::{FirstHit, Integrator, PixelContext, Sample};
use crate::math::{Color, Vec3};
use crate::ray::Ray;
use crate::scene::{Scene, SurfaceNeeds};

/// Which property of the first hit a debug view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DebugView {
    /// The world-space geometric normal as colour, (n + 1) / 2, not flipped towards the
    /// camera; black where the ray leaves the scene (`--integrator normals`).
    Normals,
    /// `FirstHit::albedo`.
    Albedo,
    /// `FirstHit::depth` in every channel.
    Depth,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct DebugIntegrator {
    view: DebugView,
}

impl DebugIntegrator {
    pub fn new(_scene: &Scene, view: DebugView) -> DebugIntegrator {
        DebugIntegrator { view }
    }

    fn radiance(&self, scene: &Scene, ray: &Ray) -> Color {
        match self.view {
            DebugView::Normals => match scene.intersect(ray) {
                Some(hit) => (scene.surface(ray, &hit, SurfaceNeeds::Uv).normal + Vec3::ONE) * 0.5,
                None => Color::ZERO,
            },
            // The camera ray was counted by the grid's sample already.
            DebugView::Albedo => FirstHit::trace(scene, ray, &mut 0).albedo,
            DebugView::Depth => Color::splat(FirstHit::trace(scene, ray, &mut 0).depth),
        }
    }
}

impl Integrator for DebugIntegrator {
    fn pixel_samples(
        &self,
        scene: &Scene,
        pixel: &PixelContext,
        samples: Range<u32>,
        rays: &mut u64,
        sink: &mut impl FnMut(Sample),
    ) {
        grid_samples(scene, pixel, samples, None, rays, sink, None, &|ray, _| {
            self.radiance(scene, ray)
        });
    }
}
