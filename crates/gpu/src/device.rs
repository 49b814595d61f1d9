//! The kernel on a wgpu device: `GpuRenderer` opens a Vulkan adapter, uploads the flattened
//! scene and renders in progressive passes (the `device` feature).

use std::sync::{mpsc, Arc, Mutex, OnceLock};

use glint_render::{Color, Features, Film, RenderSettings, SceneParts, Vec3};
use wgpu::util::DeviceExt;

use crate::layout::{self, FlatScene};
use crate::{check_supported, GpuError};

/// How many path samples one dispatch traces at most (over the whole image): small enough
/// that a dispatch on a real GPU lasts milliseconds, far from any watchdog.
const SAMPLES_PER_DISPATCH: u64 = 1 << 20;

/// vec4s per case of the BSDF probe (`physical.wgsl` PROBE_STRIDE).
pub(crate) const PROBE_STRIDE: usize = 17;

/// One input of `GpuRenderer::probe_bsdfs`: BSDF tree `bsdf` of the scene, the shading data
/// of a hit (as `PhysicalSurface` has them: the geometric normal, the shading frame's u, v,
/// w, ∂p/∂u, ∂p/∂v, what textures read), the world directions towards the viewer (`wo`) and
/// the light (`wi`), and the random numbers of one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProbeCase {
    pub bsdf: u32,
    pub u_lobe: f32,
    pub u: [f32; 2],
    pub normal: [f32; 3],
    pub frame: [[f32; 3]; 3],
    pub dp_du: [f32; 3],
    pub dp_dv: [f32; 3],
    pub uv: [f32; 2],
    pub uv1: [f32; 2],
    pub vertex_color: [f32; 3],
    pub face_color: [f32; 3],
    pub bitangent_sign: f32,
    pub wo: [f32; 3],
    pub wi: [f32; 3],
}

/// What the GPU's resolved BSDF gives for a `ProbeCase`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeResult {
    /// f·|cos θi| and the density at (`wo`, `wi`).
    pub f: [f32; 3],
    pub pdf: f32,
    /// The sample drawn with the case's numbers, if any.
    pub sample: Option<ProbeSample>,
    pub albedo: [f32; 3],
    /// How many leaves the tree resolved to.
    pub leaves: u32,
    pub has_non_delta: bool,
}

/// A BSDF sample in world space (`BsdfSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    pub wi: [f32; 3],
    pub weight: [f32; 3],
    pub pdf: f32,
    pub is_specular: bool,
    pub eta: f32,
}

/// vec4s per case of the microfacet probe (`physical.wgsl` MICROFACET_STRIDE).
pub(crate) const MICROFACET_STRIDE: usize = 6;

/// One input of `GpuRenderer::probe_microfacets`: a distribution (GGX or Beckmann), its
/// roughness, whether it samples visible normals, a direction `wo`, a microfacet normal `m`
/// and the two numbers of one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MicrofacetCase {
    pub ggx: bool,
    pub alpha_u: f32,
    pub alpha_v: f32,
    pub sample_visible: bool,
    pub wo: [f32; 3],
    pub m: [f32; 3],
    pub u: [f32; 2],
}

/// The GPU's D(m), G1(wo, m), G(wo, wo', m) with wo' the mirror of wo about m, pdf(wo, m),
/// and the normal sampled for wo with its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicrofacetResult {
    pub d: f32,
    pub g1: f32,
    pub g: f32,
    pub pdf: f32,
    pub sampled: [f32; 3],
    pub sampled_pdf: f32,
}

/// What `GpuRenderer::bind` makes: the buffers a dispatch writes or sets, and the bind group.
struct Bound {
    uniform: wgpu::Buffer,
    accum: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// The kernel, one WGSL module: the path loop, the physically based materials, then each
/// family of them.
pub(crate) const KERNEL: &str = concat!(
    include_str!("path.wgsl"),
    include_str!("physical.wgsl"),
    include_str!("conductor.wgsl"),
    include_str!("dielectric.wgsl"),
    include_str!("plastic.wgsl"),
    include_str!("principled.wgsl"),
    include_str!("gltf.wgsl"),
);

/// What a GPU render did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuStats {
    /// Path samples traced (pixels times samples per pixel).
    pub samples: u64,
    /// Samples whose radiance was NaN or infinite: dropped from the pixel's average.
    pub nonfinite_samples: u64,
    /// The first pixel (x, y from the top-left of the whole image) with a non-finite sample.
    pub first_nonfinite_pixel: Option<(u32, u32)>,
    /// Samples the driver's loop limit cut short (a render with any fails).
    cut_samples: u64,
}

/// The accumulation buffer's bytes per pixel (three vec4: `ACCUM_STRIDE` in `path.wgsl`).
pub(crate) const ACCUM_BYTES_PER_PIXEL: usize = 48;

/// An opened GPU device with the kernel's module validated; its pipelines are compiled
/// when first used.
pub struct GpuRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    /// The path tracer without (0) and with (1) physically based materials: a course scene
    /// runs a kernel whose physical code the compiler removed (`physical_materials`).
    pipelines: [OnceLock<wgpu::ComputePipeline>; 2],
    layout: wgpu::BindGroupLayout,
    /// For the BSDF probe's pipeline (`probe_bsdfs`), made when first asked for.
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    max_binding: u64,
    samples_per_pass: Option<u32>,
    device_error: Arc<Mutex<Option<String>>>,
}

impl std::fmt::Debug for GpuRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuRenderer")
            .field("adapter", &self.info.name)
            .finish()
    }
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl GpuRenderer {
    /// Opens the first adapter wgpu finds (high-performance preference) and compiles the
    /// kernel. `GpuError::NoAdapter` when there is none.
    pub fn new() -> Result<GpuRenderer, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|error| GpuError::NoAdapter(error.to_string()))?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let required_limits = wgpu::Limits {
            max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
            max_buffer_size: limits.max_buffer_size,
            ..wgpu::Limits::default()
        };
        let max_binding = required_limits.max_storage_buffer_binding_size as u64;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("glint"),
            required_limits,
            ..Default::default()
        }))
        .map_err(|error| GpuError::Device(error.to_string()))?;
        // wgpu's default for errors nobody captures is a panic; keep the first one and turn
        // it into a `GpuError::Device` at the next check instead.
        let device_error = Arc::new(Mutex::new(None::<String>));
        let sink = Arc::clone(&device_error);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            if let Ok(mut slot) = sink.lock() {
                slot.get_or_insert_with(|| error.to_string());
            }
        }));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("path.wgsl"),
            source: wgpu::ShaderSource::Wgsl(KERNEL.into()),
        });
        let mut entries = vec![wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }];
        entries.extend((1..=6).map(|binding| storage_entry(binding, true)));
        entries.push(storage_entry(7, false));
        entries.push(storage_entry(8, true));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("glint scene"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("glint"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let renderer = GpuRenderer {
            device,
            queue,
            max_binding,
            samples_per_pass: None,
            info,
            pipelines: [OnceLock::new(), OnceLock::new()],
            layout,
            module,
            pipeline_layout,
            device_error,
        };
        renderer.check_device()?;
        Ok(renderer)
    }

    /// The first error the device reported, if any (a shader the driver rejects, memory).
    fn check_device(&self) -> Result<(), GpuError> {
        match self.device_error.lock() {
            Ok(slot) => match slot.as_ref() {
                Some(error) => Err(GpuError::Device(error.clone())),
                None => Ok(()),
            },
            Err(_) => Err(GpuError::Device(
                "the device's error handler panicked".into(),
            )),
        }
    }

    /// Sets how many samples of each pixel one dispatch takes (`None`: the default, one on a
    /// CPU adapter such as lavapipe, otherwise as many as keep a dispatch near 2^20 samples).
    /// More per pass means fewer dispatches; on lavapipe more than a few run into its loop
    /// limit, which `render` detects and reports as an error.
    pub fn set_samples_per_pass(&mut self, samples: Option<u32>) {
        self.samples_per_pass = samples.map(|n| n.max(1));
    }

    /// The adapter's name and backend, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)".
    pub fn adapter_name(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// Renders `parts` with the path tracer. `progress(done, total)` hears after every pass
    /// (samples per pixel done and asked for) and may cancel by returning false.
    pub fn render(
        &self,
        parts: &SceneParts,
        settings: &RenderSettings,
        progress: &dyn Fn(u32, u32) -> bool,
    ) -> Result<(Film, GpuStats), GpuError> {
        check_supported(parts, settings)?;
        let mut flat = FlatScene::new(parts);
        flat.pack_texels_half(self.max_binding);
        let (width, height) = (settings.width, settings.height);
        let bounds = settings.bounds();
        let (crop_width, crop_height) = (bounds.x1 - bounds.x0, bounds.y1 - bounds.y0);
        let pixels = crop_width as u64 * crop_height as u64;
        let mut params = flat.params;
        params.width = width;
        params.height = height;
        params.x0 = bounds.x0;
        params.y0 = bounds.y0;
        params.crop_width = crop_width;
        params.crop_height = crop_height;
        params.seed_lo = settings.seed as u32;
        params.seed_hi = (settings.seed >> 32) as u32;
        params.max_depth = settings.max_depth();
        params.camera_w[3] = settings.aspect.unwrap_or(width as f32 / height as f32);

        let accum_bytes = vec![0u8; pixels as usize * ACCUM_BYTES_PER_PIXEL];
        let Bound {
            uniform,
            accum,
            bind_group,
        } = self.bind(&flat, &accum_bytes)?;

        let samples = settings.samples();
        let total = samples.len() as u32;
        // On a CPU adapter (lavapipe) one sample per invocation and pass keeps every
        // invocation far below llvmpipe's loop limit (`path.wgsl`, `loop_limit_reached`).
        let per_invocation = match (self.samples_per_pass, self.info.device_type) {
            (Some(samples), _) => samples as u64,
            (None, wgpu::DeviceType::Cpu) => 1,
            (None, _) => SAMPLES_PER_DISPATCH / pixels,
        };
        let per_pass = per_invocation.clamp(1, total.max(1) as u64) as u32;
        let pipeline = self.path_pipeline(!parts.physical.bsdfs.is_empty());
        let mut done = 0u32;
        while done < total {
            let count = per_pass.min(total - done);
            params.first_sample = samples.start + done;
            params.samples = count;
            self.queue
                .write_buffer(&uniform, 0, bytemuck::bytes_of(&params));
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("path samples"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(crop_width.div_ceil(8), crop_height.div_ceil(8), 1);
            }
            self.queue.submit([encoder.finish()]);
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|error| GpuError::Device(error.to_string()))?;
            self.check_device()?;
            done += count;
            if !progress(done, total) {
                return Err(GpuError::Cancelled);
            }
        }

        self.check_device()?;
        let sums = self.read_back(&accum, pixels * ACCUM_BYTES_PER_PIXEL as u64)?;
        let mut film = Film::new(crop_width, crop_height);
        film.origin = (bounds.x0, bounds.y0);
        film.full_size = (width, height);
        let mut features = Features {
            albedo: Vec::with_capacity(pixels as usize),
            normal: Vec::with_capacity(pixels as usize),
            depth: Vec::with_capacity(pixels as usize),
        };
        let taken = total.max(1) as f32;
        let mut stats = GpuStats {
            samples: pixels * total as u64,
            ..GpuStats::default()
        };
        for (index, (pixel, sum)) in film.pixels.iter_mut().zip(sums.chunks_exact(3)).enumerate() {
            let [beauty, albedo_depth, normal] = [sum[0], sum[1], sum[2]];
            let cut = normal[3] as u64;
            stats.cut_samples += cut;
            let dropped = (total as u64).saturating_sub(beauty[3] as u64 + cut);
            if dropped > 0 {
                stats.nonfinite_samples += dropped;
                let (x, y) = (index as u32 % crop_width, index as u32 / crop_width);
                stats
                    .first_nonfinite_pixel
                    .get_or_insert((bounds.x0 + x, bounds.y0 + y));
            }
            // Non-finite samples were dropped; the valid ones are averaged and the feature
            // layers divided by every sample taken, as the CPU pipeline does.
            *pixel = if beauty[3] > 0.0 {
                Color::new(beauty[0], beauty[1], beauty[2]) / beauty[3]
            } else {
                Color::ZERO
            };
            features
                .albedo
                .push(Color::new(albedo_depth[0], albedo_depth[1], albedo_depth[2]) / taken);
            features.depth.push(albedo_depth[3] / taken);
            features
                .normal
                .push(Vec3::new(normal[0], normal[1], normal[2]) / taken);
        }
        if stats.cut_samples > 0 {
            return Err(GpuError::Device(format!(
                "the driver stopped {} path sample{} short (llvmpipe ends a shader's loops \
                 after 65535 iterations): this scene's paths are too long for this adapter",
                stats.cut_samples,
                if stats.cut_samples == 1 { "" } else { "s" }
            )));
        }
        film.features = settings.features.then_some(features);
        Ok((film, stats))
    }

    /// The scene's buffers, an accumulation buffer holding `accum_bytes`, a uniform block
    /// for `Params`, and their bind group.
    fn bind(&self, flat: &FlatScene, accum_bytes: &[u8]) -> Result<Bound, GpuError> {
        let storage = |label: &str, bytes: &[u8], extra: wgpu::BufferUsages| {
            // wgpu refuses empty bindings: an empty table is one zero word.
            let padded: &[u8] = if bytes.is_empty() { &[0u8; 16] } else { bytes };
            if padded.len() as u64 > self.max_binding {
                return Err(GpuError::Unsupported(format!(
                    "a scene whose {label} take {} bytes (the adapter binds at most {})",
                    padded.len(),
                    self.max_binding
                )));
            }
            Ok(self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents: padded,
                    usage: wgpu::BufferUsages::STORAGE | extra,
                }))
        };
        let none = wgpu::BufferUsages::empty();
        let nodes = storage("BVH nodes", bytemuck::cast_slice(&flat.nodes), none)?;
        let prims = storage("primitives", bytemuck::cast_slice(&flat.prims), none)?;
        let materials = storage("materials", bytemuck::cast_slice(&flat.materials), none)?;
        let lights = storage("lights", bytemuck::cast_slice(&flat.lights), none)?;
        let tables = storage("tables", bytemuck::cast_slice(&flat.tables), none)?;
        let texels = storage("texels", bytemuck::cast_slice(&flat.texels), none)?;
        let physical = storage("physical", bytemuck::cast_slice(&flat.physical), none)?;
        let accum = storage("accumulation", accum_bytes, wgpu::BufferUsages::COPY_SRC)?;
        let uniform = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: std::mem::size_of::<layout::Params>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("glint scene"),
            layout: &self.layout,
            entries: &[
                (0, &uniform),
                (1, &nodes),
                (2, &prims),
                (3, &materials),
                (4, &lights),
                (5, &tables),
                (6, &texels),
                (7, &accum),
                (8, &physical),
            ]
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }),
        });
        Ok(Bound {
            uniform,
            accum,
            bind_group,
        })
    }

    /// Compiles the pipeline `parts` needs (which `render` would otherwise do first), so
    /// that a caller can keep the driver's compilation out of its render time.
    pub fn prepare(&self, parts: &SceneParts) -> Result<(), GpuError> {
        self.path_pipeline(!parts.physical.bsdfs.is_empty());
        self.check_device()
    }

    /// The path-tracing pipeline, with or without the physically based materials.
    fn path_pipeline(&self, physical: bool) -> &wgpu::ComputePipeline {
        self.pipelines[usize::from(physical)].get_or_init(|| {
            let constants = [("physical_materials", if physical { 1.0 } else { 0.0 })];
            self.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("glint path"),
                    layout: Some(&self.pipeline_layout),
                    module: &self.module,
                    entry_point: Some("main"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    cache: None,
                })
        })
    }

    /// Resolves BSDF trees of `parts` on the GPU at given shading data and evaluates and
    /// samples them (`physical.wgsl`, `probe`): what the CPU's `SurfaceBsdf` gives for the
    /// same inputs, for tests that hold the two to each other.
    pub fn probe_bsdfs(
        &self,
        parts: &SceneParts,
        cases: &[ProbeCase],
    ) -> Result<Vec<ProbeResult>, GpuError> {
        let mut flat = FlatScene::new(parts);
        flat.pack_texels_half(self.max_binding);
        let mut words: Vec<[f32; 4]> = Vec::with_capacity(cases.len() * PROBE_STRIDE);
        for c in cases {
            let v = |a: [f32; 3], w: f32| [a[0], a[1], a[2], w];
            words.extend([
                [layout::bits(c.bsdf), c.u_lobe, c.u[0], c.u[1]],
                v(c.normal, 0.0),
                v(c.frame[0], 0.0),
                v(c.frame[1], 0.0),
                v(c.frame[2], 0.0),
                v(c.dp_du, 0.0),
                v(c.dp_dv, 0.0),
                [c.uv[0], c.uv[1], c.uv1[0], c.uv1[1]],
                v(c.vertex_color, c.bitangent_sign),
                v(c.face_color, 0.0),
                v(c.wo, 0.0),
                v(c.wi, 0.0),
            ]);
            words.extend([[0.0; 4]; PROBE_STRIDE - 12]);
        }
        let out = self.run_probe(&flat, "probe", &words, cases.len())?;
        Ok(out
            .chunks_exact(PROBE_STRIDE)
            .map(|w| {
                let xyz = |a: [f32; 4]| [a[0], a[1], a[2]];
                let flags = w[14][3].to_bits();
                let counts = w[15][3].to_bits();
                ProbeResult {
                    f: xyz(w[12]),
                    pdf: w[12][3],
                    sample: (flags & 1 != 0).then(|| ProbeSample {
                        wi: xyz(w[13]),
                        pdf: w[13][3],
                        weight: xyz(w[14]),
                        is_specular: flags & 2 != 0,
                        eta: w[16][0],
                    }),
                    albedo: xyz(w[15]),
                    leaves: counts & 255,
                    has_non_delta: counts & 256 != 0,
                }
            })
            .collect())
    }

    /// Evaluates and samples microfacet distributions on the GPU (`physical.wgsl`,
    /// `probe_microfacet`): the kernel's port of `microfacet.rs`, for tests that hold it to
    /// the CPU's on the same inputs.
    pub fn probe_microfacets(
        &self,
        cases: &[MicrofacetCase],
    ) -> Result<Vec<MicrofacetResult>, GpuError> {
        let parts = SceneParts {
            camera: glint_render::Camera::new(
                glint_render::Projection::Perspective,
                Vec3::Z,
                -Vec3::Z,
                1.0,
                1.0,
            ),
            materials: Vec::new(),
            textures: Vec::new(),
            lights: Vec::new(),
            background: glint_render::Background::Color(Color::ZERO),
            geometries: Vec::new(),
            instances: Vec::new(),
            physical: Default::default(),
        };
        let flat = FlatScene::new(&parts);
        let mut words: Vec<[f32; 4]> = Vec::with_capacity(cases.len() * MICROFACET_STRIDE);
        for c in cases {
            let v = |a: [f32; 3]| [a[0], a[1], a[2], 0.0];
            words.extend([
                [
                    layout::bits(u32::from(c.ggx)),
                    c.alpha_u,
                    c.alpha_v,
                    layout::bits(u32::from(c.sample_visible)),
                ],
                v(c.wo),
                v(c.m),
                [c.u[0], c.u[1], 0.0, 0.0],
                [0.0; 4],
                [0.0; 4],
            ]);
        }
        let out = self.run_probe(&flat, "probe_microfacet", &words, cases.len())?;
        Ok(out
            .chunks_exact(MICROFACET_STRIDE)
            .map(|w| MicrofacetResult {
                d: w[4][0],
                g1: w[4][1],
                g: w[4][2],
                pdf: w[4][3],
                sampled: [w[5][0], w[5][1], w[5][2]],
                sampled_pdf: w[5][3],
            })
            .collect())
    }

    /// Runs probe entry point `entry` of the kernel over `count` cases written in `words`
    /// (in the accumulation buffer, which the probe overwrites with its results), with the
    /// scene `flat` bound, and returns the buffer.
    fn run_probe(
        &self,
        flat: &FlatScene,
        entry: &str,
        words: &[[f32; 4]],
        count: usize,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        let Bound {
            uniform,
            accum,
            bind_group,
        } = self.bind(flat, bytemuck::cast_slice(words))?;
        let mut params = flat.params;
        params.width = count as u32;
        params.height = 1;
        self.queue
            .write_buffer(&uniform, 0, bytemuck::bytes_of(&params));
        let pipeline = self
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&self.pipeline_layout),
                module: &self.module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(entry),
                timestamp_writes: None,
            });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups((count as u32).div_ceil(64), 1, 1);
        }
        self.queue.submit([encoder.finish()]);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|error| GpuError::Device(error.to_string()))?;
        self.check_device()?;
        let out = self.read_back(&accum, (words.len() * 16) as u64)?;
        Ok(out)
    }

    fn read_back(&self, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<[f32; 4]>, GpuError> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (sender, receiver) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|error| GpuError::Device(error.to_string()))?;
        receiver
            .recv()
            .map_err(|error| GpuError::Device(error.to_string()))?
            .map_err(|error| GpuError::Device(error.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|error| GpuError::Device(error.to_string()))?;
        let values = bytemuck::cast_slice::<u8, [f32; 4]>(&data).to_vec();
        drop(data);
        staging.unmap();
        self.check_device()?;
        Ok(values)
    }
}
