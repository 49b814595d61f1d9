//! The `glint` binary end to end: both command-line forms, image sizes and pixels, exit
//! statuses, error locations, and that no image is left behind by a failed run.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tempfile::TempDir;

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

/// One blue Lambertian sphere of radius 1 at z = -5 in front of a camera at the origin looking
/// down -z, lit by a point light above the camera (the course's `oneSphere.xml`). The image
/// plane is 0.5 wide at focal length 1, so the corners of the image miss the sphere.
const SPHERE_XML: &str = r#"<?xml version="1.0" encoding="UTF-8" ?>
<scene>
  <camera name="main" type="perspective">
    <position>0 0 0</position>
    <viewDir>0 0 -1</viewDir>
    <focalLength>1.0</focalLength>
    <imagePlaneWidth>0.5</imagePlaneWidth>
  </camera>
  <light type="point">
    <position>0 10 0</position>
    <intensity>1.0 1.0 1.0</intensity>
  </light>
  <shader name="blue" type="Lambertian">
    <diffuse>0 0 1</diffuse>
  </shader>
  <shape name="sphere1" type="sphere">
    <shader ref="blue" />
    <center>0 0 -5</center>
    <radius>1</radius>
  </shape>
</scene>
"#;

/// The same scene in the JSON format.
const SPHERE_JSON: &str = r#"{
  "scene": {
    "camera": [{
      "position": "0 0 0", "viewDir": "0 0 -1", "focalLength": 1.0,
      "imagePlaneWidth": 0.5, "_name": "main", "_type": "perspective"
    }],
    "light": [{ "position": "0 10 0", "intensity": "1.0 1.0 1.0", "_type": "point" }],
    "shader": [{ "diffuse": "0 0 1", "_name": "blue", "_type": "Lambertian" }],
    "shape": [{
      "shader": { "_ref": "blue" },
      "center": "0 0 -5",
      "radius": 1,
      "_name": "sphere1",
      "_type": "sphere"
    }]
  }
}
"#;

fn glint_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(GLINT)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("cannot run glint")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[track_caller]
fn assert_exit(output: &Output, code: i32) {
    assert_eq!(
        output.status.code(),
        Some(code),
        "expected exit {code}\nstdout:\n{}\nstderr:\n{}",
        stdout(output),
        stderr(output)
    );
}

/// A temporary directory holding `scene.xml` (and `scene.json`) with the sphere scene.
fn scene_dir() -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.xml"), SPHERE_XML).unwrap();
    std::fs::write(dir.path().join("scene.json"), SPHERE_JSON).unwrap();
    dir
}

fn read_png(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
        .to_rgb8()
}

fn render_png(dir: &Path, name: &str, args: &[&str]) -> image::RgbImage {
    let output = dir.join(name);
    let mut all = vec!["-i", "scene.xml", "-o", name];
    all.extend_from_slice(args);
    let result = glint_in(dir, &all);
    assert_exit(&result, 0);
    read_png(&output)
}

// ---------------------------------------------------------------------------------------------
// Help and the course's flags

#[test]
fn help_exits_zero_and_lists_height() {
    let dir = tempfile::tempdir().unwrap();
    for flag in ["--help", "-?"] {
        let output = glint_in(dir.path(), &[flag]);
        assert_exit(&output, 0);
        let text = stdout(&output);
        assert!(text.contains("--height"), "{flag}:\n{text}");
        assert!(text.contains("--inputfile"), "{flag}:\n{text}");
    }
    let output = glint_in(dir.path(), &["render", "--help"]);
    assert_exit(&output, 0);
    assert!(stdout(&output).contains("<SCENE>"));
    let output = glint_in(dir.path(), &["--version"]);
    assert_exit(&output, 0);
}

#[test]
fn dash_h_is_the_height() {
    let dir = scene_dir();
    let image = render_png(dir.path(), "out.png", &["-w", "8", "-h", "4"]);
    assert_eq!(image.dimensions(), (8, 4));
}

#[test]
fn course_long_options_are_accepted() {
    let dir = scene_dir();
    let output = glint_in(
        dir.path(),
        &[
            "--inputfile",
            "scene.xml",
            "--outputfile",
            "long.png",
            "--width",
            "12",
            "--height",
            "10",
            "--rpp",
            "4",
            "--recursionDepth",
            "2",
            "--numcpus",
            "1",
            "--aspect",
            "1.2",
        ],
    );
    assert_exit(&output, 0);
    assert_eq!(
        read_png(&dir.path().join("long.png")).dimensions(),
        (12, 10)
    );
}

#[cfg(feature = "preview")]
#[test]
fn course_options_depth_split_and_window_take_effect() {
    let dir = scene_dir();
    // No display: the preview window cannot open, which must not stop the render.
    let output = Command::new(GLINT)
        .args([
            "-i",
            "scene.xml",
            "-o",
            "o.png",
            "-w",
            "4",
            "-h",
            "4",
            "-d",
            "2.5",
            "-s",
            "objectMedian",
            "-x",
            "640",
            "-y",
            "480",
        ])
        .current_dir(dir.path())
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("cannot run glint");
    assert_exit(&output, 0);
    let text = stderr(&output);
    assert!(!text.contains("has no effect"), "{text}");
    assert!(text.contains("warning: no preview window"), "{text}");
    assert_eq!(read_png(&dir.path().join("o.png")).dimensions(), (4, 4));
}

#[test]
fn an_unknown_split_method_is_a_usage_error_naming_the_methods() {
    let dir = scene_dir();
    let output = glint_in(
        dir.path(),
        &["-i", "scene.xml", "-o", "o.png", "-s", "kdtree"],
    );
    assert_exit(&output, 2);
    let text = stderr(&output);
    assert!(text.contains("objectMedian, spatialMedian, sah"), "{text}");
    assert!(!dir.path().join("o.png").exists());
}

// ---------------------------------------------------------------------------------------------
// Rendering through both forms

#[test]
fn both_forms_render_the_requested_size() {
    let dir = scene_dir();
    let course = render_png(dir.path(), "course.png", &["-w", "20", "-h", "14"]);
    assert_eq!(course.dimensions(), (20, 14));

    let output = glint_in(
        dir.path(),
        &[
            "render",
            "scene.xml",
            "-o",
            "modern.png",
            "-w",
            "20",
            "-h",
            "14",
        ],
    );
    assert_exit(&output, 0);
    let modern = read_png(&dir.path().join("modern.png"));
    assert_eq!(course.as_raw(), modern.as_raw());

    // The JSON twin renders the same picture.
    let output = glint_in(
        dir.path(),
        &[
            "render",
            "scene.json",
            "-o",
            "json.png",
            "-w",
            "20",
            "-h",
            "14",
        ],
    );
    assert_exit(&output, 0);
    assert_eq!(
        read_png(&dir.path().join("json.png")).as_raw(),
        course.as_raw()
    );

    // The sphere is in the middle and lit from above: blue, no red or green.
    let centre = course.get_pixel(10, 7).0;
    assert!(
        centre[2] > 50 && centre[0] == 0 && centre[1] == 0,
        "{centre:?}"
    );
}

#[test]
fn background_override_sets_miss_pixels() {
    let dir = scene_dir();
    let plain = render_png(dir.path(), "plain.png", &["-w", "16", "-h", "16"]);
    assert_eq!(
        plain.get_pixel(0, 0).0,
        [0, 0, 0],
        "the default background is black"
    );

    let grey = render_png(
        dir.path(),
        "grey.png",
        &["-w", "16", "-h", "16", "--background", "0.2,0.2,0.2"],
    );
    // floor(0.2 * 255) = 51, the course's 8-bit conversion.
    for (x, y) in [(0, 0), (15, 0), (0, 15), (15, 15)] {
        assert_eq!(grey.get_pixel(x, y).0, [51, 51, 51], "corner ({x}, {y})");
    }
    // Pixels on the sphere do not see the background.
    assert_eq!(grey.get_pixel(8, 8), plain.get_pixel(8, 8));
}

#[test]
fn thread_count_does_not_change_the_image() {
    let dir = scene_dir();
    // Several tiles (16 x 16) including partial ones, and jittered samples.
    let args = ["-w", "40", "-h", "36", "-r", "4"];
    let one = render_png(dir.path(), "one.png", &[&args[..], &["-n", "1"]].concat());
    let two = render_png(dir.path(), "two.png", &[&args[..], &["-n", "2"]].concat());
    assert_eq!(one.as_raw(), two.as_raw());

    // The seed does change jittered samples on the silhouette, so the comparison above is
    // not vacuous.
    let seeded = render_png(
        dir.path(),
        "seeded.png",
        &[&args[..], &["-n", "2", "--seed", "12345"]].concat(),
    );
    assert_ne!(one.as_raw(), seeded.as_raw());
}

#[test]
fn exr_output_is_linear_float() {
    let dir = scene_dir();
    let output = glint_in(
        dir.path(),
        &[
            "render",
            "scene.xml",
            "-o",
            "out.exr",
            "-w",
            "9",
            "-h",
            "7",
            "--background",
            "0.2,0.2,0.2",
        ],
    );
    assert_exit(&output, 0);
    let image = image::open(dir.path().join("out.exr")).unwrap();
    assert!(
        matches!(
            image,
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
        ),
        "EXR should decode as float, got {:?}",
        image.color()
    );
    let image = image.to_rgb32f();
    assert_eq!(image.dimensions(), (9, 7));
    assert_eq!(image.get_pixel(0, 0).0, [0.2, 0.2, 0.2]);
    let centre = image.get_pixel(4, 3).0;
    assert!(
        centre[0] == 0.0 && centre[2] > 0.2 && centre[2] <= 1.0,
        "{centre:?}"
    );
}

/// `--integrator path` with an .exr output writes the beauty as R, G, B and the denoiser
/// features under Blender's pass names (`Denoising Albedo.R/G/B`, `Denoising Normal.X/Y/Z`,
/// `Depth.Z`); the sphere's albedo is its Lambertian colour, its centre normal faces the
/// camera and its depth is the distance to its front pole.
#[test]
fn path_tracer_exr_has_albedo_and_normal_layers() {
    let dir = scene_dir();
    let output = glint_in(
        dir.path(),
        &[
            "render",
            "scene.xml",
            "--integrator",
            "path",
            "--spp",
            "8",
            "-o",
            "out.exr",
            "-w",
            "9",
            "-h",
            "7",
        ],
    );
    assert_exit(&output, 0);
    assert!(stderr(&output).contains(" 8 rpp"), "{}", stderr(&output));
    let image = exr::prelude::read_all_flat_layers_from_file(dir.path().join("out.exr")).unwrap();
    let layer = &image.layer_data[0];
    let channel = |name: &str| -> Vec<f32> {
        let channel = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no channel {name}"));
        channel.sample_data.values_as_f32().collect()
    };
    let centre = 3 * 9 + 4;
    // The test scene's sphere is Lambertian (0, 0, 1).
    assert_eq!(channel("Denoising Albedo.B")[centre], 1.0);
    assert_eq!(channel("Denoising Albedo.R")[centre], 0.0);
    assert!(channel("Denoising Normal.Z")[centre] > 0.99);
    assert!(channel("Denoising Normal.X")[centre].abs() < 0.1);
    // Camera at the origin, sphere of radius 1 centred at z = -5.
    let depth = channel("Depth.Z")[centre];
    assert!((depth - 4.0).abs() < 0.05, "{depth}");
    assert_eq!(channel("Depth.Z")[0], 0.0, "a missed ray has depth 0");
    assert!(channel("B")[centre] > 0.0);
    assert_eq!(channel("R").len(), 9 * 7);
}

#[test]
fn normals_shader_shows_the_normal_facing_the_camera() {
    let dir = scene_dir();
    // An odd size puts the centre pixel's ray straight down -z onto the sphere's front pole,
    // where the normal is +z: colour (n + 1) / 2 = (0.5, 0.5, 1.0).
    for flag in ["--shader", "--integrator"] {
        let name = format!("normals{flag}.png");
        let image = render_png(dir.path(), &name, &["-w", "9", "-h", "9", flag, "normals"]);
        let [r, g, b] = image.get_pixel(4, 4).0;
        for (value, expected) in [(r, 127.5), (g, 127.5), (b, 255.0)] {
            assert!(
                (value as f32 - expected).abs() <= 1.0,
                "{flag}: {:?}",
                [r, g, b]
            );
        }
        assert_eq!(image.get_pixel(0, 0).0, [0, 0, 0]);
    }
}

#[test]
fn output_defaults_to_the_scene_name_in_the_current_directory() {
    let dir = scene_dir();
    let work = dir.path().join("work");
    std::fs::create_dir(&work).unwrap();
    let output = glint_in(&work, &["render", "../scene.xml", "-w", "4", "-h", "3"]);
    assert_exit(&output, 0);
    assert_eq!(read_png(&work.join("scene.png")).dimensions(), (4, 3));
}

#[test]
fn stderr_gets_only_the_closing_line_when_it_is_not_a_terminal() {
    let dir = scene_dir();
    let output = glint_in(
        dir.path(),
        &[
            "-i",
            "scene.xml",
            "-o",
            "o.png",
            "-w",
            "8",
            "-h",
            "4",
            "-r",
            "4",
            "-n",
            "2",
        ],
    );
    assert_exit(&output, 0);
    let text = stderr(&output);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1, "{text}");
    assert!(
        lines[0].starts_with("rendered 8x4, 4 rpp in ")
            && lines[0].contains(" rays/s, 2 threads -> o.png"),
        "{text}"
    );
    assert!(stdout(&output).is_empty());
}

#[test]
fn check_names_what_the_gpu_cannot_render() {
    // A Mitsuba scene with a medium: it loads (exit 0, no warning), and the note names the
    // medium, which --device gpu refuses; the course scene gets no note.
    let dir = scene_dir();
    std::fs::write(
        dir.path().join("fog.xml"),
        r#"<scene version="3.0.0">
  <medium type="heterogeneous" id="fog"/>
  <integrator type="volpath"/>
  <shape type="sphere"><ref name="interior" id="fog"/></shape>
</scene>"#,
    )
    .unwrap();
    let output = glint_in(dir.path(), &["check", "fog.xml", "scene.xml"]);
    assert_exit(&output, 0);
    let text = stderr(&output);
    assert!(
        text.contains("note: --device gpu cannot render medium 0 (heterogeneous;"),
        "{text}"
    );
    assert!(text.contains("fog.xml: ok (0 warnings)"), "{text}");
    assert_eq!(text.matches("note:").count(), 1, "{text}");
    let output = glint_in(
        dir.path(),
        &["render", "fog.xml", "--device", "gpu", "-o", "fog.png"],
    );
    assert_exit(&output, 2);
    // Without the GPU back end the refusal names the feature instead.
    if cfg!(feature = "gpu") {
        assert!(stderr(&output).contains("medium 0"), "{}", stderr(&output));
    }
}

#[test]
fn scene_warnings_are_printed_with_their_location_before_the_render() {
    let dir = scene_dir();
    let scene = SPHERE_XML.replace("<radius>1</radius>", "<radius>1</radius> <bogus>2</bogus>");
    std::fs::write(dir.path().join("warn.xml"), &scene).unwrap();
    let output = glint_in(
        dir.path(),
        &["-i", "warn.xml", "-o", "w.png", "-w", "4", "-h", "4"],
    );
    assert_exit(&output, 0);
    let text = stderr(&output);
    assert_eq!(text.matches("warning: ").count(), 1, "{text}");
    assert!(text.starts_with("warning: warn.xml:"), "{text}");
    let (line, _) = location(&text, "warn.xml").unwrap();
    assert_eq!(line, line_of(&scene, "<bogus>"), "{text}");
    assert!(text.contains("bogus"), "{text}");
    assert!(
        text.lines().last().unwrap().starts_with("rendered 4x4"),
        "{text}"
    );
}

// ---------------------------------------------------------------------------------------------
// Failures: exit status, location, and no image left behind

/// Finds `name:LINE:COL` in `text` and returns (LINE, COL).
fn location(text: &str, name: &str) -> Option<(u32, u32)> {
    let pattern = format!("{name}:");
    text.match_indices(&pattern).find_map(|(at, _)| {
        let rest = &text[at + pattern.len()..];
        let mut numbers = rest.splitn(3, ':');
        let line = numbers.next()?.parse().ok()?;
        let column = numbers.next()?.parse().ok()?;
        Some((line, column))
    })
}

/// Runs glint on `scene` (written as `file_name`) and checks that it fails with status 2, a
/// location in `file_name`, and no output image. Returns (stderr, location).
fn assert_bad_scene(file_name: &str, scene: &str) -> (String, (u32, u32)) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(file_name), scene).unwrap();
    for args in [
        &["-i", file_name, "-o", "out.png", "-w", "8", "-h", "8"][..],
        &["render", file_name, "-o", "out.exr", "-w", "8", "-h", "8"],
    ] {
        let output = glint_in(dir.path(), args);
        assert_exit(&output, 2);
        assert!(!dir.path().join("out.png").exists());
        assert!(!dir.path().join("out.exr").exists());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "only the scene may be left in the directory"
        );
    }
    let output = glint_in(dir.path(), &["-i", file_name, "-o", "out.png"]);
    let text = stderr(&output);
    assert!(text.starts_with("error: "), "{text}");
    let at = location(&text, file_name)
        .unwrap_or_else(|| panic!("no {file_name}:LINE:COL in stderr:\n{text}"));
    (text, at)
}

fn line_of(text: &str, needle: &str) -> u32 {
    text.lines().position(|line| line.contains(needle)).unwrap() as u32 + 1
}

#[test]
fn malformed_xml_fails_with_its_location() {
    let scene = SPHERE_XML.replace("<center>0 0 -5</center>", "<center>0 0 -5</centre>");
    let (text, (line, _)) = assert_bad_scene("scene.xml", &scene);
    assert_eq!(line, line_of(&scene, "</centre>"), "{text}");
}

#[test]
fn truncated_json_fails_with_its_location() {
    let scene = &SPHERE_JSON[..SPHERE_JSON.find("\"radius\"").unwrap()];
    let (text, (line, column)) = assert_bad_scene("scene.json", scene);
    // Where a parser blames a truncation varies (the end of the file, or the object left
    // open); it must be a real place in the file.
    let lines = scene.lines().count() as u32;
    assert!((1..=lines + 1).contains(&line) && column >= 1, "{text}");
}

#[test]
fn negative_radius_fails_with_its_location_and_source_line() {
    let scene = SPHERE_XML.replace("<radius>1</radius>", "<radius>-1</radius>");
    let (text, (line, _)) = assert_bad_scene("scene.xml", &scene);
    assert_eq!(line, line_of(&scene, "<radius>"), "{text}");
    assert!(
        text.contains("<radius>-1</radius>\n"),
        "source line missing:\n{text}"
    );
    assert!(text.contains('^'), "caret missing:\n{text}");
}

#[test]
fn a_word_where_a_vector_belongs_fails_with_its_location() {
    let scene = SPHERE_JSON.replace("\"center\": \"0 0 -5\"", "\"center\": \"0 zero -5\"");
    let (text, (line, _)) = assert_bad_scene("scene.json", &scene);
    assert_eq!(line, line_of(&scene, "0 zero -5"), "{text}");
}

#[test]
fn a_missing_obj_is_a_located_error_unless_allowed() {
    let dir = scene_dir();
    let scene = SPHERE_XML.replace(
        "</scene>",
        "  <instance name=\"ghost\" type=\"mesh\">\n    <file>objFiles/nowhere.obj</file>\n  </instance>\n  \
         <shape name=\"g\" type=\"instance\" id=\"ghost\">\n    <shader ref=\"blue\"/>\n  </shape>\n</scene>",
    );
    std::fs::write(dir.path().join("mesh.xml"), &scene).unwrap();
    let args = ["-i", "mesh.xml", "-o", "mesh.png", "-w", "8", "-h", "8"];
    let output = glint_in(dir.path(), &args);
    assert_exit(&output, 2);
    let text = stderr(&output);
    assert!(text.contains("error: "), "{text}");
    assert!(
        text.contains("cannot read mesh `objFiles/nowhere.obj`"),
        "{text}"
    );
    let (line, _) = location(&text, "mesh.xml").unwrap_or_else(|| panic!("no location:\n{text}"));
    assert_eq!(line, line_of(&scene, "nowhere.obj"), "{text}");
    assert!(!dir.path().join("mesh.png").exists());

    // The course renderer's way, asked for: a warning, and the render goes on.
    let output = glint_in(
        dir.path(),
        &[&args[..], &["--allow-missing-assets"]].concat(),
    );
    assert_exit(&output, 0);
    let text = stderr(&output);
    assert!(text.contains("warning: "), "{text}");
    assert!(text.contains("the mesh is omitted"), "{text}");
    assert!(dir.path().join("mesh.png").exists());
}

#[test]
fn failed_run_leaves_an_existing_output_unchanged() {
    let dir = scene_dir();
    let bad = SPHERE_XML.replace("<radius>1</radius>", "<radius>-1</radius>");
    std::fs::write(dir.path().join("bad.xml"), bad).unwrap();
    let previous = b"the previous image";
    std::fs::write(dir.path().join("out.png"), previous).unwrap();
    for args in [
        &["-i", "bad.xml", "-o", "out.png"][..],
        &["-i", "scene.xml", "-o", "out.png", "-w", "0"],
        &["-i", "missing.xml", "-o", "out.png"],
    ] {
        let output = glint_in(dir.path(), args);
        assert_exit(&output, 2);
        assert_eq!(std::fs::read(dir.path().join("out.png")).unwrap(), previous);
    }
}

#[test]
fn missing_scene_file_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let output = glint_in(dir.path(), &["render", "nope.xml", "-o", "o.png"]);
    assert_exit(&output, 2);
    assert!(stderr(&output).contains("nope.xml"), "{}", stderr(&output));
    assert!(!dir.path().join("o.png").exists());
}

#[test]
fn missing_input_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    for args in [&[][..], &["-o", "o.png", "-w", "10"]] {
        let output = glint_in(dir.path(), args);
        assert_exit(&output, 2);
        assert!(
            stderr(&output).contains("Need input file!"),
            "{}",
            stderr(&output)
        );
    }
}

#[test]
fn bad_arguments_exit_2_without_output() {
    let dir = scene_dir();
    for args in [
        &["-w", "0"][..],
        &["-h", "0"],
        &["-r", "0"],
        &["-n", "0"],
        &["-w", "ten"],
        &["--background", "1,2"],
        &["--background", "1,2,nan"],
        &["--aspect", "-1"],
        &["--shader", "phong"],
        &["--frobnicate"],
        &["-o", "out.jpg"],
    ] {
        let mut all = vec!["-i", "scene.xml"];
        if !args.contains(&"-o") {
            all.extend(["-o", "out.png"]);
        }
        all.extend_from_slice(args);
        let output = glint_in(dir.path(), &all);
        assert_exit(&output, 2);
        assert!(
            stderr(&output).contains("error"),
            "{args:?}: {}",
            stderr(&output)
        );
        assert!(!dir.path().join("out.png").exists(), "{args:?}");
        assert!(!dir.path().join("out.jpg").exists(), "{args:?}");
    }
}

#[test]
fn a_missing_output_folder_is_refused_before_rendering() {
    let dir = scene_dir();
    let output = glint_in(
        dir.path(),
        &[
            "-i",
            "scene.xml",
            "-o",
            "no/such/dir/out.png",
            "-w",
            "4",
            "-h",
            "4",
        ],
    );
    assert_exit(&output, 2);
    let text = stderr(&output);
    assert!(text.contains("out.png"), "{text}");
    assert!(text.contains("does not exist"), "{text}");
    assert!(!text.contains("rendered 4x4"), "{text}");
}

/// Ctrl-C during the render cancels it: status 130 and no image.
#[cfg(unix)]
#[test]
fn interrupt_cancels_without_writing() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;

    let dir = scene_dir();
    // Far too big to finish before the signal: 4000 x 4000 pixels, 64 samples each.
    let mut child = Command::new(GLINT)
        .args([
            "-i",
            "scene.xml",
            "-o",
            "big.png",
            "-w",
            "4000",
            "-h",
            "4000",
            "-r",
            "64",
            "-n",
            "1",
            "-v",
        ])
        .current_dir(dir.path())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // -v prints "rendering ..." once the Ctrl-C handler is installed and the scene is loaded.
    let mut reader = BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).unwrap() == 0 {
            panic!("glint ended before rendering:\n{seen}");
        }
        seen.push_str(&line);
        if line.starts_with("rendering ") {
            break;
        }
    }
    // The shell's own `kill`, so no procps package is needed.
    let status = Command::new("sh")
        .args(["-c", &format!("kill -INT {}", child.id())])
        .status()
        .expect("cannot run sh");
    assert!(status.success());
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut reader, &mut rest).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "stderr:\n{seen}{rest}");
    assert!(rest.contains("interrupted"), "{rest}");
    assert!(!dir.path().join("big.png").exists());
    let left: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .collect();
    assert_eq!(left.len(), 2, "only the scenes may be left: {left:?}");
}

// ---------------------------------------------------------------------------------------------
// `glint bench rays --walk`

/// Each walk `bench rays --walk` names runs (its JSON line says which, read back from the
/// tree, not from the flag) and finds the same hit distance for every ray: a bumpy 8x8 grid
/// of 128 triangles and 2000 rays from above, some of them missing it.
#[test]
fn bench_rays_walks_report_which_ran_and_agree() {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::new();
    for j in 0..9 {
        for i in 0..9 {
            let height = ((i * 7 + j * 3) % 5) as f32 * 0.1;
            obj.push_str(&format!("v {i} {height} {j}\n"));
        }
    }
    for j in 0..8 {
        for i in 0..8 {
            let v = 1 + i + 9 * j;
            obj.push_str(&format!(
                "f {v} {} {}\nf {} {} {}\n",
                v + 1,
                v + 10,
                v,
                v + 10,
                v + 9
            ));
        }
    }
    std::fs::write(dir.path().join("grid.obj"), obj).unwrap();
    let mut state = 0x2545_f491u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    let rays: Vec<glint_render::Ray> = (0..2000)
        .map(|_| {
            let origin =
                glint_render::Vec3::new(next() * 10.0 - 1.0, 2.0 + next(), next() * 10.0 - 1.0);
            let direction = glint_render::Vec3::new(next() - 0.5, -1.0, next() - 0.5);
            glint_render::Ray::new(origin, direction)
        })
        .collect();
    glint_io::write_rays(&dir.path().join("grid.rays"), &rays).unwrap();
    #[cfg(target_arch = "x86_64")]
    let (avx2, evex) = (
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma"),
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl"),
    );
    #[cfg(not(target_arch = "x86_64"))]
    let (avx2, evex) = (false, false);
    let auto = match (avx2, evex) {
        (true, true) => "evex",
        (true, false) => "avx2",
        _ => "scalar",
    };
    let mut distances = Vec::new();
    for (walk, expected) in [("auto", auto), ("avx2", "avx2"), ("scalar", "scalar")] {
        let t = format!("{walk}.t");
        let args = [
            "bench",
            "rays",
            "--mesh",
            "grid.obj",
            "--rays",
            "grid.rays",
            "--repeat",
            "1",
            "--walk",
            walk,
            "--write-t",
            &t,
        ];
        let output = glint_in(dir.path(), &args);
        if walk == "avx2" && !avx2 {
            assert_exit(&output, 1);
            assert!(stderr(&output).contains("no AVX2"), "{}", stderr(&output));
            continue;
        }
        assert_exit(&output, 0);
        let line = stdout(&output);
        assert!(
            line.contains(&format!("\"walk\": \"{expected}\"")),
            "--walk {walk}: {line}"
        );
        distances.push(std::fs::read(dir.path().join(&t)).unwrap());
    }
    let t: Vec<f32> = distances[0]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let hits = t.iter().filter(|t| t.is_finite()).count();
    assert!(
        hits > 500 && hits < 2000,
        "{hits} of 2000 rays hit the grid"
    );
    for other in &distances[1..] {
        assert!(
            other == &distances[0],
            "the walks found different distances"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Mitsuba scenes bring their own render settings

/// A diffuse square lit by a constant environment, with a 12x8 film, 4 samples, and the path
/// tracer at Mitsuba's max_depth 3 (two scattering events in Glint's count).
const MITSUBA_XML: &str = r#"<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="8"/></film>
  </sensor>
  <emitter type="constant"/>
  <shape type="rectangle"><bsdf type="conductor"/></shape>
</scene>
"#;

#[test]
fn a_mitsuba_scene_renders_with_its_own_settings_unless_flags_say_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.xml"), MITSUBA_XML).unwrap();
    let result = glint_in(dir.path(), &["render", "m.xml", "-o", "out.exr", "-v"]);
    assert_exit(&result, 0);
    let log = stderr(&result);
    assert!(
        log.contains("rendering 12x8, 4 samples per pixel, depth 2,")
            && log.contains("path integrator"),
        "{log}"
    );
    let image = image::open(dir.path().join("out.exr")).unwrap();
    assert_eq!(image::GenericImageView::dimensions(&image), (12, 8));
    // Every flag still wins over the scene.
    let result = glint_in(
        dir.path(),
        &[
            "render",
            "m.xml",
            "-o",
            "flags.exr",
            "-v",
            "-w",
            "6",
            "-h",
            "5",
            "--spp",
            "9",
            "-k",
            "7",
            "--integrator",
            "normals",
        ],
    );
    assert_exit(&result, 0);
    let log = stderr(&result);
    assert!(
        log.contains("rendering 6x5, 9 samples per pixel, depth 7,")
            && log.contains("normals integrator"),
        "{log}"
    );
    let image = image::open(dir.path().join("flags.exr")).unwrap();
    assert_eq!(image::GenericImageView::dimensions(&image), (6, 5));
    // `direct` is the path tracer with one scattering event.
    let direct = MITSUBA_XML.replace(
        r#"<integrator type="path"><integer name="max_depth" value="3"/></integrator>"#,
        r#"<integrator type="direct"/>"#,
    );
    std::fs::write(dir.path().join("d.xml"), direct).unwrap();
    let result = glint_in(dir.path(), &["render", "d.xml", "-o", "d.exr", "-v"]);
    assert_exit(&result, 0);
    let log = stderr(&result);
    assert!(
        log.contains("depth 1,") && log.contains("path integrator"),
        "{log}"
    );
}

#[cfg(feature = "gpu")]
#[test]
fn the_gpu_renders_mitsubas_materials_as_the_cpu_does() {
    // Mitsuba's default conductor on a rectangle under a constant white sky: the middle of
    // the image is the same constant on either device, and the edges, where the filter
    // mixes sky and metal at random, agree on average (to 1e-4 at 1024 spp).
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.xml"), MITSUBA_XML).unwrap();
    let result = glint_in(
        dir.path(),
        &[
            "render", "m.xml", "-o", "g.exr", "--device", "gpu", "--spp", "256",
        ],
    );
    let log = stderr(&result);
    if result.status.code() == Some(1) && log.contains("no GPU adapter") {
        assert!(
            std::env::var_os("CI").is_none_or(|v| v.is_empty() || v == "0"),
            "CI is set but there is no Vulkan adapter: {log}"
        );
        println!("SKIPPED (no Vulkan adapter): {log}");
        return;
    }
    assert_exit(&result, 0);
    assert_exit(
        &glint_in(
            dir.path(),
            &["render", "m.xml", "-o", "c.exr", "--spp", "256"],
        ),
        0,
    );
    let read = |name: &str| image::open(dir.path().join(name)).unwrap().into_rgb32f();
    let (gpu, cpu) = (read("g.exr"), read("c.exr"));
    assert_eq!(gpu.dimensions(), (12, 8));
    for (x, y) in [(5, 3), (6, 3), (5, 4), (6, 4)] {
        let (g, c) = (gpu.get_pixel(x, y).0, cpu.get_pixel(x, y).0);
        for k in 0..3 {
            assert!(
                (g[k] - c[k]).abs() < 1e-4,
                "({x}, {y}): GPU {g:?}, CPU {c:?}"
            );
        }
        // The metal, not the sky.
        assert!(c[2] < 0.99, "({x}, {y}): CPU {c:?}");
    }
    let mean = |image: &image::Rgb32FImage| {
        image.pixels().map(|p| p.0.iter().sum::<f32>()).sum::<f32>() / (3.0 * 96.0)
    };
    let (g, c) = (mean(&gpu), mean(&cpu));
    assert!((g - c).abs() < 0.01 * c, "image means: GPU {g}, CPU {c}");
}
