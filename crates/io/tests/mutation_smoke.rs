//! A mutation smoke test on stable, for CI (the fuzz targets in `fuzz/` go much further, on
//! nightly). Every course scene, and a small scene of each format, is mutated deterministically
//! (bytes flipped, cut, duplicated; hostile tokens such as `nan`, `1e40`, `<` and `"` put in;
//! the file truncated), and so are the meshes and textures they name. Each mutant must load or
//! fail with an error that points inside the file, never panic; each mutant that loads is
//! rendered small with the course and path integrators, and no pixel or feature value may be
//! NaN or infinite.
//!
//! `GLINT_MUTANTS=N` sets the mutants per file (default 6); a failure names the seed.

mod common;

use std::cell::RefCell;
use std::collections::HashMap;
use std::io;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glint_io::{Assets, FileSystem, Limits, SceneError};
use glint_render::{IntegratorKind, RenderSettings, Scene};

/// splitmix64: a deterministic stream of numbers from a seed.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const TOKENS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e40",
    "-1e30",
    "1e20",
    "0",
    "-0",
    "-1",
    "1e-45",
    "<",
    ">",
    "/>",
    "</shape>",
    "<scene>",
    "<!--",
    "&amp;",
    "&#0;",
    "{",
    "}",
    "[",
    "]",
    "\"",
    "'",
    ",",
    ":",
    "\\",
    "null",
    "true",
    "\u{feff}",
    "\u{0}",
    "é",
    "\n",
    "f 1 2 999999",
    "v nan 0 0",
    "f -1 -2 -3",
];

/// One to three mutations of `bytes`.
fn mutate(bytes: &[u8], random: &mut Random) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..1 + random.below(3) {
        let at = random.below(out.len() + 1);
        match random.below(6) {
            0 if !out.is_empty() => {
                let at = at.min(out.len() - 1);
                out[at] = 32 + random.below(95) as u8;
            }
            1 => {
                let end = (at + 1 + random.below(20)).min(out.len());
                out.drain(at..end);
            }
            2 | 3 => {
                let token = TOKENS[random.below(TOKENS.len())].as_bytes();
                out.splice(at..at, token.iter().copied());
            }
            4 => {
                let end = (at + 1 + random.below(200)).min(out.len());
                let copy = out[at..end].to_vec();
                out.splice(at..at, copy);
            }
            _ => out.truncate(at),
        }
    }
    out
}

/// The file system, read once per path, with one file replaced by a mutant.
struct MutatedAssets<'a> {
    cache: &'a RefCell<HashMap<PathBuf, Option<Vec<u8>>>>,
    replaced: Option<(PathBuf, Vec<u8>)>,
}

impl Assets for MutatedAssets<'_> {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        if let Some((replaced, bytes)) = &self.replaced {
            if replaced == path {
                return Ok(bytes.clone());
            }
        }
        let mut cache = self.cache.borrow_mut();
        let entry = cache.entry(path.to_path_buf()).or_insert_with(|| {
            FileSystem
                .read_at_most(path, Limits::default().max_file_bytes)
                .ok()
        });
        entry
            .clone()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "not found"))
    }

    fn exists(&self, path: &Path) -> bool {
        self.replaced
            .as_ref()
            .is_some_and(|(replaced, _)| replaced == path)
            || FileSystem.exists(path)
    }
}

/// The assets a scene names that exist: OBJ files and images mentioned in its text.
fn named_assets(text: &str, directory: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for piece in text.split(['"', '<', '>']) {
        let piece = piece.trim();
        if piece.ends_with(".obj") || piece.ends_with(".png") {
            let path = directory.join(piece);
            if path.is_file() && !found.contains(&path) {
                found.push(path);
            }
        }
    }
    found
}

struct Outcome {
    loaded: usize,
    refused: usize,
    rendered: usize,
}

/// Loads (and when it loads, renders) one mutant; a panic or a misplaced error is an `Err`.
fn try_mutant(
    text: &str,
    path: &Path,
    assets: &MutatedAssets,
    outcome: &mut Outcome,
) -> Result<(), String> {
    let limits = Limits {
        max_texture_side: 4096,
        max_texture_bytes: 1 << 30,
        ..Limits::default()
    };
    let result = catch_unwind(AssertUnwindSafe(|| {
        glint_io::load_scene_with_assets_limited(text, path, assets, &limits)
    }))
    .map_err(|_| "loading panicked".to_owned())?;
    let loaded = match result {
        Ok(loaded) => loaded,
        Err(error @ (SceneError::Invalid(_) | SceneError::Several(_))) => {
            outcome.refused += 1;
            let lines = text.lines().count() as u32 + 1;
            for diagnostic in error.diagnostics() {
                if diagnostic.path != path
                    || diagnostic.line == 0
                    || diagnostic.line > lines
                    || diagnostic.column == 0
                {
                    return Err(format!("error outside the file: {diagnostic}"));
                }
            }
            return Ok(());
        }
        Err(error) => return Err(format!("unlocated error: {error}")),
    };
    outcome.loaded += 1;
    let shapes: usize = loaded.parts.geometries.iter().map(|g| g.shapes.len()).sum();
    if shapes > 20_000 {
        return Ok(());
    }
    let scene = catch_unwind(AssertUnwindSafe(|| Scene::new(loaded.parts)))
        .map_err(|_| "building the scene panicked".to_owned())?;
    for integrator in [IntegratorKind::Course, IntegratorKind::Path] {
        let settings = RenderSettings {
            width: 6,
            height: 4,
            samples_per_pixel: 1,
            max_depth: Some(3),
            integrator,
            features: true,
            threads: Some(1),
            ..RenderSettings::default()
        };
        let rendered = catch_unwind(AssertUnwindSafe(|| {
            glint_render::render(&scene, &settings, &|_| true)
        }))
        .map_err(|_| format!("rendering with {integrator:?} panicked"))?;
        let Ok((film, _)) = rendered else {
            continue;
        };
        let features = film.features.as_ref().expect("features asked for");
        let finite = film.pixels.iter().all(|p| p.is_finite())
            && features.albedo.iter().all(|p| p.is_finite())
            && features.normal.iter().all(|n| n.is_finite())
            && features.depth.iter().all(|d| d.is_finite());
        if !finite {
            return Err(format!("{integrator:?} wrote a non-finite value"));
        }
    }
    outcome.rendered += 1;
    Ok(())
}

const SMALL_XML: &str = r#"<scene bgColor="0.1 0.1 0.1">
  <camera name="c" type="perspective"><position>0 0 3</position><viewDir>0 0 -1</viewDir>
    <focalLength>1</focalLength><imagePlaneWidth>1</imagePlaneWidth></camera>
  <light type="point"><position>0 3 3</position><intensity>1 1 1</intensity></light>
  <light type="area"><position>0 3 0</position><normal>0 -1 0</normal>
    <intensity>1 1 1</intensity><width>1</width><length>1</length></light>
  <shader name="r" type="BlinnPhong"><diffuse>0.8 0.1 0.1</diffuse>
    <specular>1 1 1</specular><phongExp>32</phongExp></shader>
  <shader name="g" type="Dielectric"><refractiveIndex>1.5</refractiveIndex></shader>
  <shape name="s" type="sphere"><shader ref="r"/><center>0 0 -1</center><radius>1</radius></shape>
  <shape name="b" type="box"><shader ref="g"/><minPt>-2 -2 -3</minPt><maxPt>2 -1 -1</maxPt></shape>
  <shape name="t" type="triangle"><shader ref="r"/><v0>0 0 0</v0><v1>1 0 0</v1><v2>0 1 0</v2></shape>
</scene>"#;

const SMALL_JSON: &str = r#"{ "scene": {
  "camera": [{ "_type": "orthographic", "position": "0 0 3", "viewDir": "0 0 -1",
               "imagePlaneWidth": 4 }],
  "light": [{ "_type": "point", "position": "0 3 3", "intensity": "1 1 1" }],
  "shader": [{ "_name": "m", "_type": "Mirror" }, { "_name": "l", "_type": "Lambertian",
               "diffuse": "0.5 0.5 0.5" }],
  "instance": [{ "_name": "ball", "_type": "sphere", "radius": 1, "shader": { "_ref": "l" } }],
  "shape": [{ "_type": "instance", "_id": "ball", "transform": { "translate": "1 0 0",
              "scale": "1 2 1" } },
            { "_type": "sphere", "center": "-1 0 0", "radius": 0.5, "shader": { "_ref": "m" } }]
} }"#;

#[test]
fn mutated_scenes_never_panic_and_fail_where_the_damage_is() {
    let per_file: usize = std::env::var("GLINT_MUTANTS")
        .ok()
        .and_then(|value| value.parse().ok())
        .unwrap_or(6);
    let mut files: Vec<(PathBuf, String)> = vec![
        (PathBuf::from("inline/small.xml"), SMALL_XML.to_owned()),
        (PathBuf::from("inline/small.json"), SMALL_JSON.to_owned()),
    ];
    if let Some(corpus) = common::corpus() {
        for (path, _) in common::scene_files(&corpus) {
            let text = std::fs::read_to_string(&path).expect("course scenes are UTF-8");
            files.push((path, text));
        }
    }
    let cache = RefCell::new(HashMap::new());
    let mut outcome = Outcome {
        loaded: 0,
        refused: 0,
        rendered: 0,
    };
    let mut failures = Vec::new();
    let mut mutants = 0;
    for (index, (path, text)) in files.iter().enumerate() {
        let directory = path.parent().unwrap_or(Path::new(""));
        let assets = named_assets(text, directory);
        for round in 0..per_file {
            let seed = (index as u64) << 32 | round as u64;
            let mut random = Random(seed);
            // Most mutants change the scene; some change one of the files it names.
            let (scene_text, replaced) = if !assets.is_empty() && random.below(4) == 0 {
                let asset = &assets[random.below(assets.len())];
                let bytes = std::fs::read(asset).expect("asset readable");
                (
                    text.clone(),
                    Some((asset.clone(), mutate(&bytes, &mut random))),
                )
            } else {
                let bytes = mutate(text.as_bytes(), &mut random);
                (String::from_utf8_lossy(&bytes).into_owned(), None)
            };
            let mutated = MutatedAssets {
                cache: &cache,
                replaced,
            };
            mutants += 1;
            if let Err(why) = try_mutant(&scene_text, path, &mutated, &mut outcome) {
                failures.push(format!("{} (seed {seed:#x}): {why}", path.display()));
            }
        }
    }
    eprintln!(
        "{mutants} mutants: {} loaded ({} rendered), {} refused with a located error",
        outcome.loaded, outcome.rendered, outcome.refused
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The mutations must be able to break files, and leave some loadable.
    assert!(
        outcome.refused > mutants / 10,
        "too few mutants were refused"
    );
    assert!(outcome.loaded > 0, "no mutant loaded");
}

/// A small Mitsuba 3 scene with every kind of object the reader builds from text alone.
const SMALL_MITSUBA: &str = r#"<scene version="3.0.0">
  <default name="spp" value="4"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,6" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="6"/><integer name="height" value="4"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
  <bsdf type="roughconductor" id="metal"><float name="alpha" value="0.2"/></bsdf>
  <shape type="cube"><ref id="metal"/><transform name="to_world"><scale value="0.5"/></transform></shape>
  <shape type="cylinder"><float name="radius" value="0.3"/><bsdf type="dielectric"/></shape>
  <shape type="disk"><emitter type="area"><rgb name="radiance" value="2"/></emitter>
    <transform name="to_world"><translate y="2"/></transform></shape>
  <shape type="shapegroup" id="g"><shape type="sphere"><float name="radius" value="0.2"/></shape></shape>
  <shape type="instance"><ref id="g"/><transform name="to_world"><translate x="1"/></transform></shape>
</scene>"#;

#[test]
fn mutated_mitsuba_scenes_never_panic_and_fail_where_the_damage_is() {
    let per_file: usize = std::env::var("GLINT_MUTANTS")
        .ok()
        .and_then(|value| value.parse().ok())
        .unwrap_or(6)
        * 4;
    let mut files = vec![(
        PathBuf::from("inline/small_mitsuba.xml"),
        SMALL_MITSUBA.to_owned(),
    )];
    let suite = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/mitsuba/tests/scenes");
    for scene in [
        "orthographic_sensor/test_orthographic_path.xml",
        "floating_sphere/test_directional_direct.xml",
    ] {
        match std::fs::read_to_string(suite.join(scene)) {
            Ok(text) => files.push((suite.join(scene), text)),
            Err(_) => {
                assert!(std::env::var_os("CI").is_none(), "{scene} is missing");
                println!("SKIPPED: ../shared/mitsuba/tests/scenes/{scene} is missing");
            }
        }
    }
    let cache = RefCell::new(HashMap::new());
    let mut outcome = Outcome {
        loaded: 0,
        refused: 0,
        rendered: 0,
    };
    let (mut failures, mut mutants) = (Vec::new(), 0);
    for (index, (path, text)) in files.iter().enumerate() {
        // The unmutated scene must load, or the mutants test nothing.
        let mut clean = Outcome {
            loaded: 0,
            refused: 0,
            rendered: 0,
        };
        let plain = MutatedAssets {
            cache: &cache,
            replaced: None,
        };
        try_mutant(text, path, &plain, &mut clean).unwrap();
        assert_eq!(clean.loaded, 1, "{} does not load", path.display());
        for round in 0..per_file {
            let seed = 0x4d49_0000_0000 | (index as u64) << 32 | round as u64;
            let mut random = Random(seed);
            let bytes = mutate(text.as_bytes(), &mut random);
            let mutated = MutatedAssets {
                cache: &cache,
                replaced: None,
            };
            mutants += 1;
            let scene_text = String::from_utf8_lossy(&bytes);
            if let Err(why) = try_mutant(&scene_text, path, &mutated, &mut outcome) {
                failures.push(format!("{} (seed {seed:#x}): {why}", path.display()));
            }
        }
    }
    eprintln!(
        "{mutants} Mitsuba mutants: {} loaded ({} rendered), {} refused with a located error",
        outcome.loaded, outcome.rendered, outcome.refused
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        outcome.refused > mutants / 10,
        "too few mutants were refused"
    );
    assert!(outcome.loaded > 0, "no mutant loaded");
}
