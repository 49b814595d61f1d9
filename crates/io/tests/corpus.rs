//! The loader against the real course corpus in `../shared/scenes/course` (FORMAT.md 8): every
//! scene loads, with exactly the warnings listed here, and specific scenes build what the
//! course means.

mod common;

use common::{corpus, load_as_the_course_did, scene_files};

use glint_io::{load_scene, Diagnostic, LoadedScene, SceneError, Severity};
use glint_render::{
    Background, ColorSource, Light, Material, Matrix4, Projection, SceneParts, Shape, Vec3,
};

fn load(relative: &str) -> Option<LoadedScene> {
    let path = corpus()?.join(relative);
    Some(load_scene(&path).unwrap_or_else(|error| panic!("{relative} failed to load:\n{error}")))
}

/// `load` as the course renderer loaded: files that cannot be read are warnings.
fn load_as_the_course(relative: &str) -> Option<LoadedScene> {
    let path = corpus()?.join(relative);
    Some(
        load_as_the_course_did(&path)
            .unwrap_or_else(|error| panic!("{relative} failed to load:\n{error}")),
    )
}

/// The corpus files that name a file existing nowhere (FORMAT.md A17), with the start of the
/// one error each gets by default. With `allow_missing_assets` they load, with the warnings
/// `EXPECTED_WARNINGS` lists.
const MISSING_ASSETS: &[(&str, &str)] = &[
    (
        "willemsen/scenes_B/dielectric_Test00.xml",
        "cannot read environment-map face `data/reef_posX.png` (tried ",
    ),
    (
        "willemsen/scenes_B/solarSystem.json",
        "cannot read texture image `images/jupiter_map_css_plus_juno_bj.png` (tried ",
    ),
];

/// Warnings each corpus file must produce: (file, part of the message, how many). Files not
/// listed must load without any warning.
const EXPECTED_WARNINGS: &[(&str, &str, usize)] = &[
    // FORMAT.md 2.3: stray normal/width/length on point lights.
    ("students/XTheGreat__RaytracerAndRasterizer/sceneXMLs/scenes_A/oneSphereUpPt.xml", "is not used in a point light", 3),
    ("students/and04276__Graphics/floor.json", "is not used in a point light", 9),
    ("willemsen/scenes_B/solarSystem.xml", "is not used in a point light", 3),
    ("willemsen/scenes_B/solarSystem.2021-03.json", "is not used in a point light", 3),
    // FORMAT.md 2.5: the student typo `Mirrored`, in a shader that redefines `greyMirror`.
    ("students/XTheGreat__RaytracerAndRasterizer/sceneXMLs/scenes_A/simpleTwoSpheres_MirroredFloor.xml", "unknown shader type `Mirrored` (did you mean `Mirror`?)", 1),
    ("students/XTheGreat__RaytracerAndRasterizer/sceneXMLs/scenes_A/simpleTwoSpheres_MirroredFloor.xml", "shader `greyMirror` is defined again", 1),
    // A student's `2.5.0`, read as the C++ stream parser reads it.
    ("students/XTheGreat__RaytracerAndRasterizer/sceneXMLs/scenes_B/table.xml", "`0.0 2.5.0 5.0` is not three plain numbers; read as 0 2.5 0", 1),
    ("students/and04276__Graphics/oneTriangle.json", "the shape has no shader", 1),
    // FORMAT.md 1.1: a fourth number in an intensity.
    ("students/kvatsaas__renderer/scenes_custom/PhongExpThreeLights.json", "`intensity` has 4 numbers", 1),
    // FORMAT.md A4: `_bgColor` and `bgColor` in one scene.
    ("students/kvatsaas__renderer/scenes_custom/areaLight.json", "`bgColor` is ignored", 1),
    ("students/kvatsaas__renderer/scenes_custom/areaLight_birdseye.json", "`bgColor` is ignored", 1),
    ("students/kvatsaas__renderer/scenes_custom/areaLight_visibiltytest.json", "`bgColor` is ignored", 1),
    // FORMAT.md 3.8: the student extension `monster`, and parameters a shader type lacks.
    ("students/kvatsaas__renderer/scenes_custom/gridOfBunniculas.json", "`monster` is not used in an instance shape", 16),
    ("students/kvatsaas__renderer/scenes_custom/gridOfBunniculas.json", "`mirrorCoef` is not used in a `Lambertian` shader", 16),
    ("students/kvatsaas__renderer/scenes_custom/gridOfBunniculasGlaze_ortho.json", "`monster` is not used in an instance shape", 16),
    ("students/kvatsaas__renderer/scenes_custom/gridOfBunnies.json", "`mirrorCoef` is not used in a `Lambertian` shader", 16),
    ("students/kvatsaas__renderer/scenes_custom/gridOfBunnies_nomirror.json", "`mirrorCoef` is not used in a `Lambertian` shader", 16),
    ("students/kvatsaas__renderer/scenes_custom/monsterSphereScene01.json", "`monster` is not used in a sphere shape", 2),
    // A comment closed twice leaves `-->` as text in the scene.
    ("willemsen/scenes_A/CornellRoom_wMirroredSpheres.xml", "text `-->` is not used in the scene", 1),
    // FORMAT.md A17: missing assets (`MISSING_ASSETS`), with `allow_missing_assets`.
    ("willemsen/scenes_B/dielectric_Test00.xml", "cannot read environment-map face `data/reef_posX.png`", 1),
    ("willemsen/scenes_B/solarSystem.json", "cannot read texture image `images/jupiter_map_css_plus_juno_bj.png`", 1),
    // FORMAT.md 4.2: Mirror shaders carrying other shaders' parameters.
    ("willemsen/scenes_B/glossyReflection.json", "is not used in a `Mirror` shader", 20),
    ("willemsen/scenes_B/marbles01.json", "`mirrorCoef` is not used in a `Mirror` shader", 6),
    ("willemsen/scenes_B/solarSystem.2021-03.json", "is not used in a `Lambertian` shader", 6),
    // FORMAT.md A16: a dangling shader in definitions whose every placement overrides it.
    ("willemsen/scenes_B/threeOBJS_CooltoWarm.json", "shader `redBlinnPhong` is not defined; harmless here", 3),
];

#[test]
fn every_corpus_scene_loads_with_the_expected_warnings() {
    let Some(corpus) = corpus() else { return };
    let files = scene_files(&corpus);
    assert!(files.len() >= 80, "only {} scene files found", files.len());
    let mut failures = Vec::new();
    let mut checked_expectations = 0;
    let mut checked_missing = 0;
    for (path, relative) in &files {
        let missing = MISSING_ASSETS.iter().find(|(file, _)| file == relative);
        if let Some((_, start)) = missing {
            checked_missing += 1;
            match load_scene(path) {
                Err(SceneError::Invalid(error))
                    if error.message.starts_with(start) && error.path == *path => {}
                Err(error) => failures.push(format!("{relative}: not the error expected: {error}")),
                Ok(_) => failures.push(format!("{relative}: loaded despite its missing file")),
            }
        }
        let loaded = if missing.is_some() {
            load_as_the_course_did(path)
        } else {
            load_scene(path)
        };
        let loaded = match loaded {
            Ok(loaded) => loaded,
            Err(error) => {
                failures.push(format!("{relative}: {error}"));
                continue;
            }
        };
        let mut remaining: Vec<&Diagnostic> = loaded.warnings.iter().collect();
        for warning in &remaining {
            assert_eq!(warning.severity, Severity::Warning);
            assert_eq!(warning.path, *path);
            assert!(warning.line >= 1 && warning.column >= 1);
        }
        for &(file, fragment, count) in EXPECTED_WARNINGS {
            if file != relative {
                continue;
            }
            checked_expectations += 1;
            let matching = remaining
                .iter()
                .filter(|warning| warning.message.contains(fragment))
                .count();
            if matching != count {
                failures.push(format!(
                    "{relative}: expected {count} warnings containing {fragment:?}, got {matching}"
                ));
            }
            remaining.retain(|warning| !warning.message.contains(fragment));
        }
        for warning in remaining {
            failures.push(format!("unexpected warning: {warning}"));
        }
    }
    assert_eq!(
        checked_expectations,
        EXPECTED_WARNINGS.len(),
        "a listed file was not found"
    );
    assert_eq!(
        checked_missing,
        MISSING_ASSETS.len(),
        "a listed file was not found"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn one_sphere_is_a_blue_lambertian_sphere() {
    let Some(loaded) = load("willemsen/scenes_A/oneSphere.xml") else {
        return;
    };
    assert!(loaded.warnings.is_empty());
    let parts = loaded.parts;
    assert_eq!(parts.geometries.len(), 1);
    assert_eq!(
        parts.geometries[0].shapes,
        vec![Shape::Sphere {
            center: Vec3::new(0.0, 0.0, -5.0),
            radius: 1.0
        }]
    );
    let material = &parts.materials[parts.geometries[0].materials[0] as usize];
    assert_eq!(
        *material,
        Material::Lambertian {
            diffuse: ColorSource::constant(Vec3::new(0.0, 0.0, 1.0))
        }
    );
    assert_eq!(parts.instances.len(), 1);
    assert_eq!(parts.instances[0].transform, None);
    assert_eq!(parts.instances[0].material, None);
    assert!(parts.instances[0].casts_shadow);
    assert_eq!(
        parts.lights,
        vec![Light::Point {
            position: Vec3::new(0.0, 10.0, 0.0),
            intensity: Vec3::ONE
        }]
    );
    assert_eq!(parts.camera.projection, Projection::Perspective);
    assert_eq!(parts.camera.position, Vec3::ZERO);
    assert_eq!(parts.camera.basis.w, Vec3::new(0.0, 0.0, 1.0));
    assert_eq!(parts.camera.focal_length, 1.0);
    assert_eq!(parts.camera.image_plane_width, 0.5);
    // FORMAT.md A4: no background given means black.
    assert_eq!(parts.background, Background::Color(Vec3::ZERO));
}

/// Compares everything but, when `same_view` is false, the camera and the background. Lists are
/// compared element by element so a failure names the first difference, not 800 shapes.
fn assert_same_parts(a: &SceneParts, b: &SceneParts, what: &str, same_view: bool) {
    fn same_list<T: PartialEq + std::fmt::Debug>(a: &[T], b: &[T], what: &str) {
        assert_eq!(a.len(), b.len(), "{what}: lengths differ");
        if let Some(index) = (0..a.len()).find(|&index| a[index] != b[index]) {
            panic!("{what}[{index}]: {:?} != {:?}", a[index], b[index]);
        }
    }
    if same_view {
        assert_eq!(a.camera, b.camera, "{what}: camera");
        assert_eq!(a.background, b.background, "{what}: background");
    }
    same_list(&a.materials, &b.materials, &format!("{what}: materials"));
    same_list(&a.textures, &b.textures, &format!("{what}: textures"));
    same_list(&a.lights, &b.lights, &format!("{what}: lights"));
    same_list(&a.instances, &b.instances, &format!("{what}: instances"));
    assert_eq!(
        a.geometries.len(),
        b.geometries.len(),
        "{what}: geometry count"
    );
    for (index, (first, second)) in a.geometries.iter().zip(&b.geometries).enumerate() {
        same_list(
            &first.shapes,
            &second.shapes,
            &format!("{what}: geometry {index} shapes"),
        );
        same_list(
            &first.materials,
            &second.materials,
            &format!("{what}: geometry {index} materials"),
        );
    }
}

#[test]
fn xml_and_json_twins_build_equal_parts() {
    let twins = [
        (
            "willemsen/scenes_A/oneSphere.xml",
            "willemsen/scenes_A/oneSphere.json",
            true,
        ),
        (
            "willemsen/scenes_A/oneTriangle.xml",
            "willemsen/scenes_A/oneTriangle.json",
            true,
        ),
        (
            "willemsen/scenes_A/threeTriangles.xml",
            "willemsen/scenes_A/threeTriangles.json",
            true,
        ),
        (
            "willemsen/scenes_A/oneBox.xml",
            "willemsen/scenes_A/oneBox.json",
            true,
        ),
        // The files themselves differ in the camera (lookatPoint 0 0 0 in XML, 0 50 0 in
        // JSON) and the background (0.5 grey, 0.2 0.2 1). boxSphereTest is left out: its XML
        // has a box the JSON lacks.
        (
            "willemsen/scenes_A/spheres_1K.xml",
            "willemsen/scenes_A/spheres_1K.json",
            false,
        ),
        (
            "willemsen/scenes_A/simpleSphereScene.xml",
            "willemsen/scenes_A/simpleSphereScene.json",
            true,
        ),
        (
            "willemsen/scenes_B/metallicDragons.xml",
            "willemsen/scenes_B/metallicDragons.json",
            true,
        ),
    ];
    for (xml, json, same_view) in twins {
        let (Some(xml_scene), Some(json_scene)) = (load(xml), load(json)) else {
            return;
        };
        assert_same_parts(&xml_scene.parts, &json_scene.parts, xml, same_view);
    }
}

#[test]
fn instanced_dragons_share_one_mesh() {
    let Some(loaded) = load("willemsen/scenes_B/StanfordDragon_Instanced.json") else {
        return;
    };
    let parts = loaded.parts;
    let placed: Vec<_> = parts
        .instances
        .iter()
        .filter(|instance| instance.transform.is_some())
        .collect();
    assert!(placed.len() >= 2);
    let dragon = placed[0].geometry;
    assert!(placed.iter().all(|instance| instance.geometry == dragon));
    let dragon_triangles = parts.geometries[dragon as usize].shapes.len();
    assert!(dragon_triangles > 50_000, "{dragon_triangles} triangles");
    let total: usize = parts
        .geometries
        .iter()
        .map(|geometry| geometry.shapes.len())
        .sum();
    assert!(
        total < dragon_triangles + 100,
        "the mesh was copied: {total} shapes in all"
    );

    // A student grid: sixteen bunnies, one bunny mesh.
    let Some(grid) = load("students/kvatsaas__renderer/scenes_custom/gridOfBunnies.json") else {
        return;
    };
    let bunnies: Vec<_> = grid
        .parts
        .instances
        .iter()
        .filter(|instance| instance.transform.is_some())
        .map(|instance| instance.geometry)
        .collect();
    assert_eq!(bunnies.len(), 16);
    assert!(bunnies.iter().all(|&geometry| geometry == bunnies[0]));
}

fn rows(parts: &SceneParts, instance: usize) -> [[f32; 4]; 3] {
    parts.instances[instance]
        .transform
        .expect("a transform")
        .world_from_object
}

fn assert_rows_close(actual: [[f32; 4]; 3], expected: [[f64; 4]; 4], what: &str) {
    for (row, expected_row) in actual.iter().zip(expected) {
        for (value, expected_value) in row.iter().zip(expected_row) {
            assert!(
                (f64::from(*value) - expected_value).abs() < 1e-5,
                "{what}: {actual:?} vs {expected:?}"
            );
        }
    }
}

#[test]
fn legacy_spellings_read_like_the_current_ones() {
    // 2019: camera and light as single objects, numbers as strings.
    let (Some(old), Some(new)) = (
        load("willemsen/scenes_A/threeTriangles.2019.json"),
        load("willemsen/scenes_A/threeTriangles.json"),
    ) else {
        return;
    };
    assert!(old.warnings.is_empty());
    assert_eq!(old.parts.camera, new.parts.camera);
    assert_eq!(old.parts.geometries, new.parts.geometries);
    assert_eq!(old.parts.materials, new.parts.materials);
    assert_eq!(old.parts.lights.len(), 1);

    // 2019-2020: a `transform` object with a `rotate` array instead of `xform`.
    let (Some(old), Some(new)) = (
        load("willemsen/scenes_B/metallicDragons.2019.json"),
        load("willemsen/scenes_B/metallicDragons.json"),
    ) else {
        return;
    };
    assert!(old.warnings.is_empty());
    let placed = |parts: &SceneParts| -> Vec<[[f32; 4]; 3]> {
        parts
            .instances
            .iter()
            .filter_map(|instance| instance.transform.map(|t| t.world_from_object))
            .collect()
    };
    assert_eq!(placed(&old.parts).len(), 3);
    assert_eq!(placed(&old.parts), placed(&new.parts));
    // dragon0: translate 0 1.5 0, scale 2, rotate Y 120, rotate X -90, in that order.
    let expected = Matrix4::translate(Vec3::new(0.0, 1.5, 0.0))
        .mul(&Matrix4::scale(Vec3::splat(2.0)))
        .mul(&Matrix4::rotate(1, 120.0))
        .mul(&Matrix4::rotate(0, -90.0));
    assert_rows_close(placed(&old.parts)[0], expected.m, "dragon0");

    // 2021-03: `xform` entries of type `rotate` and `transform` (= translate).
    let Some(solar) = load("willemsen/scenes_B/solarSystem.2021-03.json") else {
        return;
    };
    let earth = Matrix4::translate(Vec3::new(0.0, 5.0, 0.0))
        .mul(&Matrix4::rotate(2, 23.5))
        .mul(&Matrix4::rotate(1, 0.0))
        .mul(&Matrix4::scale(Vec3::splat(5.0)));
    let moon = Matrix4::translate(Vec3::new(-7.0, 6.0, 1.5)).mul(&Matrix4::rotate(1, 0.0));
    // Instance 0 is the plain shapes; the Earth and the Moon are the first two placements.
    assert_rows_close(rows(&solar.parts, 1), earth.m, "Earth");
    assert_rows_close(rows(&solar.parts, 2), moon.m, "Moon");
}

fn warning_containing<'a>(loaded: &'a LoadedScene, fragment: &str) -> &'a Diagnostic {
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

#[test]
fn missing_assets_are_errors_at_their_location() {
    let Some(corpus) = corpus() else { return };
    for (relative, at, shown) in [
        (
            "willemsen/scenes_B/solarSystem.json",
            (56, 17),
            "solarSystem.json:56:17: error: cannot read texture image \
             `images/jupiter_map_css_plus_juno_bj.png` (tried /",
        ),
        (
            "willemsen/scenes_B/dielectric_Test00.xml",
            (7, 19),
            "dielectric_Test00.xml:7:19: error: cannot read environment-map face \
             `data/reef_posX.png` (tried /",
        ),
    ] {
        let error = load_scene(&corpus.join(relative)).expect_err("a file is missing");
        let [error] = error.diagnostics() else {
            panic!("{relative}: one error expected:\n{error}");
        };
        assert_eq!((error.line, error.column), at);
        assert!(error.to_string().contains(shown), "{error}");
        assert!(
            error.message.ends_with(": No such file or directory"),
            "{error}"
        );
    }
}

#[test]
fn missing_assets_allowed_are_warnings_at_their_location() {
    let Some(solar) = load_as_the_course("willemsen/scenes_B/solarSystem.json") else {
        return;
    };
    let warning = warning_containing(&solar, "jupiter_map_css_plus_juno_bj.png");
    assert!(warning
        .path
        .ends_with("willemsen/scenes_B/solarSystem.json"));
    assert_eq!((warning.line, warning.column), (56, 17));
    assert_eq!(
        warning.source_line(),
        Some("\t\t\"sourcefile\": \"images/jupiter_map_css_plus_juno_bj.png\",")
    );
    let shown = warning.to_string();
    assert!(
        shown.contains("solarSystem.json:56:17: warning: cannot read texture image"),
        "{shown}"
    );
    // The other planets keep their textures; Jupiter's shader falls back to its plain colour.
    assert_eq!(solar.parts.textures.len(), 8);
    let untextured = solar
        .parts
        .materials
        .iter()
        .filter(|material| {
            matches!(material, Material::Lambertian { diffuse } if diffuse.texture.is_none() && diffuse.color == Vec3::ONE)
        })
        .count();
    assert_eq!(untextured, 1);

    let Some(dielectric) = load_as_the_course("willemsen/scenes_B/dielectric_Test00.xml") else {
        return;
    };
    let warning = warning_containing(&dielectric, "data/reef_");
    assert!(warning
        .path
        .ends_with("willemsen/scenes_B/dielectric_Test00.xml"));
    assert_eq!((warning.line, warning.column), (7, 19));
    // No environment map: the sceneParameters background colour.
    assert_eq!(
        dielectric.parts.background,
        Background::Color(Vec3::new(0.5, 0.5, 0.6))
    );
}

#[test]
fn environment_maps_and_textures_load_as_linear_values() {
    let Some(cross) = load("willemsen/scenes_B/diffuseScene_multipleSpheres.json") else {
        return;
    };
    let Background::CubeMap(map) = &cross.parts.background else {
        panic!("expected the vertical cross as a cube map");
    };
    for face in &map.faces {
        assert_eq!((face.width, face.height), (512, 512));
    }
    assert!(cross.parts.lights.is_empty());

    let Some(cube) = load("willemsen/scenes_B/environmentMappedScene.json") else {
        return;
    };
    let Background::CubeMap(map) = &cube.parts.background else {
        panic!("expected the reef cube map");
    };
    let positive_x = image::open(
        corpus()
            .unwrap()
            .join("willemsen/scenes_B/images/reef_posX.png"),
    )
    .unwrap()
    .to_rgb8();
    let pixel = positive_x.get_pixel(10, 20);
    assert_eq!(
        map.faces[0].texel(10, 20),
        Vec3::new(
            f32::from(pixel[0]) / 255.0,
            f32::from(pixel[1]) / 255.0,
            f32::from(pixel[2]) / 255.0
        )
    );

    let Some(textured) = load("willemsen/scenes_B/texture_sphere.json") else {
        return;
    };
    assert_eq!(textured.parts.textures.len(), 1);
    let Material::Lambertian { diffuse } = &textured.parts.materials[0] else {
        panic!("expected a Lambertian");
    };
    assert_eq!(diffuse.texture, Some(0));
    let texture = &textured.parts.textures[0];
    assert!(texture
        .texels
        .iter()
        .all(|texel| (0.0..=1.0).contains(&texel.x)
            && (texel.x * 255.0 - (texel.x * 255.0).round()).abs() < 1e-3));
}

#[test]
fn emitters_and_area_lights_become_lights_and_geometry() {
    let Some(emitter) = load("willemsen/scenes_B/emitterTest.json") else {
        return;
    };
    let parts = &emitter.parts;
    assert_eq!(
        parts.lights,
        vec![Light::Sphere {
            center: Vec3::new(-1.0, 2.0, 2.0),
            radius: 0.25,
            intensity: Vec3::ONE
        }]
    );
    let plain = &parts.geometries[0];
    let emitting = plain
        .shapes
        .iter()
        .position(|shape| matches!(shape, Shape::Sphere { radius, .. } if *radius == 0.25))
        .unwrap();
    let Material::Emissive {
        radiance,
        surface,
        light,
    } = &parts.materials[plain.materials[emitting] as usize]
    else {
        panic!("the emitting sphere is not emissive");
    };
    assert_eq!(*radiance, Vec3::ONE);
    assert_eq!(*light, Some(0));
    // The shape's own shader (darkYellow) stays as its surface.
    assert_eq!(
        parts.materials[surface.unwrap() as usize],
        Material::Lambertian {
            diffuse: ColorSource::constant(Vec3::new(1.0, 1.0, 0.4))
        }
    );

    // Area lights: a Light::Area and an emissive rectangle that casts no shadow.
    let Some(dragons) = load("willemsen/scenes_B/metallicDragons.json") else {
        return;
    };
    let parts = &dragons.parts;
    let areas = parts
        .lights
        .iter()
        .filter(|light| matches!(light, Light::Area { .. }))
        .count();
    assert_eq!(areas, 3);
    let rectangles: Vec<_> = parts.instances.iter().filter(|i| !i.casts_shadow).collect();
    assert_eq!(rectangles.len(), 3);
    for rectangle in rectangles {
        let geometry = &parts.geometries[rectangle.geometry as usize];
        assert_eq!(geometry.shapes.len(), 2);
        assert!(matches!(
            parts.materials[geometry.materials[0] as usize],
            Material::Emissive { surface: None, .. }
        ));
    }

    // The student extension `"visible": 0` keeps the light but hides the rectangle.
    let Some(grid) = load("students/kvatsaas__renderer/scenes_custom/gridOfBunnies.json") else {
        return;
    };
    assert!(grid
        .parts
        .lights
        .iter()
        .any(|light| matches!(light, Light::Area { .. })));
    assert!(grid
        .parts
        .instances
        .iter()
        .all(|instance| instance.casts_shadow));
}
