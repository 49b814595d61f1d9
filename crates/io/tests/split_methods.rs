//! `-s`: every split method renders the course's scenes bit for bit alike (the same closest
//! hits: ties in t go to the lowest primitive as given, whatever the tree), with both
//! integrators; and the methods do build different trees.

mod common;

use glint_render::{
    render, Film, IntegratorKind, RenderSettings, Scene, SceneOptions, SplitMethod,
};

fn bits(film: &Film) -> Vec<u32> {
    film.pixels
        .iter()
        .flat_map(|p| p.to_array().map(f32::to_bits))
        .collect()
}

#[test]
fn every_split_method_renders_the_same_image() {
    let Some(dir) = common::corpus() else { return };
    // (scene, integrator, big enough that the methods must build different trees)
    let cases = [
        (
            "willemsen/scenes_A/spheres_1K.xml",
            IntegratorKind::Course,
            true,
        ),
        (
            "willemsen/scenes_A/boxSphereTest.json",
            IntegratorKind::Course,
            true,
        ),
        (
            "willemsen/scenes_A/spheresAndTriangles.json",
            IntegratorKind::Path,
            false,
        ),
        (
            "willemsen/scenes_B/CornellBox_Dielectric.json",
            IntegratorKind::Course,
            false,
        ),
        (
            "willemsen/scenes_B/rowOfBunnys.json",
            IntegratorKind::Course,
            true,
        ),
        (
            "willemsen/scenes_B/StanfordDragon_Instanced.json",
            IntegratorKind::Path,
            true,
        ),
    ];
    for (name, integrator, big) in cases {
        let parts = glint_io::load_scene(&dir.join(name)).expect("loads").parts;
        let settings = RenderSettings {
            width: 48,
            height: 36,
            samples_per_pixel: 4,
            seed: 3,
            integrator,
            ..RenderSettings::default()
        };
        let mut reference: Option<(Vec<u32>, usize)> = None;
        let mut node_counts = Vec::new();
        for split in SplitMethod::ALL {
            let scene = Scene::with_options(parts.clone(), SceneOptions { split });
            assert_eq!(scene.bvh_stats().split, split);
            node_counts.push(scene.bvh_stats().nodes);
            let (film, _) = render(&scene, &settings, &|_| true).expect("renders");
            let image = bits(&film);
            match &reference {
                None => {
                    let lit = film
                        .pixels
                        .iter()
                        .filter(|p| p.max_component() > 0.0)
                        .count();
                    assert!(lit > 0, "{name}: a black image proves nothing");
                    reference = Some((image, lit));
                }
                Some((expected, _)) => {
                    let differing = image.iter().zip(expected).filter(|(a, b)| a != b).count();
                    assert_eq!(
                        differing,
                        0,
                        "{name}: {} differs from {}",
                        split.name(),
                        SplitMethod::ALL[0].name()
                    );
                }
            }
        }
        node_counts.dedup();
        assert!(
            !big || node_counts.len() > 1,
            "{name}: every method built the same number of nodes"
        );
    }
}
