//! Criterion benches of the ray engine (issue 3): BVH build, and closest-hit and shadow-ray
//! throughput on the Stanford bunny for coherent camera rays and incoherent bounce rays, with
//! the 8-wide BVH's AVX2 kernel, its scalar kernel, and the reference binary BVH, and camera
//! and shadow rays in packets of eight; and a small whole-frame render. `cargo bench -p glint-io --bench accel`.
//!
//! The whole-program table over all workloads is `glint bench table`; the comparison with
//! Embree is `bench/embree_compare.sh`.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glint_render::bench::{workload, AccelKind, Isa, WideBvh, PACKET};
use glint_render::{Ray, RenderSettings, Scene, SceneParts, Shape};

fn bunny() -> SceneParts {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models/stanford-bunny.obj");
    let mesh = glint_io::load_mesh(&path).expect("../shared/models/stanford-bunny.obj");
    workload::mesh_scene_parts(mesh.geometry())
}

fn rays(parts: &SceneParts) -> (Vec<Ray>, Vec<Ray>, Vec<Ray>) {
    let scene = Scene::new(parts.clone());
    let bounds = scene.bounds();
    let camera = workload::framing_camera(bounds);
    let primary = workload::primary_rays(&camera, 256, 256);
    let (bounce, shadow) =
        workload::secondary_rays(&scene, &primary, workload::default_light(bounds), 1);
    (primary, bounce, shadow)
}

fn build(c: &mut Criterion) {
    let parts = bunny();
    let shapes: Vec<Shape> = parts.geometries[0].shapes.clone();
    let mut group = c.benchmark_group("build");
    group.sample_size(10);
    group.throughput(Throughput::Elements(shapes.len() as u64));
    group.bench_function("bunny/wide", |b| {
        b.iter(|| black_box(glint_render::bench::build(&shapes)))
    });
    group.bench_function("bunny/binary", |b| {
        b.iter(|| {
            let bounds: Vec<_> = shapes.iter().map(Shape::bounds).collect();
            black_box(glint_render::bench::Bvh::build(&bounds))
        })
    });
    group.finish();
}

fn traverse(c: &mut Criterion) {
    let parts = bunny();
    let (primary, bounce, shadow) = rays(&parts);
    let wide = Scene::with_accel(parts.clone(), AccelKind::Wide);
    let binary = Scene::with_accel(parts.clone(), AccelKind::Binary);
    let built: WideBvh = glint_render::bench::build(&parts.geometries[0].shapes);
    let mut scalar = built.clone();
    scalar.set_isa(Isa::Scalar);
    let mut group = c.benchmark_group("bunny");
    group.sample_size(10);
    for (name, set) in [("primary", &primary), ("bounce", &bounce)] {
        group.throughput(Throughput::Elements(set.len() as u64));
        group.bench_with_input(BenchmarkId::new("wide-avx2", name), set, |b, rays| {
            b.iter(|| rays.iter().filter(|r| wide.intersect(r).is_some()).count())
        });
        group.bench_with_input(BenchmarkId::new("wide-scalar", name), set, |b, rays| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| scalar.intersect(r).is_some())
                    .count()
            })
        });
        group.bench_with_input(BenchmarkId::new("binary", name), set, |b, rays| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| binary.intersect(r).is_some())
                    .count()
            })
        });
    }
    group.throughput(Throughput::Elements(shadow.len() as u64));
    group.bench_with_input(
        BenchmarkId::new("wide-avx2", "shadow"),
        &shadow,
        |b, rays| b.iter(|| rays.iter().filter(|r| wide.occluded(r)).count()),
    );
    group.bench_with_input(BenchmarkId::new("binary", "shadow"), &shadow, |b, rays| {
        b.iter(|| rays.iter().filter(|r| binary.occluded(r)).count())
    });
    // Packets of eight (`Scene::intersect_packet`): camera rays of 4x2 pixel blocks, shadow
    // rays eight consecutive at a time.
    let blocks = pixel_blocks(&primary, 256);
    group.throughput(Throughput::Elements(primary.len() as u64));
    group.bench_with_input(
        BenchmarkId::new("wide-avx2-packets", "primary"),
        &blocks,
        |b, packets| {
            b.iter(|| {
                packets
                    .iter()
                    .map(|p| {
                        wide.instances()
                            .intersect_packet(p)
                            .iter()
                            .flatten()
                            .count()
                    })
                    .sum::<usize>()
            })
        },
    );
    let shadow_packets: Vec<[Ray; PACKET]> = shadow
        .chunks_exact(PACKET)
        .map(|c| std::array::from_fn(|l| c[l]))
        .collect();
    group.throughput(Throughput::Elements((shadow_packets.len() * PACKET) as u64));
    group.bench_with_input(
        BenchmarkId::new("wide-avx2-packets", "shadow"),
        &shadow_packets,
        |b, packets| {
            b.iter(|| {
                packets
                    .iter()
                    .map(|p| {
                        wide.instances()
                            .occluded_packet(p)
                            .iter()
                            .filter(|&&o| o)
                            .count()
                    })
                    .sum::<usize>()
            })
        },
    );
    group.finish();
}

/// Rays of a `width`-pixel-wide image (row by row) regrouped into 4x2 pixel blocks.
fn pixel_blocks(rays: &[Ray], width: usize) -> Vec<[Ray; PACKET]> {
    let height = rays.len() / width;
    let mut packets = Vec::new();
    for by in (0..height).step_by(2) {
        for bx in (0..width).step_by(4) {
            packets.push(std::array::from_fn(|l| {
                let (x, y) = ((bx + l % 4).min(width - 1), (by + l / 4).min(height - 1));
                rays[y * width + x]
            }));
        }
    }
    packets
}

fn frame(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/course/willemsen/scenes_B/StanfordDragon_Instanced.json");
    let parts = glint_io::load_scene(&path)
        .expect("instanced dragon scene")
        .parts;
    let scene = Scene::new(parts);
    let settings = RenderSettings {
        width: 128,
        height: 128,
        ..RenderSettings::default()
    };
    let mut group = c.benchmark_group("frame");
    group.sample_size(10);
    group.bench_function("instanced-dragon-128", |b| {
        b.iter(|| {
            glint_render::render(&scene, &settings, &|_| true).map(|(film, _)| film.pixels.len())
        })
    });
    group.finish();
}

criterion_group!(benches, build, traverse, frame);
criterion_main!(benches);
