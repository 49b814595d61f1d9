//! Small scene files written to a temporary directory: malformed input is an error and
//! recoverable problems are warnings, each at an exact file:line:col; and the course's rules
//! (transform order, instance shaders, defaults, fallbacks) hold.

use std::path::{Path, PathBuf};

use glint_io::{
    load_scene, load_scene_from_text, load_scene_limited, Diagnostic, Limits, LoadedScene,
    SceneError, Severity,
};
use glint_render::{Background, ColorSource, Light, Material, Shape, Vec3};

struct Fixture {
    directory: tempfile::TempDir,
}

impl Fixture {
    fn new() -> Fixture {
        Fixture {
            directory: tempfile::tempdir().unwrap(),
        }
    }

    fn write(&self, name: &str, contents: &str) -> PathBuf {
        let path = self.directory.path().join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(&path, contents).unwrap();
        path
    }

    fn load(&self, name: &str, contents: &str) -> Result<LoadedScene, SceneError> {
        load_scene(&self.write(name, contents))
    }

    /// `load` with the course renderer's leniency: files that cannot be read are warnings.
    fn load_allowing_missing(&self, name: &str, contents: &str) -> Result<LoadedScene, SceneError> {
        let limits = Limits {
            allow_missing_assets: true,
            ..Limits::default()
        };
        load_scene_limited(&self.write(name, contents), &limits)
    }
}

fn expect_error(result: Result<LoadedScene, SceneError>) -> Diagnostic {
    match result {
        Ok(_) => panic!("expected an error"),
        Err(SceneError::Invalid(diagnostic)) => {
            assert_eq!(diagnostic.severity, Severity::Error);
            diagnostic
        }
        Err(other) => panic!("expected a located error, got {other}"),
    }
}

fn expect_ok(result: Result<LoadedScene, SceneError>) -> LoadedScene {
    result.unwrap_or_else(|error| panic!("expected the scene to load:\n{error}"))
}

fn warning<'a>(loaded: &'a LoadedScene, fragment: &str) -> &'a Diagnostic {
    loaded
        .warnings
        .iter()
        .find(|warning| warning.message.contains(fragment))
        .unwrap_or_else(|| {
            panic!(
                "no warning containing {fragment:?} in {:#?}",
                loaded.warnings
            )
        })
}

fn at(diagnostic: &Diagnostic) -> (u32, u32) {
    (diagnostic.line, diagnostic.column)
}

const CAMERA_XML: &str = r#"<camera name="main" type="perspective">
    <position>0 0 0</position>
    <viewDir>0 0 -1</viewDir>
  </camera>"#;

const CAMERA_JSON: &str = r#""camera": [{"position": "0 0 0", "viewDir": "0 0 -1"}]"#;

fn xml_scene(body: &str) -> String {
    format!("<scene>\n  {CAMERA_XML}\n{body}</scene>\n")
}

// ---- errors --------------------------------------------------------------------------------

#[test]
fn truncated_xml_is_an_error_at_the_end() {
    let fixture = Fixture::new();
    let path = fixture.write(
        "truncated.xml",
        "<scene>\n  <camera type=\"perspective\">\n    <position>0 0 0</position>\n",
    );
    let error = expect_error(load_scene(&path));
    assert_eq!(error.path, path);
    assert_eq!(at(&error), (4, 1));
    assert!(
        error.message.starts_with("malformed XML"),
        "{}",
        error.message
    );
}

#[test]
fn unclosed_xml_tag_is_an_error_at_the_mismatch() {
    let fixture = Fixture::new();
    let error = expect_error(fixture.load(
        "mismatch.xml",
        "<scene>\n  <camera>\n    <position>0 0 0</postion>\n  </camera>\n</scene>\n",
    ));
    assert_eq!(at(&error), (3, 20));
    assert!(error.message.contains("position"), "{}", error.message);
}

#[test]
fn json_syntax_error_is_located() {
    let fixture = Fixture::new();
    let error = expect_error(fixture.load(
        "colon.json",
        "{\n  \"scene\": {\n    \"camera\": [{\"position\": \"0 0 0\", \"viewDir\" \"0 0 -1\"}]\n  }\n}\n",
    ));
    assert_eq!(at(&error), (3, 48));
    assert_eq!(
        error.message,
        "malformed JSON: Expected colon after the string or word in object property"
    );
    let shown = error.to_string();
    assert!(
        shown.contains("colon.json:3:48: error: malformed JSON"),
        "{shown}"
    );
    assert!(
        shown.ends_with(&format!("\n{}^", " ".repeat(47))),
        "{shown}"
    );
}

#[test]
fn a_missing_comma_between_members_is_an_error_where_it_belongs() {
    let fixture = Fixture::new();
    // jsonc-parser alone reads `"position": "0 0 0" "viewDir": ...` as two members.
    let error = expect_error(fixture.load(
        "comma.json",
        "{\"scene\": {\n  \"camera\": [{\"position\": \"0 0 0\"\n    \"viewDir\": \"0 0 -1\"}]\n}}\n",
    ));
    assert_eq!(at(&error), (2, 34), "{error}");
    assert!(
        error
            .message
            .starts_with("malformed JSON: expected `,` or `}` here"),
        "{error}"
    );
    assert!(error.message.contains("(line 3, column 5)"), "{error}");
    assert!(
        error
            .to_string()
            .ends_with(&format!("\n{}^", " ".repeat(33))),
        "{error}"
    );
}

#[test]
fn a_missing_comma_between_elements_is_an_error_where_it_belongs() {
    let fixture = Fixture::new();
    let text = format!(
        "{{\"scene\": {{\n  {CAMERA_JSON},\n  \"shape\": [{{\"_type\": \"sphere\", \"radius\": 1}} /* no comma */ {{\"_type\": \"sphere\", \"radius\": 2}}]\n}}}}\n"
    );
    let error = expect_error(fixture.load("elements.json", &text));
    assert_eq!(at(&error), (3, 45), "{error}");
    assert!(
        error
            .message
            .starts_with("malformed JSON: expected `,` or `]` here"),
        "{error}"
    );
    // A comma inside a comment is no comma, and comments and trailing commas stay allowed.
    let commented = text.replace("/* no comma */", "/* , */");
    assert_eq!(
        at(&expect_error(fixture.load("commented.json", &commented))),
        (3, 45)
    );
    let fine = text.replace("/* no comma */", "/* ok */ , // and a line comment\n");
    let fine = fine.replace("2}]", "2},]");
    expect_ok(fixture.load("fine.json", &fine));
}

#[test]
fn a_vector_with_two_numbers_is_an_error_at_the_value() {
    let fixture = Fixture::new();
    let text = format!(
        "{{\"scene\": {{\n  {CAMERA_JSON},\n  \"shape\": [{{\"_type\": \"sphere\",\n    \"center\": \"1 2\", \"radius\": 1}}]\n}}}}\n"
    );
    let error = expect_error(fixture.load("short.json", &text));
    assert_eq!(at(&error), (4, 15));
    assert!(
        error.message.contains("expected three numbers"),
        "{}",
        error.message
    );
    assert!(error.message.contains("`center`"), "{}", error.message);
}

#[test]
fn a_word_where_a_number_belongs_is_an_error() {
    let fixture = Fixture::new();
    let text = xml_scene(
        "  <shape name=\"s\" type=\"sphere\">\n    <center>0 0 -5</center>\n    <radius>abc</radius>\n  </shape>\n",
    );
    let error = expect_error(fixture.load("word.xml", &text));
    assert_eq!(at(&error), (8, 13));
    assert_eq!(error.message, "expected a number for `radius`, found `abc`");
    assert_eq!(error.source_line(), Some("    <radius>abc</radius>"));
}

#[test]
fn a_negative_radius_is_an_error() {
    let fixture = Fixture::new();
    let text = xml_scene(
        "  <shape name=\"s\" type=\"sphere\">\n    <radius>\n      -1.5</radius>\n  </shape>\n",
    );
    let error = expect_error(fixture.load("negative.xml", &text));
    assert_eq!(at(&error), (8, 7));
    assert!(
        error.message.contains("`radius` must be positive"),
        "{}",
        error.message
    );
}

#[test]
fn a_singular_transform_is_an_error_at_the_transform() {
    let fixture = Fixture::new();
    let text = xml_scene(
        r#"  <instance name="ball" type="sphere"><shader ref="s"/></instance>
  <shader name="s" type="Lambertian"><diffuse>1 1 1</diffuse></shader>
  <shape name="flat" type="instance" id="ball">
    <transform name="t">
      <scale>1 0 1</scale>
    </transform>
  </shape>
"#,
    );
    let error = expect_error(fixture.load("singular.xml", &text));
    assert_eq!(at(&error), (10, 7));
    assert!(
        error.message.contains("cannot be inverted"),
        "{}",
        error.message
    );
}

#[test]
fn a_scene_without_camera_is_an_error() {
    let fixture = Fixture::new();
    let error = expect_error(fixture.load(
        "nocamera.xml",
        "<?xml version=\"1.0\"?>\n<!-- nothing -->\n  <scene>\n  </scene>\n",
    ));
    assert_eq!(at(&error), (3, 3));
    assert!(error.message.contains("no camera"), "{}", error.message);
}

#[test]
fn json_without_a_scene_is_an_error() {
    let fixture = Fixture::new();
    let error = expect_error(fixture.load(
        "other.json",
        "\n  {\"name\": \"package\", \"version\": 1}\n",
    ));
    assert_eq!(at(&error), (2, 3));
    assert!(error.message.contains("no `scene`"), "{}", error.message);
    let error = expect_error(fixture.load("root.xml", "<html>\n</html>\n"));
    assert_eq!(at(&error), (1, 1));
}

#[test]
fn zero_view_direction_is_an_error() {
    let fixture = Fixture::new();
    let error = expect_error(fixture.load(
        "gaze.json",
        "{\"scene\": {\"camera\": {\"position\": \"1 2 3\",\n \"lookatPoint\": \"1 2 3\"}}}",
    ));
    assert_eq!(at(&error), (2, 17));
}

#[test]
fn unreadable_file_is_an_io_error() {
    let error = load_scene(Path::new("/nonexistent/scene.xml")).unwrap_err();
    assert!(matches!(error, SceneError::Io { .. }));
    assert!(error.to_string().contains("/nonexistent/scene.xml"));
}

#[test]
fn non_utf8_text_is_located() {
    let fixture = Fixture::new();
    let path = fixture.directory.path().join("latin1.xml");
    std::fs::write(&path, b"<scene>\n  <!-- caf\xe9 -->\n</scene>\n").unwrap();
    let error = expect_error(load_scene(&path));
    assert_eq!(at(&error), (2, 11));
}

// ---- warnings ------------------------------------------------------------------------------

#[test]
fn a_missing_obj_is_an_error_naming_the_path_tried() {
    let fixture = Fixture::new();
    let text = format!(
        "{{\"scene\": {{\n  {CAMERA_JSON},\n  \"shader\": [{{\"_name\": \"grey\", \"_type\": \"Lambertian\", \"diffuse\": \"0.5 0.5 0.5\"}}],\n  \"shape\": [\n    {{\"_type\": \"mesh\", \"shader\": {{\"_ref\": \"grey\"}},\n      \"file\": \"objFiles/missing.obj\"}}\n  ]\n}}}}\n"
    );
    let error = expect_error(fixture.load("scenes/mesh.json", &text));
    let tried = fixture.directory.path().join("scenes/objFiles/missing.obj");
    assert_eq!(
        error.message,
        format!(
            "cannot read mesh `objFiles/missing.obj` (tried {}): No such file or directory",
            tried.display()
        )
    );
    assert_eq!(
        error.path,
        fixture.directory.path().join("scenes/mesh.json")
    );
    assert_eq!(at(&error), (6, 15));
}

#[test]
fn every_unreadable_file_of_a_load_is_reported_together() {
    let fixture = Fixture::new();
    let text = format!(
        "{{\"scene\": {{\n  {CAMERA_JSON},\n  \"texture\": [{{\"_name\": \"wood\", \"_type\": \"image\", \"sourcefile\": \"images/wood.png\"}}],\n  \"shader\": [{{\"_name\": \"grey\", \"_type\": \"Lambertian\", \"diffuse\": {{\"tex\": \"wood\"}}}}],\n  \"shape\": [{{\"_type\": \"mesh\", \"shader\": {{\"_ref\": \"grey\"}}, \"file\": \"a.obj\"}}],\n  \"envMapPrefix\": \"sky/reef_\"\n}}}}\n"
    );
    let error = fixture
        .load("all.json", &text)
        .expect_err("three files are missing");
    let found: Vec<(u32, u32, &str)> = error
        .diagnostics()
        .iter()
        .map(|d| (d.line, d.column, d.message.split(" (tried").next().unwrap()))
        .collect();
    assert_eq!(
        found,
        vec![
            (3, 65, "cannot read texture image `images/wood.png`"),
            (5, 67, "cannot read mesh `a.obj`"),
            (
                6,
                19,
                "cannot read environment-map face `sky/reef_posX.png`"
            ),
        ],
        "{error}"
    );
    assert!(error
        .diagnostics()
        .iter()
        .all(|d| d.severity == Severity::Error));
    // Shown one after the other, each located.
    let shown = error.to_string();
    assert_eq!(shown.matches(": error: cannot read").count(), 3, "{shown}");
}

#[test]
fn allowing_missing_files_warns_and_omits_the_mesh() {
    let fixture = Fixture::new();
    let text = format!(
        "{{\"scene\": {{\n  {CAMERA_JSON},\n  \"shader\": [{{\"_name\": \"grey\", \"_type\": \"Lambertian\", \"diffuse\": \"0.5 0.5 0.5\"}}],\n  \"shape\": [\n    {{\"_type\": \"mesh\", \"shader\": {{\"_ref\": \"grey\"}},\n      \"file\": \"objFiles/missing.obj\"}}\n  ]\n}}}}\n"
    );
    let loaded = expect_ok(fixture.load_allowing_missing("scenes/mesh.json", &text));
    let warning = warning(&loaded, "cannot read mesh `objFiles/missing.obj`");
    assert_eq!(warning.severity, Severity::Warning);
    assert_eq!(
        warning.path,
        fixture.directory.path().join("scenes/mesh.json")
    );
    assert_eq!(at(warning), (6, 15));
    assert!(warning.message.contains("the mesh is omitted"));
    assert!(loaded.parts.geometries.is_empty());
    assert!(loaded.parts.instances.is_empty());
}

#[test]
fn unknown_keys_are_warnings_with_suggestions() {
    let fixture = Fixture::new();
    let text = xml_scene(
        r#"  <shader name="s" type="Lambertian"><diffuse>1 1 1</diffuse></shader>
  <shape name="ball" type="sphere">
    <shader ref="s"/>
    <raduis>2</raduis>
    <monster>1 2 3 4</monster>
  </shape>
  <light type="point"><position>0 5 0</position><intensity>1 1 1</intensity><normal>0 -1 0</normal></light>
"#,
    );
    let loaded = expect_ok(fixture.load("keys.xml", &text));
    let typo = warning(&loaded, "`raduis`");
    assert_eq!(at(typo), (9, 5));
    assert!(
        typo.message.contains("did you mean `radius`?"),
        "{}",
        typo.message
    );
    let extension = warning(&loaded, "`monster`");
    assert_eq!(at(extension), (10, 5));
    assert!(!extension.message.contains("did you mean"));
    let stray = warning(&loaded, "`normal` is not used in a point light");
    assert_eq!(at(stray), (12, 77));
    assert_eq!(loaded.warnings.len(), 3);
    // The radius was not read: the default of 1 stands.
    assert_eq!(
        loaded.parts.geometries[0].shapes[0],
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0
        }
    );
}

#[test]
fn dangling_references_fall_back_visibly() {
    let fixture = Fixture::new();
    let text = xml_scene(
        r#"  <shader name="blue" type="Lambertian"><diffuse>0 0 1</diffuse></shader>
  <shader name="shiny" type="Mirrored"/>
  <shape name="a" type="sphere"><shader ref="bleu"/></shape>
  <shape name="b" type="sphere"><shader ref="shiny"/></shape>
  <shape name="c" type="instance" id="nothing"/>
"#,
    );
    let loaded = expect_ok(fixture.load("dangling.xml", &text));
    let missing = warning(&loaded, "shader `bleu` is not defined");
    assert_eq!(at(missing), (8, 46));
    assert!(missing.message.contains("did you mean `blue`?"));
    let unknown = warning(&loaded, "unknown shader type `Mirrored`");
    assert_eq!(at(unknown), (7, 30));
    assert!(unknown.message.contains("did you mean `Mirror`?"));
    let instance = warning(&loaded, "instance `nothing` is not defined");
    assert_eq!(at(instance), (10, 39));
    let parts = &loaded.parts;
    let fallback = Material::fallback();
    for &material in &parts.geometries[0].materials {
        assert_eq!(parts.materials[material as usize], fallback);
    }
    assert_eq!(parts.geometries[0].shapes.len(), 2);
}

#[test]
fn a_missing_texture_is_an_error_or_if_allowed_leaves_the_plain_colour() {
    let fixture = Fixture::new();
    let text = format!(
        "{{\"scene\": {{\n  {CAMERA_JSON},\n  \"texture\": [{{\"_name\": \"wood\", \"_type\": \"image\",\n    \"sourcefile\": \"images/wood.png\"}}],\n  \"shader\": [\n    {{\"_name\": \"a\", \"_type\": \"Lambertian\", \"diffuse\": {{\"tex\": \"wood\", \"data\": \"0.5 0.5 0.5\"}}}},\n    {{\"_name\": \"b\", \"_type\": \"Lambertian\", \"diffuse\": {{\"tex\": \"stone\"}}}}\n  ]\n}}}}\n"
    );
    let error = expect_error(fixture.load("texture.json", &text));
    assert_eq!(at(&error), (4, 19));
    assert!(
        error.message.starts_with(&format!(
            "cannot read texture image `images/wood.png` (tried {}): ",
            fixture.directory.path().join("images/wood.png").display()
        )),
        "{error}"
    );
    let loaded = expect_ok(fixture.load_allowing_missing("texture.json", &text));
    assert_eq!(
        at(warning(
            &loaded,
            "cannot read texture image `images/wood.png`"
        )),
        (4, 19)
    );
    assert_eq!(
        at(warning(&loaded, "texture `stone` is not defined")),
        (7, 62)
    );
    assert_eq!(
        loaded.parts.materials[0],
        Material::Lambertian {
            diffuse: ColorSource::constant(Vec3::splat(0.5))
        }
    );
    // FORMAT.md 5: a texture without `data` multiplies 1 1 1.
    assert_eq!(
        loaded.parts.materials[1],
        Material::Lambertian {
            diffuse: ColorSource::constant(Vec3::ONE)
        }
    );
    assert!(loaded.parts.textures.is_empty());
}

#[test]
fn a_texture_in_xml_is_loaded_as_linear_values() {
    let fixture = Fixture::new();
    std::fs::create_dir_all(fixture.directory.path().join("images")).unwrap();
    image::RgbaImage::from_pixel(2, 1, image::Rgba([51, 102, 255, 7]))
        .save(fixture.directory.path().join("images/tile.png"))
        .unwrap();
    let text = xml_scene(
        r#"  <texture name="tile" type="image"><sourcefile>images/tile.png</sourcefile></texture>
  <shader name="t" type="BlinnPhong"><diffuse tex="tile">1 0.5 1</diffuse><specular>1 1 1</specular></shader>
  <shape name="ball" type="sphere"><shader ref="t"/></shape>
"#,
    );
    let loaded = expect_ok(fixture.load("textured.xml", &text));
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    assert_eq!(loaded.parts.textures.len(), 1);
    assert_eq!(
        loaded.parts.textures[0].texels,
        vec![Vec3::new(0.2, 0.4, 1.0); 2]
    );
    let Material::BlinnPhong {
        diffuse,
        phong_exponent,
        mirror_coef,
        ..
    } = &loaded.parts.materials[0]
    else {
        panic!("expected BlinnPhong");
    };
    assert_eq!(
        *diffuse,
        ColorSource {
            color: Vec3::new(1.0, 0.5, 1.0),
            texture: Some(0)
        }
    );
    // FORMAT.md 5 defaults.
    assert_eq!((*phong_exponent, *mirror_coef), (1.0, 0.0));
}

// ---- the course's rules --------------------------------------------------------------------

#[test]
fn transforms_compose_in_listed_order() {
    // FORMAT.md 2.8 (slide_Instancing pp.52-54): translate then scale gives
    // [[0.5,0,0,0],[0,1.5,0,1.5],[0,0,1,-4]]: the scale applies to the object first.
    let text = xml_scene(
        r#"  <shader name="s" type="Lambertian"><diffuse>1 1 1</diffuse></shader>
  <instance name="unitBox" type="box"><shader ref="s"/><minPt>-1 -1 -1</minPt><maxPt>1 1 1</maxPt></instance>
  <shape name="placed" type="instance" id="unitBox">
    <transform name="t">
      <translate>0 1.5 -4</translate>
      <scale>0.5 1.5 1</scale>
    </transform>
  </shape>
"#,
    );
    let loaded = expect_ok(load_scene_from_text(&text, Path::new("inline.xml")));
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    let instance = loaded.parts.instances[0];
    let rows = instance.transform.unwrap().world_from_object;
    assert_eq!(
        rows,
        [
            [0.5, 0.0, 0.0, 0.0],
            [0.0, 1.5, 0.0, 1.5],
            [0.0, 0.0, 1.0, -4.0]
        ]
    );
}

#[test]
fn instances_share_their_definition_and_its_shader() {
    let text = format!(
        r#"{{"scene": {{ {CAMERA_JSON},
  "shader": [{{"_name": "red", "_type": "Lambertian", "diffuse": "1 0 0"}},
             {{"_name": "green", "_type": "Lambertian", "diffuse": "0 1 0"}}],
  "instance": [{{"_name": "egg", "_type": "sphere", "shader": {{"_ref": "red"}}}}],
  "shape": [
    {{"_type": "instance", "_id": "egg", "xform": [{{"type": "translate", "amount": [1, 0, 0]}}]}},
    {{"_type": "instance", "_id": "egg", "shader": {{"_ref": "green"}},
      "xform": [{{"type": "scale", "amount": "1 2 1"}}, {{"type": "rotation", "axis": "Y", "amount": 90}}]}},
    {{"_type": "instance", "_id": "egg"}}
  ]
}}}}"#
    );
    let loaded = expect_ok(load_scene_from_text(&text, Path::new("eggs.json")));
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    let parts = &loaded.parts;
    assert_eq!(parts.geometries.len(), 1);
    assert_eq!(parts.instances.len(), 3);
    assert!(parts
        .instances
        .iter()
        .all(|instance| instance.geometry == 0));
    // FORMAT.md A15: no shader on the instance keeps the definition's.
    assert_eq!(parts.instances[0].material, None);
    assert_eq!(parts.geometries[0].materials, vec![0]);
    assert_eq!(parts.instances[1].material, Some(1));
    assert_eq!(
        parts.instances[0].transform.unwrap().world_from_object[0][3],
        1.0
    );
    assert_eq!(parts.instances[2].transform, None);
}

#[test]
fn defaults_and_background_priority() {
    let text = r#"<scene bgColor="0.1 0.2 0.3">
  <sceneParameters><bgColor>0.4 0.5 0.6</bgColor></sceneParameters>
  <camera type="orthographic"><position>0 0 0</position><lookatPoint>0 0 -1</lookatPoint><viewDir>1 0 0</viewDir></camera>
  <shader name="glass" type="Dielectric"></shader>
  <shader name="chrome" type="Mirror"/>
  <shape name="ball" type="sphere"><shader ref="glass"/></shape>
</scene>"#;
    let loaded = expect_ok(load_scene_from_text(text, Path::new("defaults.xml")));
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    let parts = &loaded.parts;
    // FORMAT.md A4: sceneParameters outranks the scene attribute.
    assert_eq!(
        parts.background,
        Background::Color(Vec3::new(0.4, 0.5, 0.6))
    );
    // FORMAT.md 1.2: lookatPoint wins over viewDir; FORMAT.md 5 defaults for f and w.
    assert_eq!(parts.camera.basis.w, Vec3::new(0.0, 0.0, 1.0));
    assert_eq!(parts.camera.focal_length, 1.0);
    assert_eq!(parts.camera.image_plane_width, 0.5);
    assert_eq!(
        parts.materials[0],
        Material::Dielectric {
            refractive_index: 1.0,
            attenuation: Vec3::ONE
        }
    );
    assert_eq!(parts.materials[1], Material::Mirror { roughness: 0.0 });
    assert_eq!(
        parts.geometries[0].shapes[0],
        Shape::Sphere {
            center: Vec3::ZERO,
            radius: 1.0
        }
    );
}

#[test]
fn shape_lights_and_area_lights() {
    let text = format!(
        r#"{{"scene": {{ {CAMERA_JSON},
  "light": [
    {{"_type": "shape", "intensity": "2 2 2", "shape": {{"_type": "box", "minPt": "0 0 0", "maxPt": "1 1 1"}}}},
    {{"_type": "area", "position": "0 5 0", "intensity": "1 1 1", "normal": "0 -2 0", "width": 2, "length": 4}},
    {{"_type": "area", "position": "0 5 0", "intensity": "1 1 1", "normal": "0 -1 0", "visible": 0}}
  ]
}}}}"#
    );
    let loaded = expect_ok(load_scene_from_text(&text, Path::new("lights.json")));
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    let parts = &loaded.parts;
    assert_eq!(parts.lights.len(), 3);
    let Light::Triangles {
        triangles,
        intensity,
    } = &parts.lights[0]
    else {
        panic!("expected the box as triangles");
    };
    assert_eq!((triangles.len(), *intensity), (12, Vec3::splat(2.0)));
    assert!(matches!(
        parts.lights[1],
        Light::Area { normal, width, length, .. } if normal == Vec3::new(0.0, -1.0, 0.0) && width == 2.0 && length == 4.0
    ));
    assert!(
        matches!(parts.lights[2], Light::Area { width, length, .. } if width == 1.0 && length == 1.0)
    );
    // The emitting box in the plain group, plus one rectangle: the hidden light adds none.
    assert_eq!(parts.geometries.len(), 2);
    let rectangle = parts
        .instances
        .iter()
        .find(|instance| !instance.casts_shadow)
        .unwrap();
    let geometry = &parts.geometries[rectangle.geometry as usize];
    assert_eq!(geometry.shapes.len(), 2);
    let area: f32 = geometry.shapes.iter().map(Shape::area).sum();
    assert!((area - 8.0).abs() < 1e-5);
    assert_eq!(
        parts.materials[geometry.materials[0] as usize],
        Material::Emissive {
            radiance: Vec3::ONE,
            surface: None,
            light: Some(1)
        }
    );
}

#[test]
fn obj_files_are_read_once_and_fan_triangulated() {
    let fixture = Fixture::new();
    fixture.write(
        "objFiles/quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    let text = format!(
        r#"{{"scene": {{ {CAMERA_JSON},
  "shader": [{{"_name": "a", "_type": "Diffuse", "diffuse": "1 1 1"}}, {{"_name": "b", "_type": "CoolToWarm", "diffuse": "1 0 0"}}],
  "instance": [{{"_name": "quadA", "_type": "mesh", "file": "objFiles/quad.obj", "shader": {{"_ref": "a"}}}}],
  "shape": [
    {{"_type": "mesh", "file": "objFiles/quad.obj", "shader": {{"_ref": "a"}}}},
    {{"_type": "mesh", "file": "objFiles/quad.obj", "shader": {{"_ref": "b"}}}},
    {{"_type": "instance", "_id": "quadA"}}
  ]
}}}}"#
    );
    let loaded = expect_ok(fixture.load("meshes.json", &text));
    assert!(loaded.warnings.is_empty(), "{:#?}", loaded.warnings);
    let parts = &loaded.parts;
    // One geometry for the file used directly (two placements), one for the definition.
    assert_eq!(parts.geometries.len(), 2);
    assert_eq!(parts.geometries[0].shapes.len(), 2);
    assert_eq!(parts.instances[0].geometry, parts.instances[1].geometry);
    assert_eq!(parts.instances[0].material, Some(0));
    assert_eq!(parts.instances[1].material, Some(1));
}

#[test]
fn diagnostics_display_with_a_caret() {
    let fixture = Fixture::new();
    let text = xml_scene("  <shape name=\"s\" type=\"sphere\"><radius>0</radius></shape>\n");
    let error = fixture.load("zero.xml", &text).unwrap_err();
    let shown = error.to_string();
    let lines: Vec<&str> = shown.lines().collect();
    assert!(
        lines[0].ends_with("zero.xml:6:41: error: `radius` must be positive, found 0"),
        "{shown}"
    );
    assert_eq!(
        lines[1],
        "  <shape name=\"s\" type=\"sphere\"><radius>0</radius></shape>"
    );
    assert_eq!(lines[2], format!("{}^", " ".repeat(40)));
}

/// Nothing panics on damaged input: every prefix of a valid scene, in both formats, loads or
/// fails with a located error.
#[test]
fn truncated_scenes_never_panic() {
    let xml = xml_scene(
        r#"  <shader name="s" type="Glaze"><diffuse tex="t">1 1 1</diffuse><mirrorCoef>0.5</mirrorCoef></shader>
  <instance name="d" type="box"><shader ref="s"/></instance>
  <shape type="instance" id="d"><transform><rotate axis="Y">30</rotate><scale>2</scale></transform></shape>
  <light type="area"><position>0 5 0</position><normal>0 -1 0</normal></light>
"#,
    );
    let json = format!(
        r#"{{"scene": {{ {CAMERA_JSON}, "_bgColor": "1 1 1",
  "sceneParameters": {{"envMapVertCross": "x.png"}},
  "shader": [{{"_name": "s", "_type": "BlinnPhongMirrored", "specular": {{"_tex": "t", "__text": "1 1 1"}}}}],
  "instance": [{{"_name": "e", "_type": "sphere", "radius": 2}}],
  "light": {{"_type": "shape", "shape": {{"_type": "instance", "_id": "e", "xform": [{{"type": "scale", "amount": "1 2 3"}}]}}}},
  "shape": [{{"_type": "instance", "_id": "e", "transform": {{"translate": "1 1 1", "rotate": [{{"_axis": "X", "_angle": 5}}]}}}}]
}}}}"#
    );
    // `x.png` is not there: the fallback's path is walked too.
    let limits = Limits {
        allow_missing_assets: true,
        ..Limits::default()
    };
    let load = |text: &str, name: &str| {
        glint_io::load_scene_with_assets_limited(
            text,
            Path::new(name),
            &glint_io::FileSystem,
            &limits,
        )
    };
    for (text, name) in [(xml.as_str(), "cut.xml"), (json.as_str(), "cut.json")] {
        expect_ok(load(text, name));
        for end in (0..text.len()).filter(|&end| text.is_char_boundary(end)) {
            if let Err(error) = load(&text[..end], name) {
                let diagnostic = error.diagnostic().expect("a located error");
                assert!(diagnostic.line >= 1 && diagnostic.column >= 1);
            }
        }
    }
}

/// Absurd nesting is refused with a location instead of overflowing the stack.
#[test]
fn deep_nesting_is_an_error() {
    let depth = 200_000;
    let json = format!("{{\"scene\": {}{}}}", "[".repeat(depth), "]".repeat(depth));
    let error = expect_error(load_scene_from_text(&json, Path::new("deep.json")));
    assert_eq!(at(&error), (1, 110));
    let xml = format!(
        "<scene>{}{}</scene>",
        "<a>".repeat(depth),
        "</a>".repeat(depth)
    );
    let error = expect_error(load_scene_from_text(&xml, Path::new("deep.xml")));
    assert_eq!(at(&error), (1, 8 + 3 * 99));
    assert!(
        error.message.contains("nested more than 100 levels"),
        "{}",
        error.message
    );
}

// ---- text the parsers rewrite ----------------------------------------------------------------

/// Keys and values are borrowed from the file where they read as written; those the parsers
/// rewrite (XML entities and CDATA, text split by a processing instruction, JSON escapes) are copied. Either
/// way the scene must be the one its plain twin gives, with the same warnings.
#[test]
fn escaped_and_split_text_reads_as_its_plain_twin() {
    let fixture = Fixture::new();
    let plain_body = r#"  <shader name="red&blue" type="Lambertian"><diffuse>1 0 0.5</diffuse></shader>
  <shape name="ball" type="sphere"><shader ref="red&blue"/>
    <center>0 0 -5</center><radius>1.5</radius></shape>
  <shape type="sphere"><center>0 2 -5</center><radius>0.25</radius><colour>1</colour></shape>
"#;
    let escaped_body = r#"  <shader name="red&amp;blue" type="Lambertian"><diffuse>&#49; 0 0.5</diffuse></shader>
  <shape name="ball" type="sphere"><shader ref="red&#38;blue"/>
    <center>0 0 -<?note five?>5</center><radius><![CDATA[1.5]]></radius></shape>
  <shape type="sphere"><center> 0 2 -5 </center><radius>0.25</radius><colour>1</colour></shape>
"#;
    let plain = expect_ok(fixture.load(
        "plain.xml",
        &xml_scene(&plain_body.replace("red&blue", "red and blue")),
    ));
    let escaped = expect_ok(
        fixture.load(
            "escaped.xml",
            &xml_scene(
                &escaped_body
                    .replace("red&amp;blue", "red and blue")
                    .replace("red&#38;blue", "red and blue"),
            ),
        ),
    );
    let ampersand = expect_ok(fixture.load("ampersand.xml", &xml_scene(escaped_body)));
    let json = |body: &str| {
        format!(
            r#"{{"scene": {{{CAMERA_JSON},
  "shader": [{{"_name": "red&blue", "_type": "Lambertian", "diffuse": "1 0 0.5"}}],
  {body}}}}}"#
        )
    };
    let json_plain = expect_ok(fixture.load(
        "plain.json",
        &json(
            r#""shape": [{"_name": "ball", "_type": "sphere", "shader": {"_ref": "red&blue"},
                  "center": "0 0 -5", "radius": "1.5"}]"#,
        ),
    ));
    let json_escaped = expect_ok(fixture.load(
        "escaped.json",
        &json(r#""\u0073hape": [{"_name": "ball", "\u005ftype": "sph\u0065re", "shader": {"_ref": "red\u0026blue"},
                  "center": "0 0 \u002d5", "radius": "1.\u0035"}]"#),
    ));
    let hash = |loaded: &LoadedScene| glint_io::scene_hash(&loaded.parts);
    let messages = |loaded: &LoadedScene| {
        loaded
            .warnings
            .iter()
            .map(|warning| warning.message.clone())
            .collect::<Vec<_>>()
    };
    // The warnings are the unknown `colour` and the second sphere's missing shader: every
    // other entry was read.
    assert_eq!(messages(&plain).len(), 2, "{:?}", messages(&plain));
    assert_eq!(messages(&json_plain), Vec::<String>::new());
    assert_eq!(hash(&escaped), hash(&plain));
    assert_eq!(messages(&escaped), messages(&plain));
    assert_eq!(hash(&ampersand), hash(&plain), "a name with `&` in it");
    assert_eq!(hash(&json_escaped), hash(&json_plain));
    assert_eq!(messages(&json_escaped), messages(&json_plain));
    // The warning about the unknown `colour` entry names it as written, at its place.
    let unknown = warning(&plain, "colour");
    assert_eq!(at(unknown), (9, 68));
    assert_eq!(at(warning(&escaped, "colour")), (9, 70));
}
