//! Any bytes as a texture image and as a vertical-cross environment map.
#![no_main]

mod common;

const SCENE: &str = r#"{ "scene": {
  "sceneParameters": { "envMapVertCross": "cross.png" },
  "camera": [{ "_type": "perspective", "position": "0 0 3", "viewDir": "0 0 -1",
               "focalLength": 1, "imagePlaneWidth": 1 }],
  "texture": [{ "_name": "t", "_type": "image", "sourcefile": "t.png" }],
  "shader": [{ "_name": "s", "_type": "Lambertian", "diffuse": { "_tex": "t" } }],
  "shape": [{ "_type": "sphere", "shader": { "_ref": "s" }, "center": "0 0 0", "radius": 1 }]
} }"#;

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let mut assets = glint_io::MemoryAssets::new();
    assets.insert("t.png", bytes.to_vec());
    assets.insert("cross.png", bytes.to_vec());
    if let Some(loaded) = common::load(SCENE, "scene.json", &assets) {
        for texture in &loaded.parts.textures {
            assert_eq!(
                texture.texels.len(),
                texture.width as usize * texture.height as usize
            );
        }
    }
});
