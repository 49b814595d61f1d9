//! Limits and validation through the public API, with files held in memory: what is refused
//! is refused at its place, before its memory is taken; textures are decoded once per file.

use std::path::Path;

use glint_render::Material;

use glint_io::{
    load_scene_limited, load_scene_with_assets_limited, Limits, LoadedScene, MemoryAssets,
    SceneError, TooLarge, BYTES_PER_TEXEL,
};

const CAMERA: &str = "<camera type=\"perspective\"><position>0 0 3</position>\
    <viewDir>0 0 -1</viewDir><focalLength>1</focalLength><imagePlaneWidth>1</imagePlaneWidth>\
    </camera>\n";

fn png(width: u32, height: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    image::RgbImage::new(width, height)
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

/// A scene with `count` textures naming `file`, each used by a shader and a sphere.
fn textured(count: usize, file: &str) -> String {
    let mut scene = format!("<scene>\n{CAMERA}");
    for index in 0..count {
        scene.push_str(&format!(
            "<texture name=\"t{index}\" type=\"image\"><sourcefile>{file}</sourcefile></texture>\n\
             <shader name=\"s{index}\" type=\"Lambertian\"><diffuse tex=\"t{index}\">1 1 1</diffuse></shader>\n\
             <shape type=\"sphere\"><shader ref=\"s{index}\"/><center>{index} 0 0</center></shape>\n"
        ));
    }
    scene.push_str("</scene>\n");
    scene
}

fn load(text: &str, assets: &MemoryAssets, limits: &Limits) -> Result<LoadedScene, SceneError> {
    load_scene_with_assets_limited(text, Path::new("dir/scene.xml"), assets, limits)
}

#[track_caller]
fn error_at(result: Result<LoadedScene, SceneError>) -> (u32, u32, String) {
    match result {
        Err(SceneError::Invalid(diagnostic)) => {
            (diagnostic.line, diagnostic.column, diagnostic.message)
        }
        Err(other) => panic!("unlocated error: {other}"),
        Ok(_) => panic!("the scene loaded"),
    }
}

#[test]
fn texture_entries_naming_one_file_share_one_decoded_image() {
    let mut assets = MemoryAssets::new();
    assets.insert("dir/a.png", png(16, 8));
    let loaded = load(&textured(3, "a.png"), &assets, &Limits::default()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(loaded.parts.textures.len(), 1);
    // The budget is charged once too: three entries fit where two copies would not.
    let limits = Limits {
        max_texture_bytes: 16 * 8 * BYTES_PER_TEXEL,
        ..Limits::default()
    };
    assert!(load(&textured(3, "a.png"), &assets, &limits).is_ok());
}

#[test]
fn textures_over_the_limits_are_located_errors() {
    let mut assets = MemoryAssets::new();
    assets.insert("dir/a.png", png(300, 10));
    let limits = Limits {
        max_texture_side: 256,
        ..Limits::default()
    };
    let (line, _, message) = error_at(load(&textured(1, "a.png"), &assets, &limits));
    assert_eq!(line, 3);
    assert!(message.contains("300 x 10"), "{message}");
    let limits = Limits {
        max_file_bytes: 10,
        ..Limits::default()
    };
    let (line, _, message) = error_at(load(&textured(1, "a.png"), &assets, &limits));
    assert_eq!(line, 3);
    assert!(message.contains("limit of 10 bytes"), "{message}");
}

#[test]
fn meshes_over_the_limits_are_located_errors() {
    let mut assets = MemoryAssets::new();
    assets.insert(
        "dir/m.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 1 2 3\n".to_vec(),
    );
    let scene = format!(
        "<scene>\n{CAMERA}<shader name=\"g\" type=\"Lambertian\"><diffuse>1 1 1</diffuse></shader>\n\
         <shape type=\"mesh\">\n<file>m.obj</file><shader ref=\"g\"/></shape>\n</scene>\n"
    );
    assert!(load(&scene, &assets, &Limits::default()).is_ok());
    let limits = Limits {
        max_triangles: 3,
        ..Limits::default()
    };
    let (line, column, message) = error_at(load(&scene, &assets, &limits));
    assert_eq!((line, column), (5, 7));
    assert!(message.contains("4 triangles"), "{message}");
}

#[test]
fn scene_files_over_the_size_limit_are_not_read() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("big.xml");
    std::fs::write(&path, format!("<scene>{}</scene>", " ".repeat(5000))).unwrap();
    let limits = Limits {
        max_file_bytes: 4096,
        ..Limits::default()
    };
    match load_scene_limited(&path, &limits) {
        Err(SceneError::Io { source, .. }) => {
            assert_eq!(TooLarge::of(&source), Some(TooLarge { limit: 4096 }))
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn overflowing_numbers_are_errors_and_negative_colours_warnings() {
    let assets = MemoryAssets::new();
    let scene = |shape: &str| {
        format!(
            "<scene>\n{CAMERA}<shader name=\"g\" type=\"Lambertian\">\n<diffuse>{shape}</diffuse>\n\
             </shader>\n<shape type=\"sphere\"><shader ref=\"g\"/>\n<radius>RADIUS</radius></shape>\n</scene>\n"
        )
    };
    let (line, _, message) = error_at(load(
        &scene("1e7 0 0").replace("RADIUS", "1"),
        &assets,
        &Limits::default(),
    ));
    assert_eq!(line, 4);
    assert!(message.contains("cannot be rendered"), "{message}");
    let (line, _, message) = error_at(load(
        &scene("1 1 1").replace("RADIUS", "1e20"),
        &assets,
        &Limits::default(),
    ));
    assert_eq!(line, 7);
    assert!(message.contains("too large"), "{message}");
    let loaded = load(
        &scene("-0.5 1 1").replace("RADIUS", "1e6"),
        &assets,
        &Limits::default(),
    )
    .unwrap();
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert_eq!(loaded.warnings[0].line, 4);
}

#[test]
fn json_accepts_comments_and_trailing_commas_only() {
    let assets = MemoryAssets::new();
    let json = |body: &str| format!("{{ \"scene\": {{\n  // the camera\n  {body}\n}} }}\n");
    let camera = "\"camera\": { \"_type\": \"orthographic\", \"position\": \"0 0 3\", \
                  \"viewDir\": \"0 0 -1\", \"imagePlaneWidth\": 2, },";
    let loaded = load_scene_with_assets_limited(
        &json(camera),
        Path::new("s.json"),
        &assets,
        &Limits::default(),
    );
    assert!(loaded.is_ok(), "{:?}", loaded.err().map(|e| e.to_string()));
    for (broken, at) in [
        (camera.replace("\"camera\"", "camera"), "camera"),
        (camera.replace("\"0 0 3\"", "'0 0 3'"), "'0 0 3'"),
    ] {
        let column = 3 + broken.find(at).unwrap() as u32;
        let result = load_scene_with_assets_limited(
            &json(&broken),
            Path::new("s.json"),
            &assets,
            &Limits::default(),
        );
        let (line, found, message) = error_at(result);
        assert_eq!((line, found), (3, column), "{message}");
    }
}

#[test]
fn a_misspelled_only_camera_keeps_its_hint() {
    let assets = MemoryAssets::new();
    let scene = format!("<scene>\n{}</scene>\n", CAMERA.replace("camera", "camra"));
    let (line, column, message) = error_at(load(&scene, &assets, &Limits::default()));
    assert_eq!((line, column), (2, 1));
    assert!(message.contains("did you mean `camera`?"), "{message}");
}

#[test]
fn warnings_share_the_scene_text() {
    let assets = MemoryAssets::new();
    // 500 unused keys on one line of 20 KB: each warning's line is the same span.
    let keys: String = (0..500)
        .map(|index| format!(" junk{index}=\"{index:030}\""))
        .collect();
    let scene = format!("<scene{keys}>\n{CAMERA}</scene>\n");
    let loaded = load(&scene, &assets, &Limits::default()).unwrap();
    let unused = loaded
        .warnings
        .iter()
        .filter(|warning| warning.message.contains("junk"))
        .count();
    assert_eq!(unused, 500);
    let first = loaded.warnings[0].source_line().unwrap();
    assert_eq!(first.len(), scene.lines().next().unwrap().len());
    for warning in &loaded.warnings {
        assert!(std::ptr::eq(warning.source_line().unwrap(), first));
    }
}

/// `png(width, height)` with its image data spoilt after the header: the header (all the
/// limits look at) reads, the decode fails.
fn spoilt_png(width: u32, height: u32) -> Vec<u8> {
    let mut bytes = png(width, height);
    let idat = bytes.windows(4).position(|w| w == b"IDAT").unwrap();
    for byte in &mut bytes[idat + 4..idat + 12] {
        *byte ^= 0x5a;
    }
    bytes
}

/// The texture images are read ahead and decoded in parallel; what the load reports is what
/// reading and decoding each one when a shader first names it gives: the errors (or, allowed,
/// the warnings) in that order (a failed decode's before those of the shaders after it), the images numbered in that
/// order without the failed ones, each colour with its own texture.
#[test]
fn textures_are_reported_and_numbered_in_the_order_shaders_name_them() {
    let mut assets = MemoryAssets::new();
    assets.insert("dir/a.png", png(4, 2));
    assets.insert("dir/b.png", spoilt_png(8, 8));
    assets.insert("dir/d.png", png(2, 6));
    let scene = format!(
        "<scene>\n{CAMERA}\
         <texture name=\"td\" type=\"image\"><sourcefile>d.png</sourcefile></texture>\n\
         <texture name=\"tc\" type=\"image\"><sourcefile>c.png</sourcefile></texture>\n\
         <texture name=\"tb\" type=\"image\"><sourcefile>b.png</sourcefile></texture>\n\
         <texture name=\"ta\" type=\"image\"><sourcefile>a.png</sourcefile></texture>\n\
         <shader name=\"s0\" type=\"BlinnPhong\"><diffuse tex=\"ta\">1 1 1</diffuse>\
         <specular tex=\"tb\">1 1 1</specular></shader>\n\
         <shader name=\"s1\" type=\"Lambertian\"><diffuse tex=\"tx\">1 1 1</diffuse></shader>\n\
         <shader name=\"s2\" type=\"Lambertian\"><diffuse tex=\"tc\">1 1 1</diffuse></shader>\n\
         <shader name=\"s3\" type=\"Phong\"><diffuse>1 1 1</diffuse>\
         <specular tex=\"td\">1 1 1</specular></shader>\n\
         <shape type=\"sphere\"><shader ref=\"s0\"/></shape>\n</scene>\n"
    );
    // By default the two images that cannot be read are errors, reported in that order.
    let error = load(&scene, &assets, &Limits::default()).unwrap_err();
    let errors: Vec<(u32, &str)> = error
        .diagnostics()
        .iter()
        .map(|d| (d.line, d.message.as_str()))
        .collect();
    assert_eq!(errors.len(), 2, "{error}");
    assert!(errors[0].0 == 5 && errors[0].1.contains("b.png"), "{error}");
    assert!(errors[1].0 == 4 && errors[1].1.contains("c.png"), "{error}");
    // Allowed, as the course renderer had it: warnings, and the plain colours.
    let lenient = Limits {
        allow_missing_assets: true,
        ..Limits::default()
    };
    let loaded = load(&scene, &assets, &lenient).unwrap();
    let warnings: Vec<(u32, &str)> = loaded
        .warnings
        .iter()
        .map(|w| (w.line, w.message.as_str()))
        .collect();
    assert_eq!(warnings.len(), 3, "{warnings:?}");
    assert_eq!(warnings[0].0, 5, "{warnings:?}");
    assert!(warnings[0].1.contains("b.png"), "{warnings:?}");
    assert!(
        warnings[1].1.contains("`tx` is not defined"),
        "{warnings:?}"
    );
    assert_eq!(warnings[2].0, 4, "{warnings:?}");
    assert!(warnings[2].1.contains("c.png"), "{warnings:?}");
    let sizes: Vec<(u32, u32)> = loaded
        .parts
        .textures
        .iter()
        .map(|t| (t.width, t.height))
        .collect();
    assert_eq!(sizes, [(4, 2), (2, 6)]);
    let textures: Vec<[Option<u32>; 2]> = loaded
        .parts
        .materials
        .iter()
        .map(|material| match material {
            Material::BlinnPhong {
                diffuse, specular, ..
            }
            | Material::Phong {
                diffuse, specular, ..
            } => [diffuse.texture, specular.texture],
            Material::Lambertian { diffuse } => [diffuse.texture, None],
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(
        textures,
        [[Some(0), None], [None, None], [None, None], [None, Some(1)]]
    );
}

/// The texture budget is charged in the order the shaders name the images, not the order
/// they are declared in: the image named last is the one refused, where the first two fit.
#[test]
fn the_texture_budget_is_charged_in_the_order_shaders_name_the_images() {
    let mut assets = MemoryAssets::new();
    let mut scene = format!("<scene>\n{CAMERA}");
    for index in 0..3 {
        assets.insert(format!("dir/t{index}.png"), png(10 + index, 10));
        scene.push_str(&format!(
            "<texture name=\"t{index}\" type=\"image\"><sourcefile>t{index}.png</sourcefile></texture>\n"
        ));
    }
    for index in (0..3).rev() {
        scene.push_str(&format!(
            "<shader name=\"s{index}\" type=\"Lambertian\"><diffuse tex=\"t{index}\">1 1 1</diffuse></shader>\n"
        ));
    }
    scene.push_str("<shape type=\"sphere\"><shader ref=\"s0\"/></shape>\n</scene>\n");
    // Room for t2 and t1 (12 x 10 and 11 x 10 texels), not for t0 after them.
    let limits = Limits {
        max_texture_bytes: (120 + 110 + 50) * BYTES_PER_TEXEL,
        ..Limits::default()
    };
    let (line, _, message) = error_at(load(&scene, &assets, &limits));
    assert_eq!(line, 3, "{message}");
    assert!(message.contains("t0.png"), "{message}");
    // Files held ahead of their decode are decoded in batches of at most one file's limit:
    // the same images when every file is its own batch.
    let one_file = Limits {
        max_file_bytes: (0..3)
            .map(|index| assets_size(&assets, &format!("dir/t{index}.png")))
            .max()
            .unwrap(),
        ..Limits::default()
    };
    let batched = load(&scene, &assets, &one_file).unwrap();
    let whole = load(&scene, &assets, &Limits::default()).unwrap();
    assert_eq!(batched.parts.textures, whole.parts.textures);
    assert_eq!(whole.parts.textures.len(), 3);
    assert_eq!(whole.parts.textures[0].width, 12);
}

fn assets_size(assets: &MemoryAssets, path: &str) -> u64 {
    use glint_io::Assets;
    assets
        .read_at_most(Path::new(path), u64::MAX)
        .unwrap()
        .len() as u64
}
