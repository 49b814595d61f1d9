//! The memory a render would need, estimated before anything is allocated, against the
//! `--max-memory` budget: a render that cannot fit is refused before it starts.

use glint_render::{Background, SceneParts};

use crate::failure::Failure;

/// Bytes per pixel of a render: the pipeline's per-pixel values (40), the film (12), the
/// 8-bit copy and its encoding (6), and with feature layers their film copies (28); an EXR's
/// channels as the writer lays them out and encodes them (40); adaptive sampling's counts (8);
/// and for a render in passes (adaptive sampling, `--time`) the running sums each pixel keeps
/// between passes, twice during a pass (256). Peak resident memory measured on 3000 x 3000
/// renders (bench/results/2026-11-29-hostile.md): 22 bytes a pixel to PNG, 111-118 to EXR,
/// 234 with `--time`, 274 adaptive to EXR; the estimate is above each.
pub fn film_bytes(settings: &glint_render::RenderSettings, time_budget: bool, exr: bool) -> u64 {
    let mut per_pixel = if settings.features { 86 } else { 58 };
    if exr {
        per_pixel += 40;
    }
    if settings.adaptive.is_some() {
        per_pixel += 8;
    }
    if time_budget || settings.adaptive.is_some() {
        per_pixel += 256;
    }
    // A tile or crop holds and writes its own pixels only.
    let bounds = settings.bounds();
    u64::from(bounds.width()) * u64::from(bounds.height()) * per_pixel
}

/// Bytes per shape of the scene and its acceleration structures: the shape (up to 40 bytes),
/// its material, its triangle copy in the ray engine and its share of BVH nodes, with room.
const BYTES_PER_SHAPE: u64 = 160;

/// Bytes of the scene's textures and cube map, as the renderer holds them (12 a texel).
pub fn texture_bytes(parts: &SceneParts) -> u64 {
    let mut texels: u64 = parts
        .textures
        .iter()
        .map(|texture| texture.texels.len() as u64)
        .sum();
    if let Background::CubeMap(map) = &parts.background {
        texels += map
            .faces
            .iter()
            .map(|face| face.texels.len() as u64)
            .sum::<u64>();
    }
    texels * 12
}

/// Shapes the scene's acceleration structures hold: the geometry's, every emitting
/// triangle and every instance.
pub fn shape_count(parts: &SceneParts) -> u64 {
    let shapes: u64 = parts
        .geometries
        .iter()
        .map(|geometry| geometry.shapes.len() as u64)
        .sum();
    let light_triangles: u64 = parts
        .lights
        .iter()
        .map(|light| match light {
            glint_render::Light::Triangles { triangles, .. } => triangles.len() as u64,
            _ => 1,
        })
        .sum();
    shapes + light_triangles + parts.instances.len() as u64
}

/// Refuses a render whose estimated memory is over the budget; returns the estimate.
pub fn check(
    film: u64,
    textures: u64,
    shapes: u64,
    budget: u64,
    source: &str,
) -> Result<u64, Failure> {
    let structures = shapes.saturating_mul(BYTES_PER_SHAPE);
    let total = film.saturating_add(textures).saturating_add(structures);
    if total <= budget {
        return Ok(total);
    }
    let bytes = glint_io::format_bytes;
    Err(Failure::Memory(format!(
        "the render would need about {} (image {}, textures {}, shapes and their acceleration \
         structures {}), more than the limit of {} ({source}); render a smaller image, or \
         raise the limit with --max-memory",
        bytes(total),
        bytes(film),
        bytes(textures),
        bytes(structures),
        bytes(budget)
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_estimates_refuse_what_does_not_fit() {
        let huge = glint_render::RenderSettings {
            width: 65_535,
            height: 65_535,
            ..glint_render::RenderSettings::default()
        };
        let film = film_bytes(&huge, false, false);
        assert!(film > 200 << 30, "{film}");
        let refused = check(film, 0, 0, 8 << 30, "test").unwrap_err();
        assert_eq!(refused.exit_code(), 2);
        assert!(refused.to_string().contains("--max-memory"), "{refused}");
        assert!(check(1 << 20, 1 << 20, 1000, 8 << 30, "test").is_ok());
        assert!(check(0, 0, u64::MAX, 8 << 30, "test").is_err());
        let tile = glint_render::RenderSettings {
            pixel_bounds: Some(glint_render::PixelBounds {
                x0: 8,
                x1: 24,
                y0: 0,
                y1: 16,
            }),
            ..huge
        };
        assert_eq!(film_bytes(&tile, false, false), 16 * 16 * 58);
    }
}
