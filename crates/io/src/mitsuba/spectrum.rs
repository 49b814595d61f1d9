//! Spectra to RGB as Mitsuba 3's RGB variants convert them, and the named indices of
//! refraction and conductors.

use super::tables::{CIE_D65, CIE_XYZ, CONDUCTORS};

const CIE_MIN: f64 = 360.0;
const CIE_MAX: f64 = 830.0;
const CIE_SAMPLES: usize = 95;
/// Mitsuba's `MI_CIE_Y_NORMALIZATION`: a unit spectrum integrates to a luminance of 1.
const CIE_Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;

/// Where a spectrum is used, which decides its conversion (Mitsuba's `get_texture`,
/// `get_unbounded_texture` and `get_emissive_texture`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// A reflectance: weighted by D65 and clamped to [0, 1].
    Reflectance,
    /// An unbounded non-emissive quantity (an index of refraction, a roughness): weighted by
    /// D65, clamped below at 0.
    Unbounded,
    /// Emitted radiance, intensity or irradiance: not weighted, clamped below at 0.
    Emission,
}

/// Linear interpolation in a table sampled every 5 nm from 360 nm, zero outside.
fn lerp_table(wavelength: f64, at: impl Fn(usize) -> f64) -> f64 {
    if !(CIE_MIN..=CIE_MAX).contains(&wavelength) {
        return 0.0;
    }
    let t = (wavelength - CIE_MIN) * ((CIE_SAMPLES - 1) as f64 / (CIE_MAX - CIE_MIN));
    let i0 = (t as usize).min(CIE_SAMPLES - 2);
    let w1 = t - i0 as f64;
    (1.0 - w1) * at(i0) + w1 * at(i0 + 1)
}

/// The linear sRGB of `values` at `wavelengths` (increasing): the spectrum integrated
/// against the CIE 1931 curves by Mitsuba's 1000-point rule, times D65 for non-emitters,
/// then out-of-gamut values clamped as Mitsuba clamps them.
pub(crate) fn spectrum_to_rgb(wavelengths: &[f64], values: &[f64], role: Role) -> [f64; 3] {
    let d65 = role != Role::Emission;
    let mut xyz = [0.0f64; 3];
    let steps = 1000;
    for i in 0..steps {
        let w = CIE_MIN + (i as f64 / (steps - 1) as f64) * (CIE_MAX - CIE_MIN);
        let (Some(&first), Some(&last)) = (wavelengths.first(), wavelengths.last()) else {
            break;
        };
        if w < first || w > last || wavelengths.len() < 2 {
            continue;
        }
        // The last interval whose start is at or below w.
        let index = wavelengths
            .partition_point(|&start| start <= w)
            .saturating_sub(1)
            .min(wavelengths.len() - 2);
        let (w0, w1) = (wavelengths[index], wavelengths[index + 1]);
        let (v0, v1) = (values[index], values[index + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let weight = if d65 {
            lerp_table(w, |k| f64::from(CIE_D65[k]))
        } else {
            1.0
        };
        for (channel, sum) in xyz.iter_mut().enumerate() {
            *sum += lerp_table(w, |k| f64::from(CIE_XYZ[k][channel])) * v * weight;
        }
    }
    let scale = (CIE_MAX - CIE_MIN) * CIE_Y_NORMALIZATION / steps as f64;
    let rgb = xyz_to_srgb(xyz.map(|value| value * scale));
    match role {
        Role::Reflectance => rgb.map(|value| value.clamp(0.0, 1.0)),
        Role::Unbounded | Role::Emission => rgb.map(|value| value.max(0.0)),
    }
}

/// Linear sRGB (Rec. 709 primaries, D65 white) from CIE XYZ, Mitsuba's matrix.
pub(crate) fn xyz_to_srgb(xyz: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = xyz;
    [
        3.240479 * x - 1.537150 * y - 0.498535 * z,
        -0.969256 * x + 1.875991 * y + 0.041556 * z,
        0.055648 * x - 0.204043 * y + 1.057311 * z,
    ]
}

/// A uniform spectrum of 1 as an emitter's RGB: the sRGB of XYZ (1, 1, 1), not white,
/// because sRGB's white is D65 (Mitsuba's RGB variants do the same to match its spectral
/// ones).
pub(crate) fn uniform_emission() -> [f64; 3] {
    xyz_to_srgb([1.0, 1.0, 1.0])
}

/// Mitsuba's named indices of refraction (its `ior.h` table, measured near 589 nm).
const IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// A named index of refraction, case-insensitive, as an f32 the way Mitsuba stores it.
pub(crate) fn named_ior(name: &str) -> Option<f32> {
    let lower = name.to_lowercase();
    IORS.iter()
        .find(|(known, _)| *known == lower)
        .map(|&(_, value)| value as f32)
}

/// The names `named_ior` knows, for messages.
pub(crate) fn ior_names() -> impl Iterator<Item = &'static str> {
    IORS.iter().map(|(name, _)| *name)
}

/// A named conductor's RGB eta and k (Mitsuba's `data/ior/<name>.{eta,k}.spd`).
pub(crate) fn named_conductor(name: &str) -> Option<([f32; 3], [f32; 3])> {
    CONDUCTORS
        .iter()
        .find(|(known, _, _)| *known == name)
        .map(|&(_, eta, k)| (eta, k))
}

/// The names `named_conductor` knows, for messages.
pub(crate) fn conductor_names() -> impl Iterator<Item = &'static str> {
    CONDUCTORS.iter().map(|(name, _, _)| *name)
}

/// Wavelengths and values of an `.spd` file: two numbers a line, `#` starts a comment.
pub(crate) fn parse_spd(text: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
    let mut wavelengths = Vec::new();
    let mut values = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] => continue,
            [w, v] => {
                let parse = |word: &str| {
                    word.parse::<f64>()
                        .ok()
                        .filter(|value| value.is_finite())
                        .ok_or_else(|| format!("line {}: `{word}` is not a number", number + 1))
                };
                wavelengths.push(parse(w)?);
                values.push(parse(v)?);
            }
            _ => {
                return Err(format!(
                    "line {}: expected a wavelength and a value",
                    number + 1
                ))
            }
        }
    }
    check_increasing(&wavelengths)?;
    Ok((wavelengths, values))
}

/// Mitsuba's rule for a sampled spectrum: at least two wavelengths, increasing.
pub(crate) fn check_increasing(wavelengths: &[f64]) -> Result<(), String> {
    if wavelengths.len() < 2 {
        return Err("a spectrum needs at least two wavelength:value entries".into());
    }
    if wavelengths.windows(2).any(|pair| pair[1] <= pair[0]) {
        return Err("the wavelengths must increase".into());
    }
    Ok(())
}
