//! Issue 56: a file a scene names that cannot be read (a mesh, a texture image, an
//! environment-map face, a glTF buffer, a Mitsuba mesh) is an error in `glint check` and
//! `glint render`: exit 2, no image, every such file named where the scene names it, with the
//! path tried. `--allow-missing-assets` gives back the course renderer's warning and image.
//! And a JSON scene with a comma missing is refused where the comma belongs.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

const CAMERA: &str = "<camera type=\"perspective\"><position>0 0 0</position>\
    <viewDir>0 0 -1</viewDir><focalLength>1</focalLength>\
    <imagePlaneWidth>1</imagePlaneWidth></camera>\n\
    <light type=\"point\"><position>0 3 0</position><intensity>1 1 1</intensity></light>\n\
    <shader name=\"b\" type=\"Lambertian\"><diffuse>1 1 1</diffuse></shader>\n\
    <shape type=\"sphere\"><shader ref=\"b\"/><center>0 0 -5</center><radius>1</radius></shape>\n";

/// A course scene: the camera, a light and a lit sphere, then `body`.
fn course(body: &str) -> String {
    format!("<scene>\n{CAMERA}{body}</scene>\n")
}

const MESH: &str =
    "<shape type=\"mesh\"><shader ref=\"b\"/>\n<file>objFiles/bunny.obj</file></shape>\n";
const TEXTURE: &str = "<texture name=\"t\" type=\"image\">\n<sourcefile>images/wood.png</sourcefile></texture>\n\
    <shader name=\"wood\" type=\"Lambertian\"><diffuse tex=\"t\">0.8 0.4 0.1</diffuse></shader>\n\
    <shape type=\"sphere\"><shader ref=\"wood\"/><center>1 0 -4</center><radius>0.5</radius></shape>\n";
const ENVIRONMENT: &str =
    "<sceneParameters><bgColor>0.2 0.3 0.4</bgColor>\n<envMapPrefix>sky/reef_</envMapPrefix></sceneParameters>\n";

const MITSUBA: &str = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
  </sensor>
  <emitter type="constant"/>
  <shape type="sphere"/>
  <shape type="obj">
    <string name="filename" value="meshes/bunny.obj"/>
  </shape>
  <shape type="ply">
    <string name="filename" value="meshes/dragon.ply"/>
  </shape>
</scene>
"#;

/// One triangle whose positions are in `tri.bin`, which is not there.
const GLTF: &str = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "buffers": [{"byteLength": 36,
               "uri": "tri.bin"}]}
"#;

fn glint(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("cannot run glint")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The 1-based line of the first line of `text` holding `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|line| line.contains(needle))
        .unwrap_or_else(|| panic!("{needle} not in the scene"))
        + 1
}

/// A temporary folder holding `files`; its canonical path (what glint, run in it, resolves
/// relative names against).
fn folder(files: &[(&str, &str)]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    for (name, contents) in files {
        std::fs::write(dir.path().join(name), contents).unwrap();
    }
    let real = dir.path().canonicalize().unwrap();
    (dir, real)
}

/// `check` and `render` of `scene` (in `dir`) both exit 2, render writing nothing, and
/// stderr says, for each of `expected` (a line of the scene, what was looked for, the name as
/// written), `error: SCENE:LINE:COL: cannot read WHAT `NAME` (tried DIR/NAME): No such file
/// or directory`.
#[track_caller]
fn assert_refused(dir: &Path, real: &Path, scene: &str, expected: &[(usize, &str, &str)]) {
    let check = glint(dir, &["check", scene]);
    let render = glint(
        dir,
        &["render", scene, "-o", "out.png", "-w", "8", "-h", "8"],
    );
    for output in [&check, &render] {
        let text = stderr(output);
        assert_eq!(output.status.code(), Some(2), "{scene}: {text}");
        for (line, what, name) in expected {
            let message = format!(
                "cannot read {what} `{name}` (tried {}): No such file or directory",
                real.join(name).display()
            );
            let found = text.lines().any(|shown| {
                shown.starts_with(&format!("error: {scene}:{line}:")) && shown.ends_with(&message)
            });
            assert!(
                found,
                "{scene}: no `{scene}:{line}:COL: {message}` in\n{text}"
            );
        }
        assert_eq!(
            text.matches(": cannot read ").count(),
            expected.len(),
            "{scene}: {text}"
        );
    }
    assert!(stderr(&check).contains(&format!("{scene}: cannot be loaded")));
    assert!(
        !dir.join("out.png").exists(),
        "{scene}: an image was written"
    );
}

#[test]
fn a_missing_course_mesh_texture_or_environment_map_is_an_error() {
    let mesh = course(MESH);
    let texture = course(TEXTURE);
    let environment = course(ENVIRONMENT);
    let (dir, real) = folder(&[
        ("mesh.xml", &mesh),
        ("texture.xml", &texture),
        ("environment.xml", &environment),
    ]);
    let dir = dir.path();
    assert_refused(
        dir,
        &real,
        "mesh.xml",
        &[(line_of(&mesh, "bunny.obj"), "mesh", "objFiles/bunny.obj")],
    );
    assert_refused(
        dir,
        &real,
        "texture.xml",
        &[(
            line_of(&texture, "wood.png"),
            "texture image",
            "images/wood.png",
        )],
    );
    assert_refused(
        dir,
        &real,
        "environment.xml",
        &[(
            line_of(&environment, "reef_"),
            "environment-map face",
            "sky/reef_posX.png",
        )],
    );
}

#[test]
fn every_missing_file_of_a_scene_is_reported_at_once() {
    let all = course(&format!("{ENVIRONMENT}{TEXTURE}{MESH}"));
    let (dir, real) = folder(&[("all.xml", &all)]);
    assert_refused(
        dir.path(),
        &real,
        "all.xml",
        &[
            (
                line_of(&all, "wood.png"),
                "texture image",
                "images/wood.png",
            ),
            (line_of(&all, "bunny.obj"), "mesh", "objFiles/bunny.obj"),
            (
                line_of(&all, "reef_"),
                "environment-map face",
                "sky/reef_posX.png",
            ),
        ],
    );
}

#[test]
fn missing_mitsuba_meshes_and_gltf_buffers_are_errors() {
    let (dir, real) = folder(&[("mitsuba.xml", MITSUBA), ("model.gltf", GLTF)]);
    assert_refused(
        dir.path(),
        &real,
        "mitsuba.xml",
        &[
            (line_of(MITSUBA, "bunny.obj"), "mesh", "meshes/bunny.obj"),
            (line_of(MITSUBA, "dragon.ply"), "mesh", "meshes/dragon.ply"),
        ],
    );
    assert_refused(
        dir.path(),
        &real,
        "model.gltf",
        &[(line_of(GLTF, "tri.bin"), "buffer", "tri.bin")],
    );
}

/// `--allow-missing-assets` renders what the course renderer rendered: the scene without the
/// mesh, with the texture's plain colour and the background colour, pixel for pixel, with a
/// warning for each file. In both command-line forms, and `check` passes.
#[test]
fn allowing_missing_assets_renders_the_course_renderers_image() {
    let all = course(&format!("{ENVIRONMENT}{TEXTURE}{MESH}"));
    let without = course(
        &format!("{ENVIRONMENT}{TEXTURE}")
            .replace("<envMapPrefix>sky/reef_</envMapPrefix>", "")
            .replace(" tex=\"t\"", ""),
    );
    let (dir, _) = folder(&[("all.xml", &all), ("without.xml", &without)]);
    let dir = dir.path();
    let size = ["-w", "16", "-h", "12"];
    let allow = "--allow-missing-assets";
    let runs: [(&str, Vec<&str>); 3] = [
        (
            "lenient.png",
            [
                &["render", "all.xml", allow, "-o", "lenient.png"][..],
                &size,
            ]
            .concat(),
        ),
        (
            "course.png",
            [&["-i", "all.xml", allow, "-o", "course.png"][..], &size].concat(),
        ),
        (
            "without.png",
            [&["render", "without.xml", "-o", "without.png"][..], &size].concat(),
        ),
    ];
    for (image, args) in &runs {
        let output = glint(dir, args);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(0), "{args:?}: {text}");
        if *image != "without.png" {
            for fallback in [
                "the mesh is omitted",
                "show their plain colour",
                "the background colour is used instead",
            ] {
                assert!(text.contains(fallback), "{args:?}: {text}");
            }
        }
    }
    let pixels = |name: &str| image::open(dir.join(name)).unwrap().to_rgb8();
    let expected = pixels("without.png");
    // The fallbacks show: the background colour, and the plain-coloured sphere.
    assert!(expected.pixels().any(|p| p.0 != expected.get_pixel(0, 0).0));
    assert_eq!(pixels("lenient.png"), expected);
    assert_eq!(pixels("course.png"), expected);

    let check = glint(dir, &["check", "all.xml", allow]);
    let text = stderr(&check);
    assert_eq!(check.status.code(), Some(0), "{text}");
    assert!(text.contains("all.xml: ok (3 warnings)"), "{text}");
    assert!(!text.contains("error: "), "{text}");
}

/// A comma missing between two members or two elements is refused where it belongs, with
/// and without `--strict` (no course file relies on one).
#[test]
fn a_missing_json_comma_is_a_located_error() {
    let members = "{\"scene\": {\n  \"camera\": [{\"_type\": \"perspective\", \"position\": \"0 0 0\"\n    \"viewDir\": \"0 0 -1\"}]\n}}\n";
    let elements = "{\"scene\": {\n  \"camera\": [{\"_type\": \"perspective\", \"position\": \"0 0 0\", \"viewDir\": \"0 0 -1\"}],\n  \"shape\": [{\"_type\": \"sphere\", \"radius\": 1}\n    {\"_type\": \"sphere\", \"radius\": 2}]\n}}\n";
    let (dir, _) = folder(&[("members.json", members), ("elements.json", elements)]);
    for (scene, at, closer) in [
        ("members.json", "error: members.json:2:58: ", '}'),
        ("elements.json", "error: elements.json:3:45: ", ']'),
    ] {
        for strict in [false, true] {
            let mut args = vec!["check", scene];
            args.extend(strict.then_some("--strict"));
            let output = glint(dir.path(), &args);
            let text = stderr(&output);
            assert_eq!(output.status.code(), Some(2), "{args:?}: {text}");
            let expected = format!("{at}malformed JSON: expected `,` or `{closer}` here");
            assert!(
                text.contains(&expected),
                "{args:?}: no {expected:?} in\n{text}"
            );
        }
    }
}
