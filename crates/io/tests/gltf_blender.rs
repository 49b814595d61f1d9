//! Glint's glTF importer against Blender 3.4 and Cycles (`tests/gltf_refs/`, made by
//! `scripts/gltf-references.sh`; how, and what each comparison means, in the README there).
//!
//! For every model of `tests/gltf_refs/manifest.json` (the shared models in `../shared/gltf`
//! and Glint's material test models in `scenes/gltf`):
//!
//! - Layers, pixel for pixel: Glint renders depth, normal and albedo at the reference's size
//!   with one camera ray through each pixel's centre (the depth debug view's one-sample
//!   grid with features on), as Cycles did (one sample, a 0.01-pixel box filter). A pixel
//!   disagrees when its depth differs by more than `DEPTH_TOLERANCE` times max(1, depth) or
//!   a normal component by more than `NORMAL_TOLERANCE` (the reference stores normals as
//!   half floats: 2⁻¹¹ relative); the model passes when at most `EDGE_SHARE` of its pixels
//!   disagree and every one of them is an edge pixel (a silhouette or crease: the
//!   reference's escape, depth or normal changes across its 8-neighbourhood), where a ray a
//!   rounding error away meets another surface. Albedo is compared off edges where the
//!   reference's albedo is linear over the 3x3 neighbourhood (`albedo_is_linear`: elsewhere
//!   the renderers' texture filtering differs), within `ALBEDO_TOLERANCE` per channel, and at
//!   most `ALBEDO_SHARE` of those pixels may disagree. Pixels the reference masks out (first hit on a BLEND material: stochastic in
//!   both renderers) are not compared. `KNOWN_LAYER_DISAGREEMENTS` lists the models Glint
//!   gets wrong today; they must keep failing until fixed, and then leave the list.
//! - Beauty, for the models the manifest marks `tested` (metal-only or diffuse-only
//!   materials under the white sky): Glint's path tracer renders two halves of
//!   `BEAUTY_SPP` / 2 samples and `glint_render::testing::compare::judge` holds their mean to
//!   the Cycles reference, with the reference's own noise as Blender measured it (two halves,
//!   manifest `beauty_noise_relmse`). Diffuse-only models get the full rule (relMSE within
//!   1.15 times the noise's, every 40x40 block mean within 2% or five standard errors).
//!   Metal-only models get the block rule alone, at `METAL_BLOCK_TOLERANCE`: Cycles' metal
//!   differs from Appendix B by up to 3.1% on average (the README's furnace measurement), a
//!   bias no relMSE allowance of noise may absorb; block channels darker than
//!   `METAL_DARK_BLOCK` are not judged. `KNOWN_BEAUTY_DISAGREEMENTS` lists the rough metals
//!   the reference itself cannot hold that closely. (`GLTF_PBR_IS_PLACEHOLDER` turns the
//!   metal judgement off while Glint's glTF material is a Lambertian placeholder.)
//! - Negative controls: a camera moved sideways by 2% of its distance must fail the layers,
//!   and Glint's beauty made 3% darker (diffuse) or `METAL_NEGATIVE` darker (metal) must
//!   fail the beauty rule.
//!
//! `--nocapture` prints the per-model figures the README's table quotes.

use std::path::{Path, PathBuf};

use glint_render::testing::compare::{judge, scaled, Criterion, Pixel, Reference};
use glint_render::{Features, IntegratorKind, RenderSettings, Scene};

const DEPTH_TOLERANCE: f32 = 1e-3;
const NORMAL_TOLERANCE: f32 = 2e-3;
const ALBEDO_TOLERANCE: f32 = 2e-3;
/// Largest share of a model's pixels that may disagree in depth or normal (all of them
/// edge pixels).
const EDGE_SHARE: f64 = 0.01;
/// Largest second difference of the reference's albedo where it counts as linear.
const LINEAR_ALBEDO: f32 = 1e-3;
/// Largest share of the albedo-compared pixels that may disagree (a texel edge of a NEAREST
/// texture a rounding error from a pixel centre).
const ALBEDO_SHARE: f64 = 0.005;
const BEAUTY_SPP: u32 = 128;
const BLOCK: u32 = 40;
/// Block-mean tolerance for metal-only models (README: Cycles' metal against Appendix B).
const METAL_BLOCK_TOLERANCE: f64 = 0.05;
/// Metal block channels whose reference mean is at or below this are not judged: there the
/// metal's reflectance is mostly Schlick's (1 − cos)⁵ tail (F0 near 0, as the red Box's
/// green and blue), which the reference takes at N·V and Appendix B at V·H, tens of percent
/// apart on a rough metal.
const METAL_DARK_BLOCK: f64 = 0.1;
/// How much darker the metal negative control is: more than `METAL_BLOCK_TOLERANCE`.
const METAL_NEGATIVE: f64 = 0.90;

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn refs_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf_refs")
}

/// One model of the manifest.
#[derive(Clone, Debug)]
struct Entry {
    model: String,
    /// Relative to the repository root (`../shared/gltf/...` or `scenes/gltf/...`).
    path: String,
    reference: String,
    width: u32,
    height: u32,
    beauty_tested: bool,
    /// Diffuse-only (Lambertian) rather than metal-only.
    diffuse: bool,
    beauty_noise: f64,
}

fn manifest() -> Vec<Entry> {
    let text = std::fs::read_to_string(refs_dir().join("manifest.json")).expect("manifest.json");
    let value = jsonc_parser::parse_to_value(&text, &Default::default())
        .expect("manifest.json parses")
        .expect("manifest.json is not empty");
    let jsonc_parser::JsonValue::Object(root) = value else {
        panic!("manifest.json is not an object")
    };
    let models = root.get_array("models").expect("models");
    models
        .iter()
        .map(|model| {
            let jsonc_parser::JsonValue::Object(m) = model else {
                panic!("a model entry is not an object")
            };
            let text = |key: &str| {
                m.get_string(key)
                    .unwrap_or_else(|| panic!("{key}"))
                    .to_string()
            };
            let number = |key: &str| -> f64 {
                m.get_number(key)
                    .unwrap_or_else(|| panic!("{key}"))
                    .parse()
                    .expect("a number")
            };
            let reason = text("beauty_reason");
            Entry {
                model: text("model"),
                path: text("path"),
                reference: text("reference"),
                width: number("width") as u32,
                height: number("height") as u32,
                beauty_tested: text("beauty") == "tested",
                diffuse: reason == "diffuse-only",
                beauty_noise: number("beauty_noise_relmse"),
            }
        })
        .collect()
}

/// The Cycles reference of one model (rows top to bottom).
struct BlenderReference {
    beauty: Vec<Pixel>,
    albedo: Vec<[f32; 3]>,
    normal: Vec<[f32; 3]>,
    depth: Vec<f32>,
    /// 1 where the layers are compared.
    mask: Vec<f32>,
}

fn read_reference(entry: &Entry) -> BlenderReference {
    use exr::prelude::FlatSamples;
    let path = refs_dir().join(&entry.reference);
    let image = exr::prelude::read_first_flat_layer_from_file(&path)
        .unwrap_or_else(|error| panic!("{}: {error}", path.display()));
    let layer = &image.layer_data;
    assert_eq!(
        (layer.size.0 as u32, layer.size.1 as u32),
        (entry.width, entry.height),
        "{}",
        path.display()
    );
    let channel = |name: &str| -> Option<Vec<f32>> {
        let found = layer.channel_data.list.iter().find(|c| c.name.eq(name))?;
        Some(match &found.sample_data {
            FlatSamples::F16(values) => values.iter().map(|v| v.to_f32()).collect(),
            FlatSamples::F32(values) => values.clone(),
            FlatSamples::U32(values) => values.iter().map(|&v| v as f32).collect(),
        })
    };
    let need =
        |name: &str| channel(name).unwrap_or_else(|| panic!("{}: no {name}", path.display()));
    let triple = |a: &str, b: &str, c: &str| -> Vec<[f32; 3]> {
        let (a, b, c) = (need(a), need(b), need(c));
        (0..a.len()).map(|i| [a[i], b[i], c[i]]).collect()
    };
    let rgb = triple("R", "G", "B");
    let pixels = rgb.len();
    BlenderReference {
        beauty: rgb.iter().map(|p| p.map(f64::from)).collect(),
        albedo: triple("albedo.R", "albedo.G", "albedo.B"),
        normal: triple("normal.X", "normal.Y", "normal.Z"),
        depth: need("depth.Z"),
        mask: channel("mask").unwrap_or_else(|| vec![1.0; pixels]),
    }
}

/// The model's scene, or `None` (with a message) where the shared models are absent; under
/// CI their absence is a failure.
fn load(entry: &Entry) -> Option<Scene> {
    let path = repository().join(&entry.path);
    if !path.exists() {
        let message = format!("{} is absent", path.display());
        assert!(std::env::var_os("CI").is_none(), "{message} (CI is set)");
        println!("SKIPPED: {message}");
        return None;
    }
    let loaded =
        glint_io::load_scene(&path).unwrap_or_else(|error| panic!("{}: {error}", entry.model));
    Some(Scene::new(loaded.parts))
}

/// Glint's layers at the pixel centres.
fn render_layers(scene: &Scene, entry: &Entry) -> Features {
    let settings = RenderSettings {
        width: entry.width,
        height: entry.height,
        samples_per_pixel: 1,
        integrator: IntegratorKind::Depth,
        features: true,
        ..RenderSettings::default()
    };
    let (film, _) = glint_render::render(scene, &settings, &|_| true).unwrap();
    film.features.expect("features were asked for")
}

/// Whether the reference's albedo is linear across pixel (x, y)'s neighbourhood (every
/// second difference at most `LINEAR_ALBEDO`). Elsewhere a texture varies within a pixel's
/// footprint, and the renderers filter it differently: Cycles reads the full-resolution
/// texture at the point, Glint honours the sampler's mipmapped minification.
fn albedo_is_linear(reference: &BlenderReference, width: u32, height: u32, x: u32, y: u32) -> bool {
    if x == 0 || y == 0 || x + 1 >= width || y + 1 >= height {
        return false;
    }
    let at = |x: u32, y: u32| reference.albedo[(y * width + x) as usize];
    let (c, l, r, u, d) = (
        at(x, y),
        at(x - 1, y),
        at(x + 1, y),
        at(x, y - 1),
        at(x, y + 1),
    );
    (0..3).all(|k| {
        (l[k] + r[k] - 2.0 * c[k]).abs() <= LINEAR_ALBEDO
            && (u[k] + d[k] - 2.0 * c[k]).abs() <= LINEAR_ALBEDO
    })
}

/// What the layers' comparison found for one model.
#[derive(Debug, Default)]
struct LayerFigures {
    compared: usize,
    /// Pixels whose albedo is compared (off edges), and those that disagree.
    albedo_compared: usize,
    albedo_disagreeing: usize,
    disagreeing: usize,
    disagreeing_off_edges: usize,
    max_depth: f32,
    mean_depth: f64,
    max_normal: f32,
    mean_normal: f64,
    max_albedo: f32,
    mean_albedo: f64,
}

impl LayerFigures {
    fn passes(&self) -> bool {
        self.disagreeing_off_edges == 0
            && self.disagreeing as f64 <= EDGE_SHARE * self.compared.max(1) as f64
            && self.albedo_disagreeing as f64 <= ALBEDO_SHARE * self.albedo_compared.max(1) as f64
    }

    fn summary(&self) -> String {
        format!(
            "{} of {} pixels disagree ({} off edges); depth max {:.2e} mean {:.2e}; normal max \
             {:.2e} mean {:.2e}; albedo ({} pixels, {} disagree) max {:.2e} mean {:.2e}",
            self.disagreeing,
            self.compared,
            self.disagreeing_off_edges,
            self.max_depth,
            self.mean_depth,
            self.max_normal,
            self.mean_normal,
            self.albedo_compared,
            self.albedo_disagreeing,
            self.max_albedo,
            self.mean_albedo
        )
    }
}

/// Whether pixel (x, y) of the reference lies on a silhouette or crease.
fn is_edge(reference: &BlenderReference, width: u32, height: u32, x: u32, y: u32) -> bool {
    let at = |x: u32, y: u32| (y * width + x) as usize;
    let here = at(x, y);
    let (d0, n0) = (reference.depth[here], reference.normal[here]);
    for dy in -1i32..=1 {
        for dx in -1i32..=1 {
            let (nx, ny) = (x as i32 + dx, y as i32 + dy);
            if nx < 0 || ny < 0 || nx >= width as i32 || ny >= height as i32 {
                continue;
            }
            let there = at(nx as u32, ny as u32);
            let (d1, n1) = (reference.depth[there], reference.normal[there]);
            if (d0 > 0.0) != (d1 > 0.0)
                || (d0 - d1).abs() > 0.05 * d0.max(d1)
                || (0..3).any(|c| (n0[c] - n1[c]).abs() > 0.01)
                || reference.mask[there] < 0.5
            {
                return true;
            }
        }
    }
    false
}

fn compare_layers(reference: &BlenderReference, glint: &Features, entry: &Entry) -> LayerFigures {
    let mut figures = LayerFigures::default();
    let (mut depth_sum, mut normal_sum, mut albedo_sum) = (0.0, 0.0, 0.0);
    for y in 0..entry.height {
        for x in 0..entry.width {
            let i = (y * entry.width + x) as usize;
            if reference.mask[i] < 0.5 {
                continue;
            }
            figures.compared += 1;
            let depth = (glint.depth[i] - reference.depth[i]).abs();
            let n = glint.normal[i];
            let normal = [n.x, n.y, n.z]
                .iter()
                .zip(reference.normal[i])
                .map(|(g, r)| (g - r).abs())
                .fold(0.0f32, f32::max);
            let edge = is_edge(reference, entry.width, entry.height, x, y);
            let a = glint.albedo[i];
            let albedo = if !edge && albedo_is_linear(reference, entry.width, entry.height, x, y) {
                figures.albedo_compared += 1;
                [a.x, a.y, a.z]
                    .iter()
                    .zip(reference.albedo[i])
                    .map(|(g, r)| (g - r).abs())
                    .fold(0.0f32, f32::max)
            } else {
                0.0
            };
            figures.max_depth = figures.max_depth.max(depth);
            figures.max_normal = figures.max_normal.max(normal);
            figures.max_albedo = figures.max_albedo.max(albedo);
            depth_sum += depth as f64;
            normal_sum += normal as f64;
            albedo_sum += albedo as f64;
            if albedo > ALBEDO_TOLERANCE {
                figures.albedo_disagreeing += 1;
            }
            let bad = !(depth <= DEPTH_TOLERANCE * reference.depth[i].max(1.0)
                && normal <= NORMAL_TOLERANCE);
            if bad {
                figures.disagreeing += 1;
                if !edge {
                    figures.disagreeing_off_edges += 1;
                }
            }
        }
    }
    let n = figures.compared.max(1) as f64;
    figures.mean_depth = depth_sum / n;
    figures.mean_normal = normal_sum / n;
    figures.mean_albedo = albedo_sum / figures.albedo_compared.max(1) as f64;
    figures
}

/// Models whose layers Glint gets wrong today, with why (reported to the importer's
/// author): they must keep disagreeing, so that the list is emptied once they are fixed.
const KNOWN_LAYER_DISAGREEMENTS: &[(&str, &str)] = &[];

#[test]
fn layers_match_blender() {
    let mut failures = Vec::new();
    for entry in manifest() {
        let Some(scene) = load(&entry) else { continue };
        let reference = read_reference(&entry);
        let glint = render_layers(&scene, &entry);
        let figures = compare_layers(&reference, &glint, &entry);
        let known = KNOWN_LAYER_DISAGREEMENTS
            .iter()
            .find(|(model, _)| *model == entry.model);
        let verdict = match (figures.passes(), known) {
            (true, None) => "agree".to_string(),
            (false, Some((_, why))) => format!("disagree as known ({why})"),
            (true, Some(_)) => "AGREE though listed as a known disagreement".to_string(),
            (false, None) => "DISAGREE".to_string(),
        };
        println!("{} layers {verdict}: {}", entry.model, figures.summary());
        if figures.passes() == known.is_some() {
            failures.push(entry.model.clone());
        }
    }
    assert!(
        failures.is_empty(),
        "layers disagree with Blender: {failures:?}"
    );
}

/// Negative control: the framing camera moved sideways by 2% of its distance to the model
/// must fail the same layer comparison.
#[test]
fn a_moved_camera_fails_the_layers() {
    let entries = manifest();
    let entry = entries
        .iter()
        .find(|e| e.model == "diffuse_only")
        .expect("diffuse_only in the manifest");
    let mut scene = load(entry).expect("scenes/gltf is in the repository");
    let reference = read_reference(entry);
    let distance = reference
        .depth
        .iter()
        .copied()
        .filter(|&d| d > 0.0)
        .fold(f32::INFINITY, f32::min);
    scene.camera.position += scene.camera.basis.u * (0.02 * distance);
    let glint = render_layers(&scene, entry);
    let figures = compare_layers(&reference, &glint, entry);
    println!(
        "diffuse_only, camera moved (must fail): {}",
        figures.summary()
    );
    assert!(!figures.passes(), "a moved camera passed the layers");
}

fn render_beauty(scene: &Scene, entry: &Entry, samples: u32, seed: u64) -> Vec<Pixel> {
    let settings = RenderSettings {
        width: entry.width,
        height: entry.height,
        samples_per_pixel: samples,
        seed,
        integrator: IntegratorKind::Path,
        ..RenderSettings::default()
    };
    let (film, stats) = glint_render::render(scene, &settings, &|_| true).unwrap();
    assert_eq!(stats.nonfinite_samples, 0, "{}", entry.model);
    glint_render::testing::compare::to_pixels(&film.pixels)
}

/// Glint's glTF material is still the Lambertian placeholder of b447848 (base colour ×
/// (1 − metallic), no specular lobe): metals render black, so the metal-only models are
/// reported but not judged until the full Appendix B model lands; then set this to false.
/// (`gltf-rs-box_sparse` agrees even now: its faces are wound inwards, so the camera sees
/// the inside of a closed box, which no light reaches.)
const GLTF_PBR_IS_PLACEHOLDER: bool = false;

/// Metal models whose beauty the reference cannot hold to `METAL_BLOCK_TOLERANCE`: rough
/// (roughness 1) metal seen at grazing angles, where the reference's Fresnel at N·V and
/// separable Smith term depart from Appendix B by up to 13% (the README's furnace
/// measurement). They must keep failing; a better reference graph empties the list.
const KNOWN_BEAUTY_DISAGREEMENTS: [&str; 2] = ["Box", "BoxVertexColors"];

#[test]
fn beauty_matches_blender() {
    let mut failures = Vec::new();
    for entry in manifest().into_iter().filter(|e| e.beauty_tested) {
        let Some(scene) = load(&entry) else { continue };
        let reference = read_reference(&entry);
        let pending = GLTF_PBR_IS_PLACEHOLDER && !entry.diffuse;
        // Models reported but not judged take fewer samples: the test stays short.
        let spp = if pending { BEAUTY_SPP / 4 } else { BEAUTY_SPP };
        let first = render_beauty(&scene, &entry, spp / 2, 1);
        let second = render_beauty(&scene, &entry, spp / 2, 2);
        let criterion = if entry.diffuse {
            Criterion::new(entry.width, entry.height, BLOCK)
        } else {
            Criterion {
                tolerance: f64::INFINITY,
                block_tolerance: METAL_BLOCK_TOLERANCE,
                dark_block: Some(METAL_DARK_BLOCK),
                ..Criterion::new(entry.width, entry.height, BLOCK)
            }
        };
        let blender = Reference::Measured {
            image: &reference.beauty,
            noise: entry.beauty_noise,
        };
        let verdict = judge(&criterion, (&first, &second), blender);
        let darker = if entry.diffuse { 0.97 } else { METAL_NEGATIVE };
        let control = judge(
            &criterion,
            (&scaled(&first, darker), &scaled(&second, darker)),
            blender,
        );
        let kind = if entry.diffuse { "diffuse" } else { "metal" };
        println!(
            "{} beauty ({kind}, {spp} spp): {}; {darker} x darker (must fail): {}",
            entry.model,
            verdict.as_ref().unwrap_or_else(|e| e),
            if control.is_err() { "fails" } else { "PASSES" }
        );
        if pending {
            println!("  (metal: reported, not judged, until the full glTF material lands)");
        }
        let known = KNOWN_BEAUTY_DISAGREEMENTS.contains(&entry.model.as_str());
        if known {
            println!("  (known: the reference's rough metal at grazing angles; must fail)");
        }
        if (verdict.is_err() != known && !pending) || control.is_ok() {
            failures.push(entry.model.clone());
        }
    }
    assert!(
        failures.is_empty(),
        "beauty disagrees with Blender: {failures:?}"
    );
}
