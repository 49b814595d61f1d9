//! Any bytes as the OBJ mesh of a scene: placed directly, instanced, and as a shape light.
#![no_main]

mod common;

const SCENE: &str = r#"<scene>
  <camera type="perspective"><position>0 0 3</position><viewDir>0 0 -1</viewDir>
    <focalLength>1</focalLength><imagePlaneWidth>1</imagePlaneWidth></camera>
  <shader name="grey" type="Lambertian"><diffuse>0.5 0.5 0.5</diffuse></shader>
  <instance name="m" type="mesh"><file>mesh.obj</file><shader ref="grey"/></instance>
  <shape type="mesh"><file>mesh.obj</file><shader ref="grey"/></shape>
  <shape type="instance" id="m"><translate>1 0 0</translate></shape>
  <light type="shape"><intensity>1 1 1</intensity>
    <shape type="mesh"><file>mesh.obj</file></shape></light>
</scene>"#;

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    let mut assets = glint_io::MemoryAssets::new();
    assets.insert("mesh.obj", bytes.to_vec());
    let _ = common::load(SCENE, "scene.xml", &assets).expect("the scene itself is valid");
    let _ = glint_io::load_mesh_from(std::path::Path::new("mesh.obj"), &assets);
});
