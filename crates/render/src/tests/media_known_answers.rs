//! Participating media's parts against answers known on paper: the phase functions'
//! sampling (chi-square, on `scatter_harness.rs`'s machinery), and the volume grid's
//! trilinear lookup, its box and the box's ray test. Each check comes with a negative
//! control: a phase function or a lookup that is wrong in the way a plausible bug would be,
//! which the same check must reject.

use super::chi2_sampling::{sidak_level, FAMILY_SIGNIFICANCE};
use super::scatter_harness::{bsdf_config, chi2_directions, draw_all, uniforms, Chi2Figures};
use crate::medium::volume::VolumeBounds;
use crate::{Aabb, Color, Matrix4, PhaseFunction, Ray, Transform, Vec3, Volume, VolumeGrid};

use std::f64::consts::PI;

// ---- phase functions ---------------------------------------------------------------------------

/// m, the chi-square p-values this file compares with `phase_significance()`: the isotropic
/// phase function and Henyey–Greenstein at g = 0.7, −0.4, 0 and 0.9.
const PHASE_FAMILY_SIZE: usize = 5;

/// The Šidák level for one p-value of the phase family (it fails falsely with probability
/// `FAMILY_SIGNIFICANCE` as a whole); panics when more p-values are tested than counted.
fn phase_significance() -> f64 {
    static TESTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let tested = TESTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    assert!(
        tested <= PHASE_FAMILY_SIZE,
        "{tested} phase p-values tested but PHASE_FAMILY_SIZE is {PHASE_FAMILY_SIZE}"
    );
    sidak_level(FAMILY_SIGNIFICANCE, PHASE_FAMILY_SIZE)
}

/// The travel direction the phase functions are tested around: not an axis, so that a
/// sampler that ignored it would fail.
fn forward() -> Vec3 {
    Vec3::new(0.36, -0.48, 0.8)
}

/// A frame around `w` built here by Gram–Schmidt (not `Frame::from_normal`, which the
/// sampler uses), so the histogram's (cos θ, φ) are measured independently of it.
fn test_frame(w: Vec3) -> (Vec3, Vec3, Vec3) {
    let helper = if w.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let u = (helper - w * helper.dot(w)).normalized();
    (u, w.cross(u), w)
}

/// A phase function as the checks see it: `sample(forward, u)` → (direction, density) and
/// `eval(forward, wo)`.
type SampleFn<'a> = &'a (dyn Fn(Vec3, (f32, f32)) -> (Vec3, f32) + Sync);
type EvalFn<'a> = &'a (dyn Fn(Vec3, Vec3) -> f32 + Sync);

/// The checks of a phase function around `forward()`: every sample a unit vector whose
/// returned density is `eval` there (to 1e-3, relative above 1); the samples' histogram over
/// (cos θ, φ) from `forward` against `eval` integrated per cell (Pearson's chi-square); and
/// ∫ eval dω = 1 (to 1e-3, the cells' quadrature is good to 1e-7 each). Returns the figures,
/// the p-value unjudged; Err names the first check that failed.
fn examine_phase(name: &str, sample: SampleFn, eval: EvalFn) -> Result<Chi2Figures, String> {
    let config = bsdf_config();
    let forward = forward();
    let (u, v, w) = test_frame(forward);
    let directions = draw_all(&uniforms::<2>(name, config.samples), |&[u0, u1]| {
        let (wo, pdf) = sample(forward, (u0, u1));
        if !(wo.is_finite() && (wo.length() - 1.0).abs() < 1e-4) {
            return Err(format!("{name}: sampled direction {wo:?}"));
        }
        let value = eval(forward, wo);
        let agrees = (pdf - value).abs() <= 1e-3 * value.max(1.0);
        if !agrees {
            return Err(format!(
                "{name}: sample() says density {pdf} at {wo:?}, eval() says {value}"
            ));
        }
        Ok(Some(Vec3::new(wo.dot(u), wo.dot(v), wo.dot(w))))
    })?;
    let figures = chi2_directions(name, config, 0.0, &directions, &|local| {
        eval(forward, u * local.x + v * local.y + w * local.z) as f64
    })?;
    if (figures.pdf_integral - 1.0).abs() > 1e-3 {
        return Err(format!(
            "{name}: eval integrates to {:.5} over the sphere",
            figures.pdf_integral
        ));
    }
    Ok(figures)
}

fn check_phase(name: &str, phase: PhaseFunction) {
    let figures = examine_phase(name, &|f, u| phase.sample(f, u), &|f, wo| phase.eval(f, wo))
        .unwrap_or_else(|e| panic!("{e}"));
    let alpha = phase_significance();
    println!(
        "FIGURE {name}: p = {:.4} (α = {alpha:.2e}), ∫ eval dω = {:.6}",
        figures.p_value, figures.pdf_integral
    );
    assert!(
        figures.p_value > alpha,
        "{name}: chi-square rejects the sampler (p = {:.2e})",
        figures.p_value
    );
}

/// Whether `examine_phase` rejects a variant: an Err, or a p-value far below any level.
fn phase_rejected(name: &str, sample: SampleFn, eval: EvalFn) -> bool {
    match examine_phase(name, sample, eval) {
        Err(e) => {
            println!("NEGATIVE CONTROL rejected as it should be: {e}");
            true
        }
        Ok(f) => {
            println!("{name}: {f:?}");
            f.p_value < 1e-6
        }
    }
}

#[test]
fn isotropic_phase_samples_its_density() {
    check_phase("isotropic", PhaseFunction::Isotropic);
}

#[test]
fn henyey_greenstein_samples_its_density() {
    for g in [0.7, -0.4, 0.0, 0.9] {
        check_phase(
            &format!("Henyey–Greenstein g = {g}"),
            PhaseFunction::HenyeyGreenstein { g },
        );
    }
}

/// Henyey–Greenstein's density written out: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}), θ
/// from the travel direction; g > 0 scatters forward.
fn hg_by_hand(g: f64, cos_theta: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos_theta).powf(1.5))
}

#[test]
fn phase_functions_have_their_known_values() {
    let f = forward();
    let (u, _, _) = test_frame(f);
    for g in [0.7f32, -0.4, 0.0, 0.9] {
        let phase = PhaseFunction::HenyeyGreenstein { g };
        for cos_theta in [-1.0f32, -0.3, 0.0, 0.5, 0.99, 1.0] {
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            let wo = (f * cos_theta + u * sin_theta).normalized();
            let want = hg_by_hand(g as f64, cos_theta as f64);
            let got = phase.eval(f, wo) as f64;
            assert!(
                (got - want).abs() <= 1e-4 * want,
                "g = {g}, cos θ = {cos_theta}: {got} vs {want}"
            );
        }
    }
    // Forward scattering for g > 0: more density along the travel direction than against it.
    let hg = PhaseFunction::HenyeyGreenstein { g: 0.7 };
    assert!(hg.eval(f, f) > 10.0 * hg.eval(f, -f));
    let iso = PhaseFunction::Isotropic;
    assert!((iso.eval(f, u) as f64 - 1.0 / (4.0 * PI)).abs() < 1e-7);
}

/// The checks that pass the phase functions reject them broken: samples drawn with the wrong
/// sign of g (their densities consistent with eval, so only the histogram can tell), eval and
/// the sampled density both 10% too large (the integral), and a sampler whose returned
/// density is the mirrored lobe's (the per-sample agreement).
#[test]
fn phase_checks_reject_wrong_phase_functions() {
    for g in [0.7f32, -0.4] {
        let right = PhaseFunction::HenyeyGreenstein { g };
        let mirrored = PhaseFunction::HenyeyGreenstein { g: -g };
        assert!(phase_rejected(
            &format!("HG g = {g} sampled with −g"),
            &|f, u| {
                let (wo, _) = mirrored.sample(f, u);
                (wo, right.eval(f, wo))
            },
            &|f, wo| right.eval(f, wo),
        ));
        assert!(phase_rejected(
            &format!("HG g = {g}, density × 1.1"),
            &|f, u| {
                let (wo, pdf) = right.sample(f, u);
                (wo, pdf * 1.1)
            },
            &|f, wo| right.eval(f, wo) * 1.1,
        ));
        assert!(phase_rejected(
            &format!("HG g = {g}, sample() returns the −g density"),
            &|f, u| {
                let (wo, _) = right.sample(f, u);
                (wo, mirrored.eval(f, wo))
            },
            &|f, wo| right.eval(f, wo),
        ));
    }
    // A slightly wrong lobe: samples of g = 0.7 against the density of g = 0.65.
    let right = PhaseFunction::HenyeyGreenstein { g: 0.7 };
    let near = PhaseFunction::HenyeyGreenstein { g: 0.65 };
    assert!(phase_rejected(
        "HG g = 0.7 sampled, g = 0.65 claimed",
        &|f, u| {
            let (wo, _) = right.sample(f, u);
            (wo, near.eval(f, wo))
        },
        &|f, wo| near.eval(f, wo),
    ));
}

// ---- volumes -----------------------------------------------------------------------------------

fn close(a: Color, b: Color) -> bool {
    (a - b).abs().max_component() <= 1e-5 * b.abs().max_component().max(1.0)
}

/// A 2×2×2 grid of one channel whose value at sample (x, y, z) is 1 + x + 2y + 4z: its
/// trilinear interpolant is 1 + X + 2Y + 4Z, X = clamp(2 px − ½, 0, 1) (samples at ¼ and
/// ¾), so any point's value is known by hand and a swapped axis changes it.
fn linear_grid() -> VolumeGrid {
    VolumeGrid {
        size: [2, 2, 2],
        channels: 1,
        data: (0..8)
            .map(|i| 1.0 + (i & 1) as f32 + 2.0 * ((i >> 1) & 1) as f32 + 4.0 * (i >> 2) as f32)
            .collect(),
    }
}

#[test]
fn grid_interpolates_trilinearly_between_cell_centres() {
    let grid = linear_grid();
    let by_hand = |p: Vec3| {
        let c = |x: f32| (2.0 * x - 0.5).clamp(0.0, 1.0);
        Color::splat(1.0 + c(p.x) + 2.0 * c(p.y) + 4.0 * c(p.z))
    };
    let points = [
        // The samples themselves, at (i + ½)/n.
        Vec3::new(0.25, 0.25, 0.25),
        Vec3::new(0.75, 0.25, 0.25),
        Vec3::new(0.25, 0.75, 0.25),
        Vec3::new(0.75, 0.75, 0.75),
        // Between them.
        Vec3::new(0.5, 0.5, 0.5),
        Vec3::new(0.375, 0.6, 0.7),
        // In the outer half cells (clamped) and outside the cube (clamped).
        Vec3::new(0.1, 0.9, 0.5),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(-1.0, 2.0, 0.5),
        Vec3::new(1.5, -0.3, 7.0),
    ];
    for p in points {
        let (got, want) = (grid.eval(p), by_hand(p));
        assert!(close(got, want), "at {p:?}: {got:?}, by hand {want:?}");
    }
    // Values written out for a few: the centre is the mean of the eight samples (4.5).
    assert!(close(grid.eval(Vec3::splat(0.5)), Color::splat(4.5)));
    assert!(close(grid.eval(Vec3::splat(0.25)), Color::splat(1.0)));
    assert!(close(grid.eval(Vec3::splat(0.75)), Color::splat(8.0)));
    // (0.375, 0.6, 0.7): X = 0.25, Y = 0.7, Z = 0.9 → 1 + 0.25 + 1.4 + 3.6.
    assert!(close(
        grid.eval(Vec3::new(0.375, 0.6, 0.7)),
        Color::splat(6.25)
    ));
    // Negative control: samples at the cube's corners (i / (n − 1)) would give 1 + 0.375 +
    // 1.2 + 2.8 there, which the lookup must not.
    assert!(!close(
        grid.eval(Vec3::new(0.375, 0.6, 0.7)),
        Color::splat(1.0 + 0.375 + 1.2 + 2.8)
    ));

    // One sample lit: the interpolant is 8 wx wy wz, a product a linear grid cannot test.
    let mut corner = vec![0.0; 8];
    corner[7] = 8.0;
    let corner = VolumeGrid {
        size: [2, 2, 2],
        channels: 1,
        data: corner,
    };
    assert!(close(corner.eval(Vec3::splat(0.5)), Color::splat(1.0)));
    // wx = 0.75, wy = 0.5, wz = 1 (clamped).
    assert!(close(
        corner.eval(Vec3::new(0.625, 0.5, 0.9)),
        Color::splat(3.0)
    ));
    assert!(close(corner.eval(Vec3::splat(0.2)), Color::ZERO));
    assert_eq!(linear_grid().max(), 8.0);
}

#[test]
fn grid_of_three_channels_along_x() {
    // Samples at x = 1/6, 1/2, 5/6; y and z have one sample each, so they do not matter.
    let grid = VolumeGrid {
        size: [3, 1, 1],
        channels: 3,
        data: vec![1.0, 10.0, 100.0, 2.0, 20.0, 200.0, 4.0, 40.0, 400.0],
    };
    let cases = [
        (1.0 / 6.0, Color::new(1.0, 10.0, 100.0)),
        (0.5, Color::new(2.0, 20.0, 200.0)),
        (5.0 / 6.0, Color::new(4.0, 40.0, 400.0)),
        // Halfway between the first two.
        (1.0 / 3.0, Color::new(1.5, 15.0, 150.0)),
        // Three quarters of the way from the second to the third.
        (0.75, Color::new(3.5, 35.0, 350.0)),
        // Clamped in the outer half cells and beyond the cube.
        (0.0, Color::new(1.0, 10.0, 100.0)),
        (0.1, Color::new(1.0, 10.0, 100.0)),
        (0.95, Color::new(4.0, 40.0, 400.0)),
        (1.5, Color::new(4.0, 40.0, 400.0)),
        (-0.5, Color::new(1.0, 10.0, 100.0)),
    ];
    for (x, want) in cases {
        for (y, z) in [(0.5, 0.5), (0.0, 1.0), (-2.0, 3.0)] {
            let got = grid.eval(Vec3::new(x, y, z));
            assert!(close(got, want), "at x = {x}: {got:?}, want {want:?}");
        }
    }
    // `max` is over every sample and channel.
    assert_eq!(grid.max(), 400.0);
    // The channels are innermost: a grid read as if x were innermost would return 10 at the
    // second sample's first channel.
    assert!(close(
        grid.eval(Vec3::new(0.5, 0.5, 0.5)),
        Color::new(2.0, 20.0, 200.0)
    ));
}

fn scale_translate(scale: Vec3, translate: Vec3) -> Transform {
    Transform::from_matrix(&Matrix4::translate(translate).mul(&Matrix4::scale(scale)))
        .expect("invertible")
}

#[test]
fn volume_places_its_grid_by_to_world() {
    let (s, t) = (Vec3::new(2.0, 0.5, 4.0), Vec3::new(1.0, -2.0, 3.0));
    let to_world = scale_translate(s, t);
    let grid = linear_grid();
    let volume = Volume::grid(grid.clone(), to_world);
    // The unit cube's box in the world: [t, t + s].
    let VolumeBounds(bounds) = volume.bounds();
    assert!(
        close(bounds.min, t) && close(bounds.max, t + s),
        "{bounds:?}"
    );
    assert_eq!(volume.max(), 8.0);
    // A world point reads the grid at its place in the unit cube.
    for local in [
        Vec3::new(0.375, 0.6, 0.7),
        Vec3::splat(0.5),
        Vec3::new(0.9, 0.1, 0.3),
    ] {
        let world = t + s.mul_elem(local);
        let (got, want) = (volume.eval(world), grid.eval(local));
        assert!(close(got, want), "{local:?}: {got:?} vs {want:?}");
    }
    // Negative control: the grid read at the world point itself differs.
    let p = t + s.mul_elem(Vec3::new(0.375, 0.6, 0.7));
    assert!(!close(volume.eval(p), grid.eval(p)));
    // A constant volume: its value everywhere, its box, its max the largest channel.
    let constant = Volume::constant(Color::new(0.5, 3.0, 2.0), &to_world);
    assert_eq!(constant.eval(Vec3::splat(100.0)), Color::new(0.5, 3.0, 2.0));
    assert_eq!(constant.bounds(), volume.bounds());
    assert_eq!(constant.max(), 3.0);
}

#[test]
fn volume_bounds_intersect_rays() {
    let bounds = VolumeBounds(Aabb {
        min: Vec3::ZERO,
        max: Vec3::new(1.0, 2.0, 3.0),
    });
    let ray = |o: Vec3, d: Vec3| Ray::new(o, d.normalized());
    let near_far = |r: Ray| bounds.intersect(&r);
    let eq = |got: Option<(f32, f32)>, want: (f32, f32)| {
        got.is_some_and(|(a, b)| (a - want.0).abs() < 1e-5 && (b - want.1).abs() < 1e-5)
    };
    // From outside, through it.
    let got = near_far(ray(Vec3::new(-1.0, 1.0, 1.5), Vec3::X));
    assert!(eq(got, (1.0, 2.0)), "{got:?}");
    // From inside: near is behind the origin.
    let got = near_far(ray(Vec3::new(0.5, 1.0, 1.5), Vec3::X));
    assert!(eq(got, (-0.5, 0.5)), "{got:?}");
    // Diagonally, entering through an edge.
    let s2 = 2f32.sqrt();
    let got = near_far(ray(Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, 1.0, 0.0)));
    assert!(eq(got, (s2, 2.0 * s2)), "{got:?}");
    // Missing it: parallel to a face outside its slab, passing beside it, pointing away.
    assert_eq!(near_far(ray(Vec3::new(-1.0, 5.0, 1.5), Vec3::X)), None);
    assert_eq!(
        near_far(ray(Vec3::new(-1.0, -1.0, 0.5), Vec3::new(1.0, 0.2, 0.0))),
        None
    );
    assert_eq!(near_far(ray(Vec3::new(2.0, 1.0, 1.0), Vec3::X)), None);
    // Along -z from above.
    let got = near_far(ray(Vec3::new(0.5, 0.5, 10.0), -Vec3::Z));
    assert!(eq(got, (7.0, 10.0)), "{got:?}");
}
