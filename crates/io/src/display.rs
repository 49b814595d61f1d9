//! How a PNG's 8-bit values are made from the film's linear radiance: the course's conversion,
//! or a display transform (exposure, tone curve, transfer function) for the path tracer.
//!
//! EXR output never goes through this: it keeps the film's linear values as they are.

use glint_render::{Color, Film, IntegratorKind};
use rayon::prelude::*;

/// How `write_image_with` turns linear values into a PNG's 8-bit values.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum PngEncoding {
    /// The course's conversion (FORMAT.md 1.3): clamp to [0, 1], floor(c·255), no transfer
    /// function. The instructor's reference images were made this way, so the course
    /// integrator's PNGs keep it (`Film::to_rgb8_course`).
    #[default]
    Course,
    /// For viewing on a display: exposure, a tone curve, then a transfer function, rounded to
    /// the nearest 8-bit level.
    Display(DisplayTransform),
}

impl PngEncoding {
    /// Each integrator's PNG when the user asks for nothing else, the one rule every front end
    /// follows: the course integrator and the data views (`normals`, `depth`) keep the course's
    /// conversion, which the instructor's references depend on; the path tracers and the
    /// `albedo` view get the default display transform (clamp, sRGB), as pbrt and Mitsuba write.
    pub fn default_for(integrator: IntegratorKind) -> PngEncoding {
        match integrator {
            IntegratorKind::Path | IntegratorKind::VolPath | IntegratorKind::Albedo => {
                PngEncoding::Display(DisplayTransform::default())
            }
            IntegratorKind::Course | IntegratorKind::Normals | IntegratorKind::Depth => {
                PngEncoding::Course
            }
        }
    }

    /// The PNG the user's display options ask for, the one rule of every front end (the CLI's
    /// `--exposure`, `--tonemap`, `--transfer`, the page's and Python's): none given keeps
    /// `default` (the integrator's own, `default_for`); any given turns the display transform
    /// on, the others at `DisplayTransform`'s defaults.
    pub fn from_options(
        default: PngEncoding,
        exposure: Option<f32>,
        tone_map: Option<ToneMap>,
        transfer: Option<Transfer>,
    ) -> PngEncoding {
        if exposure.is_none() && tone_map.is_none() && transfer.is_none() {
            return default;
        }
        let defaults = DisplayTransform::default();
        PngEncoding::Display(DisplayTransform {
            exposure: exposure.unwrap_or(defaults.exposure),
            tone_map: tone_map.unwrap_or(defaults.tone_map),
            transfer: transfer.unwrap_or(defaults.transfer),
        })
    }
}

/// Exposure, tone curve and transfer function, applied in that order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayTransform {
    /// Exposure in stops: every value is multiplied by 2^exposure first.
    pub exposure: f32,
    pub tone_map: ToneMap,
    pub transfer: Transfer,
}

impl Default for DisplayTransform {
    /// What pbrt and Mitsuba write: no exposure change, channels clipped to [0, 1], sRGB.
    fn default() -> Self {
        DisplayTransform {
            exposure: 0.0,
            tone_map: ToneMap::Clamp,
            transfer: Transfer::Srgb,
        }
    }
}

/// The tone curve: linear scene values (after exposure) to linear display values in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToneMap {
    /// Each channel clipped to [0, 1], no curve (what pbrt and Mitsuba do for 8-bit output).
    Clamp,
    /// Stephen Hill's fit of the ACES reference rendering transform (RRT) and the sRGB output
    /// display transform (ODT), from his BakingLab `ACES.hlsl` (2016): a matrix into ACES AP1
    /// with the RRT's saturation, the rational fit `RRTAndODTFit`, and a matrix back to linear
    /// sRGB / Rec. 709 primaries, clipped to [0, 1].
    Aces,
    /// AgX (Troy Sobotka's, Blender 4's default view transform) in Benjamin Wrensch's minimal
    /// form ("Minimal AgX implementation", iolite engine, 2023): Blender's inset matrix, a log2
    /// encoding from -12.47393 to +4.026069 stops around 0.18, the sixth-order polynomial fit of
    /// AgX's default contrast sigmoid, the inverse inset, and the 2.2 power that the
    /// implementation uses to return to linear before the display's transfer function.
    Agx,
}

impl ToneMap {
    /// The names a front end accepts, as `--tonemap` takes them (`none` is `clamp`).
    pub const NAMES: [&'static str; 4] = ["clamp", "none", "aces", "agx"];

    /// The curve `name` stands for (one of `NAMES`).
    pub fn from_name(name: &str) -> Option<ToneMap> {
        match name {
            "clamp" | "none" => Some(ToneMap::Clamp),
            "aces" => Some(ToneMap::Aces),
            "agx" => Some(ToneMap::Agx),
            _ => None,
        }
    }
}

/// The transfer function (opto-electronic) from linear display values to code values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transfer {
    /// The sRGB encoding of IEC 61966-2-1: 12.92·c up to 0.0031308, 1.055·c^(1/2.4) − 0.055
    /// above. The PNG gets an `sRGB` chunk.
    Srgb,
    /// None: code value = linear value (as the course writes its images).
    Linear,
}

impl Transfer {
    /// The names a front end accepts, as `--transfer` takes them.
    pub const NAMES: [&'static str; 2] = ["srgb", "linear"];

    /// The function `name` stands for (one of `NAMES`).
    pub fn from_name(name: &str) -> Option<Transfer> {
        match name {
            "srgb" => Some(Transfer::Srgb),
            "linear" => Some(Transfer::Linear),
            _ => None,
        }
    }
}

/// The tEXt keyword under which a PNG names its transform in words.
pub const TRANSFORM_KEYWORD: &str = "Glint output transform";
/// The tEXt keyword under which a PNG names its transfer function: `sRGB` or `linear`, for
/// programs (`glint diff`) that decode the 8-bit values back to linear.
pub const TRANSFER_KEYWORD: &str = "Glint transfer function";

impl PngEncoding {
    /// The transfer function the 8-bit values carry.
    pub fn transfer(&self) -> Transfer {
        match self {
            PngEncoding::Course => Transfer::Linear,
            PngEncoding::Display(transform) => transform.transfer,
        }
    }

    /// The transform in words, as the PNG's metadata says it.
    pub fn describe(&self) -> String {
        match self {
            PngEncoding::Course => "course: clamp to [0, 1], floor(c*255), no transfer function \
                                    (8-bit values are linear)"
                .to_owned(),
            PngEncoding::Display(transform) => format!(
                "display: exposure {:+.2} EV, tone map {}, transfer {}, round(c*255)",
                transform.exposure,
                transform.tone_map.describe(),
                transform.transfer.describe()
            ),
        }
    }

    /// The film's 8-bit RGB values, three per pixel.
    pub fn to_rgb8(&self, film: &Film) -> Vec<u8> {
        match self {
            PngEncoding::Course => film.to_rgb8_course(),
            PngEncoding::Display(transform) => transform.to_rgb8(&film.pixels),
        }
    }
}

impl ToneMap {
    pub fn describe(&self) -> &'static str {
        match self {
            ToneMap::Clamp => "clamp",
            ToneMap::Aces => "aces (Hill's fitted ACES RRT+ODT, BakingLab ACES.hlsl)",
            ToneMap::Agx => "agx (Wrensch's minimal AgX, default contrast)",
        }
    }

    /// The curve applied to one linear colour; the result is linear, in [0, 1].
    pub fn apply(&self, color: Color) -> Color {
        match self {
            ToneMap::Clamp => color.map(|v| v.clamp(0.0, 1.0)),
            ToneMap::Aces => aces_fitted(color),
            ToneMap::Agx => agx(color),
        }
    }
}

impl Transfer {
    pub fn describe(&self) -> &'static str {
        match self {
            Transfer::Srgb => "sRGB (IEC 61966-2-1)",
            Transfer::Linear => "linear",
        }
    }

    /// The code value of linear `v` in [0, 1].
    pub fn encode(&self, v: f32) -> f32 {
        match self {
            Transfer::Srgb => srgb_encode(v),
            Transfer::Linear => v,
        }
    }

    /// The linear value of code value `v` in [0, 1]: the inverse of `encode`.
    pub fn decode(&self, v: f32) -> f32 {
        match self {
            Transfer::Srgb => srgb_decode(v),
            Transfer::Linear => v,
        }
    }
}

impl DisplayTransform {
    /// The 8-bit RGB values of linear `pixels`, three per pixel: `apply`, then the nearest
    /// level. In parallel on the current rayon pool, 1024 pixels at a time (about 90 ms of
    /// `powf` for a 1024x1024 sRGB frame on one thread).
    pub fn to_rgb8(&self, pixels: &[Color]) -> Vec<u8> {
        const CHUNK: usize = 1024;
        let scale = self.exposure.exp2();
        let mut rgb = vec![0; pixels.len() * 3];
        rgb.par_chunks_mut(3 * CHUNK)
            .zip(pixels.par_chunks(CHUNK))
            .for_each(|(levels, colors)| {
                for (levels, &color) in levels.chunks_exact_mut(3).zip(colors) {
                    let code = self.apply_scaled(color, scale);
                    levels.copy_from_slice(&code.to_array().map(rounded_level));
                }
            });
        rgb
    }

    /// Exposure, curve and transfer function applied to one linear colour: code values in
    /// [0, 1]. NaN becomes 0.
    pub fn apply(&self, color: Color) -> Color {
        self.apply_scaled(color, self.exposure.exp2())
    }

    /// `apply` with the exposure's factor 2^exposure given.
    fn apply_scaled(&self, color: Color, scale: f32) -> Color {
        let exposed = color.map(|v| if v.is_nan() { 0.0 } else { v * scale });
        self.tone_map
            .apply(exposed)
            .map(|v| self.transfer.encode(v.clamp(0.0, 1.0)))
    }
}

/// The nearest 8-bit level of a code value in [0, 1], halves away from zero (`f32::round`).
/// Without the `roundf` call (x86-64's baseline has no SSE4.1 `roundss`): the scaled value
/// lies in [0, 255] (or is -0.0), where truncation is the floor and its distance from the
/// floor is exact (Sterbenz), so comparing that with 0.5 rounds as `round` does.
fn rounded_level(v: f32) -> u8 {
    if v.is_nan() {
        return 0;
    }
    let x = v.clamp(0.0, 1.0) * 255.0;
    let whole = x as u8;
    whole + u8::from(x - f32::from(whole) >= 0.5)
}

/// IEC 61966-2-1 encoding of a linear value in [0, 1].
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// IEC 61966-2-1 decoding of a code value in [0, 1] to linear.
pub fn srgb_decode(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Row-major 3x3 matrix times a colour.
fn mul(m: &[[f32; 3]; 3], c: Color) -> Color {
    let [r, g, b] = c.to_array();
    Color::new(
        m[0][0] * r + m[0][1] * g + m[0][2] * b,
        m[1][0] * r + m[1][1] * g + m[1][2] * b,
        m[2][0] * r + m[2][1] * g + m[2][2] * b,
    )
}

/// Stephen Hill's ACES fit (BakingLab `ACES.hlsl`, MIT licence): the matrices are his
/// `ACESInputMat` (sRGB -> XYZ -> D65 to D60 -> AP1 -> RRT saturation) and `ACESOutputMat`
/// (ODT saturation -> XYZ -> D60 to D65 -> sRGB), rows as written there.
fn aces_fitted(color: Color) -> Color {
    const INPUT: [[f32; 3]; 3] = [
        [0.59719, 0.35458, 0.04823],
        [0.07600, 0.90834, 0.01566],
        [0.02840, 0.13383, 0.83777],
    ];
    const OUTPUT: [[f32; 3]; 3] = [
        [1.60475, -0.53108, -0.07367],
        [-0.10208, 1.10813, -0.00605],
        [-0.00327, -0.07276, 1.07602],
    ];
    let v = mul(&INPUT, color.map(|v| v.max(0.0)));
    let fitted = v.map(|v| {
        let a = v * (v + 0.024_578_6) - 0.000_090_537;
        let b = v * (0.983_729 * v + 0.432_951) + 0.238_081;
        a / b
    });
    mul(&OUTPUT, fitted).map(|v| v.clamp(0.0, 1.0))
}

/// Wrensch's minimal AgX (`agx`, `agxDefaultContrastApprox`, `agxEotf`, default look). His
/// GLSL matrices are column-major; written here as rows.
fn agx(color: Color) -> Color {
    const INSET: [[f32; 3]; 3] = [
        [0.842_479_06, 0.078_433_6, 0.079_223_745],
        [0.042_328_242, 0.878_468_6, 0.079_166_13],
        [0.042_375_655, 0.078_433_6, 0.879_143],
    ];
    const OUTSET: [[f32; 3]; 3] = [
        [1.196_879, -0.098_020_88, -0.099_029_74],
        [-0.052_896_85, 1.151_903_1, -0.098_961_18],
        [-0.052_971_635, -0.098_043_45, 1.151_073_7],
    ];
    const MIN_EV: f32 = -12.473_93;
    const MAX_EV: f32 = 4.026_069;
    let encoded = mul(&INSET, color.map(|v| v.max(0.0))).map(|v| {
        // log2(0) is -inf, which the clamp takes to MIN_EV.
        let stops = v.max(0.0).log2().clamp(MIN_EV, MAX_EV);
        let x = (stops - MIN_EV) / (MAX_EV - MIN_EV);
        let x2 = x * x;
        let x4 = x2 * x2;
        15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
            - 0.00232
    });
    mul(&OUTSET, encoded).map(|v| v.max(0.0).powf(2.2).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_options_turn_the_transform_on_with_defaults_for_the_rest() {
        let course = PngEncoding::Course;
        assert_eq!(PngEncoding::from_options(course, None, None, None), course);
        let only_agx = PngEncoding::from_options(course, None, Some(ToneMap::Agx), None);
        assert_eq!(
            only_agx,
            PngEncoding::Display(DisplayTransform {
                tone_map: ToneMap::Agx,
                ..DisplayTransform::default()
            })
        );
        let exposed = PngEncoding::from_options(course, Some(1.5), None, Some(Transfer::Linear));
        assert_eq!(
            exposed,
            PngEncoding::Display(DisplayTransform {
                exposure: 1.5,
                tone_map: ToneMap::Clamp,
                transfer: Transfer::Linear,
            })
        );
    }

    #[test]
    fn every_name_is_read_and_others_are_not() {
        let curves: Vec<_> = ToneMap::NAMES
            .iter()
            .map(|n| ToneMap::from_name(n))
            .collect();
        let expected = [ToneMap::Clamp, ToneMap::Clamp, ToneMap::Aces, ToneMap::Agx];
        assert_eq!(curves, expected.map(Some));
        let functions: Vec<_> = Transfer::NAMES
            .iter()
            .map(|n| Transfer::from_name(n))
            .collect();
        assert_eq!(functions, [Some(Transfer::Srgb), Some(Transfer::Linear)]);
        assert_eq!(ToneMap::from_name("ACES"), None);
        assert_eq!(Transfer::from_name("gamma"), None);
    }

    fn grey(v: f32) -> Color {
        Color::splat(v)
    }

    #[test]
    fn srgb_matches_the_standard_at_known_points() {
        // IEC 61966-2-1: linear 0.18 encodes to 0.4613561, 0.5 to 0.7353570.
        assert!((srgb_encode(0.18) - 0.461_356_1).abs() < 1e-5);
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-5);
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        // The linear segment.
        assert!((srgb_encode(0.002) - 0.02584).abs() < 1e-6);
        for i in 0..=255 {
            let code = i as f32 / 255.0;
            assert!((srgb_encode(srgb_decode(code)) - code).abs() < 1e-5, "{i}");
        }
    }

    #[test]
    fn default_display_is_clamp_srgb_rounded() {
        // 0.18 -> 0.4613561 * 255 = 117.65 -> 118; 2.0 clips to 255; negative and NaN to 0.
        assert_eq!(
            DisplayTransform::default()
                .to_rgb8(&[Color::new(0.18, 2.0, -0.5), Color::new(f32::NAN, 0.0, 1.0)]),
            vec![118, 255, 0, 0, 0, 255]
        );
    }

    /// The level as first written: the nearest by `f32::round`.
    fn round_level(v: f32) -> u8 {
        if v.is_nan() {
            0
        } else {
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        }
    }

    /// `rounded_level` is the rounding it replaces, `(v.clamp(0, 1) * 255).round()`, on every
    /// half-way point (k + 0.5) / 255 and 64 ulps either side, specials and 2^20 bit patterns.
    #[test]
    fn levels_round_as_f32_round_does() {
        // Every half-way point (k + 0.5) / 255 and threshold k / 255.
        let values = glint_render::testing::float_probes(
            (0..=255u32).flat_map(|k| [(k as f32 + 0.5) / 255.0, k as f32 / 255.0]),
        );
        for v in values {
            assert_eq!(
                rounded_level(v),
                round_level(v),
                "{v:e} ({:#x})",
                v.to_bits()
            );
        }
    }

    /// The frame's levels are each pixel's `apply`, rounded, in order, whatever the transform
    /// and however many chunks the pixels fill.
    #[test]
    fn rgb8_is_apply_rounded_pixel_by_pixel() {
        let pixels: Vec<Color> = (0..2500)
            .map(|i| {
                let t = i as f32;
                Color::new(
                    (t * 0.37).sin() * 1.5,
                    t / 2000.0,
                    (t * 0.11).cos().abs() * 4.0,
                )
            })
            .chain([Color::new(f32::NAN, f32::INFINITY, -2.0)])
            .collect();
        for (exposure, tone_map, transfer) in [
            (0.0, ToneMap::Clamp, Transfer::Srgb),
            (1.5, ToneMap::Aces, Transfer::Srgb),
            (-0.75, ToneMap::Agx, Transfer::Linear),
        ] {
            let transform = DisplayTransform {
                exposure,
                tone_map,
                transfer,
            };
            let expected: Vec<u8> = pixels
                .iter()
                .flat_map(|&c| transform.apply(c).to_array().map(round_level))
                .collect();
            for count in [0, 1, 1023, 1024, 1025, pixels.len()] {
                assert_eq!(
                    transform.to_rgb8(&pixels[..count]),
                    expected[..3 * count],
                    "{transform:?}, {count} pixels"
                );
            }
        }
    }

    #[test]
    fn exposure_is_in_stops() {
        let plus_one = DisplayTransform {
            exposure: 1.0,
            tone_map: ToneMap::Clamp,
            transfer: Transfer::Linear,
        };
        assert_eq!(plus_one.apply(grey(0.25)), grey(0.5));
        let minus_two = DisplayTransform {
            exposure: -2.0,
            ..plus_one
        };
        assert_eq!(minus_two.apply(grey(0.8)), grey(0.2));
    }

    #[test]
    fn aces_fit_keeps_grey_grey_rises_and_saturates() {
        // Hill's fit at mid grey: RRTAndODTFit(0.18) = 0.10560 (grey passes the matrices).
        let mid = aces_fitted(grey(0.18));
        assert!((mid.x - 0.1056).abs() < 2e-3, "{mid:?}");
        assert!((mid.x - mid.y).abs() < 1e-3 && (mid.y - mid.z).abs() < 1e-3);
        let mut last = -1.0;
        for i in 0..200 {
            let v = aces_fitted(grey(i as f32 * 0.1)).x;
            assert!(v >= last, "not monotonic at {i}");
            last = v;
        }
        assert!(aces_fitted(grey(100.0)).x > 0.99);
        assert_eq!(aces_fitted(grey(0.0)), Color::ZERO);
    }

    #[test]
    fn agx_keeps_grey_grey_rises_and_compresses_highlights() {
        let mid = agx(grey(0.18));
        assert!(
            (mid.x - mid.y).abs() < 2e-3 && (mid.y - mid.z).abs() < 2e-3,
            "{mid:?}"
        );
        // Worked by hand: 0.18 is 10.0 stops above MIN_EV, x = 10 / 16.5 = 0.60606, the
        // polynomial gives 0.4968 (display-encoded), and 0.4968^2.2 = 0.2146 linear.
        assert!((mid.x - 0.2146).abs() < 0.002, "{mid:?}");
        let mut last = -1.0;
        for i in 0..200 {
            let v = agx(grey(i as f32 * 0.1)).x;
            assert!(v >= last, "not monotonic at {i}");
            last = v;
        }
        // 16 (4 stops over 1.0) is the top of the range: nearly white, never above.
        let top = agx(grey(16.0)).x;
        assert!(top > 0.9 && top <= 1.0, "{top}");
        // A saturated highlight loses saturation (AgX's point): pure red at 8 gains green/blue.
        let red = agx(Color::new(8.0, 0.0, 0.0));
        assert!(red.y > 0.05 && red.z > 0.05, "{red:?}");
    }

    #[test]
    fn descriptions_name_the_transform() {
        let transform = DisplayTransform {
            exposure: -1.5,
            tone_map: ToneMap::Agx,
            transfer: Transfer::Srgb,
        };
        let text = PngEncoding::Display(transform).describe();
        assert!(text.contains("exposure -1.50 EV"), "{text}");
        assert!(text.contains("agx"), "{text}");
        assert!(text.contains("IEC 61966-2-1"), "{text}");
        assert!(PngEncoding::Course.describe().contains("floor(c*255)"));
    }
}
