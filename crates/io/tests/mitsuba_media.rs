//! Participating media in Mitsuba scenes: the nine scenes of Mitsuba's `participating_media`
//! test suite build the media, boundaries and integrator Mitsuba 3.9.1 builds from them;
//! media, volumes and phase functions written inline take Mitsuba's defaults and meanings; a
//! shape's interior and exterior are on the sides Mitsuba puts them; mistakes are located.

mod common;

use std::path::{Path, PathBuf};

use glint_io::{load_scene_with_defines, Limits, MemoryAssets, SceneError};
use glint_render::{
    Color, Medium, MediumBoundary, PhaseFunction, Ray, Scene, SceneIntegrator, SceneParts, Vec3,
    Volume,
};

fn suite() -> Option<PathBuf> {
    common::mitsuba_suite().map(|root| root.join("participating_media"))
}

fn load_suite(root: &Path, name: &str) -> SceneParts {
    glint_io::load_scene(&root.join(name))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .parts
}

/// A `.vol` file read here on its own, to hold the reader to the file's bytes.
struct Vol {
    size: [usize; 3],
    channels: usize,
    bbox: [f32; 6],
    data: Vec<f32>,
}

fn read_vol(path: &Path) -> Vol {
    let bytes = std::fs::read(path).unwrap();
    let i32_at = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let f32_at = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    assert_eq!(&bytes[..4], b"VOL\x03");
    Vol {
        size: [i32_at(8), i32_at(12), i32_at(16)],
        channels: i32_at(20),
        bbox: std::array::from_fn(|k| f32_at(24 + 4 * k)),
        data: bytes[48..]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect(),
    }
}

fn close(a: Color, b: [f32; 3], tolerance: f32) -> bool {
    (a.x - b[0]).abs() <= tolerance
        && (a.y - b[1]).abs() <= tolerance
        && (a.z - b[2]).abs() <= tolerance
}

#[track_caller]
fn assert_close(a: Color, b: [f32; 3]) {
    assert!(close(a, b, 1e-5), "{a:?} is not {b:?}");
}

/// Each geometry's boundary, `None` past the end of `boundaries`.
fn boundaries(parts: &SceneParts) -> Vec<Option<MediumBoundary>> {
    (0..parts.geometries.len())
        .map(|g| parts.physical.boundaries.get(g).copied().flatten())
        .collect()
}

const INSIDE_0: Option<MediumBoundary> = Some(MediumBoundary {
    interior: Some(0),
    exterior: None,
});

#[track_caller]
fn homogeneous(parts: &SceneParts, sigma_t: [f32; 3], albedo: [f32; 3]) {
    assert_eq!(parts.physical.media.len(), 1, "{:?}", parts.physical.media);
    let Medium::Homogeneous {
        sigma_t: s,
        albedo: a,
        phase,
        sample_emitters,
    } = parts.physical.media[0]
    else {
        panic!("{:?}", parts.physical.media[0])
    };
    assert_close(s, sigma_t);
    assert_close(a, albedo);
    assert_eq!((phase, sample_emitters), (PhaseFunction::Isotropic, true));
}

/// The integrator settings of `test-scene-base.xml` (`max_depth` 6) or of
/// `test-scene-base-no-bg.xml` (16), in Glint's count.
#[track_caller]
fn volpath(parts: &SceneParts, max_depth: u32) {
    let d = &parts.physical.defaults;
    assert_eq!(d.integrator, Some(SceneIntegrator::VolPath));
    assert_eq!(d.max_depth, Some(max_depth - 1));
    assert_eq!(d.russian_roulette_depth, Some(5));
    assert_eq!(parts.physical.camera_medium, None);
}

/// A grid volume's value at the centre of sample (i, j, k) of a grid whose unit cube
/// `to_world` maps to [lo, lo + extent]³, against the file's own sample there.
#[track_caller]
fn grid_matches_file(volume: &Volume, vol: &Vol, lo: f32, extent: f32) {
    let Volume::Grid { grid, .. } = volume else {
        panic!("{volume:?}")
    };
    assert_eq!(grid.size.map(|s| s as usize), vol.size);
    assert_eq!(grid.channels as usize, vol.channels);
    let bounds = volume.bounds().0;
    for (got, want) in [(bounds.min, lo), (bounds.max, lo + extent)] {
        assert!(
            (got - Vec3::splat(want)).abs().max_component() < 1e-5,
            "{bounds:?}"
        );
    }
    let file_max = vol.data.iter().copied().fold(f32::MIN, f32::max);
    assert_eq!(volume.max(), file_max);
    for [i, j, k] in [[0, 0, 0], [3, 11, 7], [15, 2, 9], [8, 15, 0]] {
        let centre = |n: usize, s: usize| lo + extent * (n as f32 + 0.5) / s as f32;
        let p = Vec3::new(
            centre(i, vol.size[0]),
            centre(j, vol.size[1]),
            centre(k, vol.size[2]),
        );
        let index = ((k * vol.size[1] + j) * vol.size[0] + i) * vol.channels;
        let want = if vol.channels == 1 {
            [vol.data[index]; 3]
        } else {
            [vol.data[index], vol.data[index + 1], vol.data[index + 2]]
        };
        assert!(
            close(volume.eval(p), want, 1e-4),
            "sample {i} {j} {k}: {:?}, the file has {want:?}",
            volume.eval(p)
        );
    }
}

#[test]
fn the_homogeneous_scenes_build_their_media() {
    let Some(root) = suite() else { return };
    // The background, sphere_tiny and sphere_base, both spheres holding the medium, and the
    // emitting cube.
    let parts = load_suite(&root, "test_homo_area_light_volpath.xml");
    homogeneous(&parts, [2.5; 3], [0.99, 0.999, 0.99]);
    assert_eq!(boundaries(&parts), [None, INSIDE_0, INSIDE_0, None]);
    volpath(&parts, 6);

    let parts = load_suite(&root, "test_homo_null_envmap_volpath.xml");
    homogeneous(&parts, [3.0; 3], [0.99, 0.5, 0.5]);
    assert_eq!(boundaries(&parts), [None, INSIDE_0, INSIDE_0]);
    volpath(&parts, 6);

    let parts = load_suite(&root, "test_homo_obj_inside_medium_volpath.xml");
    homogeneous(&parts, [2.0; 3], [0.99, 0.7, 0.7]);
    assert_eq!(boundaries(&parts), [None, INSIDE_0, INSIDE_0, None, None]);
    volpath(&parts, 6);

    // No background shape in this one's base.
    let parts = load_suite(&root, "test_homo_roughdielectric_spot_volpath.xml");
    homogeneous(&parts, [0.102, 0.993, 0.103], [0.101, 0.105, 0.109]);
    assert_eq!(boundaries(&parts), [INSIDE_0, INSIDE_0]);
    volpath(&parts, 16);

    let parts = load_suite(&root, "test_homo_spectral_sigmat_volpathmis.xml");
    homogeneous(&parts, [10.0, 2.0, 10.0], [0.5, 0.5, 0.99]);
    assert_eq!(boundaries(&parts), [None, INSIDE_0, INSIDE_0]);
    volpath(&parts, 6);

    let parts = load_suite(&root, "test_surf_area_light_volpath.xml");
    assert!(parts.physical.media.is_empty());
    assert_eq!(boundaries(&parts), [None; 4]);
    volpath(&parts, 6);
}

#[test]
fn the_heterogeneous_scenes_build_their_volumes() {
    let Some(root) = suite() else { return };
    // sigma_t: sigmat.vol (16³, one channel, box (0,0,0)-(1,1,1)) placed by
    // translate(-0.5) · scale(1.5), the file's box unused: the unit cube goes to
    // [-0.5, 1]³. The plain rgb albedo is a constant volume over the unit cube.
    let parts = load_suite(&root, "test_hetero_sigmat_volpath.xml");
    volpath(&parts, 6);
    assert_eq!(boundaries(&parts), [None, INSIDE_0, None]);
    let [Medium::Heterogeneous {
        sigma_t,
        albedo,
        scale,
        phase,
        sample_emitters,
    }] = parts.physical.media.as_slice()
    else {
        panic!("{:?}", parts.physical.media)
    };
    assert_eq!(
        (*scale, *phase, *sample_emitters),
        (5.0, PhaseFunction::Isotropic, true)
    );
    let vol = read_vol(&root.join("textures/sigmat.vol"));
    assert_eq!((vol.size, vol.channels), ([16; 3], 1));
    assert_eq!(vol.bbox, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    grid_matches_file(sigma_t, &vol, -0.5, 1.5);
    let Volume::Constant { value, bounds } = albedo else {
        panic!("{albedo:?}")
    };
    assert_close(*value, [0.99, 0.5, 0.5]);
    assert_eq!((bounds.0.min, bounds.0.max), (Vec3::ZERO, Vec3::ONE));

    // A constvolume's rgb sigma_t over the unit cube moved by -0.5, and a black albedo.
    let parts = load_suite(
        &root,
        "test_hetero_spectral_sigmat_no_scattering_volpath.xml",
    );
    volpath(&parts, 6);
    assert_eq!(boundaries(&parts), [None, INSIDE_0, None]);
    let [Medium::Heterogeneous {
        sigma_t: Volume::Constant { value, bounds },
        albedo: Volume::Constant { value: black, .. },
        scale: 5.0,
        ..
    }] = parts.physical.media.as_slice()
    else {
        panic!("{:?}", parts.physical.media)
    };
    assert_close(*value, [0.5, 0.4, 0.3]);
    assert_eq!(*black, Color::ZERO);
    assert_eq!(
        (bounds.0.min, bounds.0.max),
        (Vec3::splat(-0.5), Vec3::splat(0.5))
    );

    // albedo.vol's three channels as the extinction, under volpathmis.
    let parts = load_suite(&root, "test_hetero_spectral_sigmat_volpathmis.xml");
    volpath(&parts, 6);
    let [Medium::Heterogeneous {
        sigma_t,
        albedo: Volume::Constant { value, .. },
        scale: 2.0,
        ..
    }] = parts.physical.media.as_slice()
    else {
        panic!("{:?}", parts.physical.media)
    };
    assert_close(*value, [0.99; 3]);
    let vol = read_vol(&root.join("textures/albedo.vol"));
    assert_eq!((vol.size, vol.channels), ([16; 3], 3));
    grid_matches_file(sigma_t, &vol, -0.5, 1.5);
}

// ---- scenes written here -----------------------------------------------------------------

fn load_with(text: &str, files: &[(&str, Vec<u8>)]) -> Result<glint_io::LoadedScene, SceneError> {
    let mut assets = MemoryAssets::new();
    for (name, bytes) in files {
        assets.insert(Path::new("mem").join(name), bytes.clone());
    }
    load_scene_with_defines(
        text,
        Path::new("mem/scene.xml"),
        &assets,
        &Limits::default(),
        &[],
    )
}

fn load(text: &str) -> SceneParts {
    load_with(text, &[]).unwrap().parts
}

fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>")
}

/// A `.vol` file of `size` samples of `channels` values each, `value(x, y, z, channel)`.
fn vol_bytes(
    size: [i32; 3],
    channels: i32,
    bbox: [f32; 6],
    value: impl Fn(usize, usize, usize, usize) -> f32,
) -> Vec<u8> {
    let mut bytes = b"VOL\x03".to_vec();
    for v in [1, size[0], size[1], size[2], channels] {
        bytes.extend(v.to_le_bytes());
    }
    for v in bbox {
        bytes.extend(v.to_le_bytes());
    }
    for z in 0..size[2] as usize {
        for y in 0..size[1] as usize {
            for x in 0..size[0] as usize {
                for c in 0..channels as usize {
                    bytes.extend(value(x, y, z, c).to_le_bytes());
                }
            }
        }
    }
    bytes
}

#[test]
fn media_take_mitsubas_defaults() {
    // sigma_t 1, albedo 0.75, isotropic, emitter sampling on (homogeneous.cpp,
    // heterogeneous.cpp, medium.cpp); hg's g 0.8 (hg.cpp).
    let parts = load(&scene(
        r#"<medium type="homogeneous" id="h"/>
        <medium type="heterogeneous" id="v"><phase type="hg"/></medium>
        <shape type="sphere"><ref name="interior" id="h"/><ref name="exterior" id="v"/></shape>"#,
    ));
    let [Medium::Homogeneous {
        sigma_t,
        albedo,
        phase: PhaseFunction::Isotropic,
        sample_emitters: true,
    }, Medium::Heterogeneous {
        sigma_t: Volume::Constant { value, bounds },
        albedo: Volume::Constant { value: a, .. },
        scale: 1.0,
        phase: PhaseFunction::HenyeyGreenstein { g },
        sample_emitters: true,
    }] = parts.physical.media.as_slice()
    else {
        panic!("{:?}", parts.physical.media)
    };
    assert_eq!((*sigma_t, *albedo), (Color::ONE, Color::splat(0.75)));
    // A plain value's volume is Mitsuba's constvolume with an identity to_world: the unit
    // cube bounds the heterogeneous medium's extinction.
    assert_eq!((*value, *a), (Color::ONE, Color::splat(0.75)));
    assert_eq!((bounds.0.min, bounds.0.max), (Vec3::ZERO, Vec3::ONE));
    assert_eq!(*g, 0.8);
    assert_eq!(
        parts.physical.boundaries,
        [Some(MediumBoundary {
            interior: Some(0),
            exterior: Some(1),
        })]
    );
}

#[test]
fn media_are_read_as_mitsuba_reads_them() {
    let grid = vol_bytes(
        [2, 2, 2],
        3,
        [0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        |_, _, _, c| 0.25 * c as f32,
    );
    let text = scene(
        r#"<medium type="homogeneous" id="unused"><float name="sigma_t" value="3"/></medium>
        <medium type="homogeneous" id="fog">
            <float name="scale" value="4"/>
            <volume type="constvolume" name="sigma_t"><rgb name="value" value="0.5, 2, 3"/></volume>
            <spectrum name="albedo" value="400:0.78, 500:0.78, 600:0.78, 700:0.78"/>
            <boolean name="sample_emitters" value="false"/>
            <boolean name="has_spectral_extinction" value="false"/>
            <phase type="hg" name="whatever"><float name="g" value="-0.3"/></phase>
        </medium>
        <sensor type="perspective"><ref id="fog"/></sensor>
        <shape type="sphere"/>
        <shape type="rectangle">
            <medium type="heterogeneous" name="interior">
                <volume type="gridvolume" name="albedo">
                    <string name="filename" value="g.vol"/>
                    <boolean name="use_grid_bbox" value="true"/>
                    <transform name="to_world"><translate x="10"/></transform>
                    <string name="filter_type" value="trilinear"/>
                    <string name="wrap_mode" value="clamp"/>
                    <boolean name="raw" value="true"/>
                </volume>
            </medium>
            <ref name="exterior" id="fog"/>
        </shape>
        <shape type="sphere"><ref name="interior" id="fog"/></shape>"#,
    );
    let parts = load_with(&text, &[("g.vol", grid)]).unwrap().parts;
    // The unused medium is not among the parts; "fog" is one medium wherever it is used.
    let media = &parts.physical.media;
    assert_eq!(media.len(), 2, "{media:?}");
    let Medium::Homogeneous {
        sigma_t,
        albedo,
        phase,
        sample_emitters,
    } = media[0]
    else {
        panic!("{media:?}")
    };
    // A constvolume's value is unbounded; `scale` multiplies σt. The spectrum is converted as
    // a reflectance (mitsuba_reader.rs holds the same numbers from pip mitsuba 3.9.1).
    assert_close(sigma_t, [2.0, 8.0, 12.0]);
    assert!(
        close(albedo, [0.776368, 0.779809, 0.776029], 2e-5),
        "{albedo:?}"
    );
    assert_eq!(
        (phase, sample_emitters),
        (PhaseFunction::HenyeyGreenstein { g: -0.3 }, false)
    );
    assert_eq!(parts.physical.camera_medium, Some(0));
    assert_eq!(
        boundaries(&parts),
        [
            None,
            Some(MediumBoundary {
                interior: Some(1),
                exterior: Some(0)
            }),
            Some(MediumBoundary {
                interior: Some(0),
                exterior: None
            }),
        ]
    );
}

#[test]
fn an_emitters_medium_is_checked_and_ignored() {
    // Mitsuba's endpoints take a medium, but of its integrators only the sensor's is read.
    let loaded = load_with(
        &scene(
            r#"<medium type="homogeneous" id="m"/>
        <emitter type="point"><ref id="m"/></emitter>
        <shape type="sphere"><emitter type="area">
            <medium type="heterogeneous" name="medium"/></emitter></shape>"#,
        ),
        &[],
    )
    .unwrap();
    assert!(loaded.parts.physical.media.is_empty());
    let lines: Vec<u32> = loaded
        .warnings
        .iter()
        .filter(|w| w.message.contains("emitter's medium is ignored"))
        .map(|w| w.line)
        .collect();
    assert_eq!(lines, [3, 5], "{:?}", loaded.warnings);
    // Still checked.
    let (line, message) = error_line(load_with(
        &scene("<emitter type=\"point\">\n<medium type=\"homogeneous\"><float name=\"sigma\" value=\"1\"/></medium></emitter>"),
        &[],
    ));
    assert_eq!(line, 3);
    assert!(message.contains("sigma"), "{message}");
}

#[test]
fn a_grid_placed_by_its_files_box() {
    // use_grid_bbox: the unit cube goes onto the file's box, then to_world: here
    // translate(10, 0, 0) · translate(1, 2, 3) · scale(2, 1, 2), a box from (11, 2, 3) to
    // (13, 3, 5).
    let grid = vol_bytes(
        [4, 2, 3],
        3,
        [1.0, 2.0, 3.0, 3.0, 3.0, 5.0],
        |x, y, z, c| (100 * z + 10 * y + x) as f32 + c as f32 * 0.25,
    );
    let text = |bbox: bool| {
        scene(&format!(
            r#"<shape type="sphere"><medium type="heterogeneous" name="interior">
                <volume type="gridvolume" name="sigma_t">
                    <string name="filename" value="g.vol"/>
                    <boolean name="use_grid_bbox" value="{bbox}"/>
                    <transform name="to_world"><translate x="10"/></transform>
                </volume>
            </medium></shape>"#
        ))
    };
    let parts = load_with(&text(true), &[("g.vol", grid.clone())])
        .unwrap()
        .parts;
    let Medium::Heterogeneous { sigma_t, .. } = &parts.physical.media[0] else {
        panic!()
    };
    let bounds = sigma_t.bounds().0;
    assert_eq!(
        (bounds.min, bounds.max),
        (Vec3::new(11.0, 2.0, 3.0), Vec3::new(13.0, 3.0, 5.0))
    );
    // Sample (3, 0, 2)'s centre: x = 11 + 2 · 3.5/4, y = 2 + 0.5/2, z = 3 + 2 · 2.5/3.
    let p = Vec3::new(11.0 + 2.0 * 3.5 / 4.0, 2.25, 3.0 + 2.0 * 2.5 / 3.0);
    assert!(close(sigma_t.eval(p), [203.0, 203.25, 203.5], 1e-3));
    // Without it the file's box is ignored: the unit cube moved by 10.
    let parts = load_with(&text(false), &[("g.vol", grid)]).unwrap().parts;
    let Medium::Heterogeneous { sigma_t, .. } = &parts.physical.media[0] else {
        panic!()
    };
    let bounds = sigma_t.bounds().0;
    assert_eq!(
        (bounds.min, bounds.max),
        (Vec3::new(10.0, 0.0, 0.0), Vec3::new(11.0, 1.0, 1.0))
    );
}

#[test]
fn volpath_and_volpathmis_read_the_path_tracers_settings() {
    for (plugin, extra) in [
        ("volpath", ""),
        (
            "volpathmis",
            r#"<boolean name="use_spectral_mis" value="false"/>"#,
        ),
    ] {
        let parts = load(&scene(&format!(
            r#"<integrator type="moment"><integrator type="{plugin}">
                <integer name="max_depth" value="8"/><integer name="rr_depth" value="3"/>
                <boolean name="hide_emitters" value="true"/>{extra}
            </integrator></integrator>"#
        )));
        let d = parts.physical.defaults;
        assert_eq!(
            (
                d.integrator,
                d.max_depth,
                d.russian_roulette_depth,
                d.hide_emitters
            ),
            (Some(SceneIntegrator::VolPath), Some(7), Some(3), true),
            "{plugin}"
        );
    }
    // volpath has no spectral MIS to turn off.
    let (line, message) = error_line(load_with(
        &scene(
            r#"<integrator type="volpath">
    <boolean name="use_spectral_mis" value="false"/></integrator>"#,
        ),
        &[],
    ));
    assert_eq!(line, 3, "{message}");
}

// ---- which side is which ------------------------------------------------------------------

/// The medium a ray along `direction` from `origin` enters when it crosses the first surface
/// it meets, as Glint's volumetric path tracer decides it: by the geometric normal of the
/// built scene. The shape has interior medium 0 and exterior medium 1.
fn entered(parts: SceneParts, origin: Vec3, direction: Vec3) -> Option<u32> {
    let scene = Scene::new(parts);
    let ray = Ray::new(origin, direction);
    let hit = scene.intersect(&ray).expect("the ray hits the shape");
    let surface = scene.physical_surface(&ray, &hit);
    let boundary = scene.medium_boundary(&hit).expect("the shape bounds media");
    boundary.target(surface.normal, direction)
}

#[test]
fn interior_and_exterior_are_on_mitsubas_sides() {
    // A tetrahedron whose faces are wound counter-clockwise seen from outside, so that the
    // cross product of their edges points out.
    let tetrahedron = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    // A sphere of radius 0.3 about the unit cube's centre as a signed distance, negative
    // inside, sampled at (i / 15, j / 15, k / 15) as sdfgrid places its samples.
    let sdf = vol_bytes([16; 3], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0], |x, y, z, _| {
        let d = Vec3::new(x as f32, y as f32, z as f32) / 15.0 - Vec3::splat(0.5);
        d.length() - 0.3
    });
    let files = [("t.obj", tetrahedron.to_vec()), ("s.vol", sdf)];
    const INSIDE: Option<u32> = Some(0);
    const OUTSIDE: Option<u32> = Some(1);
    let up = Vec3::Z;
    // What Mitsuba 3.9.1 decides: a ray goes into the exterior medium when it travels along
    // the geometric normal (`target_medium`, interaction.h), and that normal is
    // - for meshes (obj, ply, serialized, rectangle, cube), the cross product of the
    //   triangle's edges after `to_world` (mesh.cpp), so a mirror turns it over;
    // - for the sphere, outwards, unless the polar decomposition of `to_world` has a
    //   negative scale, which toggles `flip_normals` (sphere.cpp): a mirror turns it in;
    // - for the cylinder, the outward normal carried as a normal, with `flip_normals`
    //   toggled by a mirror (cylinder.cpp): a mirror turns it in;
    // - for the disk and sdfgrid, `to_world` applied to the normal or gradient as a normal,
    //   which a mirror does not turn over (disk.cpp, sdfgrid.cpp);
    // and `flip_normals` turns each of them over.
    let mirror_x = r#"<transform name="to_world"><scale x="-1"/></transform>"#;
    let mirror_z = r#"<transform name="to_world"><scale z="-1"/></transform>"#;
    let flip = r#"<boolean name="flip_normals" value="true"/>"#;
    let cases: Vec<(&str, &str, Vec3, Vec3, Option<u32>)> = vec![
        // Into a closed shape from outside, at the bottom (normal -z).
        (
            r#"type="sphere""#,
            "",
            Vec3::new(0.0, 0.0, -5.0),
            up,
            INSIDE,
        ),
        (
            r#"type="sphere""#,
            mirror_x,
            Vec3::new(0.0, 0.0, -5.0),
            up,
            OUTSIDE,
        ),
        (r#"type="cube""#, "", Vec3::new(0.1, 0.2, -5.0), up, INSIDE),
        (
            r#"type="cube""#,
            mirror_x,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            OUTSIDE,
        ),
        (
            r#"type="cube""#,
            flip,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            OUTSIDE,
        ),
        (r#"type="obj""#, "", Vec3::new(0.2, 0.2, -5.0), up, INSIDE),
        (
            r#"type="obj""#,
            mirror_x,
            Vec3::new(-0.2, 0.2, -5.0),
            up,
            OUTSIDE,
        ),
        (
            r#"type="obj""#,
            flip,
            Vec3::new(0.2, 0.2, -5.0),
            up,
            OUTSIDE,
        ),
        (
            r#"type="sdfgrid""#,
            "",
            Vec3::new(0.5, 0.52, -5.0),
            up,
            INSIDE,
        ),
        (
            r#"type="sdfgrid""#,
            mirror_x,
            Vec3::new(-0.5, 0.52, -5.0),
            up,
            INSIDE,
        ),
        // Into the open tube through its side (normal -y there).
        (
            r#"type="cylinder""#,
            "",
            Vec3::new(0.1, -5.0, 0.5),
            Vec3::Y,
            INSIDE,
        ),
        (
            r#"type="cylinder""#,
            mirror_x,
            Vec3::new(0.1, -5.0, 0.5),
            Vec3::Y,
            OUTSIDE,
        ),
        (
            r#"type="cylinder""#,
            flip,
            Vec3::new(0.1, -5.0, 0.5),
            Vec3::Y,
            OUTSIDE,
        ),
        // Up through a flat shape whose object normal is +z.
        (
            r#"type="rectangle""#,
            "",
            Vec3::new(0.1, 0.2, -5.0),
            up,
            OUTSIDE,
        ),
        (
            r#"type="rectangle""#,
            mirror_x,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            INSIDE,
        ),
        (
            r#"type="rectangle""#,
            flip,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            INSIDE,
        ),
        (r#"type="disk""#, "", Vec3::new(0.1, 0.2, -5.0), up, OUTSIDE),
        (
            r#"type="disk""#,
            mirror_x,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            OUTSIDE,
        ),
        (
            r#"type="disk""#,
            mirror_z,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            INSIDE,
        ),
        (
            r#"type="disk""#,
            flip,
            Vec3::new(0.1, 0.2, -5.0),
            up,
            INSIDE,
        ),
    ];
    for (shape, extra, origin, direction, want) in cases {
        let file = match shape {
            r#"type="obj""# => r#"<string name="filename" value="t.obj"/>"#,
            r#"type="sdfgrid""# => r#"<string name="filename" value="s.vol"/>"#,
            _ => "",
        };
        let text = scene(&format!(
            r#"<medium type="homogeneous" id="in"/><medium type="homogeneous" id="out"/>
            <shape {shape}>{file}{extra}
                <ref name="interior" id="in"/><ref name="exterior" id="out"/>
            </shape>"#
        ));
        let parts = load_with(&text, &files)
            .unwrap_or_else(|e| panic!("{shape} {extra}: {e}"))
            .parts;
        assert_eq!(
            parts.physical.media.len(),
            2,
            "{shape} {extra}: the interior is medium 0"
        );
        assert_eq!(
            entered(parts, origin, direction),
            want,
            "{shape} {extra}: the ray enters the wrong medium"
        );
    }
}

#[test]
fn shapes_in_a_shapegroup_bound_media() {
    // The geometry is shared by the instances; its media are the shape's.
    let parts = load(&scene(
        r#"<medium type="homogeneous" id="m"/>
        <shape type="shapegroup" id="g">
            <shape type="sphere"><ref name="interior" id="m"/></shape>
        </shape>
        <shape type="instance"><ref id="g"/></shape>
        <shape type="instance"><ref id="g"/>
            <transform name="to_world"><translate x="3"/></transform></shape>"#,
    ));
    assert_eq!(boundaries(&parts), [INSIDE_0]);
    assert_eq!(parts.instances.len(), 2);
}

// ---- mistakes -----------------------------------------------------------------------------

/// The line of a located error, and its message.
#[track_caller]
fn error_line(result: Result<glint_io::LoadedScene, SceneError>) -> (u32, String) {
    let error = result.expect_err("the load fails");
    let d = error.diagnostic().expect("located").clone();
    assert!(d.column >= 1);
    (d.line, d.message)
}

#[test]
fn mistakes_in_media_are_located() {
    let grid = |channels| {
        vol_bytes(
            [2, 2, 2],
            channels,
            [0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            |_, _, _, _| 1.0,
        )
    };
    let mut truncated = grid(1);
    truncated.truncate(60);
    let files = [
        ("one.vol", grid(1)),
        ("six.vol", grid(6)),
        ("cut.vol", truncated),
    ];
    // Each case: the body (line 2 onwards of the scene), the line the error is on, and what
    // the message says.
    let volume = |inner: &str| {
        format!(
            "<shape type=\"sphere\"><medium type=\"heterogeneous\" name=\"interior\">\n\
             <volume type=\"gridvolume\" name=\"sigma_t\">\n\
             <string name=\"filename\" value=\"one.vol\"/>\n{inner}\n</volume></medium></shape>"
        )
    };
    let cases: Vec<(String, u32, &str)> = vec![
        (
            "<medium type=\"homogeneous\" id=\"m\">\n<float name=\"sigma_s\" value=\"1\"/>\n</medium>".into(),
            3,
            "sigma_s",
        ),
        ("<medium type=\"homogenous\" id=\"m\"/>".into(), 2, "did you mean"),
        (
            "<medium type=\"homogeneous\" id=\"m\">\n<phase type=\"hg\">\n<float name=\"g\" value=\"1\"/>\n</phase></medium>".into(),
            4,
            "(-1, 1)",
        ),
        ("<phase type=\"rayleigh\"/>".into(), 2, "rayleigh"),
        (
            "<medium type=\"homogeneous\" id=\"m\">\n<phase type=\"isotropic\"/>\n<phase type=\"isotropic\"/>\n</medium>".into(),
            4,
            "one phase function",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\">\n<volume type=\"gridvolume\" name=\"sigma_t\">\n<string name=\"filename\" value=\"one.vol\"/></volume>\n</medium>".into(),
            3,
            "homogeneous medium takes a constant",
        ),
        (
            "<medium type=\"heterogeneous\" id=\"m\">\n<volume type=\"gridvolum\" name=\"sigma_t\"/>\n</medium>".into(),
            3,
            "gridvolume",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\">\n<rgb name=\"sigma_t\" value=\"2, 2, 2\"/>\n</medium>".into(),
            3,
            "[0, 1]",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\">\n<float name=\"sigma_t\" value=\"-1\"/>\n</medium>".into(),
            3,
            "negative",
        ),
        (volume("<string name=\"filter_type\" value=\"nearest\"/>"), 5, "trilinear"),
        (volume("<string name=\"wrap_mode\" value=\"repeat\"/>"), 5, "clamp"),
        (volume("<string name=\"wrap_mode\" value=\"wrap\"/>"), 5, "invalid wrap_mode"),
        (volume("<float name=\"max_value\" value=\"3\"/>"), 5, "majorant"),
        (
            volume("").replace("one.vol", "six.vol"),
            4,
            "6 channels",
        ),
        (
            volume("").replace("one.vol", "cut.vol"),
            4,
            "cut.vol",
        ),
        (
            "<shape type=\"sphere\">\n<ref id=\"fog\" name=\"interior\"/>\n</shape>".into(),
            3,
            "fog",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\"/>\n<shape type=\"sphere\">\n<ref id=\"m\" name=\"inside\"/>\n</shape>".into(),
            4,
            "`interior` or `exterior`",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\"/>\n<shape type=\"sphere\">\n<ref id=\"m\"/>\n</shape>".into(),
            4,
            "`interior` or `exterior`",
        ),
        (
            "<bsdf type=\"diffuse\" id=\"b\"/>\n<shape type=\"sphere\">\n<ref id=\"b\" name=\"interior\"/>\n</shape>".into(),
            4,
            "must be a medium",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\"/>\n<sensor type=\"perspective\"><ref id=\"m\"/>\n<ref id=\"m\" name=\"medium\"/></sensor>".into(),
            4,
            "one medium",
        ),
        (
            "<medium type=\"homogeneous\" id=\"m\"/>\n<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>\n<shape type=\"instance\"><ref id=\"g\"/>\n<ref id=\"m\" name=\"interior\"/></shape>".into(),
            5,
            "instance takes no media",
        ),
    ];
    for (body, line, says) in cases {
        let text = scene(&body);
        let (got, message) = error_line(load_with(&text, &files));
        assert!(message.contains(says), "{body}\n{message}");
        assert_eq!(got, line, "{body}\n{message}");
    }
    // The truncated file: named, with the byte offset where its data falls short.
    let (_, message) = error_line(load_with(
        &scene(&volume("").replace("one.vol", "cut.vol")),
        &files,
    ));
    assert!(message.contains("byte 48"), "{message}");
}
