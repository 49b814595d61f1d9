//! The Mitsuba 3 scene reader: every scene of Mitsuba's render test suite
//! (`../shared/mitsuba/tests/scenes`) loads into the parts Mitsuba renders, and hostile or
//! mistaken files get located errors. Participating media have their own file,
//! `mitsuba_media.rs`.

mod common;

use std::path::{Path, PathBuf};

use glint_io::{load_scene_with_defines, Limits, MemoryAssets, SceneError};
use glint_render::{Background, BsdfNode, Light, Material, Param, PixelFilter, SceneIntegrator};

fn suite() -> Option<PathBuf> {
    common::mitsuba_suite()
}

fn suite_scenes(root: &Path) -> Vec<PathBuf> {
    let mut scenes = Vec::new();
    for folder in std::fs::read_dir(root).unwrap() {
        let folder = folder.unwrap().path();
        if !folder.is_dir() {
            continue;
        }
        for file in std::fs::read_dir(&folder).unwrap() {
            let file = file.unwrap().path();
            if file.extension().is_some_and(|e| e == "xml") {
                scenes.push(file);
            }
        }
    }
    scenes.sort();
    scenes
}

fn load(path: &Path) -> Result<glint_io::LoadedScene, SceneError> {
    glint_io::load_scene(path)
}

#[test]
fn every_scene_of_the_suite_loads() {
    let Some(root) = suite() else { return };
    let mut failures = Vec::new();
    for scene in suite_scenes(&root) {
        if let Err(error) = load(&scene) {
            failures.push(format!("{}: {error}", scene.display()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn load_text(text: &str, defines: &[(&str, &str)]) -> Result<glint_io::LoadedScene, SceneError> {
    let defines: Vec<(String, String)> = defines
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    load_scene_with_defines(
        text,
        Path::new("mem/scene.xml"),
        &MemoryAssets::new(),
        &Limits::default(),
        &defines,
    )
}

fn error_at(result: Result<glint_io::LoadedScene, SceneError>) -> (u32, u32, String) {
    let error = result.expect_err("the load fails");
    let d = error.diagnostic().expect("located").clone();
    (d.line, d.column, d.message)
}

fn close(a: glint_render::Color, b: [f32; 3], tolerance: f32) -> bool {
    (a.x - b[0]).abs() <= tolerance
        && (a.y - b[1]).abs() <= tolerance
        && (a.z - b[2]).abs() <= tolerance
}

#[test]
fn spectra_convert_as_mitsuba_does() {
    // Expected values printed by pip mitsuba 3.9.1 (scalar_rgb):
    // mi.spectrum_list_to_srgb([400,500,600,700],[0.78]*4, True, True) and
    // mi.spectrum_list_to_srgb([400,500,600,700],[0,8,15.6,18.4], False, False),
    // mi.xyz_to_srgb([1,1,1]) for a uniform emitter spectrum.
    let scene = r#"<scene version="3.0.0">
        <shape type="rectangle">
            <bsdf type="diffuse"><spectrum name="reflectance" value="400:0.78, 500:0.78, 600:0.78, 700:0.78"/></bsdf>
            <emitter type="area"><spectrum name="radiance" value="400:0, 500:8, 600:15.6, 700:18.4"/></emitter>
        </shape>
        <emitter type="constant"><spectrum name="radiance" value="2"/></emitter>
    </scene>"#;
    let parts = load_text(scene, &[]).unwrap().parts;
    let BsdfNode::Diffuse {
        reflectance: Param::Constant(r),
    } = parts.physical.bsdfs[0]
    else {
        panic!()
    };
    assert!(close(r, [0.776368, 0.779809, 0.776029], 2e-5), "{r:?}");
    let Light::Triangles { intensity, .. } = &parts.lights[0] else {
        panic!()
    };
    assert!(
        close(*intensity, [20.7108, 10.8546, 2.77115], 2e-3),
        "{intensity:?}"
    );
    let Background::Color(c) = parts.background else {
        panic!()
    };
    assert!(
        close(c, [2.0 * 1.20479, 2.0 * 0.948291, 2.0 * 0.908916], 1e-4),
        "{c:?}"
    );
    assert!(matches!(
        parts.materials[1],
        Material::Emissive {
            surface: Some(0),
            light: Some(0),
            ..
        }
    ));
}

#[test]
fn named_conductors_and_iors() {
    // Au and Cu: mi.spectrum_list_to_srgb over ior/Au.eta.spd etc. (bounded=False, d65=False),
    // pip mitsuba 3.9.1; bk7 1.5046 and air 1.000277 from Mitsuba's ior.h.
    let scene = r#"<scene version="3.0.0">
        <bsdf type="conductor" id="au"><string name="material" value="Au"/></bsdf>
        <bsdf type="conductor" id="cu"/>
        <bsdf type="conductor" id="mirror"><string name="material" value="none"/></bsdf>
        <bsdf type="dielectric" id="glass"/>
        <bsdf type="principled" id="p"><float name="specular" value="0.5"/></bsdf>
    </scene>"#;
    let parts = load_text(scene, &[]).unwrap().parts;
    let conductor = |i: usize| match &parts.physical.bsdfs[i] {
        BsdfNode::Conductor { eta_k, .. } => *eta_k,
        other => panic!("{other:?}"),
    };
    let Some((Param::Constant(eta), Param::Constant(k))) = conductor(0) else {
        panic!()
    };
    assert!(
        close(eta, [0.143037, 0.375306, 1.442044], 1e-5)
            && close(k, [3.982986, 2.385559, 1.60336], 1e-5)
    );
    let Some((Param::Constant(eta), _)) = conductor(1) else {
        panic!()
    };
    assert!(
        close(eta, [0.201005, 0.923749, 1.102214], 1e-5),
        "default conductor is Cu"
    );
    assert_eq!(conductor(2), None);
    let BsdfNode::Dielectric { eta, .. } = parts.physical.bsdfs[3] else {
        panic!()
    };
    assert!((eta - 1.5046 / 1.000277).abs() < 1e-6);
    let BsdfNode::Principled(p) = &parts.physical.bsdfs[4] else {
        panic!()
    };
    let Param::Constant(e) = p.eta else { panic!() };
    assert!((e.x - (2.0 / (1.0 - 0.04f32.sqrt()) - 1.0)).abs() < 1e-6);
}

#[test]
fn defaults_and_defines_substitute() {
    let scene = r#"<scene version="3.0.0">
        <default name="spp" value="7"/>
        <default name="res" value="32"/>
        <sensor type="perspective">
            <float name="fov" value="90"/>
            <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
            <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/>
                <rfilter type="gaussian"/></film>
        </sensor>
        <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    </scene>"#;
    let d = load_text(scene, &[]).unwrap().parts.physical.defaults;
    assert_eq!(
        (d.samples_per_pixel, d.width, d.height),
        (Some(7), Some(32), Some(32))
    );
    assert_eq!(d.filter, PixelFilter::Gaussian { stddev: 0.5 });
    assert_eq!(
        (d.integrator, d.max_depth, d.russian_roulette_depth),
        (Some(SceneIntegrator::Path), Some(2), Some(5))
    );
    let d = load_text(scene, &[("spp", "64")])
        .unwrap()
        .parts
        .physical
        .defaults;
    assert_eq!(d.samples_per_pixel, Some(64));
    // Undefined, and defined through itself.
    let (line, column, message) = error_at(load_text(
        r#"<scene version="3.0.0">
  <integrator type="$kind"/></scene>"#,
        &[],
    ));
    // The value's first character, its `$`.
    assert_eq!((line, column), (2, 21), "{message}");
    assert!(message.contains("undefined parameter: $kind"), "{message}");
    let (line, _, message) = error_at(load_text(
        r#"<scene version="3.0.0">
  <default name="a" value="$a"/></scene>"#,
        &[],
    ));
    assert_eq!(line, 2);
    assert!(message.contains("$a"), "{message}");
}

#[test]
fn unknown_plugins_and_properties_are_located() {
    let (line, column, message) = error_at(load_text(
        "<scene version=\"3.0.0\">\n  <bsdf type=\"difuse\"/>\n</scene>",
        &[],
    ));
    assert_eq!((line, column), (2, 3));
    assert!(
        message.contains("difuse") && message.contains("did you mean"),
        "{message}"
    );
    let (line, column, message) = error_at(load_text(
        "<scene version=\"3.0.0\">\n  <bsdf type=\"diffuse\">\n    <float name=\"roughnes\" value=\"1\"/>\n  </bsdf>\n</scene>",
        &[],
    ));
    assert_eq!((line, column), (3, 5));
    assert!(message.contains("roughnes"), "{message}");
    let (_, _, message) = error_at(load_text(
        "<scene version=\"3.0.0\"><shape type=\"rectangle\"><ref id=\"nothing\"/></shape></scene>",
        &[],
    ));
    assert!(message.contains("nothing"), "{message}");
    let (_, _, message) = error_at(load_text(
        "<scene version=\"3.0.0\"><texture type=\"checkerboard\" id=\"t\"/><shape type=\"rectangle\"><ref id=\"t\"/></shape></scene>",
        &[],
    ));
    assert!(message.contains("a shape takes a BSDF"), "{message}");
    let (_, _, message) = error_at(load_text(
        "<scene version=\"3.0.0\"><bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"oops\"/></bsdf></scene>",
        &[],
    ));
    assert!(message.contains("oops"), "{message}");
    let warnings = load_text(
        "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"shutter_open\" value=\"0\"/></sensor></scene>",
        &[],
    )
    .unwrap()
    .warnings;
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].message.contains("shutter_open"));
}

#[test]
fn include_cycles_are_located_errors() {
    let mut assets = MemoryAssets::new();
    assets.insert(
        "mem/a.xml",
        b"<scene version=\"3.0.0\">\n<include filename=\"b.xml\"/></scene>".to_vec(),
    );
    assets.insert(
        "mem/b.xml",
        b"<scene version=\"3.0.0\">\n<include filename=\"a.xml\"/></scene>".to_vec(),
    );
    assets.insert(
        "mem/self.xml",
        b"<scene version=\"3.0.0\"><include filename=\"self.xml\"/></scene>".to_vec(),
    );
    for name in ["mem/a.xml", "mem/self.xml"] {
        let text =
            String::from_utf8(glint_io::Assets::read(&assets, Path::new(name)).unwrap()).unwrap();
        let error =
            load_scene_with_defines(&text, Path::new(name), &assets, &Limits::default(), &[])
                .expect_err("a cycle fails");
        assert!(error.to_string().contains("includes itself"), "{error}");
    }
}

#[test]
fn includes_are_found_as_mitsuba_finds_them() {
    // As in Mitsuba's participating_media suite: the scene includes include/base.xml, which
    // includes "include/pre.xml": not beside base.xml but beside the scene, where Mitsuba's
    // resolver also looks.
    let mut assets = MemoryAssets::new();
    assets.insert(
        "mem/include/base.xml",
        b"<scene version=\"3.0.0\"><include filename=\"include/pre.xml\"/>\n<integrator type=\"path\"><integer name=\"max_depth\" value=\"$depth\"/></integrator></scene>".to_vec(),
    );
    assets.insert(
        "mem/include/pre.xml",
        b"<scene version=\"3.0.0\"><default name=\"depth\" value=\"4\"/></scene>".to_vec(),
    );
    let text = "<scene version=\"3.0.0\"><include filename=\"include/base.xml\"/></scene>";
    let max_depth = |assets: &MemoryAssets| {
        load_scene_with_defines(
            text,
            Path::new("mem/scene.xml"),
            assets,
            &Limits::default(),
            &[],
        )
        .unwrap()
        .parts
        .physical
        .defaults
        .max_depth
    };
    assert_eq!(max_depth(&assets), Some(3));
    // The including file's folder comes first: a pre.xml beside base.xml wins.
    assets.insert(
        "mem/include/include/pre.xml",
        b"<scene version=\"3.0.0\"><default name=\"depth\" value=\"9\"/></scene>".to_vec(),
    );
    assert_eq!(max_depth(&assets), Some(8));
}

#[test]
fn the_camera_follows_mitsubas_conventions() {
    let scene = r#"<scene version="3.0.0">
        <sensor type="perspective">
            <float name="fov" value="90"/>
            <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
            <film type="hdrfilm"><integer name="width" value="200"/><integer name="height" value="100"/></film>
        </sensor></scene>"#;
    let camera = load_text(scene, &[]).unwrap().parts.camera;
    // Looking down -z with +y up: Mitsuba's image x runs along world -x... of its local frame,
    // whose local x is up × dir = (-1, 0, 0), so the image's x runs along world +x.
    assert!((camera.basis.w.z - 1.0).abs() < 1e-6, "{:?}", camera.basis);
    assert!((camera.basis.u.x - 1.0).abs() < 1e-6, "{:?}", camera.basis);
    assert!((camera.basis.v.y - 1.0).abs() < 1e-6, "{:?}", camera.basis);
    assert!((camera.image_plane_width - 2.0).abs() < 1e-5);
    assert_eq!(camera.position, glint_render::Vec3::new(0.0, 0.0, 5.0));
}

#[test]
fn suite_golden_facts() {
    let Some(root) = suite() else { return };
    let parts = load(&root.join("orthographic_sensor/test_orthographic_path.xml"))
        .unwrap()
        .parts;
    assert_eq!(
        parts.camera.projection,
        glint_render::Projection::Orthographic
    );
    assert!((parts.camera.image_plane_width - 3.0).abs() < 1e-5);
    let d = parts.physical.defaults;
    assert_eq!(
        (d.width, d.height, d.samples_per_pixel, d.max_depth),
        (Some(200), Some(120), Some(16), Some(1))
    );
    assert!(matches!(parts.background, Background::Color(c) if close(c, [1.0, 1.0, 1.0], 0.0)));
    let parts = load(&root.join("bsdf_spheres/test_envmap_path.xml"))
        .unwrap()
        .parts;
    assert!(matches!(parts.background, Background::Environment { .. }));
    assert_eq!(parts.physical.defaults.samples_per_pixel, Some(128));
    let parts = load(&root.join("floating_sphere/test_directional_direct.xml"))
        .unwrap()
        .parts;
    assert!(matches!(
        parts.lights.as_slice(),
        [Light::Directional { .. }]
    ));
    assert_eq!(
        parts.physical.defaults.integrator,
        Some(SceneIntegrator::Direct)
    );
    assert_eq!(
        parts.physical.bsdfs.len(),
        1,
        "the shared diffuse is one node"
    );
}

/// Triangles, world-space area and world bounds of each instance, in scene order.
fn placed(parts: &glint_render::SceneParts) -> Vec<(usize, f64, [f32; 3], [f32; 3])> {
    parts
        .instances
        .iter()
        .map(|instance| {
            let geometry = &parts.geometries[instance.geometry as usize];
            let (mut area, mut lo, mut hi) = (0.0f64, [f32::MAX; 3], [f32::MIN; 3]);
            for shape in &geometry.shapes {
                let glint_render::Shape::Triangle { vertices } = shape else {
                    panic!("not a triangle: {shape:?}");
                };
                let v = vertices.map(|p| match &instance.transform {
                    Some(t) => t.point_to_world(p),
                    None => p,
                });
                area += 0.5 * f64::from((v[1] - v[0]).cross(v[2] - v[0]).length());
                for p in v {
                    for (axis, value) in p.to_array().into_iter().enumerate() {
                        lo[axis] = lo[axis].min(value);
                        hi[axis] = hi[axis].max(value);
                    }
                }
            }
            (geometry.shapes.len(), area, lo, hi)
        })
        .collect()
}

fn near(a: [f32; 3], b: [f32; 3], tolerance: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

/// A version 4 `.serialized` file of one shape: positions and triangles, optional normals.
fn serialized_file(positions: &[[f32; 3]], triangles: &[[u32; 3]], normals: bool) -> Vec<u8> {
    use std::io::Write;
    let mut raw = Vec::new();
    let flags: u32 = 0x1000 | if normals { 0x1 } else { 0 };
    raw.extend(flags.to_le_bytes());
    raw.extend(b"shape\0");
    raw.extend((positions.len() as u64).to_le_bytes());
    raw.extend((triangles.len() as u64).to_le_bytes());
    for p in positions {
        p.iter().for_each(|v| raw.extend(v.to_le_bytes()));
    }
    if normals {
        for _ in positions {
            [0.0f32, 0.0, 1.0]
                .iter()
                .for_each(|v| raw.extend(v.to_le_bytes()));
        }
    }
    for t in triangles {
        t.iter().for_each(|i| raw.extend(i.to_le_bytes()));
    }
    let mut file = vec![0x1C, 0x04, 4, 0];
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    encoder.write_all(&raw).unwrap();
    file.extend(encoder.finish().unwrap());
    file.extend(0u64.to_le_bytes());
    file.extend(1u32.to_le_bytes());
    file
}

/// A `.vol` grid of `n`³ float samples given by `f` at the unit cube's sample points.
fn vol_file(n: u32, f: impl Fn([f32; 3]) -> f32) -> Vec<u8> {
    let mut file = b"VOL\x03".to_vec();
    for v in [1i32, n as i32, n as i32, n as i32, 1] {
        file.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        file.extend(v.to_le_bytes());
    }
    let step = 1.0 / (n - 1) as f32;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let value = f([i as f32 * step, j as f32 * step, k as f32 * step]);
                file.extend(value.to_le_bytes());
            }
        }
    }
    file
}

fn load_with(assets: &MemoryAssets, text: &str) -> Result<glint_io::LoadedScene, SceneError> {
    load_scene_with_defines(
        text,
        Path::new("mem/scene.xml"),
        assets,
        &Limits::default(),
        &[],
    )
}

#[test]
fn mitsubas_shapes_load_with_their_size_and_place() {
    let mut assets = MemoryAssets::new();
    // A unit square in z = 0 from two triangles, without normals.
    assets.insert(
        "mem/square.serialized",
        serialized_file(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            &[[0, 1, 2], [0, 2, 3]],
            false,
        ),
    );
    // A sphere of radius 0.3 around the unit cube's centre.
    assets.insert(
        "mem/ball.vol",
        vol_file(24, |[x, y, z]| {
            ((x - 0.5).powi(2) + (y - 0.5).powi(2) + (z - 0.5).powi(2)).sqrt() - 0.3
        }),
    );
    let scene = r#"<scene version="3.0.0">
        <shape type="cube"><transform name="to_world"><scale value="2"/></transform></shape>
        <shape type="disk"><transform name="to_world"><scale value="3"/><translate z="1"/></transform></shape>
        <shape type="cylinder"><float name="radius" value="0.5"/><point name="p0" x="1" y="0" z="0"/><point name="p1" x="1" y="0" z="2"/></shape>
        <shape type="serialized"><string name="filename" value="square.serialized"/><transform name="to_world"><scale x="2" y="3" z="1"/><translate x="5"/></transform></shape>
        <shape type="sdfgrid"><string name="filename" value="ball.vol"/><transform name="to_world"><scale value="2"/></transform></shape>
        <shape type="shapegroup" id="group"><shape type="cube"/></shape>
        <shape type="instance"><ref id="group"/><transform name="to_world"><translate x="10"/></transform></shape>
        <shape type="instance"><ref id="group"/><transform name="to_world"><translate y="-10"/></transform></shape>
    </scene>"#;
    let parts = load_with(&assets, scene).unwrap().parts;
    let shapes = placed(&parts);
    assert_eq!(shapes.len(), 7, "five shapes and two instances");
    let pi = std::f64::consts::PI;
    let within = |area: f64, expected: f64, share: f64| (area / expected - 1.0).abs() <= share;
    // The cube: 12 triangles, six faces of 4 × 4.
    let (count, area, lo, hi) = shapes[0];
    assert_eq!(count, 12);
    assert!(within(area, 96.0, 1e-6), "{area}");
    assert!(near(lo, [-2.0; 3], 1e-6) && near(hi, [2.0; 3], 1e-6));
    // The disk: radius 3 at z = 1, its polygon within 0.05 % of the circle.
    let (count, area, lo, hi) = shapes[1];
    assert_eq!(count, 128);
    assert!(within(area, 9.0 * pi, 5e-4), "{area}");
    assert!(near(lo, [-3.0, -3.0, 1.0], 1e-5) && near(hi, [3.0, 3.0, 1.0], 1e-5));
    // The cylinder: radius 0.5 and length 2 along z, open ends.
    let (count, area, lo, hi) = shapes[2];
    assert_eq!(count, 256);
    assert!(within(area, 2.0 * pi, 2e-4), "{area}");
    assert!(near(lo, [0.5, -0.5, 0.0], 1e-5) && near(hi, [1.5, 0.5, 2.0], 1e-5));
    // The serialized square, stretched to 2 × 3 and moved.
    let (count, area, lo, hi) = shapes[3];
    assert_eq!(count, 2);
    assert!(within(area, 6.0, 1e-6), "{area}");
    assert!(near(lo, [5.0, 0.0, 0.0], 1e-6) && near(hi, [7.0, 3.0, 0.0], 1e-6));
    // The sdfgrid sphere, radius 0.6 after the scale, centred on (1, 1, 1).
    let (count, area, lo, hi) = shapes[4];
    assert!(count > 100, "{count}");
    assert!(within(area, 4.0 * pi * 0.36, 0.02), "{area}");
    assert!(
        near(lo, [0.4; 3], 0.02) && near(hi, [1.6; 3], 0.02),
        "{lo:?} {hi:?}"
    );
    // Two instances of one cube geometry.
    assert_eq!(parts.instances[5].geometry, parts.instances[6].geometry);
    assert_eq!(parts.geometries.len(), 6);
    let (_, area, lo, hi) = shapes[5];
    assert!(
        within(area, 24.0, 1e-6)
            && near(lo, [9.0, -1.0, -1.0], 1e-6)
            && near(hi, [11.0, 1.0, 1.0], 1e-6)
    );
    let (_, _, lo, hi) = shapes[6];
    assert!(near(lo, [-1.0, -11.0, -1.0], 1e-6) && near(hi, [1.0, -9.0, 1.0], 1e-6));
    // The serialized square had no normals: Mitsuba computes them (+z); the cube's point out.
    let attributes = |g: usize| parts.physical.attributes[g].as_ref().unwrap();
    let normals = attributes(3).normals.as_ref().expect("computed normals");
    assert!(normals.iter().flatten().all(|n| n.z > 0.999), "{normals:?}");
}

#[test]
fn flip_normals_and_face_normals_follow_mitsuba() {
    let mut assets = MemoryAssets::new();
    assets.insert(
        "mem/square.serialized",
        serialized_file(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            &[[0, 1, 2], [0, 2, 3]],
            true,
        ),
    );
    let scene = r#"<scene version="3.0.0">
        <shape type="cube"><boolean name="flip_normals" value="true"/></shape>
        <shape type="cylinder"/>
        <shape type="cylinder"><transform name="to_world"><scale x="-1"/></transform></shape>
        <shape type="cylinder"><boolean name="flip_normals" value="true"/><transform name="to_world"><scale x="-1"/></transform></shape>
        <shape type="serialized"><string name="filename" value="square.serialized"/><boolean name="face_normals" value="true"/></shape>
        <shape type="serialized"><string name="filename" value="square.serialized"/></shape>
        <shape type="disk"><boolean name="flip_normals" value="true"/></shape>
    </scene>"#;
    let parts = load_with(&assets, scene).unwrap().parts;
    let attributes = |g: usize| parts.physical.attributes[g].as_ref().unwrap();
    // Whether every shading normal, and every winding, points away from the object's axis
    // (the origin for the cube, the z axis for the cylinders).
    let outward = |g: usize, axis_only: bool| {
        let normals = attributes(g).normals.as_ref().unwrap();
        let geometry = &parts.geometries[g];
        let mut signs = Vec::new();
        for (shape, corners) in geometry.shapes.iter().zip(normals) {
            let glint_render::Shape::Triangle { vertices: v } = shape else {
                panic!()
            };
            let mut centre = (v[0] + v[1] + v[2]) / 3.0;
            if axis_only {
                centre.z = 0.0;
            }
            let winding = (v[1] - v[0]).cross(v[2] - v[0]);
            signs.push((winding.dot(centre) > 0.0, corners[0].dot(centre) > 0.0));
        }
        assert!(signs.iter().all(|s| *s == signs[0]), "mixed signs in {g}");
        signs[0]
    };
    assert_eq!(outward(0, false), (false, false), "a flipped cube faces in");
    assert_eq!(outward(1, true), (true, true));
    // Mitsuba toggles flip_normals when to_world mirrors a cylinder (in object space, so the
    // mirror then turns the winding back out in the world).
    assert_eq!(outward(2, true), (false, false));
    assert_eq!(outward(3, true), (true, true));
    // face_normals drops the file's normals; without it they are kept.
    assert!(attributes(4).normals.is_none());
    assert!(attributes(5).normals.is_some());
    let disk = attributes(6).normals.as_ref().unwrap();
    assert!(disk.iter().flatten().all(|n| n.z == -1.0));
    let glint_render::Shape::Triangle { vertices: v } = parts.geometries[6].shapes[0] else {
        panic!()
    };
    assert!(
        (v[1] - v[0]).cross(v[2] - v[0]).z < 0.0,
        "a flipped disk winds clockwise"
    );
}

#[test]
fn broken_shape_files_are_located_errors() {
    let mut assets = MemoryAssets::new();
    let mut corrupt = serialized_file(
        &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2]],
        false,
    );
    // Past the 4-byte header and zlib's 2-byte header: garbage in the deflate stream.
    for byte in &mut corrupt[6..20] {
        *byte = 0xFF;
    }
    assets.insert("mem/corrupt.serialized", corrupt);
    // A header that claims a 4096³ grid over a few bytes of data.
    let mut lying = b"VOL\x03".to_vec();
    for v in [1i32, 4096, 4096, 4096, 1] {
        lying.extend(v.to_le_bytes());
    }
    lying.extend([0u8; 24 + 64]);
    assets.insert("mem/lying.vol", lying);
    assets.insert("mem/ok.vol", vol_file(4, |p| p[0] - 0.5));
    let cases = [
        ("<shape type=\"serialized\"><string name=\"filename\" value=\"corrupt.serialized\"/></shape>", "corrupt.serialized"),
        ("<shape type=\"sdfgrid\"><string name=\"filename\" value=\"lying.vol\"/></shape>", "lying.vol"),
    ];
    for (shape, file) in cases {
        let scene = format!("<scene version=\"3.0.0\">\n\n  {shape}\n</scene>");
        let (line, column, message) = error_at(load_with(&assets, &scene));
        assert_eq!((line, column), (3, 3), "{message}");
        assert!(message.contains(file), "{message}");
        assert!(message.contains("at byte"), "{message}");
    }
    // A missing index, a negative one, and flip_normals where Mitsuba's sdfgrid reads none.
    for (shape, why) in [
        ("<shape type=\"serialized\"><string name=\"filename\" value=\"corrupt.serialized\"/><integer name=\"shape_index\" value=\"-1\"/></shape>", "0 or more"),
        ("<shape type=\"sdfgrid\"><string name=\"filename\" value=\"ok.vol\"/><boolean name=\"flip_normals\" value=\"true\"/></shape>", "flip_normals"),
        ("<shape type=\"cylinder\"><point name=\"p1\" x=\"0\" y=\"0\" z=\"0\"/></shape>", "coincide"),
        ("<shape type=\"shapegroup\" id=\"g\"><shape type=\"cube\"><emitter type=\"area\"/></shape></shape>", "cannot emit"),
    ] {
        let scene = format!("<scene version=\"3.0.0\">\n{shape}\n</scene>");
        let (line, _, message) = error_at(load_with(&assets, &scene));
        assert!(message.contains(why), "{message}");
        assert_eq!(line, 2, "{message}");
    }
}

#[test]
fn rr_depth_is_kept_as_mitsuba_counts_it() {
    let depth = |integrator: &str| {
        let scene = format!("<scene version=\"3.0.0\">{integrator}</scene>");
        load_text(&scene, &[])
            .unwrap()
            .parts
            .physical
            .defaults
            .russian_roulette_depth
    };
    // Both renderers start roulette once `depth >= rr_depth`, depth counted after the
    // bounce, so the value passes through unchanged.
    assert_eq!(depth(r#"<integrator type="path"/>"#), Some(5));
    assert_eq!(
        depth(r#"<integrator type="path"><integer name="rr_depth" value="3"/></integrator>"#),
        Some(3)
    );
    assert_eq!(
        depth(r#"<integrator type="path"><integer name="rr_depth" value="1"/></integrator>"#),
        Some(1)
    );
    let (_, _, message) = error_at(load_text(
        r#"<scene version="3.0.0"><integrator type="path"><integer name="rr_depth" value="0"/></integrator></scene>"#,
        &[],
    ));
    assert!(message.contains("rr_depth"), "{message}");
}
