//! The page's API, natively: tiles rendered one by one and encoded here give the CLI's PNG and
//! EXR byte for byte, a broken scene gives the CLI's located error text, and a Mitsuba scene
//! loads from memory with the settings it asks for; glTF models load from their bytes; a
//! tile rendered in passes refines to `render_tile`'s pixels.

use std::path::Path;

use glint_render::RenderSettings;
use glint_wasm::{encode, load, load_bytes, Files, SceneSettings, Settings};

const WEB: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

fn example_files() -> (String, Files) {
    let root = Path::new(WEB).join("scenes");
    let mut files = Files::new();
    for asset in [
        "textured/images/checker.png",
        "textured/objFiles/pyramid.obj",
    ] {
        files.add(asset, std::fs::read(root.join(asset)).unwrap());
    }
    let text = std::fs::read_to_string(root.join("textured/textured.xml")).unwrap();
    (text, files)
}

#[test]
fn tiles_assembled_and_encoded_equal_the_cli_files() {
    let (text, files) = example_files();
    let loaded = load(&text, "textured/textured.xml", &files);
    assert!(loaded.ok());
    assert!(loaded.messages().is_empty());
    let (width, height) = (70, 45); // not a multiple of the tile size
    let settings = Settings::new(width, height, 4, "course", 3, None, true).unwrap();

    let count = (width * height) as usize;
    let (mut pixels, mut albedo, mut normal) = (
        vec![0.0; count * 3],
        vec![0.0; count * 3],
        vec![0.0; count * 3],
    );
    let mut depth = vec![0.0; count];
    let mut rays = 0.0;
    let tile = 32;
    for y0 in (0..height).step_by(tile) {
        for x0 in (0..width).step_by(tile) {
            let (x1, y1) = (
                (x0 + tile as u32).min(width),
                (y0 + tile as u32).min(height),
            );
            let result = loaded.render_tile(&settings, x0, y0, x1, y1).unwrap();
            let tile_width = (x1 - x0) as usize;
            assert_eq!(result.rgb8.len(), result.pixels.len());
            for row in 0..(y1 - y0) as usize {
                let to = (y0 as usize + row) * width as usize + x0 as usize;
                let from = row * tile_width;
                let copy = |target: &mut Vec<f32>, source: &[f32], n: usize| {
                    target[to * n..(to + tile_width) * n]
                        .copy_from_slice(&source[from * n..(from + tile_width) * n]);
                };
                copy(&mut pixels, &result.pixels, 3);
                copy(&mut albedo, &result.albedo, 3);
                copy(&mut normal, &result.normal, 3);
                copy(&mut depth, &result.depth, 1);
            }
            rays += result.rays;
        }
    }
    assert!(rays >= f64::from(width * height * 4));

    // What `glint render textured/textured.xml -w 70 -h 45 -r 4 --seed 3 -o out.png` writes.
    let scene_path = Path::new(WEB).join("scenes/textured/textured.xml");
    let cli_loaded = glint_io::load_scene(&scene_path).unwrap();
    let scene = glint_render::Scene::new(cli_loaded.parts);
    let directory = tempfile::tempdir().unwrap();
    for (format, features) in [("png", false), ("exr", true)] {
        let cli_settings = RenderSettings {
            width,
            height,
            samples_per_pixel: 4,
            seed: 3,
            features,
            ..RenderSettings::default()
        };
        let (film, _) = glint_render::render(&scene, &cli_settings, &|_| true).unwrap();
        let file = directory.path().join(format!("cli.{format}"));
        glint_io::write_image(&file, &film).unwrap();
        let page = encode(
            format,
            "course",
            width,
            height,
            &pixels,
            Some(albedo.clone()),
            Some(normal.clone()),
            Some(depth.clone()),
        )
        .unwrap();
        assert!(
            page == std::fs::read(&file).unwrap(),
            "the page's {format} differs from the CLI's"
        );
    }
}

#[test]
fn a_path_traced_png_gets_the_cli_display_transform() {
    let (text, files) = example_files();
    let loaded = load(&text, "textured/textured.xml", &files);
    let (width, height) = (24, 16);
    let settings = Settings::new(width, height, 2, "path", 0, None, false).unwrap();
    let tile = loaded.render_tile(&settings, 0, 0, width, height).unwrap();
    let page = encode("png", "path", width, height, &tile.pixels, None, None, None).unwrap();

    // `glint render --integrator path` writes its PNG with the display transform's defaults.
    let scene_path = Path::new(WEB).join("scenes/textured/textured.xml");
    let scene = glint_render::Scene::new(glint_io::load_scene(&scene_path).unwrap().parts);
    let cli_settings = RenderSettings {
        width,
        height,
        samples_per_pixel: 2,
        integrator: glint_render::IntegratorKind::Path,
        ..RenderSettings::default()
    };
    let (film, _) = glint_render::render(&scene, &cli_settings, &|_| true).unwrap();
    let options = glint_io::WriteOptions {
        png: glint_io::PngEncoding::Display(glint_io::DisplayTransform::default()),
    };
    let directory = tempfile::tempdir().unwrap();
    let file = directory.path().join("cli.png");
    glint_io::write_image_with(&file, &film, &options).unwrap();
    assert!(page == std::fs::read(&file).unwrap());
    assert_eq!(tile.rgb8, options.png.to_rgb8(&film));
}

#[test]
fn a_tile_in_passes_refines_to_the_render_tile_bit_for_bit() {
    let (text, files) = example_files();
    let loaded = load(&text, "textured/textured.xml", &files);
    // 8 samples over passes of 1, 1, 2, 4 (the page's doubling); a tile cut by the film's
    // edge, off the origin, so that its pixels are placed as in the whole render.
    let settings = Settings::new(70, 45, 8, "path", 5, None, true).unwrap();
    let (x0, y0, x1, y1) = (32, 32, 64, 45);
    let single = loaded.render_tile(&settings, x0, y0, x1, y1).unwrap();
    let mut passes = loaded.start_passes(&settings, x0, y0, x1, y1).unwrap();
    assert_eq!(passes.samples_taken(), 0);
    let mut images = Vec::new();
    let mut rays = 0.0;
    for (samples, taken) in [(1, 1), (1, 2), (2, 4), (4, 8)] {
        assert!(!passes.finished());
        let tile = passes.pass(&loaded, samples).unwrap();
        assert_eq!(passes.samples_taken(), taken);
        assert_eq!(tile.pixels.len(), ((x1 - x0) * (y1 - y0) * 3) as usize);
        rays += tile.rays;
        images.push(tile);
    }
    assert!(passes.finished());
    let last = images.last().unwrap();
    let bits = |values: &[f32]| values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&last.pixels), bits(&single.pixels));
    assert_eq!(last.rgb8, single.rgb8);
    assert_eq!(bits(&last.albedo), bits(&single.albedo));
    assert_eq!(bits(&last.normal), bits(&single.normal));
    assert_eq!(bits(&last.depth), bits(&single.depth));
    // Each pass counts its own rays: together, the single render's.
    assert_eq!(rays, single.rays);
    // The first pass is a real image, and a noisier one: the passes refine it.
    let first = &images[0];
    assert!(first.pixels.iter().any(|&v| v > 0.0));
    let differing = first
        .pixels
        .iter()
        .zip(&last.pixels)
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differing > first.pixels.len() / 4,
        "{differing} values differ"
    );
    // A pass past the last adds nothing.
    let again = passes.pass(&loaded, 4).unwrap();
    assert_eq!(passes.samples_taken(), 8);
    assert_eq!(bits(&again.pixels), bits(&single.pixels));
}

#[test]
fn only_the_path_tracers_render_in_passes_and_on_their_own_scene() {
    let (text, files) = example_files();
    let loaded = load(&text, "textured/textured.xml", &files);
    for integrator in ["course", "normals", "albedo", "depth"] {
        let settings = Settings::new(8, 8, 4, integrator, 0, None, false).unwrap();
        let error = loaded
            .start_passes(&settings, 0, 0, 8, 8)
            .err()
            .unwrap_or_else(|| panic!("{integrator} started passes"));
        assert!(error.contains("path tracers"), "{error}");
        assert!(error.contains(integrator), "{error}");
        let error = settings.check_progressive("a time budget").unwrap_err();
        assert!(
            error.starts_with("a time budget is for the path tracers"),
            "{error}"
        );
    }
    for integrator in ["path", "volpath"] {
        let settings = Settings::new(8, 8, 4, integrator, 0, None, false).unwrap();
        assert_eq!(settings.check_progressive("a time budget"), Ok(()));
        let mut passes = loaded.start_passes(&settings, 0, 0, 8, 8).unwrap();
        // Another load of the same text is another scene: its sums would not belong.
        let other = load(&text, "textured/textured.xml", &files);
        assert!(passes.pass(&other, 1).is_err());
        assert_eq!(passes.samples_taken(), 0);
        assert!(passes.pass(&loaded, 1).is_ok());
    }
    let settings = Settings::new(8, 8, 4, "path", 0, None, false).unwrap();
    assert!(loaded.start_passes(&settings, 0, 0, 9, 8).is_err());
    let broken = load("<scene>", "broken.xml", &Files::new());
    assert!(broken.start_passes(&settings, 0, 0, 8, 8).is_err());
}

#[test]
fn a_broken_scene_gives_the_located_error_text() {
    let text = "<scene>\n  <shape type=\"sphere\" name=\"s\">\n    <radius>wide</radius>\n  </shape>\n</scene>\n";
    let loaded = load(text, "broken.xml", &Files::new());
    assert!(!loaded.ok());
    let messages = loaded.messages();
    let error = &messages[0];
    assert_eq!(error.severity, "error");
    assert_eq!((error.file.as_str(), error.line), ("broken.xml", 3));
    assert!(
        error.text.starts_with(&format!(
            "error: broken.xml:3:{}: {}\n",
            error.column, error.message
        )),
        "{}",
        error.text
    );
    assert!(error.text.ends_with(&error.excerpt));
    assert!(error.excerpt.contains("<radius>wide</radius>\n"));
    assert!(loaded
        .render_tile(
            &Settings::new(4, 4, 1, "course", 0, None, false).unwrap(),
            0,
            0,
            4,
            4
        )
        .is_err());
}

#[test]
fn bad_settings_and_formats_are_refused() {
    assert!(Settings::new(0, 4, 1, "course", 0, None, false).is_err());
    assert!(Settings::new(4, 4, 1, "photon", 0, None, false)
        .unwrap_err()
        .contains("course, path"));
    assert!(encode("jpg", "course", 1, 1, &[0.0; 3], None, None, None).is_err());
    assert!(encode("png", "course", 2, 1, &[0.0; 3], None, None, None).is_err());
}

/// A diffuse triangle from an OBJ among the page's files under a constant environment; a
/// `res` x 8 film (12 unless defined), 4 samples, the path tracer at Mitsuba's max_depth 3.
const MITSUBA: &str = r#"<scene version="3.0.0">
  <default name="res" value="12"/>
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective">
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm">
      <integer name="width" value="$res"/><integer name="height" value="8"/>
    </film>
  </sensor>
  <emitter type="constant"/>
  <shape type="obj">
    <string name="filename" value="meshes/tri.obj"/>
    <bsdf type="diffuse"/>
  </shape>
</scene>
"#;

#[test]
fn a_mitsuba_scene_loads_from_memory_and_asks_for_its_settings() {
    let mut files = Files::new();
    files.add(
        "dropped/meshes/tri.obj",
        b"v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
    );
    let loaded = load(MITSUBA, "dropped/scene.xml", &files);
    assert!(loaded.ok(), "{:?}", loaded.messages());
    assert!(loaded.messages().is_empty(), "{:?}", loaded.messages());
    let asked = loaded.scene_settings();
    assert_eq!(
        asked,
        SceneSettings {
            width: Some(12),
            height: Some(8),
            samples_per_pixel: Some(4),
            integrator: Some("path".to_owned()),
            max_depth: Some(2),
        }
    );
    // Those settings on the page give the pixels the CLI renders without flags.
    let settings = Settings::new(12, 8, 4, "path", 0, Some(2), false).unwrap();
    let tile = loaded.render_tile(&settings, 0, 0, 12, 8).unwrap();
    let native = glint_io::load_scene_with_assets(MITSUBA, Path::new("dropped/scene.xml"), &{
        let mut assets = glint_io::MemoryAssets::new();
        assets.insert(
            "dropped/meshes/tri.obj",
            b"v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
        );
        assets
    })
    .unwrap()
    .parts;
    let cli_settings = glint_render::RequestedSettings::default().settle(&native.physical.defaults);
    let (film, _) =
        glint_render::render(&glint_render::Scene::new(native), &cli_settings, &|_| true).unwrap();
    let cli: Vec<f32> = film.pixels.iter().flat_map(|p| p.to_array()).collect();
    assert_eq!(tile.pixels, cli);
    assert!(tile.pixels.iter().any(|&v| v > 0.0));

    // Without the asset the OBJ is a located error naming it.
    let missing = load(MITSUBA, "dropped/scene.xml", &Files::new());
    assert!(!missing.ok());
    assert!(
        missing.messages()[0].text.contains("tri.obj"),
        "{:?}",
        missing.messages()
    );
    // Course scenes ask for nothing: the page keeps its own settings.
    let (text, files) = example_files();
    let course = load(&text, "textured/textured.xml", &files);
    assert_eq!(course.scene_settings(), SceneSettings::default());
}

/// The project's shared glTF test files (`../shared/gltf`, beside the repository).
fn shared_gltf() -> Option<std::path::PathBuf> {
    let folder = Path::new(WEB).join("../../shared/gltf");
    if folder.is_dir() {
        return Some(folder);
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "{} is missing",
        folder.display()
    );
    eprintln!("SKIPPED: {} is missing", folder.display());
    None
}

#[test]
fn glb_and_gltf_bytes_load_with_the_dropped_files() {
    let Some(models) = shared_gltf() else {
        return;
    };
    // A GLB: binary, whole in its bytes. No camera or light: the loader says how it frames
    // and lights it, and asks for the path tracer.
    let glb = std::fs::read(models.join("BoxTextured-GLB/BoxTextured.glb")).unwrap();
    let loaded = load_bytes(&glb, "BoxTextured.glb", &Files::new(), None, None);
    assert!(loaded.ok(), "{:?}", loaded.messages());
    assert!(!loaded.messages().is_empty());
    assert!(loaded
        .messages()
        .iter()
        .all(|m| m.severity == "warning" && m.file == "BoxTextured.glb"));
    assert_eq!(loaded.scene_settings().integrator.as_deref(), Some("path"));
    let settings = Settings::new(16, 12, 1, "path", 0, None, false).unwrap();
    let tile = loaded.render_tile(&settings, 0, 0, 16, 12).unwrap();
    assert!(tile.pixels.iter().any(|&v| v > 0.0));

    // A .gltf finds its buffer among the files, beside it.
    let gltf = std::fs::read(models.join("gltf-rs/Box.gltf")).unwrap();
    let mut files = Files::new();
    files.add(
        "models/Box0.bin",
        std::fs::read(models.join("gltf-rs/Box0.bin")).unwrap(),
    );
    let loaded = load_bytes(&gltf, "models/Box.gltf", &files, None, None);
    assert!(loaded.ok(), "{:?}", loaded.messages());
    // Without it, a located error naming it; a camera it lacks, another. (With it anywhere
    // among the files, the only one of its name, it would be found by that name.)
    let missing = load_bytes(&gltf, "Box.gltf", &Files::new(), None, None);
    assert!(!missing.ok());
    let error = &missing.messages()[0];
    assert!(error.text.starts_with("error: Box.gltf:"), "{error:?}");
    assert!(error.text.contains("Box0.bin"), "{error:?}");
    let camera = load_bytes(&gltf, "models/Box.gltf", &files, None, Some("top".into()));
    assert!(
        camera.messages()[0].text.contains("top"),
        "{:?}",
        camera.messages()
    );
    assert!(!load_bytes(&gltf, "models/Box.gltf", &files, Some(1), None).ok());
}

#[test]
fn loose_files_are_found_by_their_base_name_with_a_note_and_two_are_an_error() {
    let (text, files) = example_files();
    let root = Path::new(WEB).join("scenes/textured");
    let read = |name: &str| std::fs::read(root.join(name)).unwrap();
    let settings = Settings::new(24, 18, 1, "course", 0, None, false).unwrap();
    let whole = load(&text, "textured/textured.xml", &files);
    assert!(whole.ok());
    assert!(whole.messages().is_empty(), "{:?}", whole.messages());

    // A multi-file picker's base names: found, noted, and the same image.
    let mut loose = Files::new();
    loose.add("pyramid.obj", read("objFiles/pyramid.obj"));
    loose.add("checker.png", read("images/checker.png"));
    let loaded = load(&text, "textured.xml", &loose);
    assert!(loaded.ok(), "{:?}", loaded.messages());
    let mut texts: Vec<String> = loaded.messages().into_iter().map(|m| m.text).collect();
    texts.sort();
    assert_eq!(
        texts,
        [
            "note: images/checker.png: using checker.png from the files given",
            "note: objFiles/pyramid.obj: using pyramid.obj from the files given",
        ]
    );
    let tile = |loaded: &glint_wasm::Loaded| loaded.render_tile(&settings, 0, 0, 24, 18).unwrap();
    assert_eq!(tile(&loaded).pixels, tile(&whole).pixels);

    // Two of that name and none at the path: an error at the mesh's element naming both.
    let mut two = Files::new();
    two.add("a/pyramid.obj", read("objFiles/pyramid.obj"));
    two.add("b/pyramid.obj", read("objFiles/pyramid.obj"));
    two.add("images/checker.png", read("images/checker.png"));
    let ambiguous = load(&text, "textured.xml", &two);
    assert!(!ambiguous.ok());
    let error = &ambiguous.messages()[0].text;
    assert!(
        error.starts_with("error: textured.xml:50:11: cannot read mesh `objFiles/pyramid.obj`")
            && error.contains("2 files named pyramid.obj among the files given")
            && error.contains("(a/pyramid.obj, b/pyramid.obj)"),
        "{error}"
    );
}

#[test]
fn background_depth_of_field_and_display_settings_are_checked_and_applied() {
    let (text, files) = example_files();
    let mut loaded = load(&text, "textured/textured.xml", &files);
    let plain = Settings::new(24, 18, 4, "course", 0, None, false).unwrap();
    let mut options = plain.clone();
    options.set_background("0.2,0.5,0.8").unwrap();
    options.set_depth_of_field(Some(7.0), Some(0.2)).unwrap();
    options
        .set_display(Some(1.0), Some("aces".into()), None)
        .unwrap();
    let before = loaded.render_tile(&plain, 0, 0, 24, 18).unwrap();
    loaded.apply(&options).unwrap();
    let after = loaded.render_tile(&options, 0, 0, 24, 18).unwrap();
    assert_ne!(before.pixels, after.pixels);
    assert_ne!(before.rgb8, after.rgb8);
    // Plain settings again: the scene's own background and camera.
    loaded.apply(&plain).unwrap();
    assert_eq!(
        loaded.render_tile(&plain, 0, 0, 24, 18).unwrap().pixels,
        before.pixels
    );

    let mut bad = plain.clone();
    assert!(bad
        .set_background("1,2")
        .unwrap_err()
        .starts_with("background: expected three"));
    assert!(bad.set_background("1,-2,3").is_err());
    assert!(bad.set_depth_of_field(None, Some(0.1)).is_err());
    assert!(bad.set_depth_of_field(Some(0.0), Some(0.1)).is_err());
    assert!(bad.set_depth_of_field(Some(f32::NAN), None).is_err());
    assert!(bad.set_display(Some(65.0), None, None).is_err());
    assert!(bad.set_display(None, Some("filmic".into()), None).is_err());
    assert!(bad.set_display(None, None, Some("gamma".into())).is_err());
}
