//! Hostile input, through the real `glint` binary: the nine failures of issue 9 and the cases
//! a `bad_inputs` suite holds. Every case checks the exit status, where the message points
//! (`file:line:col`), and that nothing was written: no image, no temporary file.

mod common;

use common::png_declaring;
use std::path::PathBuf;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const GLINT: &str = env!("CARGO_BIN_EXE_glint");

/// One sphere in front of a camera, lit by a point light; `{SHADER}`, `{SHAPES}` and
/// `{EXTRA}` are replaced by each case.
const BASE_XML: &str = r#"<?xml version="1.0" encoding="UTF-8" ?>
<scene bgColor="0.2 0.2 0.2">
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

const BASE_JSON: &str = r#"{
  "scene": {
    "camera": [{ "_type": "perspective", "position": "0 0 0", "viewDir": "0 0 -1",
                 "focalLength": 1.0, "imagePlaneWidth": 0.5 }],
    "light": [{ "_type": "point", "position": "0 10 0", "intensity": "1 1 1" }],
    "shader": [{ "_name": "blue", "_type": "Lambertian", "diffuse": "0 0 1" }],
    "shape": [{ "_type": "sphere", "shader": { "_ref": "blue" }, "center": "0 0 -5",
                "radius": 1 }]
  }
}
"#;

/// A scene directory: the files written into it, and glint run there.
struct Case {
    dir: tempfile::TempDir,
    inputs: Vec<String>,
}

impl Case {
    fn new() -> Case {
        Case {
            dir: tempfile::tempdir().unwrap(),
            inputs: Vec::new(),
        }
    }

    fn file(mut self, name: &str, contents: impl AsRef<[u8]>) -> Case {
        let path = self.dir.path().join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(path, contents).unwrap();
        self.inputs.push(name.split('/').next().unwrap().to_owned());
        self
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn run(&self, args: &[&str]) -> Output {
        Command::new(GLINT)
            .args(args)
            .current_dir(self.dir.path())
            .output()
            .expect("cannot run glint")
    }

    /// Renders `scene` to out.png (8 x 8) with `extra` arguments.
    fn render(&self, scene: &str, extra: &[&str]) -> Output {
        let mut args = vec!["render", scene, "-o", "out.png", "-w", "8", "-h", "8"];
        args.extend_from_slice(extra);
        self.run(&args)
    }

    /// Nothing but the inputs is in the directory: no image, no temporary file.
    #[track_caller]
    fn assert_nothing_written(&self) {
        let mut left: Vec<String> = std::fs::read_dir(self.dir.path())
            .unwrap()
            .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        let mut inputs = self.inputs.clone();
        inputs.sort();
        inputs.dedup();
        assert_eq!(left, inputs, "files other than the inputs were left");
    }

    /// `scene` fails with status 2, a message at `scene:LINE:COL` on the line holding
    /// `needle`, and writes nothing. Returns stderr.
    #[track_caller]
    fn assert_refused_at(&self, scene: &str, extra: &[&str], needle: &str) -> String {
        let output = self.render(scene, extra);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "stderr:\n{text}");
        self.assert_nothing_written();
        let (line, column) = location(&text, scene)
            .unwrap_or_else(|| panic!("no {scene}:LINE:COL in stderr:\n{text}"));
        let contents = std::fs::read(self.path(scene)).unwrap();
        let contents = String::from_utf8_lossy(&contents);
        assert!(column >= 1, "{text}");
        if !needle.is_empty() {
            assert_eq!(line, line_of(&contents, needle), "{text}");
        }
        text
    }
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The first `name:LINE:COL` in `text`.
fn location(text: &str, name: &str) -> Option<(u32, u32)> {
    let pattern = format!("{name}:");
    text.match_indices(&pattern).find_map(|(at, _)| {
        let mut numbers = text[at + pattern.len()..].splitn(3, ':');
        let line = numbers.next()?.parse().ok()?;
        let column = numbers.next()?.parse().ok()?;
        Some((line, column))
    })
}

#[track_caller]
fn line_of(text: &str, needle: &str) -> u32 {
    text.lines()
        .position(|line| line.contains(needle))
        .unwrap_or_else(|| panic!("`{needle}` is not in the scene")) as u32
        + 1
}

fn xml_with(from: &str, to: &str) -> String {
    assert!(BASE_XML.contains(from), "{from}");
    BASE_XML.replacen(from, to, 1)
}

fn json_with(from: &str, to: &str) -> String {
    assert!(BASE_JSON.contains(from), "{from}");
    BASE_JSON.replacen(from, to, 1)
}

/// A scene placing the mesh `file` as a shape.
fn mesh_scene(file: &str) -> String {
    xml_with(
        "</scene>",
        &format!(
            "  <shape name=\"m\" type=\"mesh\">\n    <file>{file}</file>\n    \
             <shader ref=\"blue\"/>\n  </shape>\n</scene>"
        ),
    )
}

/// A PNG that declares `width` x `height` but holds one pixel's data: a header must be enough
/// to refuse it.
fn textured_scene(count: usize) -> String {
    let mut extra = String::new();
    for index in 0..count {
        extra.push_str(&format!(
            "  <texture name=\"t{index}\" type=\"image\">\n    <sourcefile>big.png</sourcefile>\n  \
             </texture>\n  <shader name=\"s{index}\" type=\"Lambertian\">\n    \
             <diffuse tex=\"t{index}\">1 1 1</diffuse>\n  </shader>\n"
        ));
    }
    xml_with(
        "<shader name=\"blue\"",
        &format!("{extra}  <shader name=\"blue\""),
    )
    .replace("<shader ref=\"blue\" />", "<shader ref=\"s0\" />")
}

// ---------------------------------------------------------------------------------------------
// The nine failures of issue 9

/// Issue case 1: Thousands of warnings on one long line: a capped, quick report, not gigabytes.
#[test]
fn issue_1_thousands_of_warnings_on_one_line_are_capped() {
    let unused: String = (0..8000)
        .map(|index| format!("\"unused{index}\": \"{}\", ", "x".repeat(20)))
        .collect();
    let scene = format!(
        "{{\"scene\": {{{unused}\"camera\": [{{\"_type\": \"perspective\", \"position\": \"0 0 0\", \
         \"viewDir\": \"0 0 -1\", \"focalLength\": 1, \"imagePlaneWidth\": 0.5}}]}}}}"
    );
    assert!(scene.len() > 250_000 && !scene.contains('\n'));
    let case = Case::new().file("long.json", &scene);
    let start = Instant::now();
    let output = case.render("long.json", &[]);
    let elapsed = start.elapsed();
    let text = stderr(&output);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}",
        &text[..text.len().min(2000)]
    );
    assert_eq!(text.matches("is not used in the scene").count(), 20);
    assert_eq!(text.matches("warning: ").count(), 21);
    assert!(text.len() < 20_000, "{} bytes of warnings", text.len());
    assert!(elapsed < Duration::from_secs(60), "{elapsed:?}");
    // `glint check` lists every one, each with an excerpt of the line, not the line.
    let output = case.run(&["check", "long.json"]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(0));
    assert_eq!(text.matches("is not used in the scene").count(), 8000);
    let total = text.matches("warning: ").count();
    let rendered = stderr(&case.render("long.json", &[]));
    assert!(
        rendered.contains(&format!("{} more warnings not shown", total - 20)),
        "{}",
        &rendered[rendered.len().saturating_sub(300)..]
    );
    assert!(text.len() < 8000 * 400, "{} bytes", text.len());
}

/// Issue case 2: A scene or a mesh that never ends (/dev/zero) is cut off at the size limit.
#[cfg(unix)]
#[test]
fn issue_2_endless_files_are_refused_at_the_size_limit() {
    let case = Case::new();
    let output = case.run(&[
        "render",
        "/dev/zero",
        "-o",
        "out.png",
        "--max-file-size",
        "4M",
    ]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(text.contains("/dev/zero"), "{text}");
    assert!(text.contains("larger than the limit of 4 MiB"), "{text}");
    case.assert_nothing_written();

    // A mesh that is a link to /dev/zero.
    let mut case = Case::new().file("zero.xml", mesh_scene("endless.obj"));
    std::os::unix::fs::symlink("/dev/zero", case.path("endless.obj")).unwrap();
    case.inputs.push("endless.obj".into());
    let text = case.assert_refused_at("zero.xml", &["--max-file-size", "4M"], "endless.obj");
    assert!(text.contains("is refused"), "{text}");
    assert!(text.contains("--max-file-size"), "{text}");
}

/// Issue case 3: An image too big for memory is refused before anything is loaded.
#[test]
fn issue_3_a_huge_image_is_refused_up_front() {
    let case = Case::new().file("scene.xml", BASE_XML);
    let start = Instant::now();
    let output = case.run(&[
        "render",
        "scene.xml",
        "-o",
        "out.png",
        "-w",
        "65535",
        "-h",
        "65535",
    ]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(text.contains("--max-memory"), "{text}");
    assert!(start.elapsed() < Duration::from_secs(20));
    case.assert_nothing_written();
    // A modest image over a small budget is refused too.
    let output = case.run(&[
        "render",
        "scene.xml",
        "-o",
        "out.png",
        "-w",
        "1000",
        "-h",
        "1000",
        "--max-memory",
        "1M",
    ]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    case.assert_nothing_written();
}

/// Issue case 4: A small PNG declaring 12000 x 12000 is refused from its header; entries naming the
/// same file share it.
#[test]
fn issue_4_textures_declaring_huge_sizes_are_refused_from_their_header() {
    let case = Case::new()
        .file("big.png", png_declaring(12_000, 12_000))
        .file("tex.xml", textured_scene(3));
    let text = case.assert_refused_at("tex.xml", &[], "<sourcefile>big.png");
    assert!(text.contains("12000 x 12000"), "{text}");
    assert!(text.contains("--max-texture-size"), "{text}");
    // Allowed by size, the memory budget still refuses it before decoding.
    let text = case.assert_refused_at(
        "tex.xml",
        &["--max-texture-size", "20000", "--max-memory", "1G"],
        "<sourcefile>big.png",
    );
    assert!(text.contains("--max-memory"), "{text}");
}

/// Issue case 5: Colours that overflow and sizes too large for f32 are located errors; negative colours
/// are located warnings; no pixel is ever NaN.
#[test]
fn issue_5_overflowing_numbers_are_refused_and_negative_colours_warned() {
    for (scene, needle) in [
        (
            xml_with("<diffuse>0 0 1</diffuse>", "<diffuse>-1e30 0 1</diffuse>"),
            "<diffuse>",
        ),
        (
            xml_with("bgColor=\"0.2 0.2 0.2\"", "bgColor=\"-1e20 0 0\""),
            "bgColor",
        ),
        (
            xml_with(
                "<intensity>1.0 1.0 1.0</intensity>",
                "<intensity>1e9 1 1</intensity>",
            ),
            "<intensity>",
        ),
        (
            xml_with("<radius>1</radius>", "<radius>1e20</radius>"),
            "<radius>",
        ),
    ] {
        let case = Case::new().file("bad.xml", &scene);
        case.assert_refused_at("bad.xml", &[], needle);
    }
    let scene = xml_with("<diffuse>0 0 1</diffuse>", "<diffuse>-0.5 0 1</diffuse>");
    let case = Case::new().file("neg.xml", &scene);
    let output = case.render("neg.xml", &[]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert_eq!(
        location(&text, "neg.xml").unwrap().0,
        line_of(&scene, "<diffuse>")
    );
    assert!(text.contains("negative component"), "{text}");
    std::fs::remove_file(case.path("out.png")).unwrap();
    case.assert_refused_at("neg.xml", &["--strict"], "<diffuse>");
}

/// Issue case 6: JSON: comments and trailing commas are accepted; unquoted keys and single quotes not.
#[test]
fn issue_6_json_extensions_beyond_comments_and_trailing_commas_are_refused() {
    let lenient = json_with("\"scene\": {", "// a comment\n  \"scene\": { /* here */")
        .replace("\"radius\": 1 }]", "\"radius\": 1, }],");
    let case = Case::new().file("ok.json", &lenient);
    let output = case.render("ok.json", &[]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));

    let unquoted = json_with("\"light\":", "light:");
    let case = Case::new().file("unquoted.json", &unquoted);
    case.assert_refused_at("unquoted.json", &[], "light:");
    let single = json_with("\"0 0 1\"", "'0 0 1'");
    let case = Case::new().file("single.json", &single);
    let text = case.assert_refused_at("single.json", &[], "'0 0 1'");
    assert!(text.contains("double quotes"), "{text}");
}

/// Issue case 7: Temporary files of runs killed before their rename are removed by the next run; SIGTERM
/// is handled like Ctrl-C.
#[cfg(target_os = "linux")]
#[test]
fn issue_7_stale_temporary_files_are_removed_and_sigterm_cancels() {
    let case = Case::new().file("scene.xml", BASE_XML);
    // A process id above Linux's pid_max cannot be alive.
    let stale = case.path(".glint-4999999-abcdef.partial");
    std::fs::write(&stale, b"half an image").unwrap();
    let old = std::time::SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000_000);
    std::fs::File::options()
        .write(true)
        .open(&stale)
        .unwrap()
        .set_modified(old)
        .unwrap();
    // A recent file of a live process is left alone.
    let live = case.path(format!(".glint-{}-abcdef.partial", std::process::id()).as_str());
    std::fs::write(&live, b"being written").unwrap();
    let output = case.render("scene.xml", &[]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(!stale.exists(), "{text}");
    assert!(live.exists());
    assert!(text.contains("removed 1 temporary file"), "{text}");
    std::fs::remove_file(&live).unwrap();
    std::fs::remove_file(case.path("out.png")).unwrap();

    // SIGTERM while rendering: exit 130, nothing written.
    use std::io::{BufRead, BufReader};
    let mut child = Command::new(GLINT)
        .args([
            "render",
            "scene.xml",
            "-o",
            "out.png",
            "-w",
            "3000",
            "-h",
            "3000",
            "-r",
            "64",
            "-n",
            "1",
            "-v",
        ])
        .current_dir(case.dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut reader = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    while !line.starts_with("rendering ") {
        line.clear();
        assert!(
            reader.read_line(&mut line).unwrap() > 0,
            "glint ended early"
        );
    }
    let status = Command::new("sh")
        .args(["-c", &format!("kill -TERM {}", child.id())])
        .status()
        .unwrap();
    assert!(status.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    case.assert_nothing_written();
}

/// Issue case 8: A missing output folder, or an unknown extension, is refused before rendering.
#[test]
fn issue_8_the_output_is_checked_before_rendering() {
    let case = Case::new().file("scene.xml", BASE_XML);
    let start = Instant::now();
    let output = case.run(&[
        "render",
        "scene.xml",
        "-o",
        "missing/out.png",
        "-w",
        "4000",
        "-h",
        "4000",
        "-r",
        "64",
    ]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(text.contains("does not exist"), "{text}");
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "it rendered first"
    );
    let output = case.run(&["render", "scene.xml", "-o", "out.tiff"]);
    assert_eq!(output.status.code(), Some(2));
    case.assert_nothing_written();
}

/// Issue case 9: --strict makes warnings fatal; a misspelled only camera keeps its hint; `glint check`.
#[test]
fn issue_9_strict_mode_check_and_the_misspelled_camera() {
    let misspelled = xml_with("<camera name", "<camra name").replace("</camera>", "</camra>");
    let case = Case::new().file("camra.xml", &misspelled);
    let text = case.assert_refused_at("camra.xml", &[], "<camra");
    assert!(text.contains("did you mean `camera`?"), "{text}");

    let scene = xml_with("type=\"Lambertian\"", "type=\"Lambertain\"").replace(
        "<radius>1</radius>",
        "<radius>1</radius>\n    <radios>2</radios>",
    );
    let case = Case::new().file("typos.xml", &scene);
    let output = case.render("typos.xml", &[]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    std::fs::remove_file(case.path("out.png")).unwrap();
    let text = case.assert_refused_at("typos.xml", &["--strict"], "Lambertain");
    assert!(text.contains("error: typos.xml:"), "{text}");
    assert!(text.contains("with --strict"), "{text}");

    let ok = Case::new()
        .file("good.xml", BASE_XML)
        .file("typos.xml", &scene);
    let output = ok.run(&["check", "good.xml", "typos.xml"]);
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    assert!(text.contains("good.xml: ok (0 warnings)"), "{text}");
    assert!(text.contains("typos.xml: ok (2 warnings)"), "{text}");
    assert!(text.contains("radios"), "{text}");
    let output = ok.run(&["check", "--strict", "good.xml", "typos.xml"]);
    assert_eq!(output.status.code(), Some(2));
    let output = ok.run(&["check", "good.xml", "missing.xml"]);
    assert_eq!(output.status.code(), Some(2));
    ok.assert_nothing_written();
}

// ---------------------------------------------------------------------------------------------
// bad_inputs: each refused with status 2 at its place, nothing written

/// (file name, contents, the text on the line the error must point at; empty: line 1 or the
/// end, wherever the parser blames).
fn bad_inputs() -> Vec<(&'static str, Vec<u8>, &'static str, Vec<&'static str>)> {
    let deep_xml = format!(
        "<scene>{}{}</scene>",
        "<a>".repeat(5000),
        "</a>".repeat(5000)
    );
    let deep_json = format!("{{\"scene\": {}{}}}", "[".repeat(5000), "]".repeat(5000));
    let entity_bomb = "<?xml version=\"1.0\"?>\n<!DOCTYPE s [\n<!ENTITY a \"aaaaaaaaaa\">\n\
        <!ENTITY b \"&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;\">\n<!ENTITY c \"&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;\">\n\
        <!ENTITY d \"&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;\">\n<!ENTITY e \"&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;\">\n\
        <!ENTITY f \"&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;\">\n<!ENTITY g \"&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;\">\n]>\n\
        <scene>&g;</scene>\n";
    let mut garbage = vec![0u8; 512];
    let mut state = 12345u32;
    for byte in &mut garbage {
        state = state.wrapping_mul(1_103_515_245).wrapping_add(12_345);
        *byte = (state >> 16) as u8;
    }
    garbage[0] = 0xff;
    vec![
        ("empty.xml", Vec::new(), "", vec![]),
        ("empty.json", Vec::new(), "", vec![]),
        ("blank.json", b"  \n\n  ".to_vec(), "", vec![]),
        ("garbage.xml", garbage, "", vec![]),
        ("root.xml", xml_with("<scene bgColor", "<sceen bgColor").replace("</scene>", "</sceen>").into(), "<sceen", vec![]),
        ("root.json", b"[1, 2, 3]".to_vec(), "", vec![]),
        ("number.json", json_with("\"camera\": [{", "\"camera\": 5, \"x\": [{").into(), "\"camera\": 5", vec![]),
        ("deep.xml", deep_xml.into(), "", vec![]),
        ("deep.json", deep_json.into(), "", vec![]),
        ("bomb.xml", entity_bomb.as_bytes().to_vec(), "", vec![]),
        ("truncated.xml", BASE_XML.as_bytes()[..BASE_XML.find("<radius>").unwrap()].to_vec(), "", vec![]),
        ("duplicate.xml", xml_with("<shape name=\"sphere1\"", "<shape name=\"a\" name=\"b\"").into(), "name=\"a\" name=\"b\"", vec![]),
        ("view.xml", xml_with("<viewDir>0 0 -1</viewDir>", "<viewDir>0 0 0</viewDir>").into(), "<viewDir>", vec![]),
        ("plane.xml", xml_with("<imagePlaneWidth>0.5<", "<imagePlaneWidth>0<").into(), "<imagePlaneWidth>", vec![]),
        ("focal.xml", xml_with("<focalLength>1.0<", "<focalLength>-1<").into(), "<focalLength>", vec![]),
        ("area.xml", xml_with("<light type=\"point\">", "<light type=\"area\">\n    <width>0</width>\n    <length>1</length>\n    <normal>0 -1 0</normal>").into(), "<width>0", vec![]),
        ("nan.xml", xml_with("<center>0 0 -5</center>", "<center>nan 0 -5</center>").into(), "<center>", vec![]),
        ("vertex.xml", xml_with("</scene>", "  <shape type=\"triangle\">\n    <v0>0 0 -5</v0>\n    <v1>1 0 -5</v1>\n    <v2>0 inf -5</v2>\n  </shape>\n</scene>").into(), "<v2>", vec![]),
        ("huge.xml", xml_with("<radius>1</radius>", "<radius>1e40</radius>").into(), "<radius>", vec![]),
        ("far.xml", xml_with("<center>0 0 -5</center>", "<center>0 0 -5e8</center>").into(), "<center>", vec![]),
        ("focal-huge.xml", xml_with("<focalLength>1.0<", "<focalLength>1e30<").into(), "<focalLength>", vec![]),
        ("radius.xml", xml_with("<radius>1</radius>", "<radius>-1</radius>").into(), "<radius>", vec![]),
        ("scale.xml", xml_with("</scene>", "  <instance name=\"i\" type=\"sphere\">\n    <shader ref=\"blue\"/>\n  </instance>\n  <shape type=\"instance\" id=\"i\">\n    <transform>\n      <scale>0 1 1</scale>\n    </transform>\n  </shape>\n</scene>").into(), "<scale>", vec![]),
        ("index.xml", xml_with("<shader name=\"blue\" type=\"Lambertian\">", "<shader name=\"blue\" type=\"Dielectric\">\n    <refractiveIndex>0</refractiveIndex>").into(), "<refractiveIndex>", vec![]),
        ("phong.xml", xml_with("<shader name=\"blue\" type=\"Lambertian\">", "<shader name=\"blue\" type=\"BlinnPhong\">\n    <phongExp>-3</phongExp>").into(), "<phongExp>", vec![]),
        ("word.json", json_with("\"radius\": 1", "\"radius\": \"one\"").into(), "\"one\"", vec![]),
        ("faces.xml", mesh_scene("faces.obj").into(), "faces.obj", vec!["--max-triangles", "1000"]),
        // Dangling references, a self-referencing instance, an unknown type, broken OBJ
        // files: warnings that --strict makes errors.
        ("dangling.xml", xml_with("<shader ref=\"blue\" />", "<shader ref=\"bleu\" />").into(), "ref=\"bleu\"", vec!["--strict"]),
        ("self.xml", xml_with("</scene>", "  <instance name=\"me\" type=\"instance\" id=\"me\"/>\n  <shape type=\"instance\" id=\"me\"/>\n</scene>").into(), "name=\"me\"", vec!["--strict"]),
        ("unknown.xml", xml_with("type=\"sphere\"", "type=\"spehre\"").into(), "spehre", vec!["--strict"]),
        ("nanmesh.xml", mesh_scene("nan.obj").into(), "nan.obj", vec!["--strict"]),
        ("range.xml", mesh_scene("range.obj").into(), "range.obj", vec!["--strict"]),
        ("notex.xml", xml_with("<diffuse>0 0 1</diffuse>", "<diffuse tex=\"t\">0 0 1</diffuse>").replace("<shader name=\"blue\"", "<texture name=\"t\" type=\"image\">\n    <sourcefile>gone.png</sourcefile>\n  </texture>\n  <shader name=\"blue\"").into(), "gone.png", vec![]),
    ]
}

#[test]
fn bad_inputs_are_refused_at_their_place_without_writing() {
    let mut checked = 0;
    for (name, contents, needle, extra) in bad_inputs() {
        let mut huge_face = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
        for _ in 0..2000 {
            huge_face.push_str(" 1 2 3");
        }
        huge_face.push('\n');
        let case = Case::new()
            .file(name, &contents)
            .file("faces.obj", huge_face)
            .file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
            .file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n");
        let output = case.render(name, &extra);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{name}: {text}");
        case.assert_nothing_written();
        let (line, column) = location(&text, name)
            .unwrap_or_else(|| panic!("{name}: no {name}:LINE:COL in stderr:\n{text}"));
        let shown = String::from_utf8_lossy(&contents);
        let lines = shown.lines().count().max(1) as u32;
        assert!(
            line >= 1 && line <= lines + 1 && column >= 1,
            "{name}: {text}"
        );
        if !needle.is_empty() {
            assert_eq!(line, line_of(&shown, needle), "{name}: {text}");
        }
        checked += 1;
    }
    assert!(checked >= 33, "{checked}");
}

#[test]
fn a_folder_or_a_missing_file_as_the_scene_exits_2() {
    let case = Case::new().file("sub/scene.xml", BASE_XML);
    for scene in ["sub", "missing.xml"] {
        let output = case.render(scene, &[]);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{text}");
        assert!(text.contains(scene), "{text}");
        case.assert_nothing_written();
    }
}

/// Output written by earlier runs stays until a whole new image replaces it.
#[test]
fn a_refused_scene_leaves_the_previous_image() {
    let case = Case::new()
        .file(
            "bad.xml",
            xml_with("<radius>1</radius>", "<radius>1e20</radius>"),
        )
        .file("out.png", b"previous");
    let output = case.render("bad.xml", &[]);
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(std::fs::read(case.path("out.png")).unwrap(), b"previous");
    case.assert_nothing_written();
}

/// A Mitsuba 3 scene: a sphere under a constant environment; `</scene>` is where each case adds
/// its part.
const MITSUBA_XML: &str = r#"<scene version="3.0.0">
  <sensor type="perspective">
    <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
  </sensor>
  <emitter type="constant"/>
  <shape type="sphere"/>
</scene>
"#;

fn mitsuba_with(part: &str) -> String {
    MITSUBA_XML.replacen("</scene>", &format!("{part}\n</scene>"), 1)
}

/// Mitsuba scenes that lie, loop or name what is not there, each with its scene text, the
/// line the error must point at (empty: any line of the file named) and what the message must
/// say.
fn bad_mitsuba_scenes() -> Vec<(&'static str, String, &'static str, &'static str)> {
    vec![
        ("cycle.xml", mitsuba_with("  <include filename=\"other.xml\"/>"), "", "includes itself"),
        ("self.xml", mitsuba_with("  <include filename=\"self.xml\"/>"), "<include", "includes itself"),
        ("define.xml", mitsuba_with("  <default name=\"a\" value=\"$a\"/>"), "name=\"a\"", "$a"),
        ("missing.xml", mitsuba_with("  <shape type=\"sphere\"><ref id=\"nothere\"/></shape>"), "nothere", "nothere"),
        ("kind.xml", mitsuba_with("  <texture type=\"checkerboard\" id=\"t\"/>\n  <shape type=\"sphere\"><ref id=\"t\"/></shape>"), "<ref id=\"t\"", "texture"),
        ("vol.xml", mitsuba_with("  <shape type=\"sdfgrid\"><string name=\"filename\" value=\"lying.vol\"/></shape>"), "sdfgrid", "lying.vol"),
        ("zlib.xml", mitsuba_with("  <shape type=\"serialized\"><string name=\"filename\" value=\"corrupt.serialized\"/></shape>"), "serialized", "corrupt.serialized"),
        ("plugin.xml", mitsuba_with("  <shape type=\"sphere\"><bsdf type=\"difuse\"/></shape>"), "difuse", "difuse"),
        ("type.xml", mitsuba_with("  <shape type=\"sphere\"><string name=\"radius\" value=\"1\"/></shape>"), "name=\"radius\"", "radius"),
        ("cutvol.xml", mitsuba_with("  <medium type=\"heterogeneous\" id=\"m\">\n    <volume type=\"gridvolume\" name=\"sigma_t\">\n      <string name=\"filename\" value=\"cut.vol\"/>\n    </volume>\n  </medium>"), "cut.vol", "cut.vol"),
        ("medprop.xml", mitsuba_with("  <medium type=\"homogeneous\" id=\"m\">\n    <float name=\"sigma_s\" value=\"1\"/>\n  </medium>"), "sigma_s", "sigma_s"),
        ("phase.xml", mitsuba_with("  <medium type=\"homogeneous\" id=\"m\">\n    <phase type=\"hg\">\n      <float name=\"g\" value=\"1.5\"/>\n    </phase>\n  </medium>"), "name=\"g\"", "(-1, 1)"),
        ("homogrid.xml", mitsuba_with("  <medium type=\"homogeneous\" id=\"m\">\n    <volume type=\"gridvolume\" name=\"sigma_t\">\n      <string name=\"filename\" value=\"grid.vol\"/>\n    </volume>\n  </medium>"), "<volume", "homogeneous"),
        ("voltype.xml", mitsuba_with("  <medium type=\"heterogeneous\" id=\"m\">\n    <volume type=\"voxels\" name=\"sigma_t\"/>\n  </medium>"), "voxels", "voxels"),
        ("nomedium.xml", mitsuba_with("  <shape type=\"sphere\">\n    <ref id=\"fog\" name=\"interior\"/>\n  </shape>"), "fog", "fog"),
    ]
}

#[test]
fn hostile_mitsuba_scenes_are_located_errors_in_bounded_memory() {
    // A .vol header that claims 4096³ samples over 64 bytes of data.
    let mut lying = b"VOL\x03".to_vec();
    for value in [1i32, 4096, 4096, 4096, 1] {
        lying.extend(value.to_le_bytes());
    }
    lying.extend([0u8; 24 + 64]);
    // A .serialized header, then a zlib header followed by bytes that are no deflate stream,
    // and a dictionary naming one shape.
    let mut corrupt = vec![0x1C, 0x04, 4, 0, 0x78, 0x9C];
    corrupt.extend([0xFFu8; 64]);
    corrupt.extend(0u64.to_le_bytes());
    corrupt.extend(1u32.to_le_bytes());
    // A .vol grid of 2 × 2 × 2 samples, and the same cut short inside its data.
    let mut grid = b"VOL\x03".to_vec();
    for value in [1i32, 2, 2, 2, 1] {
        grid.extend(value.to_le_bytes());
    }
    for value in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        grid.extend(value.to_le_bytes());
    }
    grid.extend([0u8; 32]);
    let cut = grid[..60].to_vec();
    let mut checked = 0;
    for (name, scene, needle, says) in bad_mitsuba_scenes() {
        let case = Case::new()
            .file(name, &scene)
            .file(
                "other.xml",
                format!("<scene version=\"3.0.0\">\n  <include filename=\"{name}\"/>\n</scene>\n"),
            )
            .file("lying.vol", &lying)
            .file("corrupt.serialized", &corrupt)
            .file("grid.vol", &grid)
            .file("cut.vol", &cut);
        // Under a cap on address space, so that a reader that believed a header would fail
        // to allocate and abort rather than pass.
        let output = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v 4000000 && exec \"{GLINT}\" render {name} -o out.png -n 2"
            ))
            .current_dir(case.dir.path())
            .output()
            .unwrap();
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(2), "{name}: {text}");
        case.assert_nothing_written();
        assert!(text.contains(says), "{name}: {text}");
        let (line, column) = location(&text, name)
            .or_else(|| location(&text, "other.xml"))
            .unwrap_or_else(|| panic!("{name}: no file:LINE:COL in stderr:\n{text}"));
        assert!(line >= 1 && column >= 1, "{name}: {text}");
        if !needle.is_empty() {
            assert_eq!(line, line_of(&scene, needle), "{name}: {text}");
        }
        checked += 1;
    }
    assert_eq!(checked, 15);
}
