//! Sample warps: maps from the unit square to directions and points, each with its density
//! and its inverse beside it (pbrt-v4's `src/pbrt/util/sampling.h` triples), so the chi-square
//! tests and round trips can check every one the same way. The renderer samples forwards
//! only, so the inverses serve the tests (and a debugger mapping a direction back to its sample).

use std::f32::consts::{PI, TAU};

use crate::math::Vec3;

/// Cosine-weighted direction on the hemisphere around +z (Malley's method).
#[inline]
pub fn sample_cosine_hemisphere(u1: f32, u2: f32) -> Vec3 {
    let (dx, dy) = sample_uniform_disk_concentric(u1, u2);
    let z = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
    Vec3::new(dx, dy, z)
}

/// Density of `sample_cosine_hemisphere` per unit solid angle.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * std::f32::consts::FRAC_1_PI
}

/// Shirley-Chiu concentric map of the unit square to the unit disk.
#[inline]
pub fn sample_uniform_disk_concentric(u1: f32, u2: f32) -> (f32, f32) {
    let ox = 2.0 * u1 - 1.0;
    let oy = 2.0 * u2 - 1.0;
    if ox == 0.0 && oy == 0.0 {
        return (0.0, 0.0);
    }
    // r·(cos θ, sin θ) with θ = π/4 · oy/ox, or θ = π/2 − a with a = π/4 · ox/oy, where
    // cos θ = sin a and sin θ = cos a: either way the angle that enters is within ±π/4. The
    // two cases are one computation on swapped inputs and outputs, chosen by selects: which
    // case a sample falls in is a coin toss that a branch would mispredict half the time.
    let swap = ox.abs() <= oy.abs();
    let (r, other) = if swap { (oy, ox) } else { (ox, oy) };
    let (sin, cos) = sin_cos_quarter_pi(std::f32::consts::FRAC_PI_4 * (other / r));
    let (x, y) = (r * cos, r * sin);
    if swap {
        (y, x)
    } else {
        (x, y)
    }
}

/// (sin x, cos x) for |x| ≤ π/4, by the minimax polynomials of Cephes' `sinf`/`cosf` (within
/// an ulp or two there): no range reduction and no libm call, which the warps above would
/// otherwise pay on every bounce.
#[inline]
pub fn sin_cos_quarter_pi(x: f32) -> (f32, f32) {
    let z = x * x;
    let sin = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * x + x;
    let cos = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    (sin, cos)
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn sample_uniform_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform barycentrics (b1, b2) on a triangle.
#[inline]
pub fn sample_uniform_triangle(u1: f32, u2: f32) -> (f32, f32) {
    let s = u1.sqrt();
    (1.0 - s, u2 * s)
}

/// The (u1, u2) that `sample_cosine_hemisphere` maps to the unit `direction` (z >= 0): the
/// inverse of Shirley-Chiu's concentric map applied to the direction's projection on the disk.
#[cfg_attr(not(test), allow(dead_code))]
pub fn invert_cosine_hemisphere(direction: Vec3) -> (f32, f32) {
    invert_uniform_disk_concentric(direction.x, direction.y)
}

/// The (u1, u2) that `sample_uniform_disk_concentric` maps to (x, y).
#[cfg_attr(not(test), allow(dead_code))]
pub fn invert_uniform_disk_concentric(x: f32, y: f32) -> (f32, f32) {
    let r = (x * x + y * y).sqrt();
    if r == 0.0 {
        return (0.5, 0.5);
    }
    let mut phi = y.atan2(x);
    if phi < -std::f32::consts::FRAC_PI_4 {
        phi += TAU;
    }
    // The four wedges of the map: |ox| > |oy| around the x axis, else around the y axis.
    let (ox, oy) = if phi < std::f32::consts::FRAC_PI_4 {
        (r, r * phi / std::f32::consts::FRAC_PI_4)
    } else if phi < 3.0 * std::f32::consts::FRAC_PI_4 {
        (
            r * (std::f32::consts::FRAC_PI_2 - phi) / std::f32::consts::FRAC_PI_4,
            r,
        )
    } else if phi < 5.0 * std::f32::consts::FRAC_PI_4 {
        (-r, -r * (phi - PI) / std::f32::consts::FRAC_PI_4)
    } else {
        (
            -r * (3.0 * std::f32::consts::FRAC_PI_2 - phi) / std::f32::consts::FRAC_PI_4,
            -r,
        )
    };
    ((ox + 1.0) / 2.0, (oy + 1.0) / 2.0)
}

/// Density of `sample_uniform_sphere` per unit solid angle.
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    1.0 / (4.0 * PI)
}

/// The (u1, u2) that `sample_uniform_sphere` maps to the unit `direction`.
#[cfg_attr(not(test), allow(dead_code))]
pub fn invert_uniform_sphere(direction: Vec3) -> (f32, f32) {
    let phi = direction.y.atan2(direction.x);
    let u2 = if phi < 0.0 {
        phi / TAU + 1.0
    } else {
        phi / TAU
    };
    ((1.0 - direction.z) / 2.0, u2)
}

/// The (u1, u2) that `sample_uniform_triangle` maps to barycentrics (b1, b2).
#[cfg_attr(not(test), allow(dead_code))]
pub fn invert_uniform_triangle(b1: f32, b2: f32) -> (f32, f32) {
    let s = 1.0 - b1;
    (
        (s * s).clamp(0.0, 1.0),
        if s > 0.0 {
            (b2 / s).clamp(0.0, 1.0)
        } else {
            0.0
        },
    )
}

/// A direction around +z with density (p+1)/(2π) · cos^p θ per unit solid angle: the lobe
/// of Phong's and Blinn's highlights.
#[inline]
pub fn sample_phong_lobe(u1: f32, u2: f32, exponent: f32) -> Vec3 {
    let cos_theta = u1.powf(1.0 / (exponent + 1.0));
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (TAU * u2).sin_cos();
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// Density of `sample_phong_lobe` per unit solid angle.
#[inline]
pub fn phong_lobe_pdf(cos_theta: f32, exponent: f32) -> f32 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    (exponent + 1.0) / TAU * cos_theta.powf(exponent)
}

/// The (u1, u2) that `sample_phong_lobe` maps to `direction`.
#[inline]
#[cfg_attr(not(test), allow(dead_code))]
pub fn invert_phong_lobe(direction: Vec3, exponent: f32) -> (f32, f32) {
    let u1 = direction.z.clamp(0.0, 1.0).powf(exponent + 1.0);
    let phi = direction.y.atan2(direction.x);
    let u2 = if phi < 0.0 {
        phi / TAU + 1.0
    } else {
        phi / TAU
    };
    (u1, u2)
}

/// A direction uniform in the cone of half-angle θmax around +z.
#[inline]
pub fn sample_uniform_cone(u1: f32, u2: f32, cos_theta_max: f32) -> Vec3 {
    let cos_theta = 1.0 - u1 * (1.0 - cos_theta_max);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (TAU * u2).sin_cos();
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// Density of `sample_uniform_cone` per unit solid angle.
#[inline]
pub fn uniform_cone_pdf(cos_theta_max: f32) -> f32 {
    1.0 / (TAU * (1.0 - cos_theta_max))
}

/// The (u1, u2) that `sample_uniform_cone` maps to the unit `direction` inside the cone.
#[cfg_attr(not(test), allow(dead_code))]
pub fn invert_uniform_cone(direction: Vec3, cos_theta_max: f32) -> (f32, f32) {
    let u1 = (1.0 - direction.z) / (1.0 - cos_theta_max);
    let phi = direction.y.atan2(direction.x);
    let u2 = if phi < 0.0 {
        phi / TAU + 1.0
    } else {
        phi / TAU
    };
    (u1.clamp(0.0, 1.0), u2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each warp followed by its inverse gives back the sample (round trips).
    #[test]
    fn warps_invert() {
        let mut rng = crate::sampling::Rng::new(3, 5);
        for _ in 0..10_000 {
            let u = (rng.next_f32(), rng.next_f32());
            let close = |a: (f32, f32), what: &str| {
                assert!(
                    (a.0 - u.0).abs() < 2e-3 && (a.1 - u.1).abs() < 2e-3,
                    "{what}: {u:?} came back as {a:?}"
                );
            };
            close(
                invert_cosine_hemisphere(sample_cosine_hemisphere(u.0, u.1)),
                "cosine",
            );
            close(
                invert_uniform_sphere(sample_uniform_sphere(u.0, u.1)),
                "sphere",
            );
            let (b1, b2) = sample_uniform_triangle(u.0, u.1);
            close(invert_uniform_triangle(b1, b2), "triangle");
            close(
                invert_phong_lobe(sample_phong_lobe(u.0, u.1, 20.0), 20.0),
                "phong",
            );
            close(
                invert_uniform_cone(sample_uniform_cone(u.0, u.1, 0.7), 0.7),
                "cone",
            );
        }
    }

    #[test]
    fn sin_cos_quarter_pi_is_accurate() {
        for i in -1000..=1000 {
            let x = std::f32::consts::FRAC_PI_4 * i as f32 / 1000.0;
            let (sin, cos) = sin_cos_quarter_pi(x);
            let (sin64, cos64) = (x as f64).sin_cos();
            assert!(
                (sin as f64 - sin64).abs()
                    <= 2.0 * f32::EPSILON as f64 * sin64.abs().max(1e-30) + 1e-12,
                "sin {x}"
            );
            assert!(
                (cos as f64 - cos64).abs() <= 2.0 * f32::EPSILON as f64,
                "cos {x}"
            );
        }
    }
}
