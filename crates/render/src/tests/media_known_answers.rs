//! Participating media against answers known on paper: the phase functions' sampling
//! (chi-square, on `scatter_harness.rs`'s machinery), the volume grid's trilinear lookup and
//! box, Beer–Lambert through homogeneous and heterogeneous slabs seen by the camera and by
//! shadow rays, white furnaces filled with scattering media, and Mitsuba's rules for the
//! medium a ray is in (the camera's, an emitter's, across boundaries, through a thin
//! dielectric).
//!
//! Renders are judged by one rule (`Estimate::agrees`): with N independent observations
//! (pixels, whose Sobol' points are scrambled per pixel and so independent of each other; or
//! paths traced with their own PCG streams) of mean m and sample standard error s, the
//! expected value e must satisfy |m − e| ≤ 5 s + 1e-4 |e| + 1e-6. One such check fails
//! falsely with probability 5.7e-7 under the normal approximation, 5e-6 by Student's t for
//! the smallest samples here (the 64 pixels of an image's quadrant); this file makes about
//! 300, so the family fails falsely with probability below 1e-3. The 1e-4 covers f32
//! arithmetic where an estimate has no noise at all (Beer–Lambert in closed form).
//!
//! Every check comes with a negative control: a scene or an expectation that is wrong in the
//! way a plausible bug would be (a medium 5% denser, a shadow ray's path taken vertically,
//! the previous medium restored on leaving a shape, a single interface's Fresnel for a thin
//! sheet, an albedo of 0.9 in a furnace) that the same check must reject.

use super::chi2_sampling::{sidak_level, FAMILY_SIGNIFICANCE};
use super::path_known_answers::instance;
use super::scatter_harness::{bsdf_config, chi2_directions, draw_all, uniforms, Chi2Figures};
use crate::integrator::path::PathSettings;
use crate::integrator::volpath::VolPathIntegrator;
use crate::integrator::FirstHit;
use crate::material::dielectric::ThinDielectric;
use crate::material::physical::{BsdfNode, Param};
use crate::medium::volume::VolumeBounds;
use crate::sampling::Rng;
use crate::scene::physical::PhysicalParts;
use crate::{
    render, Aabb, Background, Camera, Color, GeometryDesc, IntegratorKind, Light, Material,
    Matrix4, Medium, MediumBoundary, MediumId, PhaseFunction, Projection, Ray, RenderSettings,
    Scene, SceneParts, Shape, Transform, Vec3, Volume, VolumeGrid,
};

use std::f64::consts::PI;

// ---- statistics ------------------------------------------------------------------------------

/// How many standard errors an estimate may stray from its expected value.
const Z: f64 = 5.0;
/// Relative slack for f32 arithmetic, where an estimate has no noise.
const FLOAT_TOLERANCE: f64 = 1e-4;

/// The mean of independent observations and its standard error.
#[derive(Clone, Copy, Debug)]
struct Estimate {
    mean: f64,
    standard_error: f64,
    count: usize,
}

impl Estimate {
    fn of(values: impl IntoIterator<Item = f64>) -> Estimate {
        let values: Vec<f64> = values.into_iter().collect();
        let n = values.len() as f64;
        assert!(values.len() >= 2, "an estimate needs two observations");
        let mean = values.iter().sum::<f64>() / n;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        Estimate {
            mean,
            standard_error: (variance / n).sqrt(),
            count: values.len(),
        }
    }

    /// The file's rule (module docs).
    fn agrees(&self, expected: f64) -> bool {
        self.mean.is_finite()
            && (self.mean - expected).abs()
                <= Z * self.standard_error + FLOAT_TOLERANCE * expected.abs() + 1e-6
    }

    fn judge(&self, name: &str, expected: f64) -> Result<String, String> {
        let line = format!(
            "{name}: expected {expected:.5}, measured {:.5} ± {:.5} (N = {}, bound {:.5})",
            self.mean,
            self.standard_error,
            self.count,
            Z * self.standard_error + FLOAT_TOLERANCE * expected.abs() + 1e-6
        );
        if self.agrees(expected) {
            Ok(line)
        } else {
            Err(line)
        }
    }
}

/// Every channel of `pixels` (a `size`² image) against `expected`, over the whole image and
/// over each of its four quadrants (a bias confined to a region, such as the rim of a
/// sphere, shows there). Ok holds the figures of the whole image.
fn judge_image(name: &str, pixels: &[Color], size: u32, expected: Color) -> Result<String, String> {
    let half = size / 2;
    let mut report = vec![];
    for (channel, want) in expected.to_array().into_iter().enumerate() {
        let value = |i: usize| pixels[i].to_array()[channel] as f64;
        let whole = Estimate::of((0..pixels.len()).map(value));
        report.push(whole.judge(&format!("{name}, channel {channel}"), want as f64)?);
        for quadrant in 0..4 {
            let (qx, qy) = (quadrant % 2 * half, quadrant / 2 * half);
            let indices =
                (qy..qy + half).flat_map(|y| (qx..qx + half).map(move |x| (y * size + x) as usize));
            Estimate::of(indices.map(value)).judge(
                &format!("{name}, channel {channel}, quadrant {quadrant}"),
                want as f64,
            )?;
        }
    }
    Ok(report.join("\n"))
}

/// Each channel of the traced samples' mean against `expected`.
fn judge_samples(name: &str, samples: &[Color], expected: Color) -> Result<String, String> {
    let mut report = vec![];
    for (channel, want) in expected.to_array().into_iter().enumerate() {
        let estimate = Estimate::of(samples.iter().map(|c| c.to_array()[channel] as f64));
        report.push(estimate.judge(&format!("{name}, channel {channel}"), want as f64)?);
    }
    Ok(report.join("\n"))
}

/// Prints a passing check's figures, or panics with the failing one's.
fn pass(result: Result<String, String>) {
    match result {
        Ok(figures) => println!("FIGURE {figures}"),
        Err(failure) => panic!("rejected: {failure}"),
    }
}

/// Asserts that a negative control is rejected, and prints why.
fn reject(result: Result<String, String>) {
    match result {
        Ok(figures) => panic!("a negative control passed: {figures}"),
        Err(failure) => println!("NEGATIVE CONTROL rejected as it should be: {failure}"),
    }
}

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

// ---- scenes ------------------------------------------------------------------------------------

/// The null BSDF and its material, id 0 in every scene here.
const NULL: u32 = 0;

/// A scene of physically based parts, as the media tests vary it.
struct Setup {
    camera: Camera,
    bsdfs: Vec<BsdfNode>,
    materials: Vec<Material>,
    /// Each geometry with the media its surface separates.
    geometries: Vec<(GeometryDesc, Option<MediumBoundary>)>,
    media: Vec<Medium>,
    camera_medium: Option<MediumId>,
    lights: Vec<Light>,
    background: Color,
}

impl Setup {
    fn new(camera: Camera) -> Setup {
        Setup {
            camera,
            bsdfs: vec![BsdfNode::Null],
            materials: vec![Material::Physical(0)],
            geometries: vec![],
            media: vec![],
            camera_medium: None,
            lights: vec![],
            background: Color::ZERO,
        }
    }

    /// Adds a BSDF with its material; returns the material's id.
    fn material(&mut self, bsdf: BsdfNode) -> u32 {
        self.bsdfs.push(bsdf);
        self.materials
            .push(Material::Physical(self.bsdfs.len() as u32 - 1));
        self.materials.len() as u32 - 1
    }

    fn medium(&mut self, medium: Medium) -> MediumId {
        self.media.push(medium);
        self.media.len() as MediumId - 1
    }

    fn build(self) -> Scene {
        let count = self.geometries.len() as u32;
        let (geometries, boundaries) = self.geometries.into_iter().unzip();
        Scene::new(SceneParts {
            camera: self.camera,
            materials: self.materials,
            textures: vec![],
            lights: self.lights,
            background: Background::Color(self.background),
            geometries,
            instances: (0..count).map(|i| instance(i, true)).collect(),
            physical: PhysicalParts {
                bsdfs: self.bsdfs,
                media: self.media,
                boundaries,
                camera_medium: self.camera_medium,
                ..PhysicalParts::default()
            },
        })
    }
}

/// An orthographic camera at height `z` looking down −z, its image `width` wide.
fn looking_down(z: f32, width: f32) -> Camera {
    Camera::new(
        Projection::Orthographic,
        Vec3::new(0.0, 0.0, z),
        -Vec3::Z,
        1.0,
        width,
    )
}

/// The box [min, max] as 12 triangles of `material` whose winding puts the geometric normal
/// outward (`outward`) or inward.
fn cuboid(min: Vec3, max: Vec3, material: u32, outward: bool) -> GeometryDesc {
    let mut shapes = vec![];
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        for side in [false, true] {
            let corner = |a: bool, b: bool| {
                let mut p = [0.0f32; 3];
                p[k] = if side { max[k] } else { min[k] };
                p[i] = if a { max[i] } else { min[i] };
                p[j] = if b { max[j] } else { min[j] };
                Vec3::from_array(p)
            };
            let (c00, c10, c11, c01) = (
                corner(false, false),
                corner(true, false),
                corner(true, true),
                corner(false, true),
            );
            // e_i × e_j = e_k: counter-clockwise about +e_k, the outward normal of the max
            // side; the min side and inward normals turn the other way.
            let mut triangles = [[c00, c10, c11], [c00, c11, c01]];
            if side != outward {
                for t in &mut triangles {
                    t.swap(1, 2);
                }
            }
            for vertices in triangles {
                let n = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
                let centre = (min + max) * 0.5;
                let out = n.dot(vertices[0] - centre) > 0.0;
                assert_eq!(out, outward, "the winding of a face of the cuboid");
                shapes.push(Shape::Triangle { vertices });
            }
        }
    }
    let n = shapes.len();
    GeometryDesc {
        shapes,
        materials: vec![material; n],
    }
}

/// The horizontal square of half side `half` at height `z`, facing +z.
fn square(z: f32, half: f32) -> [[Vec3; 3]; 2] {
    let c = |x: f32, y: f32| Vec3::new(x * half, y * half, z);
    [
        [c(-1.0, -1.0), c(1.0, -1.0), c(1.0, 1.0)],
        [c(-1.0, -1.0), c(1.0, 1.0), c(-1.0, 1.0)],
    ]
}

fn triangles(triangles: &[[Vec3; 3]], material: u32) -> GeometryDesc {
    GeometryDesc {
        shapes: triangles
            .iter()
            .map(|&vertices| Shape::Triangle { vertices })
            .collect(),
        materials: vec![material; triangles.len()],
    }
}

/// The surface bounds `interior` behind it and vacuum in front.
fn interior(id: MediumId) -> Option<MediumBoundary> {
    Some(MediumBoundary {
        interior: Some(id),
        exterior: None,
    })
}

fn homogeneous(sigma_t: Color, albedo: Color, phase: PhaseFunction) -> Medium {
    Medium::Homogeneous {
        sigma_t,
        albedo,
        phase,
        sample_emitters: true,
    }
}

fn absorbing(sigma_t: Color) -> Medium {
    homogeneous(sigma_t, Color::ZERO, PhaseFunction::Isotropic)
}

/// A heterogeneous medium of σt `sigma_t` (scaled by `scale`) and a constant albedo over the
/// same box.
fn heterogeneous(sigma_t: Volume, scale: f32, albedo: Color, phase: PhaseFunction) -> Medium {
    let bounds = sigma_t.bounds().0;
    let box_transform = scale_translate(bounds.max - bounds.min, bounds.min);
    Medium::Heterogeneous {
        albedo: Volume::constant(albedo, &box_transform),
        sigma_t,
        scale,
        phase,
        sample_emitters: true,
    }
}

/// Transmittance exp(−σt d) per channel.
fn beer_lambert(sigma_t: Color, distance: f32) -> Color {
    sigma_t.map(|s| (-s * distance).exp())
}

/// The volumetric path tracer's image of `scene` at `size`² pixels and `spp` samples; panics
/// on non-finite samples, which the pipeline would drop silently.
fn render_volpath(scene: &Scene, size: u32, spp: u32) -> Vec<Color> {
    let settings = RenderSettings {
        width: size,
        height: size,
        samples_per_pixel: spp,
        seed: 23,
        integrator: IntegratorKind::VolPath,
        ..RenderSettings::default()
    };
    let (film, stats) = render(scene, &settings, &|_| true).expect("renders");
    assert_eq!(
        stats.nonfinite_samples, 0,
        "non-finite samples, the first at pixel {:?}",
        stats.first_nonfinite_pixel
    );
    film.pixels
}

/// `count` independent samples of the radiance along `ray` (made unit) starting in `medium`,
/// each path on its own PCG stream.
fn trace_samples(
    scene: &Scene,
    settings: PathSettings,
    ray: Ray,
    medium: Option<MediumId>,
    count: u32,
) -> Vec<Color> {
    let integrator = VolPathIntegrator::new(scene, settings);
    let ray = Ray::new(ray.origin, ray.direction.normalized());
    (0..count)
        .map(|s| {
            let mut rng = Rng::for_sample(31, 7, s as u64);
            let mut rays = 0;
            let mut first_hit = FirstHit::default();
            let c = integrator.trace(scene, ray, medium, &mut rng, &mut rays, &mut first_hit);
            assert!(c.is_finite(), "sample {s}: {c:?}");
            c
        })
        .collect()
}

// ---- Beer–Lambert seen by the camera -----------------------------------------------------------

/// Per-channel extinction of the slabs.
const SIGMA_T: Color = Color::new(0.5, 1.0, 2.0);
/// The background's radiance behind them.
const BACKGROUND: Color = Color::new(2.0, 1.0, 0.5);
const SLAB_IMAGE: u32 = 32;
const SLAB_SPP: u32 = 64;

/// An orthographic camera above a slab z ∈ [−d/2, d/2] (4 wide, wider than the view) bounded
/// by a null box whose interior is `medium`, the background behind it.
fn slab_scene(medium: Medium, thickness: f32) -> Scene {
    let mut setup = Setup::new(looking_down(3.0, 1.0));
    let id = setup.medium(medium);
    let half = Vec3::new(2.0, 2.0, 0.5 * thickness);
    setup
        .geometries
        .push((cuboid(-half, half, NULL, true), interior(id)));
    setup.background = BACKGROUND;
    setup.build()
}

/// The unit cube placed on the slab of `slab_scene` (for a volume filling it).
fn slab_volume_transform(thickness: f32) -> Transform {
    let half = Vec3::new(2.0, 2.0, 0.5 * thickness);
    scale_translate(half * 2.0, -half)
}

fn slab_image(medium: Medium, thickness: f32) -> Vec<Color> {
    render_volpath(&slab_scene(medium, thickness), SLAB_IMAGE, SLAB_SPP)
}

/// A homogeneous absorbing slab of thickness 1: every pixel is L·exp(−σt) per channel. The
/// estimator picks a channel's σt for each distance and weighs by the mean of the three
/// densities (spectral MIS), so pixels are noisy though the answer is not. Negative control:
/// the slab 5% denser fails the same check.
#[test]
fn beer_lambert_through_a_homogeneous_slab() {
    let expected = BACKGROUND.mul_elem(beer_lambert(SIGMA_T, 1.0));
    let image = slab_image(absorbing(SIGMA_T), 1.0);
    pass(judge_image(
        "homogeneous slab",
        &image,
        SLAB_IMAGE,
        expected,
    ));
    // One channel alone has no spectral MIS: σt = 1 in every channel.
    let grey = slab_image(absorbing(Color::ONE), 1.5);
    pass(judge_image(
        "grey homogeneous slab, d = 1.5",
        &grey,
        SLAB_IMAGE,
        BACKGROUND.mul_elem(beer_lambert(Color::ONE, 1.5)),
    ));
    let denser = slab_image(absorbing(SIGMA_T * 1.05), 1.0);
    reject(judge_image(
        "homogeneous slab 5% denser",
        &denser,
        SLAB_IMAGE,
        expected,
    ));
}

/// A heterogeneous medium of constant σt = (0.5, 1, 2) over the slab: one majorant (2) for
/// all channels, so delta tracking makes null collisions, each weighing the channels by
/// σn / (σ̄ p_null). The same answer, with more noise. Negative control: 5% denser.
#[test]
fn beer_lambert_through_a_constant_heterogeneous_slab() {
    let expected = BACKGROUND.mul_elem(beer_lambert(SIGMA_T, 1.0));
    let medium = |sigma_t: Color| {
        heterogeneous(
            Volume::constant(sigma_t, &slab_volume_transform(1.0)),
            1.0,
            Color::ZERO,
            PhaseFunction::Isotropic,
        )
    };
    let image = slab_image(medium(SIGMA_T), 1.0);
    pass(judge_image(
        "heterogeneous constant slab",
        &image,
        SLAB_IMAGE,
        expected,
    ));
    // Scale is applied: σt 0.5 × scale 2 is σt 1 × scale 1.
    let scaled = slab_image(
        heterogeneous(
            Volume::constant(SIGMA_T * 0.5, &slab_volume_transform(1.0)),
            2.0,
            Color::ZERO,
            PhaseFunction::Isotropic,
        ),
        1.0,
    );
    pass(judge_image(
        "heterogeneous constant slab, σt / 2 with scale 2",
        &scaled,
        SLAB_IMAGE,
        expected,
    ));
    let denser = slab_image(medium(SIGMA_T * 1.05), 1.0);
    reject(judge_image(
        "heterogeneous constant slab 5% denser",
        &denser,
        SLAB_IMAGE,
        expected,
    ));
}

/// The samples of the ramp: σt doubling from cell to cell along z.
const RAMP: [f32; 4] = [0.25, 0.5, 1.0, 2.0];
/// A linear ramp, σt = 0.5 + 2z between the first and last cell centres.
const LINEAR_RAMP: [f32; 4] = [0.75, 1.25, 1.75, 2.25];

/// ∫ σt dz over the unit cube of a grid along z: with samples at cell centres and clamped
/// half cells at the ends, the trapezoids and the two half cells add up to the samples' mean.
fn ramp_integral_cell_centred(ramp: &[f32]) -> f32 {
    ramp.iter().sum::<f32>() / ramp.len() as f32
}

/// The same if the samples sat on the cube's faces and corners (i / (n − 1)): the trapezoid
/// rule over n − 1 intervals. What a lookup placing its samples there would integrate.
fn ramp_integral_corner_aligned() -> f32 {
    let n = RAMP.len() as f32;
    (RAMP.iter().sum::<f32>() - 0.5 * (RAMP[0] + RAMP[RAMP.len() - 1])) / (n - 1.0)
}

fn ramp_volume(ramp: &[f32], to_world: Transform) -> Volume {
    Volume::grid(
        VolumeGrid {
            size: [1, 1, ramp.len() as u32],
            channels: 1,
            data: ramp.to_vec(),
        },
        to_world,
    )
}

/// Grids whose σt ramps along the view direction: transmittance exp(−d ∫σt), ∫σt the
/// samples' mean (1.5 for the linear ramp, 0.9375 for the doubling one). Negative control:
/// the doubling ramp against the integral of corner-aligned samples (0.875), so the check
/// resolves where the samples sit (a linear ramp integrates alike either way).
#[test]
fn beer_lambert_through_a_ramp_grid() {
    let thickness = 1.0;
    let image = |ramp: &[f32]| {
        let medium = heterogeneous(
            ramp_volume(ramp, slab_volume_transform(thickness)),
            1.0,
            Color::ZERO,
            PhaseFunction::Isotropic,
        );
        slab_image(medium, thickness)
    };
    let expected = |integral: f32| BACKGROUND * (-thickness * integral).exp();
    pass(judge_image(
        "linear ramp grid slab",
        &image(&LINEAR_RAMP),
        SLAB_IMAGE,
        expected(ramp_integral_cell_centred(&LINEAR_RAMP)),
    ));
    let doubling = image(&RAMP);
    pass(judge_image(
        "doubling ramp grid slab",
        &doubling,
        SLAB_IMAGE,
        expected(ramp_integral_cell_centred(&RAMP)),
    ));
    reject(judge_image(
        "doubling ramp grid slab against corner-aligned samples",
        &doubling,
        SLAB_IMAGE,
        expected(ramp_integral_corner_aligned()),
    ));
}

// ---- Beer–Lambert on shadow rays -----------------------------------------------------------------

const FLOOR_ALBEDO: f32 = 0.6;
const LIGHT_INTENSITY: Color = Color::new(6.0, 5.0, 4.0);
/// The slab between the floor and the light: z ∈ [1, 1.5], 8 wide.
const SHADOW_SLAB: (f32, f32) = (1.0, 1.5);

/// A diffuse floor (z = 0, albedo 0.6), an absorbing slab above it bounded by a null box of
/// interior `medium`, `light` above the slab, a black sky.
fn shadow_scene(medium: Medium, light: Light) -> Scene {
    let mut setup = Setup::new(looking_down(5.0, 1.0));
    let floor = setup.material(BsdfNode::Diffuse {
        reflectance: Param::value(FLOOR_ALBEDO),
    });
    setup
        .geometries
        .push((triangles(&square(0.0, 5.0), floor), None));
    let id = setup.medium(medium);
    let (lo, hi) = SHADOW_SLAB;
    setup.geometries.push((
        cuboid(
            Vec3::new(-4.0, -4.0, lo),
            Vec3::new(4.0, 4.0, hi),
            NULL,
            true,
        ),
        interior(id),
    ));
    setup.lights.push(light);
    setup.build()
}

/// Samples of the radiance leaving floor point `p` towards an eye just above it (below the
/// slab, so only the shadow rays cross it).
fn floor_samples(scene: &Scene, p: Vec3, count: u32) -> Vec<Color> {
    let eye = p + Vec3::new(0.05, -0.03, 0.4);
    trace_samples(
        scene,
        PathSettings::default(),
        Ray::new(eye, p - eye),
        None,
        count,
    )
}

/// ρ/π · I cos θ / r² · exp(−σt · path), the path through the slab `slant` (its thickness
/// over cos θ) or, for the negative control, its thickness alone.
fn floor_expected(
    p: Vec3,
    light: Vec3,
    optical_depth: &dyn Fn(f32) -> Color,
    slant: bool,
) -> Color {
    let to_light = light - p;
    let cos_theta = to_light.normalized().z;
    let thickness = SHADOW_SLAB.1 - SHADOW_SLAB.0;
    let path = if slant {
        thickness / cos_theta
    } else {
        thickness
    };
    let tr = optical_depth(path).map(|tau| (-tau).exp());
    LIGHT_INTENSITY.mul_elem(tr)
        * (FLOOR_ALBEDO / std::f32::consts::PI * cos_theta / to_light.length_squared())
}

/// Floor point `p`'s samples against the slanted path to the light at `light` through the
/// slab of `optical_depth`, and (away from the point under the light, where the two agree)
/// rejected against the vertical path: the shadow ray must cross the slab along itself.
fn check_floor_point(
    label: &str,
    samples: &[Color],
    p: Vec3,
    light: Vec3,
    optical_depth: &dyn Fn(f32) -> Color,
) {
    pass(judge_samples(
        label,
        samples,
        floor_expected(p, light, optical_depth, true),
    ));
    if p != Vec3::ZERO {
        reject(judge_samples(
            &format!("{label}, vertical path"),
            samples,
            floor_expected(p, light, optical_depth, false),
        ));
    }
}

const FLOOR_POINTS: [Vec3; 3] = [
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(0.8, -0.5, 0.0),
    Vec3::new(-1.5, 1.2, 0.0),
];

/// A point light and a spot above a homogeneous absorbing slab: transmittance in closed form
/// on the shadow ray, so the floor's radiance is exact (no noise: the estimate has none).
/// Negative control: the slab's thickness taken vertically instead of along the ray.
#[test]
fn shadow_rays_carry_beer_lambert_transmittance() {
    let light_position = Vec3::new(0.3, 0.2, 2.5);
    let sigma = |path: f32| SIGMA_T * path;
    let point = Light::Point {
        position: light_position,
        intensity: LIGHT_INTENSITY,
    };
    // The spot points down (its +z turned to −z) with the floor points well inside its beam.
    let spot = Light::Spot {
        to_world: Transform::from_matrix(
            &Matrix4::translate(light_position).mul(&Matrix4::rotate(0, 180.0)),
        )
        .expect("invertible"),
        intensity: LIGHT_INTENSITY,
        cutoff_angle: 60.0,
        beam_width: 50.0,
        texture: None,
    };
    for (name, light) in [("point", point), ("spot", spot)] {
        let scene = shadow_scene(absorbing(SIGMA_T), light);
        for p in FLOOR_POINTS {
            let samples = floor_samples(&scene, p, 64);
            let label = format!("{name} light through a homogeneous slab at {p:?}");
            check_floor_point(&label, &samples, p, light_position, &sigma);
        }
    }
}

/// The same through the ramp grid filling the slab: ratio tracking estimates the
/// transmittance without bias but with noise; the optical depth is path · mean(ramp).
#[test]
fn shadow_rays_ratio_track_a_ramp_grid() {
    let light_position = Vec3::new(0.3, 0.2, 2.5);
    let (lo, hi) = SHADOW_SLAB;
    let to_world = scale_translate(Vec3::new(8.0, 8.0, hi - lo), Vec3::new(-4.0, -4.0, lo));
    let scene = shadow_scene(
        heterogeneous(
            ramp_volume(&RAMP, to_world),
            2.0,
            Color::ZERO,
            PhaseFunction::Isotropic,
        ),
        Light::Point {
            position: light_position,
            intensity: LIGHT_INTENSITY,
        },
    );
    let depth = |path: f32| Color::splat(2.0 * path * ramp_integral_cell_centred(&RAMP));
    for p in FLOOR_POINTS {
        let samples = floor_samples(&scene, p, 20_000);
        let label = format!("point light through a ramp grid at {p:?}");
        check_floor_point(&label, &samples, p, light_position, &depth);
    }
}

// ---- white furnaces ----------------------------------------------------------------------------

const FURNACE_IMAGE: u32 = 16;
const FURNACE_SPP: u32 = 256;

/// A null sphere of radius 1 at the origin filled with `medium`, inside an environment of
/// radiance 1, seen from 3 away by a camera narrow enough that every pixel sees the sphere.
fn furnace(medium: Medium) -> Vec<Color> {
    let mut setup = Setup::new(Camera::new(
        Projection::Perspective,
        Vec3::new(0.0, 0.0, 3.0),
        -Vec3::Z,
        1.0,
        0.4,
    ));
    let id = setup.medium(medium);
    setup.geometries.push((
        GeometryDesc {
            shapes: vec![Shape::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            }],
            materials: vec![NULL],
        },
        interior(id),
    ));
    setup.background = Color::ONE;
    render_volpath(&setup.build(), FURNACE_IMAGE, FURNACE_SPP)
}

fn furnace_grid() -> Volume {
    let mut rng = Rng::new(3, 5);
    let data = (0..64).map(|_| 0.3 + 2.7 * rng.next_f32()).collect();
    Volume::grid(
        VolumeGrid {
            size: [4, 4, 4],
            channels: 1,
            data,
        },
        scale_translate(Vec3::splat(2.0), Vec3::splat(-1.0)),
    )
}

/// Media that scatter all they extinguish (albedo 1) lose no energy: inside a furnace of
/// radiance 1 every pixel is 1, with isotropic and forward and backward Henyey–Greenstein
/// scattering, per-channel σt (spectral MIS) and a grid (delta tracking). Negative control:
/// albedo 0.9 fails the same check.
#[test]
fn white_furnace_with_scattering_media() {
    let cases = [
        (
            "homogeneous isotropic, σt (0.5, 1, 2)",
            homogeneous(SIGMA_T, Color::ONE, PhaseFunction::Isotropic),
        ),
        (
            "homogeneous HG g = 0.7, σt 1.5",
            homogeneous(
                Color::splat(1.5),
                Color::ONE,
                PhaseFunction::HenyeyGreenstein { g: 0.7 },
            ),
        ),
        (
            "homogeneous HG g = −0.4, σt (1, 1.5, 2)",
            homogeneous(
                Color::new(1.0, 1.5, 2.0),
                Color::ONE,
                PhaseFunction::HenyeyGreenstein { g: -0.4 },
            ),
        ),
        (
            "grid σt in [0.3, 3], isotropic",
            heterogeneous(furnace_grid(), 1.0, Color::ONE, PhaseFunction::Isotropic),
        ),
        (
            "grid σt in [0.6, 6] (scale 2), HG g = 0.5",
            heterogeneous(
                furnace_grid(),
                2.0,
                Color::ONE,
                PhaseFunction::HenyeyGreenstein { g: 0.5 },
            ),
        ),
    ];
    for (name, medium) in cases {
        let image = furnace(medium);
        pass(judge_image(
            &format!("furnace, {name}"),
            &image,
            FURNACE_IMAGE,
            Color::ONE,
        ));
    }
    let lossy = furnace(homogeneous(
        SIGMA_T,
        Color::splat(0.9),
        PhaseFunction::Isotropic,
    ));
    reject(judge_image(
        "furnace, albedo 0.9",
        &lossy,
        FURNACE_IMAGE,
        Color::ONE,
    ));
    let lossy = furnace(heterogeneous(
        furnace_grid(),
        1.0,
        Color::splat(0.9),
        PhaseFunction::Isotropic,
    ));
    reject(judge_image(
        "furnace, grid, albedo 0.9",
        &lossy,
        FURNACE_IMAGE,
        Color::ONE,
    ));
}

// ---- which medium a ray is in ------------------------------------------------------------------

/// The camera inside a medium (`camera_medium`) at z = 1 in a box of it spanning
/// z ∈ [−1, 2]: its rays cross 2 units of it before leaving into vacuum. Negative control:
/// the same scene with the camera in vacuum (its rays enter nothing: leaving the box along
/// its normal puts them in its exterior) sees the background unattenuated.
#[test]
fn camera_inside_a_medium() {
    let build = |camera_medium: bool| {
        let mut setup = Setup::new(looking_down(1.0, 1.0));
        let id = setup.medium(absorbing(SIGMA_T));
        setup.geometries.push((
            cuboid(
                Vec3::new(-3.0, -3.0, -1.0),
                Vec3::new(3.0, 3.0, 2.0),
                NULL,
                true,
            ),
            interior(id),
        ));
        setup.camera_medium = camera_medium.then_some(id);
        setup.background = BACKGROUND;
        setup.build()
    };
    let expected = BACKGROUND.mul_elem(beer_lambert(SIGMA_T, 2.0));
    let image = render_volpath(&build(true), SLAB_IMAGE, SLAB_SPP);
    pass(judge_image(
        "camera in a medium",
        &image,
        SLAB_IMAGE,
        expected,
    ));
    let outside = render_volpath(&build(false), SLAB_IMAGE, SLAB_SPP);
    reject(judge_image(
        "camera in vacuum",
        &outside,
        SLAB_IMAGE,
        expected,
    ));
}

/// A medium no surface bounds, with a channel of σt = 0: (σt, what survives an infinite path
/// through it, exp(−σt·∞) per channel, 1 where σt = 0).
const UNBOUNDED: [(Color, Color); 2] = [
    (Color::new(0.0, 0.5, 1.0), Color::new(1.0, 0.0, 0.0)),
    (Color::ZERO, Color::ONE),
];

/// A scene in an unbounded absorbing medium of `sigma_t` (the camera's), under the
/// background, with `geometry` (a null triangle out of view if none).
fn unbounded_scene(sigma_t: Color, floor: bool) -> (Scene, MediumId) {
    let mut setup = Setup::new(looking_down(1.0, 1.0));
    let id = setup.medium(absorbing(sigma_t));
    if floor {
        let floor = setup.material(BsdfNode::Diffuse {
            reflectance: Param::value(FLOOR_ALBEDO),
        });
        setup
            .geometries
            .push((triangles(&square(0.0, 5.0), floor), None));
    } else {
        let far_away = [
            Vec3::new(50.0, 0.0, 0.0),
            Vec3::new(51.0, 0.0, 0.0),
            Vec3::new(50.0, 1.0, 0.0),
        ];
        setup.geometries.push((triangles(&[far_away], NULL), None));
    }
    setup.camera_medium = Some(id);
    setup.background = BACKGROUND;
    (setup.build(), id)
}

/// The camera in an unbounded medium under the environment: the escaping rays keep the
/// background's radiance in the channels of σt = 0 and lose it in the others. Negative
/// control: the background unattenuated in every channel.
#[test]
fn camera_in_an_unbounded_medium() {
    for (sigma_t, survives) in UNBOUNDED {
        let (scene, _) = unbounded_scene(sigma_t, false);
        let image = render_volpath(&scene, 16, 16);
        let name = format!("camera in an unbounded medium of σt {sigma_t:?}");
        pass(judge_image(
            &name,
            &image,
            16,
            BACKGROUND.mul_elem(survives),
        ));
        if survives != Color::ONE {
            reject(judge_image(
                &format!("{name}, unattenuated"),
                &image,
                16,
                BACKGROUND,
            ));
        }
    }
}

/// A diffuse floor in the same unbounded medium, lit by the environment alone: shadow rays
/// towards it are infinitely long, so the floor is ρ L in the channels of σt = 0 (the open
/// hemisphere's irradiance π L times ρ/π) and black in the others. Negative control: ρ L in
/// every channel.
#[test]
fn environment_light_through_an_unbounded_medium() {
    for (sigma_t, survives) in UNBOUNDED {
        let (scene, id) = unbounded_scene(sigma_t, true);
        let p = Vec3::new(0.3, -0.2, 0.0);
        let eye = p + Vec3::new(0.05, -0.03, 0.4);
        let samples = trace_samples(
            &scene,
            PathSettings::default(),
            Ray::new(eye, p - eye),
            Some(id),
            20_000,
        );
        let lit = BACKGROUND * FLOOR_ALBEDO;
        let name = format!("floor in an unbounded medium of σt {sigma_t:?}");
        pass(judge_samples(&name, &samples, lit.mul_elem(survives)));
        if survives != Color::ONE {
            reject(judge_samples(
                &format!("{name}, unattenuated"),
                &samples,
                lit,
            ));
        }
    }
}

/// An emitting square (radiance L, facing up) at z = 0 inside an absorbing box
/// z ∈ [−1, 1], seen from above: L·exp(−σt · 1), the emission attenuated on the way out.
/// Negative control: the emission unattenuated.
#[test]
fn emitter_inside_a_medium() {
    let radiance = Color::new(3.0, 2.0, 1.0);
    let mut setup = Setup::new(looking_down(3.0, 1.0));
    let id = setup.medium(absorbing(SIGMA_T));
    setup.geometries.push((
        cuboid(
            Vec3::new(-3.0, -3.0, -1.0),
            Vec3::new(3.0, 3.0, 1.0),
            NULL,
            true,
        ),
        interior(id),
    ));
    let quad = square(0.0, 2.0);
    setup.lights.push(Light::Triangles {
        triangles: quad.to_vec(),
        intensity: radiance,
    });
    setup.materials.push(Material::Emissive {
        radiance,
        surface: None,
        light: Some(0),
    });
    let emitter = setup.materials.len() as u32 - 1;
    setup.geometries.push((triangles(&quad, emitter), None));
    let image = render_volpath(&setup.build(), SLAB_IMAGE, SLAB_SPP);
    let expected = radiance.mul_elem(beer_lambert(SIGMA_T, 1.0));
    pass(judge_image(
        "emitter in a medium",
        &image,
        SLAB_IMAGE,
        expected,
    ));
    reject(judge_image(
        "emitter in a medium, unattenuated",
        &image,
        SLAB_IMAGE,
        radiance,
    ));
}

/// A point light and a diffuse floor both inside one absorbing box, the eye in it too: the
/// shadow ray starts in the medium the floor's path is in (the floor bounds no medium), and
/// loses exp(−σt r) over its whole length r; the eye's segment loses exp(−σt |eye − p|).
/// Negative control: the shadow ray taken through vacuum.
#[test]
fn point_light_inside_a_medium() {
    let sigma_t = SIGMA_T * 0.5;
    let light_position = Vec3::new(0.3, 0.2, 1.5);
    let mut setup = Setup::new(looking_down(5.0, 1.0));
    let floor = setup.material(BsdfNode::Diffuse {
        reflectance: Param::value(FLOOR_ALBEDO),
    });
    setup
        .geometries
        .push((triangles(&square(0.0, 3.0), floor), None));
    let id = setup.medium(absorbing(sigma_t));
    setup.geometries.push((
        cuboid(
            Vec3::new(-4.0, -4.0, -1.0),
            Vec3::new(4.0, 4.0, 3.0),
            NULL,
            true,
        ),
        interior(id),
    ));
    setup.lights.push(Light::Point {
        position: light_position,
        intensity: LIGHT_INTENSITY,
    });
    let scene = setup.build();
    for p in [Vec3::ZERO, Vec3::new(-1.0, 0.7, 0.0)] {
        let eye = p + Vec3::new(0.02, -0.01, 0.05);
        let samples = trace_samples(
            &scene,
            PathSettings::default(),
            Ray::new(eye, p - eye),
            Some(id),
            20_000,
        );
        let to_light = light_position - p;
        let r = to_light.length();
        let direct = LIGHT_INTENSITY
            * (FLOOR_ALBEDO / std::f32::consts::PI * to_light.normalized().z / (r * r));
        let eye_tr = beer_lambert(sigma_t, (eye - p).length());
        let expected = direct.mul_elem(beer_lambert(sigma_t, r)).mul_elem(eye_tr);
        pass(judge_samples(
            &format!("point light in a medium, floor at {p:?}"),
            &samples,
            expected,
        ));
        reject(judge_samples(
            &format!("point light in a medium, floor at {p:?}, shadow ray in vacuum"),
            &samples,
            direct.mul_elem(eye_tr),
        ));
    }
}

/// Mitsuba's rule for the medium beyond a surface: along its geometric normal the exterior,
/// against it the interior, with `None` vacuum. The camera sits in medium B (a box
/// z ∈ [−3, 3] of interior B) above a box A (z ∈ [−1, 0], interior A only), the background
/// beyond.
///
/// - Outward normals: 2 units of B, 1 of A, then vacuum (A's exterior) down to B's wall,
///   which the ray leaves along its normal, into B's exterior (vacuum). τ = 2σB + σA.
///   Negative control: restoring the medium the ray came from (B) on leaving A.
/// - A's normals inward: entering it goes along them (exterior: vacuum), leaving it against
///   them (interior: A), so the ray is in A from A's far face to B's wall: τ = 2σB + 2σA.
///   Negative control: the answer of outward normals, as a rule by ray history would give.
#[test]
fn crossing_a_boundary_follows_its_geometric_normal() {
    let sigma_b = Color::new(0.4, 0.2, 0.1);
    let sigma_a = Color::new(0.5, 1.0, 1.5);
    let image = |outward: bool| {
        let mut setup = Setup::new(looking_down(2.0, 1.0));
        let b = setup.medium(absorbing(sigma_b));
        let a = setup.medium(absorbing(sigma_a));
        setup.geometries.push((
            cuboid(Vec3::splat(-3.0), Vec3::splat(3.0), NULL, true),
            interior(b),
        ));
        setup.geometries.push((
            cuboid(
                Vec3::new(-2.0, -2.0, -1.0),
                Vec3::new(2.0, 2.0, 0.0),
                NULL,
                outward,
            ),
            interior(a),
        ));
        setup.camera_medium = Some(b);
        setup.background = BACKGROUND;
        render_volpath(&setup.build(), SLAB_IMAGE, SLAB_SPP)
    };
    let through = |tau: Color| BACKGROUND.mul_elem(tau.map(|t| (-t).exp()));
    let outward = image(true);
    pass(judge_image(
        "nested boxes",
        &outward,
        SLAB_IMAGE,
        through(sigma_b * 2.0 + sigma_a),
    ));
    reject(judge_image(
        "nested boxes, the outer medium restored",
        &outward,
        SLAB_IMAGE,
        through(sigma_b * 4.0 + sigma_a),
    ));
    let inward = image(false);
    pass(judge_image(
        "nested boxes, inner normals inward",
        &inward,
        SLAB_IMAGE,
        through(sigma_b * 2.0 + sigma_a * 2.0),
    ));
    reject(judge_image(
        "nested boxes, inner normals inward, by ray history",
        &inward,
        SLAB_IMAGE,
        through(sigma_b * 2.0 + sigma_a),
    ));
}

/// The unpolarised Fresnel reflectance of a dielectric interface of relative index `eta`,
/// from the textbook's s and p amplitudes.
fn fresnel_by_hand(cos_i: f64, eta: f64) -> f64 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// A thin dielectric sheet (η 1.5) between a point light and a diffuse floor, no media:
/// shadow rays keep its null transmission 1 − R', R' = 2R / (1 + R) the sheet's reflectance
/// with its inner bounces (R from Fresnel's equations by hand, and
/// `ThinDielectric::reflectance` agreeing). Direct lighting only (max depth 1), so the answer
/// is exact. Negative control: a single interface's 1 − R.
#[test]
fn thin_dielectric_passes_one_minus_its_reflectance_to_shadow_rays() {
    let eta = 1.5;
    let light_position = Vec3::new(0.3, 0.2, 2.5);
    let mut setup = Setup::new(looking_down(5.0, 1.0));
    let floor = setup.material(BsdfNode::Diffuse {
        reflectance: Param::value(FLOOR_ALBEDO),
    });
    let sheet = setup.material(BsdfNode::ThinDielectric {
        eta,
        specular_reflectance: Param::value(1.0),
        specular_transmittance: Param::value(1.0),
    });
    setup
        .geometries
        .push((triangles(&square(0.0, 5.0), floor), None));
    setup
        .geometries
        .push((triangles(&square(1.2, 4.0), sheet), None));
    setup.lights.push(Light::Point {
        position: light_position,
        intensity: LIGHT_INTENSITY,
    });
    let scene = setup.build();
    let thin = ThinDielectric {
        eta,
        specular_reflectance: Color::ONE,
        specular_transmittance: Color::ONE,
    };
    for p in FLOOR_POINTS {
        let eye = p + Vec3::new(0.05, -0.03, 0.4);
        let samples = trace_samples(
            &scene,
            PathSettings::with_max_depth(1),
            Ray::new(eye, p - eye),
            None,
            64,
        );
        let to_light = light_position - p;
        let cos_theta = to_light.normalized().z;
        let r = fresnel_by_hand(cos_theta as f64, eta as f64);
        let r_thin = 2.0 * r / (1.0 + r);
        assert!(
            (thin.reflectance(cos_theta) as f64 - r_thin).abs() < 1e-5,
            "ThinDielectric::reflectance({cos_theta}) = {}, by hand {r_thin}",
            thin.reflectance(cos_theta)
        );
        let direct = LIGHT_INTENSITY
            * (FLOOR_ALBEDO / std::f32::consts::PI * cos_theta / to_light.length_squared());
        pass(judge_samples(
            &format!("thin dielectric over {p:?} (R' = {r_thin:.4})"),
            &samples,
            direct * (1.0 - r_thin) as f32,
        ));
        reject(judge_samples(
            &format!("thin dielectric over {p:?}, single interface"),
            &samples,
            direct * (1.0 - r) as f32,
        ));
    }
}
