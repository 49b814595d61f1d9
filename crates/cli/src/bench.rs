//! `glint bench`: measures the ray engine on fixed workloads.
//!
//! - `glint bench table` prints one table over the shared meshes and the course scenes: BVH
//!   build time, memory per unique primitive, and millions of rays per second for coherent
//!   primary rays, incoherent bounce rays and shadow rays, on 1 thread and on all threads.
//! - `glint bench make-rays` writes those ray sets in `../shared/bench/embree_rays.py`'s format.
//! - `glint bench rays` traces one ray file on one mesh and prints one JSON line with the same
//!   fields as that script, so that Glint and Embree are measured the same way; `--packets`
//!   traces it in packets of eight rays (4x2 pixel blocks of primary rays).
//! - `glint bench packets` compares packet and single-ray traversal on the same rays, runs
//!   alternating, and prints medians and their ratio.
//!
//! Rays are generated before the timed region: the figures are traversal and intersection
//! alone. Each figure is the best of `--repeat` runs (as `embree_rays.py` reports it); the
//! table also reports build times as medians.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, Subcommand, ValueEnum};
use glint_render::bench::workload::{self, Workload};
use glint_render::bench::{AccelKind, Isa, WalkCounts, PACKET};
use glint_render::{Aabb, Camera, Light, Ray, Scene, SceneParts, Vec3};
use rayon::prelude::*;

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub command: BenchCommand,

    /// Print help (-? and -h alike; -h is the image height only where a command renders).
    #[arg(short = '?', short_alias = 'h', long, action = clap::ArgAction::Help, global = true)]
    pub help: Option<bool>,
}

#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Print the table of build times, memory and ray throughput over the fixed workloads.
    Table(TableArgs),
    /// Trace one ray file on one mesh and print one JSON line (the fields of embree_rays.py).
    Rays(RaysArgs),
    /// Write the primary, bounce, shadow and random ray sets of a mesh or scene to .rays files.
    MakeRays(MakeRaysArgs),
    /// Packet against single-ray traversal on the same rays, alternating; medians and ratios.
    Packets(PacketsArgs),
}

/// Which acceleration structure the bottom level uses.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccelArg {
    /// The 8-wide BVH with SIMD traversal (the default).
    Wide,
    /// The reference binary BVH.
    Binary,
}

impl From<AccelArg> for AccelKind {
    fn from(arg: AccelArg) -> AccelKind {
        match arg {
            AccelArg::Wide => AccelKind::Wide,
            AccelArg::Binary => AccelKind::Binary,
        }
    }
}

#[derive(Args, Debug)]
pub struct TableArgs {
    /// The shared folder with models/ and scenes/course/.
    #[arg(long, value_name = "DIR", default_value = "../shared")]
    pub shared: PathBuf,
    /// Image side of the primary rays.
    #[arg(long, value_name = "PIXELS", default_value_t = 1024)]
    pub size: u32,
    /// Runs per figure (the best is reported).
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub repeat: usize,
    /// Only the workloads whose name contains this text.
    #[arg(long, value_name = "TEXT")]
    pub only: Option<String>,
    /// Threads for the "all threads" columns [default: all cores].
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Acceleration structure.
    #[arg(long, value_enum, default_value_t = AccelArg::Wide)]
    pub accel: AccelArg,
    /// Also write each workload's ray sets into this folder.
    #[arg(long, value_name = "DIR")]
    pub write_rays: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct RaysArgs {
    /// Mesh file, .obj or .ply.
    #[arg(long, value_name = "MESH")]
    pub mesh: PathBuf,
    /// Ray file (little-endian f32, origin and direction per ray).
    #[arg(long, value_name = "FILE.rays")]
    pub rays: PathBuf,
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub threads: usize,
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub repeat: usize,
    /// Any-hit (shadow) queries instead of closest hit.
    #[arg(long)]
    pub occlusion: bool,
    /// Write the closest-hit t of every ray (inf for a miss).
    #[arg(long, value_name = "FILE.t")]
    pub write_t: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = AccelArg::Wide)]
    pub accel: AccelArg,
    /// Also count the walk (untimed, a separate counting traversal of the wide BVH): inner
    /// nodes visited and triangle blocks tested per ray, printed as `nodes_per_ray` and
    /// `blocks_per_ray`; and the tree's shape: `nodes`, `leaves` and `sah_cost` (as Embree's
    /// `verbose=2` statistics count it: Σ node areas + Σ leaf areas · blocks, over the root's)
    #[arg(long)]
    pub count: bool,
    /// Trace in packets of eight rays (`Scene::intersect_packet`): 4x2 pixel blocks of an image
    /// `--image-width` pixels wide, or eight consecutive rays where the width is unknown.
    #[arg(long)]
    pub packets: bool,
    /// Width of the image the rays were shot through, row by row [default: the square root of
    /// the ray count when it is a square, as for `make-rays` primary rays].
    #[arg(long, value_name = "PIXELS", requires = "packets")]
    pub image_width: Option<u32>,
    /// Packets of eight consecutive rays whatever the width (8x1 pixel rows of primary rays,
    /// the packets of `embree_native`'s `rtcIntersect8`).
    #[arg(long, requires = "packets", conflicts_with = "image_width")]
    pub consecutive: bool,
    /// Which single-ray walk the wide bottom levels run: the best this CPU has (`auto`: the
    /// AVX2 walks compiled with AVX-512 where the CPU has AVX-512F and VL, `evex` in the
    /// output), the plain AVX2 walks (`avx2`), or the scalar ones (`scalar`: the browser's and
    /// other targets'), to time them side by side on one tree. `--packets` runs the AVX2
    /// packet walk for `auto` and `avx2` (it has no AVX-512 copy), the scalar one for
    /// `scalar`. The JSON line's `walk` says which ran (`binary` for `--accel binary`).
    #[arg(long, value_enum, default_value_t = WalkArg::Auto)]
    pub walk: WalkArg,
}

/// `bench rays --walk`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum WalkArg {
    Auto,
    Avx2,
    Scalar,
}

/// The kernel `--walk` names on this CPU; an error where it lacks the instructions.
fn walk_isa(walk: WalkArg) -> Result<Isa, String> {
    match walk {
        WalkArg::Auto => Ok(Isa::detect()),
        WalkArg::Scalar => Ok(Isa::Scalar),
        WalkArg::Avx2 => match Isa::detect() {
            Isa::Avx2(avx2) => Ok(Isa::Avx2(avx2.without_evex())),
            Isa::Scalar => Err("--walk avx2: this CPU has no AVX2 and FMA".to_string()),
        },
    }
}

/// The name of a walk in `bench rays`' output.
fn walk_name(isa: Option<Isa>) -> &'static str {
    match isa {
        None => "binary",
        Some(Isa::Scalar) => "scalar",
        Some(Isa::Avx2(avx2)) if avx2.evex() => "evex",
        Some(Isa::Avx2(_)) => "avx2",
    }
}

#[derive(Args, Debug)]
pub struct PacketsArgs {
    /// The shared folder with models/ and scenes/course/.
    #[arg(long, value_name = "DIR", default_value = "../shared")]
    pub shared: PathBuf,
    /// Meshes or scenes [default: the bunny, igea-sub4 and the dragon].
    #[arg(long = "mesh", value_name = "FILE")]
    pub meshes: Vec<PathBuf>,
    /// Image side of the primary rays.
    #[arg(long, value_name = "PIXELS", default_value_t = 1024)]
    pub size: u32,
    /// Rounds, each timing single rays then packets once per ray set.
    #[arg(long, value_name = "N", default_value_t = 7)]
    pub rounds: usize,
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub threads: usize,
}

#[derive(Args, Debug)]
pub struct MakeRaysArgs {
    /// Mesh file (.obj or .ply), framed by a fixed camera.
    #[arg(
        long,
        value_name = "MESH",
        conflicts_with = "scene",
        required_unless_present = "scene"
    )]
    pub mesh: Option<PathBuf>,
    /// Course scene file: its camera and first point light.
    #[arg(long, value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// Output folder; files are NAME.primary.rays, NAME.bounce.rays, NAME.shadow.rays and
    /// NAME.random.rays.
    #[arg(long, value_name = "DIR")]
    pub out_dir: PathBuf,
    #[arg(long, value_name = "PIXELS", default_value_t = 1024)]
    pub size: u32,
}

/// Runs a bench command; errors are messages for `main`.
pub fn run(args: BenchArgs) -> Result<(), String> {
    match args.command {
        BenchCommand::Table(args) => table(&args),
        BenchCommand::Rays(args) => rays(&args),
        BenchCommand::MakeRays(args) => make_rays(&args),
        BenchCommand::Packets(args) => packets_compare(&args),
    }
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| format!("cannot start {threads} threads: {e}"))
}

fn all_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

fn mesh_parts(path: &Path) -> Result<SceneParts, String> {
    let mesh = glint_io::load_mesh(path).map_err(|e| e.to_string())?;
    Ok(workload::mesh_scene_parts(mesh.geometry()))
}

fn scene_parts(path: &Path) -> Result<SceneParts, String> {
    let loaded = glint_io::load_scene(path).map_err(|e| e.to_string())?;
    Ok(loaded.parts)
}

/// Builds on `threads` threads; returns the scene and the seconds it took.
fn build(parts: &SceneParts, accel: AccelKind, threads: usize) -> Result<(Scene, f64), String> {
    let pool = pool(threads)?;
    let parts = parts.clone();
    Ok(pool.install(|| {
        let start = Instant::now();
        let scene = Scene::with_accel(parts, accel);
        let seconds = start.elapsed().as_secs_f64();
        (scene, seconds)
    }))
}

/// What one timed pass over a ray set found.
struct Traced {
    seconds: Vec<f64>,
    hits: usize,
    t: Vec<f32>,
}

impl Traced {
    fn best(&self) -> f64 {
        self.seconds.iter().copied().fold(f64::INFINITY, f64::min)
    }
    fn median(&self) -> f64 {
        let mut s = self.seconds.clone();
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    }
}

const CHUNK: usize = 1024;

/// Rays grouped into packets of eight, built before timing: each packet's rays, the lanes in
/// use, and where each lane's ray sits in the original order.
struct Packets {
    rays: Vec<[Ray; PACKET]>,
    lanes: Vec<u8>,
    index: Vec<[u32; PACKET]>,
}

impl Packets {
    /// 4x2 pixel blocks of an image `width` pixels wide (rays row by row), or eight consecutive
    /// rays without a width.
    fn new(rays: &[Ray], width: Option<u32>) -> Packets {
        let mut out = Packets {
            rays: Vec::new(),
            lanes: Vec::new(),
            index: Vec::new(),
        };
        let mut push = |members: &mut dyn Iterator<Item = usize>| {
            let mut packet = [Ray::new(Vec3::ZERO, Vec3::Z); PACKET];
            let mut index = [0u32; PACKET];
            let mut lanes = 0u8;
            for (l, i) in members.enumerate() {
                packet[l] = rays[i];
                index[l] = i as u32;
                lanes |= 1 << l;
            }
            out.rays.push(packet);
            out.lanes.push(lanes);
            out.index.push(index);
        };
        // A whole number of rows of `width`.
        let rows = width
            .map(|w| w as usize)
            .filter(|&w| w > 0 && rays.len().is_multiple_of(w));
        match rows {
            Some(w) => {
                let h = rays.len() / w;
                for by in (0..h).step_by(2) {
                    for bx in (0..w).step_by(4) {
                        let mut members = (0..PACKET)
                            .map(|l| (bx + l % 4, by + l / 4))
                            .filter(|&(x, y)| x < w && y < h)
                            .map(|(x, y)| y * w + x);
                        push(&mut members);
                    }
                }
            }
            None => {
                for start in (0..rays.len()).step_by(PACKET) {
                    push(&mut (start..(start + PACKET).min(rays.len())));
                }
            }
        }
        out
    }

    /// The image width of a square image of `count` rays, if it is one.
    fn square_width(count: usize) -> Option<u32> {
        let w = (count as f64).sqrt().round() as usize;
        (w > 0 && w * w == count).then_some(w as u32)
    }
}

/// How a timed pass traces its rays.
#[derive(Clone, Copy)]
enum Mode<'a> {
    Single,
    Packets(&'a Packets),
}

/// Traces `rays` `repeat` times on `threads` threads (1: the calling thread alone, no pool).
fn trace(
    scene: &Scene,
    rays: &[Ray],
    occlusion: bool,
    threads: usize,
    repeat: usize,
) -> Result<Traced, String> {
    trace_mode(scene, rays, Mode::Single, occlusion, threads, repeat)
}

fn trace_mode(
    scene: &Scene,
    rays: &[Ray],
    mode: Mode,
    occlusion: bool,
    threads: usize,
    repeat: usize,
) -> Result<Traced, String> {
    let mut t = vec![f32::INFINITY; rays.len()];
    let pool = pool(threads)?;
    let packet = |rays: &[Ray; PACKET], lanes: u8| -> [f32; PACKET] {
        if occlusion {
            let occluded = scene.occluded_lanes(rays, lanes);
            std::array::from_fn(|l| {
                if occluded & (1 << l) != 0 {
                    0.0
                } else {
                    f32::INFINITY
                }
            })
        } else {
            scene
                .intersect_lanes(rays, lanes)
                .map(|h| h.map_or(f32::INFINITY, |h| h.t))
        }
    };
    // Packet results in packet order (scattered back after timing).
    let mut packet_t = match mode {
        Mode::Single => Vec::new(),
        Mode::Packets(p) => vec![[f32::INFINITY; PACKET]; p.rays.len()],
    };
    let mut seconds = Vec::with_capacity(repeat);
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        match mode {
            Mode::Single if occlusion => single_pass(&pool, threads, &mut t, rays, |ray| {
                if scene.occluded(ray) {
                    0.0
                } else {
                    f32::INFINITY
                }
            }),
            Mode::Single => single_pass(&pool, threads, &mut t, rays, |ray| {
                scene.intersect(ray).map_or(f32::INFINITY, |h| h.t)
            }),
            Mode::Packets(p) if threads <= 1 => {
                for ((out, rays), &lanes) in packet_t.iter_mut().zip(&p.rays).zip(&p.lanes) {
                    *out = packet(rays, lanes);
                }
            }
            Mode::Packets(p) => pool.install(|| {
                let chunk = CHUNK / PACKET;
                packet_t
                    .par_chunks_mut(chunk)
                    .zip(p.rays.par_chunks(chunk))
                    .zip(p.lanes.par_chunks(chunk))
                    .for_each(|((out, rays), lanes)| {
                        for ((o, rays), &lanes) in out.iter_mut().zip(rays).zip(lanes) {
                            *o = packet(rays, lanes);
                        }
                    })
            }),
        }
        seconds.push(start.elapsed().as_secs_f64());
    }
    if let Mode::Packets(p) = mode {
        for ((values, index), &lanes) in packet_t.iter().zip(&p.index).zip(&p.lanes) {
            for l in 0..PACKET {
                if lanes & (1 << l) != 0 {
                    t[index[l] as usize] = values[l];
                }
            }
        }
    }
    let hits = t.iter().filter(|t| t.is_finite()).count();
    Ok(Traced { seconds, hits, t })
}

/// One timed pass of single rays: `t[i] = one(&rays[i])`, on the calling thread where
/// `threads` is 1, else on `pool`. A loop of its own for each kind of query, as a program
/// tracing rays would write it (`rtcIntersect1` in a loop is what `embree_native` times): with
/// the kind chosen per ray inside one closure, the any-hit query's inlined frame was set up
/// around every closest-hit call too.
fn single_pass(
    pool: &rayon::ThreadPool,
    threads: usize,
    t: &mut [f32],
    rays: &[Ray],
    one: impl Fn(&Ray) -> f32 + Sync,
) {
    if threads <= 1 {
        for (out, ray) in t.iter_mut().zip(rays) {
            *out = one(ray);
        }
    } else {
        pool.install(|| {
            t.par_chunks_mut(CHUNK)
                .zip(rays.par_chunks(CHUNK))
                .for_each(|(out, rays)| {
                    for (o, ray) in out.iter_mut().zip(rays) {
                        *o = one(ray);
                    }
                })
        })
    }
}

fn rays(args: &RaysArgs) -> Result<(), String> {
    let parts = mesh_parts(&args.mesh)?;
    let triangles = parts.geometries[0].shapes.len();
    let rays = glint_io::read_rays(&args.rays).map_err(|e| e.to_string())?;
    let threads = args.threads.max(1);
    let (mut scene, build_s) = build(&parts, args.accel.into(), threads)?;
    scene.instances_mut().set_isa(walk_isa(args.walk)?);
    let walk = walk_name(scene.instances().isa());
    let packets = args.packets.then(|| {
        let width = if args.consecutive {
            None
        } else {
            args.image_width
                .or_else(|| Packets::square_width(rays.len()))
        };
        Packets::new(&rays, width)
    });
    let mode = packets.as_ref().map_or(Mode::Single, Mode::Packets);
    let traced = trace_mode(&scene, &rays, mode, args.occlusion, threads, args.repeat)?;
    if let Some(path) = &args.write_t {
        let t = if args.occlusion {
            trace(&scene, &rays, false, threads, 1)?.t
        } else {
            traced.t.clone()
        };
        glint_io::write_hit_distances(path, &t).map_err(|e| e.to_string())?;
    }
    let counts = if args.count {
        let mut counts = WalkCounts::default();
        for ray in &rays {
            scene.instances().count_closest(ray, &mut counts);
        }
        let per_ray = |n: u64| n as f64 / rays.len().max(1) as f64;
        let tree = scene.instances().tree_stats();
        format!(
            ", \"nodes_per_ray\": {:.3}, \"blocks_per_ray\": {:.3}, \"nodes\": {}, \
             \"leaves\": {}, \"sah_cost\": {:.3}",
            per_ray(counts.nodes),
            per_ray(counts.blocks),
            tree.nodes,
            tree.leaves,
            tree.sah_cost
        )
    } else {
        String::new()
    };
    let name = args
        .mesh
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    println!(
        "{{\"engine\": \"glint\", \"accel\": \"{}\", \"walk\": \"{}\", \"traversal\": \"{}\", \
         \"mesh\": \"{}\", \"triangles\": {}, \"rays\": {}, \"threads\": {}, \"query\": \"{}\", \
         \"build_s\": {:.4}, \"best_s\": {:.4}, \"median_s\": {:.4}, \"mrays_per_s\": {:.3}, \
         \"hits\": {}{}}}",
        match args.accel {
            AccelArg::Wide => "wide",
            AccelArg::Binary => "binary",
        },
        walk,
        match (args.packets, args.consecutive) {
            (false, _) => "single",
            (true, false) => "packets",
            (true, true) => "packets8x1",
        },
        name.replace('"', "'"),
        triangles,
        rays.len(),
        threads,
        if args.occlusion {
            "occlusion"
        } else {
            "closest"
        },
        build_s,
        traced.best(),
        traced.median(),
        rays.len() as f64 / traced.best() / 1e6,
        traced.hits,
        counts
    );
    Ok(())
}

/// A workload of the table: a scene, the camera that frames it and the light for its shadow
/// rays.
struct Case {
    parts: SceneParts,
    camera: Option<Camera>,
    light: Option<Vec3>,
}

fn first_point_light(parts: &SceneParts) -> Option<Vec3> {
    parts.lights.iter().find_map(|light| match light {
        Light::Point { position, .. } => Some(*position),
        _ => None,
    })
}

fn load_case(path: &Path) -> Result<Case, String> {
    let is_mesh = matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("obj" | "ply")
    );
    if is_mesh {
        Ok(Case {
            parts: mesh_parts(path)?,
            camera: None,
            light: None,
        })
    } else {
        let parts = scene_parts(path)?;
        Ok(Case {
            camera: Some(parts.camera),
            light: first_point_light(&parts),
            parts,
        })
    }
}

fn case_workload(case: &Case, scene: &Scene, size: u32) -> Workload {
    let bounds: Aabb = scene.bounds();
    let camera = case
        .camera
        .unwrap_or_else(|| workload::framing_camera(bounds));
    let light = case
        .light
        .unwrap_or_else(|| workload::default_light(bounds));
    workload::workload(scene, &camera, size, light)
}

fn write_workload(dir: &Path, name: &str, w: &Workload) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for (set, rays) in [
        ("primary", &w.primary),
        ("bounce", &w.bounce),
        ("shadow", &w.shadow),
        ("random", &w.random),
    ] {
        let path = dir.join(format!("{name}.{set}.rays"));
        glint_io::write_rays(&path, rays).map_err(|e| e.to_string())?;
        eprintln!("wrote {} ({} rays)", path.display(), rays.len());
    }
    Ok(())
}

fn make_rays(args: &MakeRaysArgs) -> Result<(), String> {
    let path = args
        .mesh
        .as_ref()
        .or(args.scene.as_ref())
        .ok_or("give --mesh or --scene")?;
    let case = load_case(path)?;
    let (scene, _) = build(&case.parts, AccelKind::Wide, all_threads())?;
    let w = case_workload(&case, &scene, args.size);
    let stem = path
        .file_stem()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "rays".into());
    write_workload(&args.out_dir, &stem, &w)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn table(args: &TableArgs) -> Result<(), String> {
    let shared = &args.shared;
    let course = shared.join("scenes/course/willemsen");
    let paths = [
        shared.join("models/stanford-bunny.obj"),
        shared.join("models/igea-sub4.ply"),
        course.join("scenes_B/objFiles/dragon.obj"),
        course.join("scenes_A/spheres_1K.json"),
        course.join("scenes_B/StanfordDragon_Instanced.json"),
    ];
    let threads = args.threads.unwrap_or_else(all_threads).max(1);
    let accel: AccelKind = args.accel.into();
    let repeat = args.repeat.max(1);
    println!(
        "glint bench: {} BVH, {} threads for the \"nT\" columns, {}x{} primary rays (\"pkt\": \
         in packets of 4x2 pixel blocks), best of {} runs; Mrays/s",
        match args.accel {
            AccelArg::Wide => "8-wide",
            AccelArg::Binary => "binary (reference)",
        },
        threads,
        args.size,
        args.size,
        repeat
    );
    println!(
        "{:<28} {:>9} {:>5} {:>8} {:>8} {:>7} {:>7} | {:>7} {:>7} {:>7} {:>7} | {:>7} {:>7} | {:>7} {:>7}",
        "workload",
        "prims",
        "inst",
        "build1 s",
        "buildN s",
        "BVH B/p",
        "prim B/p",
        "prim 1T",
        "prim NT",
        "pkt 1T",
        "pkt NT",
        "bnce 1T",
        "bnce NT",
        "shdw 1T",
        "shdw NT"
    );
    for path in &paths {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let Some(only) = &args.only {
            if !name.contains(only.as_str()) {
                continue;
            }
        }
        if !path.exists() {
            println!("{name:<28} (missing: {})", path.display());
            continue;
        }
        let case = load_case(path)?;
        let builds = repeat.min(3);
        let mut build1 = Vec::new();
        let mut build_n = Vec::new();
        let mut scene = None;
        for _ in 0..builds {
            let (s, t) = build(&case.parts, accel, 1)?;
            build1.push(t);
            drop(s);
            let (s, t) = build(&case.parts, accel, threads)?;
            build_n.push(t);
            scene = Some(s);
        }
        let scene = scene.expect("built at least once");
        let stats = scene.accel_stats();
        let w = case_workload(&case, &scene, args.size);
        if let Some(dir) = &args.write_rays {
            let stem = path
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            write_workload(dir, &stem, &w)?;
        }
        let mut rates = Vec::new();
        // Primary rays one by one and in packets of 4x2 pixel blocks, run by run alternating.
        let packets = Packets::new(&w.primary, Some(args.size));
        let mut packet_rates = Vec::new();
        for n in [1, threads] {
            let (mut single, mut packet) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..repeat {
                single = single.min(trace(&scene, &w.primary, false, n, 1)?.best());
                let p = Mode::Packets(&packets);
                packet = packet.min(trace_mode(&scene, &w.primary, p, false, n, 1)?.best());
            }
            rates.push(w.primary.len() as f64 / single / 1e6);
            packet_rates.push(w.primary.len() as f64 / packet / 1e6);
        }
        for (rays, occlusion) in [(&w.bounce, false), (&w.shadow, true)] {
            for n in [1, threads] {
                let traced = trace(&scene, rays, occlusion, n, repeat)?;
                rates.push(rays.len() as f64 / traced.best() / 1e6);
            }
        }
        let per = |bytes: usize| bytes as f64 / stats.unique_primitives.max(1) as f64;
        println!(
            "{:<28} {:>9} {:>5} {:>8.3} {:>8.3} {:>7.1} {:>7.1} | {:>7.2} {:>7.2} {:>7.2} {:>7.2} | {:>7.2} {:>7.2} | {:>7.2} {:>7.2}",
            name,
            stats.unique_primitives,
            stats.instances,
            median(build1),
            median(build_n),
            per(stats.node_bytes),
            per(stats.primitive_bytes),
            rates[0],
            rates[1],
            packet_rates[0],
            packet_rates[1],
            rates[2],
            rates[3],
            rates[4],
            rates[5]
        );
        println!(
            "{:<28} rays: {} primary, {} bounce, {} shadow",
            "",
            w.primary.len(),
            w.bounce.len(),
            w.shadow.len()
        );
    }
    Ok(())
}

/// `glint bench packets`: single rays against packets on each workload's ray sets, alternating
/// run by run (the machine is shared: only side-by-side ratios mean much), medians.
fn packets_compare(args: &PacketsArgs) -> Result<(), String> {
    let meshes = if args.meshes.is_empty() {
        vec![
            args.shared.join("models/stanford-bunny.obj"),
            args.shared.join("models/igea-sub4.ply"),
            args.shared
                .join("scenes/course/willemsen/scenes_B/objFiles/dragon.obj"),
        ]
    } else {
        args.meshes.clone()
    };
    let threads = args.threads.max(1);
    let rounds = args.rounds.max(1);
    println!(
        "glint bench packets: {}x{} primary rays in packets of 4x2 pixel blocks, bounce, \
         shadow and random rays in packets of 8 consecutive rays; {} thread(s); medians of {} alternating \
         rounds; Mrays/s",
        args.size, args.size, threads, rounds
    );
    println!(
        "{:<30} {:<8} {:>8} {:>8} {:>8} {:>6} {:>9}",
        "workload", "rays", "count", "single", "packets", "ratio", "identical"
    );
    for path in &meshes {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if !path.exists() {
            println!("{name:<30} (missing: {})", path.display());
            continue;
        }
        let case = load_case(path)?;
        let (scene, _) = build(&case.parts, AccelKind::Wide, all_threads())?;
        let w = case_workload(&case, &scene, args.size);
        let sets = [
            ("primary", &w.primary, false, Some(args.size)),
            ("bounce", &w.bounce, false, None),
            ("shadow", &w.shadow, true, None),
            ("random", &w.random, false, None),
        ];
        let packets: Vec<Packets> = sets
            .iter()
            .map(|(_, rays, _, width)| Packets::new(rays, *width))
            .collect();
        let mut single = vec![Vec::new(); sets.len()];
        let mut packet = vec![Vec::new(); sets.len()];
        let mut identical = vec![true; sets.len()];
        for _ in 0..rounds {
            for (k, (_, rays, occlusion, _)) in sets.iter().enumerate() {
                let a = trace(&scene, rays, *occlusion, threads, 1)?;
                let b = trace_mode(
                    &scene,
                    rays,
                    Mode::Packets(&packets[k]),
                    *occlusion,
                    threads,
                    1,
                )?;
                identical[k] &=
                    a.t.iter()
                        .zip(&b.t)
                        .all(|(x, y)| x.to_bits() == y.to_bits());
                single[k].push(a.best());
                packet[k].push(b.best());
            }
        }
        for (k, (set, rays, _, _)) in sets.iter().enumerate() {
            let rate = |s: &[f64]| rays.len() as f64 / median(s.to_vec()) / 1e6;
            let (a, b) = (rate(&single[k]), rate(&packet[k]));
            println!(
                "{:<30} {:<8} {:>8} {:>8.2} {:>8.2} {:>6.2} {:>9}",
                name,
                set,
                rays.len(),
                a,
                b,
                b / a,
                if identical[k] { "yes" } else { "NO" }
            );
        }
    }
    Ok(())
}
