// Glint's path tracer as one WGSL compute kernel: one invocation traces `params.samples`
// samples of one pixel and adds them to the accumulation buffer. It is a port of
// crates/render/src/integrator/path.rs (the loop), material/bsdf.rs (the BSDFs),
// light/sampler.rs (light selection by power, area/cone/environment sampling) and camera.rs;
// the buffers it reads are laid out by crates/gpu/src/layout.rs, whose constants the names
// below repeat. Random numbers are independent PCG draws per (seed, pixel, sample), not the
// CPU's scrambled Sobol' points: the two back ends agree in distribution, not bit for bit.

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;
const FRAC_1_PI: f32 = 0.318309886183791;
// The largest finite f32 stands for infinity (WGSL has no infinite constants).
const INF: f32 = 3.4028235e38;
const NONE: u32 = 0xffffffffu;
// The one ray offset (ray.rs SPAWN_EPSILON).
const SPAWN_EPSILON: f32 = 1e-3;
const ONE_MINUS_EPSILON: f32 = 0.99999994;

// Primitive kinds (layout.rs PRIM_*).
const PRIM_TRIANGLE: u32 = 0u;
const PRIM_SPHERE: u32 = 1u;
const PRIM_BOX: u32 = 2u;
const PRIM_STRIDE: u32 = 4u;
const INSTANCE_STRIDE: u32 = 7u;
const FLAG_CASTS_SHADOW: u32 = 1u;
const FLAG_TRANSFORMED: u32 = 2u;

// Material BSDF kinds (layout.rs BSDF_*).
const BSDF_BLACK: u32 = 0u;
const BSDF_DIFFUSE: u32 = 1u;
const BSDF_BLINN_PHONG: u32 = 2u;
const BSDF_PHONG: u32 = 3u;
const BSDF_MIRROR: u32 = 4u;
const BSDF_GLAZE: u32 = 5u;
const BSDF_BLINN_PHONG_MIRRORED: u32 = 6u;
const BSDF_DIELECTRIC: u32 = 7u;
// A physically based material: its BSDF tree's id in the exponent's word (physical.wgsl).
const BSDF_PHYSICAL: u32 = 8u;
const MATERIAL_STRIDE: u32 = 6u;
// Emitter kinds.
const EMITTER_NONE: u32 = 0u;
const EMITTER_LIGHT: u32 = 1u;
const EMITTER_UNSAMPLED: u32 = 2u;

// Light kinds (layout.rs LIGHT_*).
const LIGHT_POINT: u32 = 0u;
const LIGHT_RECTANGLE: u32 = 1u;
const LIGHT_SPHERE: u32 = 2u;
const LIGHT_TRIANGLES: u32 = 3u;
const LIGHT_ENVIRONMENT: u32 = 4u;
const LIGHT_SPOT: u32 = 5u;
const LIGHT_DIRECTIONAL: u32 = 6u;
const LIGHT_PROJECTOR: u32 = 7u;
const LIGHT_STRIDE: u32 = 6u;
const LIGHT_TRIANGLE_STRIDE: u32 = 4u;

// Backgrounds (layout.rs BACKGROUND_*), the envmap's block in `tables`.
const BACKGROUND_COLOR: u32 = 0u;
const BACKGROUND_CUBE: u32 = 1u;
const BACKGROUND_LATLONG: u32 = 2u;
const LATLONG_INFO: u32 = 21u;
// Mitsuba's smallest sin θ in the envmap's Jacobian (sampler.rs POLE_SIN_THETA).
const POLE_SIN_THETA: f32 = 5.9604645e-8;

// Render flags and reconstruction filters (layout.rs RENDER_*, FILTER_*).
const RENDER_HIDE_EMITTERS: u32 = 1u;
const FILTER_BOX: u32 = 0u;
const FILTER_TENT: u32 = 1u;
const FILTER_GAUSSIAN: u32 = 2u;
const FILTER_BINS: u32 = 1024u;

// Lobes of a BSDF (bsdf.rs Lobe).
const LOBE_DIFFUSE: u32 = 0u;
const LOBE_BLINN_PHONG: u32 = 1u;
const LOBE_PHONG: u32 = 2u;
const LOBE_SPECULAR: u32 = 3u;
const LOBE_DIELECTRIC: u32 = 4u;

struct Params {
    width: u32,
    height: u32,
    first_sample: u32,
    samples: u32,
    seed_lo: u32,
    seed_hi: u32,
    max_depth: u32,
    rr_depth: u32,
    light_count: u32,
    environment_light: u32,
    material_count: u32,
    light_triangles: u32,
    background_kind: u32,
    cube_first_texture: u32,
    texture_info: u32,
    row_cdf: u32,
    column_cdf: u32,
    column_start: u32,
    first_row: u32,
    instances: u32,
    // Perspective 0, orthographic 1.
    projection: u32,
    // The crop window: its top-left pixel and size; the accumulation buffer covers it alone.
    x0: u32,
    y0: u32,
    crop_width: u32,
    crop_height: u32,
    // Always 2; read from the uniform so the compiler cannot unroll the canary loop.
    canary: u32,
    // The top-level BVH (over the instances) starts here.
    tlas_root: u32,
    _pad1: u32,
    // Physically based materials (layout.rs, the `physical` buffer): where the BSDF nodes'
    // offsets start, where the texture nodes start.
    bsdf_index: u32,
    texture_nodes: u32,
    bsdf_count: u32,
    // Bit 0: emitters are hidden from camera rays (Mitsuba's `hide_emitters`).
    render_flags: u32,
    // The reconstruction filter: 0 box, 1 tent, 2 gaussian; its radius in pixels (f32
    // bits: the half-width of its table), where its cumulative table starts in `tables`.
    filter_kind: u32,
    filter_param: u32,
    filter_table: u32,
    _pad4: u32,
    camera_position: vec4<f32>,
    // xyz: the basis vectors; w of u: focal length, of v: image-plane width, of w: aspect.
    camera_u: vec4<f32>,
    camera_v: vec4<f32>,
    camera_w: vec4<f32>,
    background: vec4<f32>,
    // A thin lens: x its aperture radius, y its focus distance; x = 0 for a pinhole. The
    // camera's clipping planes: z near, w far, distances along the view; w = 0 for none.
    lens: vec4<f32>,
}

// Whether the scene has physically based materials. The host makes one pipeline of each:
// for a course scene the physical code, and its per-invocation leaves, fall away.
override physical_materials: bool = true;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> nodes: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> prims: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> materials: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> lights: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> tables: array<f32>;
@group(0) @binding(6) var<storage, read> texels: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> accum: array<vec4<f32>>;
// Physically based materials: BSDF nodes, texture nodes and mesh attributes (layout.rs).
@group(0) @binding(8) var<storage, read> physical: array<vec4<f32>>;

// ---------------------------------------------------------------------------------------
// Random numbers: counter-based. Each draw hashes (seed, pixel, sample, draw index) with
// Jarzynski and Olano's pcg4d ("Hash Functions for GPU Rendering", JCGT 2020), so every
// number is a pure function of its coordinates and no two samples share a stream.

var<private> rng_key: vec4<u32>;

fn pcg4d(input: vec4<u32>) -> vec4<u32> {
    var v = input * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v = v ^ (v >> vec4<u32>(16u));
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

fn rng_seed(pixel: u32, sample: u32) {
    // The draw counter lives in w, mixed with the seed's high word.
    rng_key = vec4<u32>(pixel, sample, params.seed_lo, params.seed_hi << 16u);
}

fn next_1d() -> f32 {
    let out = pcg4d(rng_key).x;
    rng_key.w += 1u;
    // 24 random bits: uniform in [0, 1).
    return f32(out >> 8u) * (1.0 / 16777216.0);
}

fn next_2d() -> vec2<f32> {
    let a = next_1d();
    let b = next_1d();
    return vec2<f32>(a, b);
}

// ---------------------------------------------------------------------------------------
// Frames and warps (math.rs Frame::from_normal, sampling/warp.rs).

struct Frame {
    u: vec3<f32>,
    v: vec3<f32>,
    w: vec3<f32>,
}

fn frame_from_normal(n: vec3<f32>) -> Frame {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    var f: Frame;
    f.u = vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.v = vec3<f32>(b, sign + n.y * n.y * a, -n.y);
    f.w = n;
    return f;
}

fn to_local(f: Frame, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(v, f.u), dot(v, f.v), dot(v, f.w));
}

fn to_world(f: Frame, v: vec3<f32>) -> vec3<f32> {
    return f.u * v.x + f.v * v.y + f.w * v.z;
}

fn sample_uniform_disk_concentric(u: vec2<f32>) -> vec2<f32> {
    let o = 2.0 * u - vec2<f32>(1.0);
    if (o.x == 0.0 && o.y == 0.0) {
        return vec2<f32>(0.0);
    }
    if (abs(o.x) > abs(o.y)) {
        let phi = 0.785398163 * (o.y / o.x);
        return vec2<f32>(o.x * cos(phi), o.x * sin(phi));
    }
    let phi = 0.785398163 * (o.x / o.y);
    return vec2<f32>(o.y * sin(phi), o.y * cos(phi));
}

fn sample_cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let d = sample_uniform_disk_concentric(u);
    return vec3<f32>(d.x, d.y, sqrt(max(0.0, 1.0 - d.x * d.x - d.y * d.y)));
}

fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    return max(cos_theta, 0.0) * FRAC_1_PI;
}

fn sample_uniform_sphere(u: vec2<f32>) -> vec3<f32> {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let phi = TAU * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}

fn sample_uniform_triangle(u: vec2<f32>) -> vec2<f32> {
    let s = sqrt(u.x);
    return vec2<f32>(1.0 - s, u.y * s);
}

fn sample_phong_lobe(u: vec2<f32>, exponent: f32) -> vec3<f32> {
    let cos_theta = pow(u.x, 1.0 / (exponent + 1.0));
    let sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    let phi = TAU * u.y;
    return vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

fn phong_lobe_pdf(cos_theta: f32, exponent: f32) -> f32 {
    if (cos_theta <= 0.0) {
        return 0.0;
    }
    return (exponent + 1.0) / TAU * pow(cos_theta, exponent);
}

fn sample_uniform_cone(u: vec2<f32>, cos_theta_max: f32) -> vec3<f32> {
    let cos_theta = 1.0 - u.x * (1.0 - cos_theta_max);
    let sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    let phi = TAU * u.y;
    return vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

fn uniform_cone_pdf(cos_theta_max: f32) -> f32 {
    return 1.0 / (TAU * (1.0 - cos_theta_max));
}

fn is_finite3(v: vec3<f32>) -> bool {
    // NaN fails every comparison; infinities exceed the largest finite f32.
    return all(abs(v) <= vec3<f32>(3.4028235e38));
}

fn max_component(v: vec3<f32>) -> f32 {
    return max(v.x, max(v.y, v.z));
}

fn power_heuristic(pdf: f32, other_pdf: f32) -> f32 {
    let a = pdf * pdf;
    let b = other_pdf * other_pdf;
    if (a > 3.4028235e38) {
        return 1.0;
    }
    if (a + b > 0.0) {
        return a / (a + b);
    }
    return 0.0;
}

// ---------------------------------------------------------------------------------------
// Textures (texture.rs): nearest lookup, wrap in u, clamp in v.

fn table_u32(index: u32) -> u32 {
    return bitcast<u32>(tables[index]);
}

// Texel `index` of the texels buffer: one vec4 each, or, where the scene's images would not
// fit the adapter's binding otherwise (render_flags bit 1, layout.rs `pack_texels_half`), two
// texels to a vec4, each RGB as three halves.
fn texel_at(index: u32) -> vec3<f32> {
    if ((params.render_flags & 2u) == 0u) {
        return texels[index].xyz;
    }
    let word = texels[index >> 1u];
    let pair = select(word.xy, word.zw, (index & 1u) != 0u);
    let rg = unpack2x16float(bitcast<u32>(pair.x));
    let b = unpack2x16float(bitcast<u32>(pair.y));
    return vec3<f32>(rg, b.x);
}

fn texel(texture: u32, x: u32, y: u32) -> vec3<f32> {
    let info = params.texture_info + 3u * texture;
    let offset = table_u32(info);
    let width = table_u32(info + 1u);
    let height = table_u32(info + 2u);
    let cx = min(x, max(width, 1u) - 1u);
    let cy = min(y, max(height, 1u) - 1u);
    return texel_at(offset + cy * width + cx);
}

fn texture_lookup(texture: u32, uv: vec2<f32>) -> vec3<f32> {
    let info = params.texture_info + 3u * texture;
    let width = table_u32(info + 1u);
    let height = table_u32(info + 2u);
    if (width == 0u || height == 0u) {
        return vec3<f32>(1.0);
    }
    let u = uv.x - floor(uv.x);
    let v = clamp(uv.y, 0.0, 1.0);
    let x = min(u32(u * f32(width)), width - 1u);
    let y = min(u32((1.0 - v) * f32(height)), height - 1u);
    return texel(texture, x, y);
}

// Cube-map face and (s, t) for a direction (CubeMap::face_coordinates); face 6 for none.
fn cube_face_coordinates(d: vec3<f32>) -> vec3<f32> {
    let a = abs(d);
    var face = 0u;
    var sc = 0.0;
    var tc = 0.0;
    var ma = 0.0;
    if (a.x >= a.y && a.x >= a.z) {
        if (d.x > 0.0) {
            face = 0u; sc = -d.z; tc = -d.y;
        } else {
            face = 1u; sc = d.z; tc = -d.y;
        }
        ma = a.x;
    } else if (a.y >= a.z) {
        if (d.y > 0.0) {
            face = 2u; sc = d.x; tc = d.z;
        } else {
            face = 3u; sc = d.x; tc = -d.z;
        }
        ma = a.y;
    } else {
        if (d.z > 0.0) {
            face = 4u; sc = d.x; tc = -d.y;
        } else {
            face = 5u; sc = -d.x; tc = -d.y;
        }
        ma = a.z;
    }
    if (!(ma > 0.0) || ma > 3.4028235e38) {
        return vec3<f32>(6.0, 0.0, 0.0);
    }
    return vec3<f32>(f32(face), 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0));
}

fn cube_face_direction(face: u32, s: f32, t: f32) -> vec3<f32> {
    let sc = 2.0 * s - 1.0;
    let tc = 2.0 * t - 1.0;
    switch face {
        case 0u: { return vec3<f32>(1.0, -tc, -sc); }
        case 1u: { return vec3<f32>(-1.0, -tc, sc); }
        case 2u: { return vec3<f32>(sc, 1.0, tc); }
        case 3u: { return vec3<f32>(sc, -1.0, -tc); }
        case 4u: { return vec3<f32>(sc, -tc, 1.0); }
        default: { return vec3<f32>(-sc, -tc, -1.0); }
    }
}

fn cube_solid_angle_per_area(s: f32, t: f32) -> f32 {
    let a = 2.0 * s - 1.0;
    let b = 2.0 * t - 1.0;
    let r2 = 1.0 + a * a + b * b;
    return 4.0 / (r2 * sqrt(r2));
}

fn face_size(face: u32) -> vec2<u32> {
    let info = params.texture_info + 3u * (params.cube_first_texture + face);
    return vec2<u32>(table_u32(info + 1u), table_u32(info + 2u));
}

fn background_radiance(direction: vec3<f32>) -> vec3<f32> {
    if (params.background_kind == BACKGROUND_COLOR) {
        return params.background.xyz;
    }
    if (params.background_kind == BACKGROUND_LATLONG) {
        return latlong_radiance(direction);
    }
    let c = cube_face_coordinates(direction);
    let face = u32(c.x);
    if (face > 5u) {
        return vec3<f32>(0.0);
    }
    let size = face_size(face);
    return texel(params.cube_first_texture + face, u32(c.y * f32(size.x)), u32(c.z * f32(size.y)));
}

// ---------------------------------------------------------------------------------------
// Mitsuba's latitude-longitude `envmap` (light/envmap.rs): texture `cube_first_texture`, its
// turn and scale in the block at `first_row` in `tables`.

fn latlong_matrix(first: u32, v: vec3<f32>) -> vec3<f32> {
    let base = params.first_row + first;
    return vec3<f32>(
        dot(vec3<f32>(tables[base], tables[base + 1u], tables[base + 2u]), v),
        dot(vec3<f32>(tables[base + 3u], tables[base + 4u], tables[base + 5u]), v),
        dot(vec3<f32>(tables[base + 6u], tables[base + 7u], tables[base + 8u]), v),
    );
}

// The map's frame from the world's (Transform::vector_to_object), normalised.
fn latlong_local(direction: vec3<f32>) -> vec3<f32> {
    return normalize(latlong_matrix(0u, direction));
}

// (u, v) of a unit direction in the map's frame (envmap.rs direction_to_uv).
fn latlong_uv(d: vec3<f32>) -> vec2<f32> {
    return vec2<f32>(atan2(d.x, -d.z) * (0.5 / PI), acos(clamp(d.y, -1.0, 1.0)) * (1.0 / PI));
}

// The map's padded size (envmap.rs LatLongMap: at least 2 x 3; texel() clamps to the image).
fn latlong_size() -> vec2<u32> {
    let size = face_size(0u);
    if (size.x == 0u || size.y == 0u) {
        return vec2<u32>(0u);
    }
    return vec2<u32>(max(size.x, 2u), max(size.y, 3u));
}

// Mitsuba's bilinear lookup (LatLongMap::eval): u wraps, v is clamped.
fn latlong_eval(u_in: f32, v_in: f32) -> vec3<f32> {
    let size = latlong_size();
    if (size.x == 0u) {
        return vec3<f32>(0.0);
    }
    let u = u_in - floor(u_in);
    let v = select(clamp(v_in, 0.0, 1.0), 0.0, v_in != v_in);
    let x = u * f32(size.x) - 0.5;
    let y = v * f32(size.y - 1u);
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let w = i32(size.x);
    let xa = u32(((i32(x0) % w) + w) % w);
    let xb = u32(((i32(x0) + 1) % w + w) % w);
    let ya = min(u32(y0), size.y - 1u);
    let yb = min(ya + 1u, size.y - 1u);
    let t = params.cube_first_texture;
    let top = texel(t, xa, ya) * (1.0 - fx) + texel(t, xb, ya) * fx;
    let bottom = texel(t, xa, yb) * (1.0 - fx) + texel(t, xb, yb) * fx;
    return top * (1.0 - fy) + bottom * fy;
}

fn latlong_radiance(direction: vec3<f32>) -> vec3<f32> {
    let local = latlong_local(direction);
    if (!is_finite3(local)) {
        return vec3<f32>(0.0);
    }
    let uv = latlong_uv(local);
    return latlong_eval(uv.x, uv.y) * tables[params.first_row + 18u];
}

// The distribution's cells across and down (0 for a map without one).
fn latlong_cells() -> vec2<u32> {
    return vec2<u32>(table_u32(params.first_row + 19u), table_u32(params.first_row + 20u));
}

// ---------------------------------------------------------------------------------------
// Tables: piecewise-constant distributions (sampler.rs sample_cdf).

struct CdfSample {
    index: u32,
    probability: f32,
    remapped: f32,
    valid: bool,
}

// `cdf` has bins + 1 entries from `start` in `tables`.
fn sample_cdf(start: u32, bins: u32, u: f32) -> CdfSample {
    var result: CdfSample;
    result.valid = false;
    if (bins == 0u) {
        return result;
    }
    // partition_point over cdf[1..=bins]: the first entry > u.
    var lo = 0u;
    var hi = bins;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (tables[start + 1u + mid] <= u) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let index = min(lo, bins - 1u);
    let probability = tables[start + index + 1u] - tables[start + index];
    if (!(probability > 0.0)) {
        return result;
    }
    result.index = index;
    result.probability = probability;
    result.remapped = clamp((u - tables[start + index]) / probability, 0.0, ONE_MINUS_EPSILON);
    result.valid = true;
    return result;
}

struct DirectionPdf {
    direction: vec3<f32>,
    pdf: f32,
}

fn environment_sample(u: vec2<f32>) -> DirectionPdf {
    var result: DirectionPdf;
    result.pdf = 0.0;
    if (params.background_kind == BACKGROUND_COLOR) {
        result.direction = sample_uniform_sphere(u);
        result.pdf = 1.0 / (4.0 * PI);
        return result;
    }
    if (params.background_kind == BACKGROUND_LATLONG) {
        return latlong_sample(u);
    }
    let rows = table_u32(params.first_row + 6u);
    let row = sample_cdf(params.row_cdf, rows, u.x);
    if (!row.valid) {
        return result;
    }
    var face = 0u;
    loop {
        if (face >= 5u || table_u32(params.first_row + face + 1u) > row.index) {
            break;
        }
        face += 1u;
    }
    let size = face_size(face);
    let y = row.index - table_u32(params.first_row + face);
    let column = sample_cdf(params.column_cdf + table_u32(params.column_start + row.index), size.x, u.y);
    if (!column.valid) {
        return result;
    }
    let s = (f32(column.index) + column.remapped) / f32(size.x);
    let t = (f32(y) + row.remapped) / f32(size.y);
    let pdf_area = row.probability * column.probability * f32(size.x * size.y);
    let pdf = pdf_area / cube_solid_angle_per_area(s, t);
    if (pdf > 0.0 && pdf < 3.4028235e38) {
        result.direction = normalize(cube_face_direction(face, s, t));
        result.pdf = pdf;
    }
    return result;
}

// LatLongDistribution::sample: a cell by its row and column tables, uniform within it.
fn latlong_sample(u: vec2<f32>) -> DirectionPdf {
    var result: DirectionPdf;
    result.pdf = 0.0;
    let cells = latlong_cells();
    let row = sample_cdf(params.row_cdf, cells.y, u.x);
    if (!row.valid) {
        return result;
    }
    let column = sample_cdf(params.column_cdf + row.index * (cells.x + 1u), cells.x, u.y);
    if (!column.valid) {
        return result;
    }
    // Cells start at texel centres: half a texel on in u.
    let map_u = (f32(column.index) + 0.5 + column.remapped) / f32(cells.x);
    let map_v = (f32(row.index) + row.remapped) / f32(cells.y);
    let sin_theta = sin(map_v * PI);
    let phi = map_u * TAU;
    let local = vec3<f32>(sin(phi) * sin_theta, cos(map_v * PI), -cos(phi) * sin_theta);
    let direction = normalize(latlong_matrix(9u, local));
    let density = row.probability * column.probability * f32(cells.x * cells.y);
    // sin θ as latlong_pdf computes it, so that both give the same density.
    let back = latlong_local(direction);
    let sin_back = sqrt(back.x * back.x + back.z * back.z);
    let pdf = density / (2.0 * PI * PI * max(sin_back, POLE_SIN_THETA));
    if (pdf > 0.0 && pdf < 3.4028235e38 && is_finite3(direction)) {
        result.direction = direction;
        result.pdf = pdf;
    }
    return result;
}

fn latlong_pdf(direction: vec3<f32>) -> f32 {
    let cells = latlong_cells();
    if (cells.x == 0u || cells.y == 0u) {
        return 0.0;
    }
    let local = latlong_local(direction);
    if (!is_finite3(local)) {
        return 0.0;
    }
    let uv = latlong_uv(local);
    let x = (uv.x - floor(uv.x)) * f32(cells.x) - 0.5;
    let c = i32(cells.x);
    let column = u32(((i32(floor(x)) % c) + c) % c);
    let row = min(u32(uv.y * f32(cells.y)), cells.y - 1u);
    let row_probability = tables[params.row_cdf + row + 1u] - tables[params.row_cdf + row];
    let columns = params.column_cdf + row * (cells.x + 1u);
    let column_probability = tables[columns + column + 1u] - tables[columns + column];
    let density = row_probability * column_probability * f32(cells.x * cells.y);
    let sin_theta = sqrt(local.x * local.x + local.z * local.z);
    return density / (2.0 * PI * PI * max(sin_theta, POLE_SIN_THETA));
}

fn environment_pdf(direction: vec3<f32>) -> f32 {
    if (params.background_kind == BACKGROUND_COLOR) {
        return 1.0 / (4.0 * PI);
    }
    if (params.background_kind == BACKGROUND_LATLONG) {
        return latlong_pdf(direction);
    }
    let c = cube_face_coordinates(direction);
    let face = u32(c.x);
    if (face > 5u) {
        return 0.0;
    }
    let size = face_size(face);
    if (size.x == 0u || size.y == 0u) {
        return 0.0;
    }
    let x = min(u32(c.y * f32(size.x)), size.x - 1u);
    let y = min(u32(c.z * f32(size.y)), size.y - 1u);
    let row = table_u32(params.first_row + face) + y;
    let row_probability = tables[params.row_cdf + row + 1u] - tables[params.row_cdf + row];
    let columns = params.column_cdf + table_u32(params.column_start + row);
    let column_probability = tables[columns + x + 1u] - tables[columns + x];
    let pdf_area = row_probability * column_probability * f32(size.x * size.y);
    return pdf_area / cube_solid_angle_per_area(c.y, c.z);
}

// ---------------------------------------------------------------------------------------
// Lights (light/sampler.rs).

fn light_word(light: u32, field: u32) -> vec4<f32> {
    return lights[light * LIGHT_STRIDE + field];
}

fn light_kind(light: u32) -> u32 {
    return bitcast<u32>(light_word(light, 0u).x);
}

fn selection_probability(light: u32) -> f32 {
    if (light >= params.light_count) {
        return 0.0;
    }
    return tables[light + 1u] - tables[light];
}

struct LightSample {
    radiance: vec3<f32>,
    direction: vec3<f32>,
    position: vec3<f32>,
    distance: f32,
    pdf: f32,
    is_delta: bool,
    reachable: bool,
    // The environment: the shadow ray is not bounded by `position`.
    infinite: bool,
    valid: bool,
}

fn area_sample(reference: vec3<f32>, position: vec3<f32>, normal: vec3<f32>, pdf_area: f32, radiance: vec3<f32>) -> LightSample {
    var s: LightSample;
    s.valid = false;
    let to_light = position - reference;
    let distance_squared = dot(to_light, to_light);
    if (!(distance_squared > 0.0)) {
        return s;
    }
    let distance = sqrt(distance_squared);
    let direction = to_light / distance;
    let cos_light = -dot(direction, normal);
    if (!(cos_light > 0.0)) {
        return s;
    }
    let pdf = pdf_area * distance_squared / cos_light;
    if (!(pdf < 3.4028235e38)) {
        return s;
    }
    s.radiance = radiance;
    s.direction = direction;
    s.position = position;
    s.distance = distance;
    s.pdf = pdf;
    s.is_delta = false;
    s.valid = true;
    return s;
}

struct Cone {
    axis: vec3<f32>,
    distance: f32,
    cos_theta_max: f32,
    valid: bool,
}

fn sphere_cone(reference: vec3<f32>, center: vec3<f32>, radius: f32) -> Cone {
    var cone: Cone;
    let to_center = center - reference;
    let distance_squared = dot(to_center, to_center);
    cone.valid = distance_squared > radius * radius;
    if (!cone.valid) {
        return cone;
    }
    cone.distance = sqrt(distance_squared);
    cone.axis = to_center / cone.distance;
    cone.cos_theta_max = sqrt(max(0.0, 1.0 - radius * radius / distance_squared));
    return cone;
}

// Texture node `node` of the physical buffer at `uv` (Mitsuba's texture space, v = 0 on the
// image's top row): a spot's cone texture, a projector's irradiance. Until the kernel reads
// texture nodes, `check_supported` refuses the lights that have one.
fn light_texture(node: u32, uv: vec2<f32>) -> vec3<f32> {
    // Lights read their texture at a uv alone, as sampler.rs does (no mesh colours).
    return tex_eval(node, TexPoint(uv, vec2<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0)));
}

// The sample of a light at a point (a spot, a projector): no BSDF sample finds it.
fn delta_sample(position: vec3<f32>, reference: vec3<f32>, radiance: vec3<f32>) -> LightSample {
    var s: LightSample;
    let to_light = position - reference;
    let distance = length(to_light);
    s.radiance = radiance;
    s.direction = to_light / distance;
    s.position = position;
    s.distance = distance;
    s.pdf = 1.0;
    s.is_delta = true;
    s.infinite = false;
    s.valid = true;
    return s;
}

// Mitsuba's `spot` (sampler.rs PreparedLight::Spot): intensity × falloff × texture / r², the
// falloff linear in the angle from the beam width to the cutoff.
fn sample_spot(light: u32, reference: vec3<f32>) -> LightSample {
    var s: LightSample;
    s.valid = false;
    let p = light_word(light, 1u);
    let r0 = light_word(light, 2u);
    let r1 = light_word(light, 3u);
    let r2 = light_word(light, 4u);
    let i = light_word(light, 5u);
    let to_light = p.xyz - reference;
    let distance_squared = dot(to_light, to_light);
    if (!(distance_squared > 0.0)) {
        return s;
    }
    let direction = to_light / sqrt(distance_squared);
    let local = normalize(vec3<f32>(dot(r0.xyz, -direction), dot(r1.xyz, -direction), dot(r2.xyz, -direction)));
    let cos_theta = local.z;
    if (!(cos_theta > p.w)) {
        return s;
    }
    var falloff = 1.0;
    if (cos_theta < r0.w) {
        falloff = (r1.w - acos(clamp(cos_theta, -1.0, 1.0))) * r2.w;
    }
    var radiance = i.xyz * (falloff / distance_squared);
    let texture = bitcast<u32>(light_word(light, 0u).y);
    if (texture != NONE) {
        // Mitsuba's uv over the cutoff cone.
        let uv = vec2<f32>(0.5 + 0.5 * local.x / (local.z * i.w), 0.5 + 0.5 * local.y / (local.z * i.w));
        radiance = radiance * light_texture(texture, uv);
    }
    return delta_sample(p.xyz, reference, radiance);
}

// Mitsuba's `projector` (sampler.rs PreparedLight::Projector): π · scale · E(uv) / (z² cos θ)
// inside its frustum.
fn sample_projector(light: u32, reference: vec3<f32>) -> LightSample {
    var s: LightSample;
    s.valid = false;
    let header = light_word(light, 0u);
    let p = light_word(light, 1u);
    let axis = light_word(light, 5u);
    let h = vec4<f32>(reference, 1.0);
    let local = vec3<f32>(dot(light_word(light, 2u), h), dot(light_word(light, 3u), h), dot(light_word(light, 4u), h));
    if (!(local.z > 0.0)) {
        return s;
    }
    let cot = axis.w;
    let aspect = header.z;
    let uv = vec2<f32>(0.5 - 0.5 * cot * local.x / local.z, 0.5 - 0.5 * aspect * cot * local.y / local.z);
    if (!(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0)) {
        return s;
    }
    let to_light = p.xyz - reference;
    let distance_squared = dot(to_light, to_light);
    if (!(distance_squared > 0.0)) {
        return s;
    }
    let direction = to_light / sqrt(distance_squared);
    let cos_theta = -dot(axis.xyz, direction);
    let factor = PI * p.w / (local.z * local.z * cos_theta);
    if (!(factor > 0.0 && factor < 3.4028235e38)) {
        return s;
    }
    return delta_sample(p.xyz, reference, light_texture(bitcast<u32>(header.y), uv) * factor);
}

fn sample_light(reference: vec3<f32>, u_in: vec2<f32>) -> LightSample {
    var s: LightSample;
    s.valid = false;
    s.infinite = false;
    let chosen = sample_cdf(0u, params.light_count, u_in.x);
    if (!chosen.valid) {
        return s;
    }
    let light = chosen.index;
    var u = vec2<f32>(chosen.remapped, u_in.y);
    let header = light_word(light, 0u);
    let kind = bitcast<u32>(header.x);
    let reachable = header.w > 0.5;
    let p = light_word(light, 1u);
    let radiance = light_word(light, 5u).xyz;
    switch kind {
        case LIGHT_POINT: {
            let to_light = p.xyz - reference;
            let distance_squared = dot(to_light, to_light);
            if (!(distance_squared > 0.0)) {
                return s;
            }
            let distance = sqrt(distance_squared);
            s.radiance = radiance / distance_squared;
            s.direction = to_light / distance;
            s.position = p.xyz;
            s.distance = distance;
            s.pdf = 1.0;
            s.is_delta = true;
            s.valid = true;
        }
        case LIGHT_RECTANGLE: {
            let u_edge = light_word(light, 2u);
            let v_edge = light_word(light, 3u).xyz;
            let normal = light_word(light, 4u).xyz;
            let position = p.xyz + u_edge.xyz * (u.x - 0.5) + v_edge * (u.y - 0.5);
            s = area_sample(reference, position, normal, u_edge.w, radiance);
        }
        case LIGHT_TRIANGLES: {
            let first = bitcast<u32>(header.y);
            let count = bitcast<u32>(header.z);
            let inverse_area = light_word(light, 2u).w;
            if (count == 0u) {
                return s;
            }
            var chosen_triangle = 0u;
            var u0 = u.x;
            if (count > 1u) {
                // partition_point(cumulative <= u.0) over the light's triangles.
                var lo = 0u;
                var hi = count;
                while (lo < hi) {
                    let mid = (lo + hi) / 2u;
                    let c = lights[params.light_triangles + (first + mid) * LIGHT_TRIANGLE_STRIDE].w;
                    if (c <= u.x) {
                        lo = mid + 1u;
                    } else {
                        hi = mid;
                    }
                }
                chosen_triangle = min(lo, count - 1u);
                var start = 0.0;
                if (chosen_triangle > 0u) {
                    start = lights[params.light_triangles + (first + chosen_triangle - 1u) * LIGHT_TRIANGLE_STRIDE].w;
                }
                let width = lights[params.light_triangles + (first + chosen_triangle) * LIGHT_TRIANGLE_STRIDE].w - start;
                if (!(width > 0.0)) {
                    return s;
                }
                u0 = clamp((u.x - start) / width, 0.0, 1.0);
            }
            let base = params.light_triangles + (first + chosen_triangle) * LIGHT_TRIANGLE_STRIDE;
            let b = sample_uniform_triangle(vec2<f32>(u0, u.y));
            let position = lights[base].xyz + lights[base + 1u].xyz * b.x + lights[base + 2u].xyz * b.y;
            var emitted = radiance;
            let textured = light_word(light, 4u);
            if (bitcast<u32>(textured.x) != NONE) {
                // A textured radiance, read at the point's uv (sampler.rs textured_radiance).
                let at = bitcast<u32>(textured.y) + 6u * chosen_triangle;
                let uv0 = vec2<f32>(tables[at], tables[at + 1u]);
                let uv1 = vec2<f32>(tables[at + 2u], tables[at + 3u]);
                let uv2 = vec2<f32>(tables[at + 4u], tables[at + 5u]);
                let uv = uv0 * (1.0 - b.x - b.y) + uv1 * b.x + uv2 * b.y;
                emitted = emitted * light_texture(bitcast<u32>(textured.x), uv);
            }
            s = area_sample(reference, position, lights[base + 3u].xyz, inverse_area, emitted);
        }
        case LIGHT_SPHERE: {
            let radius = p.w;
            let cone = sphere_cone(reference, p.xyz, radius);
            if (!cone.valid) {
                return s;
            }
            let local = sample_uniform_cone(u, cone.cos_theta_max);
            let direction = to_world(frame_from_normal(cone.axis), local);
            let cos_theta = local.z;
            let sin2_theta = max(0.0, 1.0 - cos_theta * cos_theta);
            let distance = cone.distance * cos_theta
                - sqrt(max(0.0, radius * radius - cone.distance * cone.distance * sin2_theta));
            s.radiance = radiance;
            s.direction = direction;
            s.position = reference + direction * distance;
            s.distance = distance;
            s.pdf = uniform_cone_pdf(cone.cos_theta_max);
            s.is_delta = false;
            s.valid = true;
        }
        case LIGHT_SPOT: {
            s = sample_spot(light, reference);
        }
        case LIGHT_DIRECTIONAL: {
            // From infinitely far against the light's direction: an unbounded shadow ray.
            s.radiance = radiance;
            s.direction = -p.xyz;
            s.position = reference - p.xyz;
            s.distance = INF;
            s.infinite = true;
            s.pdf = 1.0;
            s.is_delta = true;
            s.valid = true;
        }
        case LIGHT_PROJECTOR: {
            s = sample_projector(light, reference);
        }
        default: {
            let env = environment_sample(u);
            if (!(env.pdf > 0.0)) {
                return s;
            }
            s.radiance = background_radiance(env.direction);
            s.direction = env.direction;
            s.position = reference + env.direction;
            s.distance = INF;
            s.infinite = true;
            s.pdf = env.pdf;
            s.is_delta = false;
            s.valid = true;
        }
    }
    s.reachable = reachable;
    if (s.is_delta) {
        s.reachable = false;
    }
    s.pdf *= chosen.probability;
    return s;
}

fn pdf_emitter_hit(light: u32, reference: vec3<f32>, hit_point: vec3<f32>, hit_normal: vec3<f32>) -> f32 {
    let probability = selection_probability(light);
    if (!(probability > 0.0)) {
        return 0.0;
    }
    let to_hit = hit_point - reference;
    let distance_squared = dot(to_hit, to_hit);
    let direction = to_hit / sqrt(distance_squared);
    var pdf = 0.0;
    switch light_kind(light) {
        case LIGHT_RECTANGLE: {
            let cos_light = abs(dot(direction, light_word(light, 4u).xyz));
            pdf = distance_squared / (cos_light * light_word(light, 1u).w);
        }
        case LIGHT_TRIANGLES: {
            let cos_light = abs(dot(direction, hit_normal));
            pdf = distance_squared / (cos_light * light_word(light, 1u).w);
        }
        case LIGHT_SPHERE: {
            let p = light_word(light, 1u);
            let cone = sphere_cone(reference, p.xyz, p.w);
            if (cone.valid) {
                pdf = uniform_cone_pdf(cone.cos_theta_max);
            }
        }
        default: {}
    }
    if (pdf < 3.4028235e38) {
        return pdf * probability;
    }
    return 0.0;
}

fn pdf_environment(direction: vec3<f32>) -> f32 {
    if (params.environment_light == NONE) {
        return 0.0;
    }
    return environment_pdf(direction) * selection_probability(params.environment_light);
}

// What light `light` emits towards a ray travelling along `travel` that hit a surface with
// normal `n`: xyz, and w = 1 on the emitting side, 0 behind it.
// The texture node of an area light's radiance, NONE for a constant one.
fn textured_radiance(light: u32) -> u32 {
    if (light_kind(light) != LIGHT_TRIANGLES) {
        return NONE;
    }
    return bitcast<u32>(light_word(light, 4u).x);
}

fn emission_towards(light: u32, travel: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let radiance = light_word(light, 5u).xyz;
    switch light_kind(light) {
        case LIGHT_RECTANGLE: {
            return vec4<f32>(radiance, select(0.0, 1.0, dot(travel, light_word(light, 4u).xyz) < 0.0));
        }
        case LIGHT_TRIANGLES, LIGHT_SPHERE: {
            return vec4<f32>(radiance, select(0.0, 1.0, dot(travel, n) < 0.0));
        }
        default: {
            return vec4<f32>(0.0, 0.0, 0.0, 1.0);
        }
    }
}

// ---------------------------------------------------------------------------------------
// BSDFs (material/bsdf.rs).

struct Lobe {
    kind: u32,
    // Exponent of the glossy lobes, η of the dielectric.
    param: f32,
    weight: vec3<f32>,
    probability: f32,
}

struct Bsdf {
    lobes: array<Lobe, 3>,
    count: u32,
}

struct BsdfSample {
    wi: vec3<f32>,
    weight: vec3<f32>,
    pdf: f32,
    is_specular: bool,
    eta: f32,
    valid: bool,
}

fn bsdf_black() -> Bsdf {
    var b: Bsdf;
    b.count = 0u;
    return b;
}

fn bsdf_add(b: ptr<function, Bsdf>, kind: u32, param: f32, weight: vec3<f32>) {
    let importance = (weight.x + weight.y + weight.z) / 3.0;
    if (importance > 0.0 && is_finite3(weight) && (*b).count < 3u) {
        let i = (*b).count;
        (*b).lobes[i].kind = kind;
        (*b).lobes[i].param = param;
        (*b).lobes[i].weight = weight;
        (*b).lobes[i].probability = importance;
        (*b).count = i + 1u;
    }
}

fn bsdf_normalise(b: ptr<function, Bsdf>) {
    var total = 0.0;
    for (var i = 0u; i < (*b).count; i += 1u) {
        total += (*b).lobes[i].probability;
    }
    for (var i = 0u; i < (*b).count; i += 1u) {
        (*b).lobes[i].probability /= total;
    }
}

fn material_color(rgb: vec4<f32>, uv: vec2<f32>) -> vec3<f32> {
    let texture = bitcast<u32>(rgb.w);
    var c = rgb.xyz;
    if (texture != NONE) {
        c = c * texture_lookup(texture, uv);
    }
    return clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn mirror_lobe_kind(roughness: f32) -> vec2<f32> {
    // x: lobe kind, y: its exponent (bsdf.rs mirror_lobe).
    if (roughness > 0.0 && roughness < 3.4028235e38) {
        return vec2<f32>(f32(LOBE_PHONG), 12.0 / (roughness * roughness));
    }
    return vec2<f32>(f32(LOBE_SPECULAR), 0.0);
}

fn build_bsdf(material: u32, uv: vec2<f32>) -> Bsdf {
    var b = bsdf_black();
    let base = material * MATERIAL_STRIDE;
    let m0 = materials[base];
    let m1 = materials[base + 1u];
    let m2 = materials[base + 2u];
    let m3 = materials[base + 3u];
    let kind = bitcast<u32>(m2.x);
    let exponent = max(m2.y, 0.0);
    let km = clamp(m2.z, 0.0, 1.0);
    let roughness = m2.w;
    switch kind {
        case BSDF_DIFFUSE: {
            bsdf_add(&b, LOBE_DIFFUSE, 0.0, material_color(m0, uv));
        }
        case BSDF_BLINN_PHONG, BSDF_PHONG, BSDF_BLINN_PHONG_MIRRORED: {
            var kd = material_color(m0, uv);
            var ks = material_color(m1, uv);
            let peak = max_component(kd + ks);
            if (peak > 1.0) {
                kd = kd / peak;
                ks = ks / peak;
            }
            if (kind == BSDF_PHONG) {
                bsdf_add(&b, LOBE_DIFFUSE, 0.0, kd);
                bsdf_add(&b, LOBE_PHONG, exponent, ks);
            } else {
                bsdf_add(&b, LOBE_DIFFUSE, 0.0, kd * (1.0 - km));
                bsdf_add(&b, LOBE_BLINN_PHONG, exponent, ks * (1.0 - km));
                if (kind == BSDF_BLINN_PHONG) {
                    bsdf_add(&b, LOBE_SPECULAR, 0.0, vec3<f32>(km));
                } else {
                    let mirror = mirror_lobe_kind(roughness);
                    bsdf_add(&b, u32(mirror.x), mirror.y, vec3<f32>(km));
                }
            }
        }
        case BSDF_MIRROR: {
            let mirror = mirror_lobe_kind(roughness);
            bsdf_add(&b, u32(mirror.x), mirror.y, vec3<f32>(1.0));
        }
        case BSDF_GLAZE: {
            bsdf_add(&b, LOBE_DIFFUSE, 0.0, material_color(m0, uv) * (1.0 - km));
            bsdf_add(&b, LOBE_SPECULAR, 0.0, vec3<f32>(km));
        }
        case BSDF_DIELECTRIC: {
            var eta = m3.x;
            if (!(eta > 0.0 && eta < 3.4028235e38)) {
                eta = 1.0;
            }
            bsdf_add(&b, LOBE_DIELECTRIC, eta, vec3<f32>(1.0));
        }
        default: {}
    }
    bsdf_normalise(&b);
    return b;
}

fn lobe_is_specular(kind: u32) -> bool {
    return kind == LOBE_SPECULAR || kind == LOBE_DIELECTRIC;
}

fn bsdf_has_non_specular(b: ptr<function, Bsdf>) -> bool {
    for (var i = 0u; i < (*b).count; i += 1u) {
        if (!lobe_is_specular((*b).lobes[i].kind)) {
            return true;
        }
    }
    return false;
}

fn bsdf_uses_lobe_sample(b: ptr<function, Bsdf>) -> bool {
    return (*b).count > 1u || ((*b).count == 1u && (*b).lobes[0].kind == LOBE_DIELECTRIC);
}

fn mirror_direction(wo: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(-wo.x, -wo.y, wo.z);
}

// f and pdf of one non-specular lobe, both directions in the upper hemisphere.
fn lobe_eval_and_pdf(kind: u32, exponent: f32, wo: vec3<f32>, wi: vec3<f32>) -> vec2<f32> {
    switch kind {
        case LOBE_DIFFUSE: {
            return vec2<f32>(FRAC_1_PI, cosine_hemisphere_pdf(wi.z));
        }
        case LOBE_BLINN_PHONG: {
            let half = normalize(wo + wi);
            let cos_half = dot(wi, half);
            if (cos_half <= 0.0) {
                return vec2<f32>(0.0);
            }
            let lobe = phong_lobe_pdf(half.z, exponent);
            return vec2<f32>(lobe / (4.0 * cos_half * max(wi.z, wo.z)), lobe / (4.0 * cos_half));
        }
        case LOBE_PHONG: {
            let cos_alpha = dot(wi, mirror_direction(wo));
            if (cos_alpha <= 0.0) {
                return vec2<f32>(0.0);
            }
            let power = pow(cos_alpha, exponent);
            return vec2<f32>((exponent + 2.0) / TAU * power, (exponent + 1.0) / TAU * power);
        }
        default: {
            return vec2<f32>(0.0);
        }
    }
}

// f (xyz) and pdf (w) of the non-specular lobes.
fn bsdf_eval_and_pdf(b: ptr<function, Bsdf>, wo_in: vec3<f32>, wi_in: vec3<f32>) -> vec4<f32> {
    if (wo_in.z * wi_in.z <= 0.0) {
        return vec4<f32>(0.0);
    }
    var wo = wo_in;
    var wi = wi_in;
    if (wo.z < 0.0) {
        wo.z = -wo.z;
        wi.z = -wi.z;
    }
    var f = vec3<f32>(0.0);
    var pdf = 0.0;
    for (var i = 0u; i < (*b).count; i += 1u) {
        let lobe = (*b).lobes[i];
        if (lobe_is_specular(lobe.kind)) {
            continue;
        }
        let fp = lobe_eval_and_pdf(lobe.kind, lobe.param, wo, wi);
        f += lobe.weight * fp.x;
        pdf += lobe.probability * fp.y;
    }
    return vec4<f32>(f, pdf);
}

fn fresnel_dielectric(cos_theta_i: f32, eta_in: f32) -> f32 {
    var cos_i = clamp(cos_theta_i, -1.0, 1.0);
    var eta = eta_in;
    if (cos_i < 0.0) {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    let cos_t = sqrt(max(0.0, 1.0 - sin2_t));
    let parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (parallel * parallel + perpendicular * perpendicular);
}

fn sample_dielectric(wo: vec3<f32>, eta: f32, u: f32) -> BsdfSample {
    var s: BsdfSample;
    s.valid = false;
    let reflectance = fresnel_dielectric(wo.z, eta);
    if (u < reflectance) {
        s.wi = mirror_direction(wo);
        s.weight = vec3<f32>(1.0);
        s.pdf = reflectance;
        s.is_specular = true;
        s.eta = 1.0;
        s.valid = true;
        return s;
    }
    var eta_relative = 1.0 / eta;
    var sign = -1.0;
    if (wo.z > 0.0) {
        eta_relative = eta;
        sign = 1.0;
    }
    let cos_i = abs(wo.z);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta_relative * eta_relative);
    if (sin2_t >= 1.0) {
        return s;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    s.wi = wo * (-1.0 / eta_relative) + vec3<f32>(0.0, 0.0, sign * (cos_i / eta_relative - cos_t));
    s.weight = vec3<f32>(1.0 / (eta_relative * eta_relative));
    s.pdf = 1.0 - reflectance;
    s.is_specular = true;
    s.eta = eta_relative;
    s.valid = true;
    return s;
}

fn bsdf_sample(b: ptr<function, Bsdf>, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> BsdfSample {
    var s: BsdfSample;
    s.valid = false;
    if ((*b).count == 0u) {
        return s;
    }
    // Pick a lobe by probability, then reuse u_lobe within it (bsdf.rs remap).
    var picked = (*b).count - 1u;
    var start = 0.0;
    for (var i = 0u; i < (*b).count; i += 1u) {
        let p = (*b).lobes[i].probability;
        if (u_lobe < start + p || i + 1u == (*b).count) {
            picked = i;
            break;
        }
        start += p;
    }
    let lobe = (*b).lobes[picked];
    let u_event = clamp((u_lobe - start) / lobe.probability, 0.0, ONE_MINUS_EPSILON);
    if (lobe.kind == LOBE_SPECULAR) {
        s.wi = mirror_direction(wo);
        s.weight = lobe.weight / lobe.probability;
        s.pdf = lobe.probability;
        s.is_specular = true;
        s.eta = 1.0;
        s.valid = true;
        return s;
    }
    if (lobe.kind == LOBE_DIELECTRIC) {
        s = sample_dielectric(wo, lobe.param, u_event);
        s.weight = s.weight * lobe.weight / lobe.probability;
        s.pdf *= lobe.probability;
        return s;
    }
    let flip = wo.z < 0.0;
    var wo_up = wo;
    if (flip) {
        wo_up.z = -wo_up.z;
    }
    var wi_up: vec3<f32>;
    switch lobe.kind {
        case LOBE_DIFFUSE: {
            wi_up = sample_cosine_hemisphere(u);
        }
        case LOBE_BLINN_PHONG: {
            let half = sample_phong_lobe(u, lobe.param);
            wi_up = -wo_up + half * (2.0 * dot(wo_up, half));
        }
        default: {
            let around = frame_from_normal(mirror_direction(wo_up));
            wi_up = to_world(around, sample_phong_lobe(u, lobe.param));
        }
    }
    if (!(wi_up.z > 0.0)) {
        return s;
    }
    var wi = wi_up;
    if (flip) {
        wi.z = -wi.z;
    }
    let fp = bsdf_eval_and_pdf(b, wo, wi);
    if (!(fp.w > 0.0)) {
        return s;
    }
    s.wi = wi;
    s.weight = fp.xyz * (abs(wi.z) / fp.w);
    s.pdf = fp.w;
    s.is_specular = false;
    s.eta = 1.0;
    s.valid = true;
    return s;
}

// ---------------------------------------------------------------------------------------
// Geometry (geometry.rs) and the BVH (layout.rs: two vec4 per node; count 0 is an interior
// node whose first child follows it and whose second child is at `offset`).

struct Ray {
    origin: vec3<f32>,
    direction: vec3<f32>,
    t_min: f32,
    t_max: f32,
}

struct Hit {
    t: f32,
    primitive: u32,
    instance: u32,
    b1: f32,
    b2: f32,
}

fn intersect_triangle(ray: Ray, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>) -> vec3<f32> {
    // Returns (t, b1, b2), t = -1 for a miss.
    let miss = vec3<f32>(-1.0, 0.0, 0.0);
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let p = cross(ray.direction, e2);
    let det = dot(e1, p);
    if (det == 0.0 || !(abs(det) < 3.4028235e38)) {
        return miss;
    }
    let inv = 1.0 / det;
    let s = ray.origin - v0;
    let b1 = dot(s, p) * inv;
    if (!(b1 >= 0.0 && b1 <= 1.0)) {
        return miss;
    }
    let q = cross(s, e1);
    let b2 = dot(ray.direction, q) * inv;
    if (b2 < 0.0 || b1 + b2 > 1.0) {
        return miss;
    }
    let t = dot(e2, q) * inv;
    // A ray that starts on the triangle's plane meets it at t = 0 exactly here, where the
    // CPU's watertight test rounds to either side: a camera in the plane of a visible area
    // light (scenes_B/threeEggs_SoftShadows) must not see only the light's back.
    if (t > ray.t_min && t <= ray.t_max) {
        return vec3<f32>(t, b1, b2);
    }
    return miss;
}

fn intersect_sphere(ray: Ray, center: vec3<f32>, radius: f32) -> f32 {
    let oc = ray.origin - center;
    let a = dot(ray.direction, ray.direction);
    if (a == 0.0) {
        return -1.0;
    }
    let half_b = dot(ray.direction, oc);
    let c = dot(oc, oc) - radius * radius;
    let perpendicular = oc - ray.direction * (half_b / a);
    let disc = a * (radius * radius - dot(perpendicular, perpendicular));
    if (disc < 0.0) {
        return -1.0;
    }
    let sq = sqrt(disc);
    var q = -half_b + sq;
    if (half_b > 0.0) {
        q = -half_b - sq;
    }
    var t0 = 0.0;
    var t1 = 0.0;
    if (q != 0.0) {
        t0 = q / a;
        t1 = c / q;
    }
    if (t0 > t1) {
        let swap = t0;
        t0 = t1;
        t1 = swap;
    }
    if (t0 >= ray.t_min && t0 <= ray.t_max) {
        return t0;
    }
    if (t1 >= ray.t_min && t1 <= ray.t_max) {
        return t1;
    }
    return -1.0;
}

// The slab interval (t_near, t_far), or t_near > t_far for none.
fn slab_interval(origin: vec3<f32>, direction: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    var t_near = -INF;
    var t_far = INF;
    for (var axis = 0u; axis < 3u; axis += 1u) {
        let o = origin[axis];
        let d = direction[axis];
        if (d == 0.0) {
            if (o < lo[axis] || o > hi[axis]) {
                return vec2<f32>(1.0, -1.0);
            }
            continue;
        }
        let inv = 1.0 / d;
        var t0 = (lo[axis] - o) * inv;
        var t1 = (hi[axis] - o) * inv;
        if (t0 > t1) {
            let swap = t0;
            t0 = t1;
            t1 = swap;
        }
        t_near = max(t_near, t0);
        t_far = min(t_far, t1);
        if (t_near > t_far) {
            return vec2<f32>(1.0, -1.0);
        }
    }
    return vec2<f32>(t_near, t_far);
}

fn intersect_box(ray: Ray, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let span = slab_interval(ray.origin, ray.direction, lo, hi);
    if (!(span.x <= span.y)) {
        return -1.0;
    }
    if (span.x >= ray.t_min && span.x <= ray.t_max) {
        return span.x;
    }
    if (span.y >= ray.t_min && span.y <= ray.t_max) {
        return span.y;
    }
    return -1.0;
}

fn transform_point(m: u32, p: vec3<f32>) -> vec3<f32> {
    let r0 = prims[m];
    let r1 = prims[m + 1u];
    let r2 = prims[m + 2u];
    return vec3<f32>(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}

fn transform_vector(m: u32, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(prims[m].xyz, v), dot(prims[m + 1u].xyz, v), dot(prims[m + 2u].xyz, v));
}

fn instance_base(instance: u32) -> u32 {
    return params.instances + instance * INSTANCE_STRIDE;
}

// [geometry's root node, material override, flags, 0].
fn instance_info(instance: u32) -> vec4<f32> {
    return prims[instance_base(instance) + 3u];
}

// (t, b1, b2) of the primitive for a ray in its object space, t < 0 for a miss.
fn intersect_primitive(ray: Ray, primitive: u32) -> vec3<f32> {
    let base = primitive * PRIM_STRIDE;
    let p0 = prims[base];
    let p1 = prims[base + 1u];
    let kind = bitcast<u32>(p0.w);
    if (kind == PRIM_TRIANGLE) {
        return intersect_triangle(ray, p0.xyz, p1.xyz, prims[base + 2u].xyz);
    }
    if (kind == PRIM_SPHERE) {
        return vec3<f32>(intersect_sphere(ray, p0.xyz, p1.x), 0.0, 0.0);
    }
    return vec3<f32>(intersect_box(ray, p0.xyz, p1.xyz), 0.0, 0.0);
}

fn node_hit(ray_origin: vec3<f32>, inverse_direction: vec3<f32>, node: u32, t_min: f32, t_max: f32) -> bool {
    let lo = (nodes[2u * node].xyz - ray_origin) * inverse_direction;
    let hi = (nodes[2u * node + 1u].xyz - ray_origin) * inverse_direction;
    let near = max(max(min(lo.x, hi.x), min(lo.y, hi.y)), max(min(lo.z, hi.z), t_min));
    let far = min(min(max(lo.x, hi.x), max(lo.y, hi.y)), min(max(lo.z, hi.z), t_max));
    // NaN (0 · ∞ for a zero direction component on a slab plane) never prunes: the
    // primitive tests decide.
    return !(near > far * 1.00000024);
}

const STACK_SIZE: u32 = 64u;

// One instance's geometry, the ray in its object space (world t kept: the direction is not
// normalised): records a closer hit in `best`; true when it found one.
fn traverse_geometry(ray_in: Ray, root: u32, instance: u32, any_hit: bool, best: ptr<function, Hit>) -> bool {
    var ray = ray_in;
    let inverse_direction = 1.0 / ray.direction;
    var stack: array<u32, STACK_SIZE>;
    var top = 0u;
    var node = root;
    var found = false;
    loop {
        if (node_hit(ray.origin, inverse_direction, node, ray.t_min, ray.t_max)) {
            let count = bitcast<u32>(nodes[2u * node + 1u].w);
            let offset = bitcast<u32>(nodes[2u * node].w);
            if (count > 0u) {
                for (var i = 0u; i < count; i += 1u) {
                    let primitive = offset + i;
                    let h = intersect_primitive(ray, primitive);
                    if (h.x >= 0.0 && h.x >= ray.t_min && h.x <= ray.t_max) {
                        (*best).t = h.x;
                        (*best).primitive = primitive;
                        (*best).instance = instance;
                        (*best).b1 = h.y;
                        (*best).b2 = h.z;
                        ray.t_max = h.x;
                        found = true;
                        if (any_hit) {
                            return true;
                        }
                    }
                }
            } else {
                // The first child follows its parent; the second waits on the stack.
                if (top < STACK_SIZE) {
                    stack[top] = offset;
                    top += 1u;
                }
                node = node + 1u;
                continue;
            }
        }
        if (top == 0u) {
            break;
        }
        top -= 1u;
        node = stack[top];
    }
    return found;
}

// The closest hit in the ray's window (any_hit: the first hit on an instance that casts
// shadows, for occlusion): the top-level BVH over the instances, then each instance's
// geometry in its object space.
fn traverse(ray_in: Ray, any_hit: bool) -> Hit {
    var ray = ray_in;
    var best: Hit;
    best.t = -1.0;
    best.primitive = NONE;
    best.instance = NONE;
    let inverse_direction = 1.0 / ray.direction;
    var stack: array<u32, STACK_SIZE>;
    var top = 0u;
    var node = params.tlas_root;
    loop {
        if (node_hit(ray.origin, inverse_direction, node, ray.t_min, ray.t_max)) {
            let count = bitcast<u32>(nodes[2u * node + 1u].w);
            let offset = bitcast<u32>(nodes[2u * node].w);
            if (count > 0u) {
                for (var i = 0u; i < count; i += 1u) {
                    let instance = offset + i;
                    let info = instance_info(instance);
                    let flags = bitcast<u32>(info.z);
                    if (any_hit && (flags & FLAG_CASTS_SHADOW) == 0u) {
                        continue;
                    }
                    var local = ray;
                    if ((flags & FLAG_TRANSFORMED) != 0u) {
                        let m = instance_base(instance);
                        local.origin = transform_point(m, ray.origin);
                        local.direction = transform_vector(m, ray.direction);
                    }
                    if (traverse_geometry(local, bitcast<u32>(info.x), instance, any_hit, &best)) {
                        if (any_hit) {
                            return best;
                        }
                        ray.t_max = best.t;
                    }
                }
            } else {
                if (top < STACK_SIZE) {
                    stack[top] = offset;
                    top += 1u;
                }
                node = node + 1u;
                continue;
            }
        }
        if (top == 0u) {
            break;
        }
        top -= 1u;
        node = stack[top];
    }
    return best;
}

// The material of a hit: the instance's override, else the primitive's.
fn hit_material(hit: Hit) -> u32 {
    let override_material = bitcast<u32>(instance_info(hit.instance).y);
    if (override_material != NONE) {
        return override_material;
    }
    return bitcast<u32>(prims[hit.primitive * PRIM_STRIDE + 1u].w);
}

struct Surface {
    point: vec3<f32>,
    normal: vec3<f32>,
    uv: vec2<f32>,
    material: u32,
}

fn box_normal(p: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec3<f32> {
    var best = INF;
    var normal = vec3<f32>(0.0, 1.0, 0.0);
    for (var axis = 0u; axis < 3u; axis += 1u) {
        let dl = abs(p[axis] - lo[axis]);
        let dh = abs(p[axis] - hi[axis]);
        if (dl < best) {
            best = dl;
            normal = vec3<f32>(0.0);
            normal[axis] = -1.0;
        }
        if (dh < best) {
            best = dh;
            normal = vec3<f32>(0.0);
            normal[axis] = 1.0;
        }
    }
    return normal;
}

fn surface(ray: Ray, hit: Hit, needs_uv: bool) -> Surface {
    var si: Surface;
    let base = hit.primitive * PRIM_STRIDE;
    let p0 = prims[base];
    let p1 = prims[base + 1u];
    let kind = bitcast<u32>(p0.w);
    si.point = ray.origin + ray.direction * hit.t;
    si.material = hit_material(hit);
    si.uv = vec2<f32>(0.0);
    var m = NONE;
    if ((bitcast<u32>(instance_info(hit.instance).z) & FLAG_TRANSFORMED) != 0u) {
        m = instance_base(hit.instance);
    }
    var local = si.point;
    if (m != NONE) {
        local = transform_point(m, si.point);
    }
    var n: vec3<f32>;
    if (kind == PRIM_TRIANGLE) {
        // The object-space normal was worked out when the scene was flattened.
        n = prims[base + 3u].xyz;
        si.uv = vec2<f32>(hit.b1, hit.b2);
    } else if (kind == PRIM_SPHERE) {
        let center = p0.xyz;
        let radius = p1.x;
        n = normalize((local - center) / radius);
        if (needs_uv) {
            let d = (local - center) / radius;
            let theta = acos(clamp(d.y, -1.0, 1.0));
            let phi = atan2(-d.z, d.x);
            let u = phi / TAU;
            si.uv = vec2<f32>(u - floor(u), 1.0 - theta / PI);
        }
    } else {
        let lo = p0.xyz;
        let hi = p1.xyz;
        n = box_normal(local, lo, hi);
        if (needs_uv) {
            let e = hi - lo;
            let rel = local - lo;
            let f = select(vec3<f32>(0.0), rel / e, e > vec3<f32>(0.0));
            if (n.x != 0.0) {
                si.uv = vec2<f32>(f.z, f.y);
            } else if (n.y != 0.0) {
                si.uv = vec2<f32>(f.x, f.z);
            } else {
                si.uv = vec2<f32>(f.x, f.y);
            }
        }
    }
    if (m != NONE) {
        // Normals go to world space by the transpose of object_from_world.
        let r0 = prims[m].xyz;
        let r1 = prims[m + 1u].xyz;
        let r2 = prims[m + 2u].xyz;
        n = normalize(r0 * n.x + r1 * n.y + r2 * n.z);
    }
    si.normal = n;
    return si;
}

// ---------------------------------------------------------------------------------------
// The camera (camera.rs) and the path loop (integrator/path.rs).

// The ray through image-plane point (px, py) (camera.rs Camera::lens_ray): with a thin lens
// (`params.lens.x` its radius, `.y` its focus distance), from the point of the lens that
// `lens_sample` maps to, through where the pinhole ray meets the plane in focus.
fn camera_ray(px: f32, py: f32, lens_sample: vec2<f32>) -> Ray {
    let w = params.camera_v.w;
    let h = w / params.camera_w.w;
    let u = -0.5 * w + w * px / f32(params.width);
    let v = -0.5 * h + h * py / f32(params.height);
    var ray: Ray;
    ray.t_min = 0.0;
    ray.t_max = INF;
    let bu = params.camera_u.xyz;
    let bv = params.camera_v.xyz;
    let bw = params.camera_w.xyz;
    if (params.projection == 0u) {
        ray.origin = params.camera_position.xyz;
        ray.direction = bw * -params.camera_u.w + bu * u + bv * v;
    } else {
        ray.origin = params.camera_position.xyz + bu * u + bv * v;
        ray.direction = -bw;
    }
    if (params.lens.x > 0.0) {
        let d = sample_uniform_disk_concentric(lens_sample);
        let offset = bu * (d.x * params.lens.x) + bv * (d.y * params.lens.x);
        let along = -dot(ray.direction, bw);
        let t_focus = params.lens.y / along;
        ray.origin = ray.origin + offset;
        ray.direction = ray.direction - offset * (1.0 / t_focus);
    }
    if (params.lens.w > 0.0) {
        // Camera::clipped: the planes' distances along the view become distances along the
        // (unit) ray.
        ray.direction = normalize(ray.direction);
        let along = -dot(ray.direction, bw);
        if (along > 0.0) {
            ray.t_min = params.lens.z / along;
            ray.t_max = params.lens.w / along;
        }
    }
    return ray;
}

// One axis of a sample's offset from the pixel's centre, by the filter's table
// (path.rs FilterSampler::sample).
fn filter_sample(u: f32) -> f32 {
    let radius = bitcast<f32>(params.filter_param);
    // partition_point(c <= u) over the FILTER_BINS + 1 entries, clamped to [1, BINS].
    var lo = 0u;
    var hi = FILTER_BINS + 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (tables[params.filter_table + mid] <= u) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let bin = clamp(lo, 1u, FILTER_BINS) - 1u;
    let c0 = tables[params.filter_table + bin];
    let c1 = tables[params.filter_table + bin + 1u];
    var within = 0.5;
    if (c1 > c0) {
        within = (u - c0) / (c1 - c0);
    }
    let width = 2.0 * radius / f32(FILTER_BINS);
    return -radius + (f32(bin) + within) * width;
}

fn spawn(origin: vec3<f32>, direction: vec3<f32>) -> Ray {
    var r: Ray;
    r.origin = origin;
    r.direction = direction;
    r.t_min = SPAWN_EPSILON;
    r.t_max = INF;
    return r;
}

fn material_index(id: u32) -> u32 {
    // The last entry is the fallback material, for ids out of range.
    return min(id, params.material_count - 1u);
}

// What the camera ray's first hit gives the feature layers (integrator/mod.rs FirstHit).
var<private> first_albedo: vec3<f32>;
var<private> first_normal: vec3<f32>;
var<private> first_depth: f32;

// The BSDF tree of a physically based material, NONE for the course's materials.
fn physical_tree(material: u32) -> u32 {
    let m2 = materials[material * MATERIAL_STRIDE + 2u];
    if (bitcast<u32>(m2.x) == BSDF_PHYSICAL) {
        return bitcast<u32>(m2.y);
    }
    return NONE;
}

// Whether nothing that casts shadows lies between `point` and the light sample.
fn unoccluded(point: vec3<f32>, sample: LightSample) -> bool {
    var shadow: Ray;
    if (sample.infinite) {
        shadow = spawn(point, sample.direction);
    } else {
        shadow = spawn(point, sample.position - point);
        shadow.t_max = 1.0 - SPAWN_EPSILON;
    }
    return traverse(shadow, true).primitive == NONE;
}

fn trace(camera: Ray) -> vec3<f32> {
    first_albedo = vec3<f32>(0.0);
    first_normal = vec3<f32>(0.0);
    first_depth = 0.0;
    var ray = camera;
    ray.direction = normalize(camera.direction);
    var radiance = vec3<f32>(0.0);
    var throughput = vec3<f32>(1.0);
    var eta_scale = 1.0;
    var specular_bounce = true;
    var bsdf_pdf = 0.0;
    var depth = 0u;
    loop {
        let hit = traverse(ray, false);
        if (hit.primitive == NONE) {
            var background = background_radiance(ray.direction);
            if (depth == 0u && (params.render_flags & RENDER_HIDE_EMITTERS) != 0u) {
                background = vec3<f32>(0.0);
            }
            if (depth == 0u) {
                first_albedo = clamp(background, vec3<f32>(0.0), vec3<f32>(1.0));
            }
            if (any(background != vec3<f32>(0.0))) {
                var weight = 1.0;
                if (!specular_bounce) {
                    weight = power_heuristic(bsdf_pdf, pdf_environment(ray.direction));
                }
                radiance += throughput * background * weight;
            }
            break;
        }
        let material = material_index(hit_material(hit));
        let mbase = material * MATERIAL_STRIDE;
        let m3 = materials[mbase + 3u];
        // Hidden emitters are not there for camera rays (Mitsuba's hide_emitters).
        if (depth == 0u && (params.render_flags & RENDER_HIDE_EMITTERS) != 0u && bitcast<u32>(m3.y) != EMITTER_NONE) {
            ray = spawn(ray.origin + ray.direction * hit.t, ray.direction);
            continue;
        }
        let textured = bitcast<u32>(materials[mbase].w) != NONE || bitcast<u32>(materials[mbase + 1u].w) != NONE;
        let si = surface(ray, hit, textured);

        let emitter = bitcast<u32>(m3.y);
        var behind_emitter = false;
        if (emitter != EMITTER_NONE) {
            var emitted = vec4<f32>(0.0);
            if (emitter == EMITTER_LIGHT) {
                let light = bitcast<u32>(m3.z);
                emitted = emission_towards(light, ray.direction, si.normal);
                let texture = textured_radiance(light);
                if (texture != NONE && emitted.w > 0.5) {
                    // A textured radiance, read where the path meets it (path.rs `emitted`).
                    emitted = vec4<f32>(emitted.xyz * tex_eval(texture, physical_surface(ray, hit).tex), emitted.w);
                }
            } else {
                emitted = vec4<f32>(materials[mbase + 5u].xyz, select(0.0, 1.0, dot(ray.direction, si.normal) < 0.0));
            }
            if (emitted.w > 0.5) {
                if (any(emitted.xyz != vec3<f32>(0.0))) {
                    var weight = 1.0;
                    if (emitter == EMITTER_LIGHT && !specular_bounce) {
                        let light_pdf = pdf_emitter_hit(bitcast<u32>(m3.z), ray.origin, si.point, si.normal);
                        weight = power_heuristic(bsdf_pdf, light_pdf);
                    }
                    radiance += throughput * emitted.xyz * weight;
                }
            } else {
                behind_emitter = true;
            }
            if (depth == 0u) {
                first_albedo = clamp(emitted.xyz * emitted.w, vec3<f32>(0.0), vec3<f32>(1.0));
            }
        }

        // Beer's law inside a dielectric.
        if (m3.w > 0.5 && dot(ray.direction, si.normal) > 0.0) {
            let attenuation = max(materials[mbase + 4u].xyz, vec3<f32>(0.0));
            throughput = throughput * pow(attenuation, vec3<f32>(hit.t));
        }

        // The vertex scatters by its physically based tree or by the course's lobes; either
        // way the path goes on from `point` along the world direction `next.wi`.
        var point = si.point;
        var next: BsdfSample;
        let tree = physical_tree(material);
        if (physical_materials && tree != NONE && !behind_emitter) {
            let ps = physical_surface(ray, hit);
            let wo_world = -ray.direction;
            resolve_bsdf(tree, ps, wo_world);
            if (depth == 0u) {
                let n = ps.frame.w;
                first_normal = select(n, -n, dot(n, wo_world) < 0.0);
                first_depth = hit.t;
                if (!phys_is_black()) {
                    first_albedo = phys_albedo();
                }
            }
            if (depth >= params.max_depth || phys_is_black()) {
                break;
            }
            // The CPU's order: direction and light numbers, then the leaf's.
            let u_direction = next_2d();
            let u_light = next_2d();
            let u_lobe = next_1d();
            let draw = phys_draw(wo_world, u_lobe, u_direction);
            var sample: LightSample;
            sample.valid = false;
            if (phys_has_non_delta()) {
                sample = sample_light(ps.point, u_light);
            }
            // The light's direction and the BSDF sample's, evaluated in one pass.
            let pair = phys_eval_pdf_pair(wo_world, sample.direction, sample.valid, draw.s.wi, draw.mis);
            let continuation = phys_finish(draw, pair[1]);
            if (sample.valid) {
                let fp = pair[0];
                if (any(fp.xyz != vec3<f32>(0.0)) && any(sample.radiance != vec3<f32>(0.0)) && unoccluded(ps.point, sample)) {
                    var weight = 1.0;
                    if (!sample.is_delta && sample.reachable) {
                        weight = power_heuristic(sample.pdf, fp.w);
                    }
                    radiance += throughput * fp.xyz * sample.radiance * (weight / sample.pdf);
                }
            }
            point = ps.point;
            next = BsdfSample(continuation.wi, continuation.weight, continuation.pdf, continuation.is_specular, continuation.eta, continuation.valid);
        } else {
            let frame = frame_from_normal(si.normal);
            let wo = to_local(frame, -ray.direction);
            var bsdf = bsdf_black();
            if (!behind_emitter) {
                bsdf = build_bsdf(material, si.uv);
            }
            if (depth == 0u) {
                first_normal = select(si.normal, -si.normal, wo.z < 0.0);
                first_depth = hit.t;
                if (bsdf.count > 0u) {
                    var albedo = vec3<f32>(0.0);
                    for (var i = 0u; i < bsdf.count; i += 1u) {
                        albedo += bsdf.lobes[i].weight;
                    }
                    first_albedo = clamp(albedo, vec3<f32>(0.0), vec3<f32>(1.0));
                }
            }
            if (depth >= params.max_depth || bsdf.count == 0u || wo.z == 0.0) {
                break;
            }

            let nee = bsdf_has_non_specular(&bsdf);
            var u_light = vec2<f32>(0.5);
            if (nee) {
                u_light = next_2d();
            }
            var u_lobe = 0.5;
            if (bsdf_uses_lobe_sample(&bsdf)) {
                u_lobe = next_1d();
            }
            let u_direction = next_2d();
            let continuation = bsdf_sample(&bsdf, wo, u_lobe, u_direction);

            if (nee) {
                let sample = sample_light(si.point, u_light);
                if (sample.valid) {
                    let wi = to_local(frame, sample.direction);
                    let fp = bsdf_eval_and_pdf(&bsdf, wo, wi);
                    if (any(fp.xyz != vec3<f32>(0.0)) && any(sample.radiance != vec3<f32>(0.0)) && unoccluded(si.point, sample)) {
                        var weight = 1.0;
                        if (!sample.is_delta && sample.reachable) {
                            weight = power_heuristic(sample.pdf, fp.w);
                        }
                        radiance += throughput * fp.xyz * sample.radiance * (abs(wi.z) * weight / sample.pdf);
                    }
                }
            }

            next = continuation;
            next.wi = to_world(frame, continuation.wi);
        }

        if (!next.valid) {
            break;
        }
        throughput = throughput * next.weight;
        if (all(throughput == vec3<f32>(0.0)) || !is_finite3(throughput)) {
            break;
        }
        specular_bounce = next.is_specular;
        bsdf_pdf = next.pdf;
        eta_scale *= next.eta * next.eta;
        ray = spawn(point, next.wi);
        depth += 1u;

        if (depth >= params.rr_depth) {
            let survival = min(max_component(throughput * eta_scale), 0.95);
            if (next_1d() >= survival) {
                break;
            }
            throughput = throughput / survival;
        }
    }
    return radiance;
}

// Mesa's llvmpipe (lavapipe) stops every loop of an invocation once their iterations
// together reach 65535 (gallivm's loop limiter, a guard against hung shaders): a traversal
// cut short that way misses geometry and the sample is silently wrong. Whether it happened
// is visible afterwards, because the limiter never recovers: a loop that must iterate twice
// then stops after one pass. Real GPUs have no such limit and the check costs two iterations.
fn loop_limit_reached() -> bool {
    var n = 0u;
    loop {
        n += 1u;
        if (n >= params.canary) {
            break;
        }
    }
    return n < params.canary;
}

// Three vec4 per pixel of the crop window in `accum`: [radiance sum, valid samples],
// [albedo sum, depth sum], [normal sum, samples cut short by the loop limit].
const ACCUM_STRIDE: u32 = 3u;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.crop_width || id.y >= params.crop_height) {
        return;
    }
    let x = params.x0 + id.x;
    let y = params.y0 + id.y;
    // Random numbers are keyed by the pixel's index in the whole image, so a crop window
    // renders its pixels exactly as the whole image does.
    let pixel = y * params.width + x;
    // The lecture's j counts rows from the bottom; film row 0 is the top.
    let j = params.height - 1u - y;
    let slot = ACCUM_STRIDE * (id.y * params.crop_width + id.x);
    var sum = accum[slot];
    var features = accum[slot + 1u];
    var normal = accum[slot + 2u];
    for (var s = 0u; s < params.samples; s += 1u) {
        rng_seed(pixel, params.first_sample + s);
        var offset = next_2d();
        if (params.filter_kind != FILTER_BOX) {
            // The sample placed by importance-sampling the filter around the pixel's centre.
            offset = vec2<f32>(0.5 + filter_sample(offset.x), 0.5 + filter_sample(offset.y));
        }
        var lens = vec2<f32>(0.5);
        if (params.lens.x > 0.0) {
            lens = next_2d();
        }
        let ray = camera_ray(f32(x) + offset.x, f32(j) + offset.y, lens);
        let radiance = trace(ray);
        if (loop_limit_reached()) {
            // This sample and the pass's remaining ones are lost: the host reports it.
            normal.w += f32(params.samples - s);
            break;
        }
        // Non-finite samples are dropped, as the CPU pipeline drops them.
        if (is_finite3(radiance)) {
            sum += vec4<f32>(radiance, 1.0);
        }
        features += vec4<f32>(first_albedo, first_depth);
        normal += vec4<f32>(first_normal, 0.0);
    }
    accum[slot] = sum;
    accum[slot + 1u] = features;
    accum[slot + 2u] = normal;
}
