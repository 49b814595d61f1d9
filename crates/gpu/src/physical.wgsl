// The physically based materials of Mitsuba scenes and glTF models on the GPU: a port of
// crates/render/src/material/{physical,surface,microfacet,fresnel,diffuse}.rs and of
// `Scene::physical_surface`. The kernel is path.wgsl followed by this file and the families'
// files (conductor, dielectric, plastic, principled, gltf .wgsl), one module; the records read
// here are written by crates/gpu/src/physical.rs, whose constants the names below repeat.
//
// A hit resolves its material's tree of BSDF nodes into at most MAX_LEAVES weighted leaves
// (`leaves`, a private array: one surface is resolved at a time), each a family with its
// parameters read at the hit, in its own shading frame, as `SurfaceBsdf::new` does; the
// path loop then evaluates and samples the mixture in world directions.

// BSDF node kinds (physical.rs NODE_*).
const NODE_NULL: u32 = 0u;
const NODE_DIFFUSE: u32 = 1u;
const NODE_CONDUCTOR: u32 = 2u;
const NODE_DIELECTRIC: u32 = 3u;
const NODE_THIN_DIELECTRIC: u32 = 4u;
const NODE_PLASTIC: u32 = 5u;
const NODE_PRINCIPLED: u32 = 6u;
const NODE_PRINCIPLED_THIN: u32 = 7u;
const NODE_TWOSIDED: u32 = 8u;
const NODE_NORMALMAP: u32 = 9u;
const NODE_BUMPMAP: u32 = 10u;
const NODE_MASK: u32 = 11u;
const NODE_BLEND: u32 = 12u;
const NODE_GLTF: u32 = 13u;

// Leaf families (surface.rs Family).
const FAMILY_NULL: u32 = 0u;
const FAMILY_DIFFUSE: u32 = 1u;
const FAMILY_CONDUCTOR: u32 = 2u;
const FAMILY_ROUGH_CONDUCTOR: u32 = 3u;
const FAMILY_DIELECTRIC: u32 = 4u;
const FAMILY_THIN_DIELECTRIC: u32 = 5u;
const FAMILY_ROUGH_DIELECTRIC: u32 = 6u;
const FAMILY_PLASTIC: u32 = 7u;
const FAMILY_ROUGH_PLASTIC: u32 = 8u;
const FAMILY_PRINCIPLED: u32 = 9u;
const FAMILY_PRINCIPLED_THIN: u32 = 10u;
const FAMILY_GLTF: u32 = 11u;

// Texture node kinds and record stride (physical.rs TEX_*).
const TEX_BITMAP: u32 = 0u;
const TEX_CHECKERBOARD: u32 = 1u;
const TEX_VERTEX_COLOR: u32 = 2u;
const TEX_FACE_COLOR: u32 = 3u;
const TEX_STRIDE: u32 = 5u;
const WRAP_REPEAT: u32 = 0u;
const WRAP_MIRROR: u32 = 1u;
const WRAP_CLAMP: u32 = 2u;

// Which corner attributes a triangle's attribute record holds, in this order after its
// header (physical.rs ATTR_*).
const ATTR_NORMALS: u32 = 1u;
const ATTR_UVS: u32 = 2u;
const ATTR_UVS1: u32 = 4u;
const ATTR_TANGENTS: u32 = 8u;
const ATTR_VERTEX_COLORS: u32 = 16u;
const ATTR_FACE_COLOR: u32 = 32u;
// A sphere's flag (its record's third word, x): Mitsuba's uv parameterisation.
const SPHERE_MITSUBA_UV: u32 = 1u;

const MAX_LEAVES: u32 = 4u;
const LEAF_WORDS: u32 = 8u;
// Wrappers nest at most this deep (surface.rs MAX_NESTING).
const MAX_NESTING: u32 = 16u;
// Pending nodes of the resolver; a tree wider than this loses its last branches.
const RESOLVE_STACK: u32 = 8u;
const MIN_ALPHA: f32 = 1e-4;
const INV_SQRT_PI: f32 = 0.5641896;

fn word_u32(v: f32) -> u32 {
    return bitcast<u32>(v);
}

fn luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// ---------------------------------------------------------------------------------------
// Texture nodes (texture.rs TextureNode): [kind, image, filter, wrap u | wrap v << 4],
// [a, b, c, uv set], [d, e, f, 0], [colour 0], [colour 1].

struct TexPoint {
    uv: vec2<f32>,
    uv1: vec2<f32>,
    vertex_color: vec3<f32>,
    face_color: vec3<f32>,
}

fn wrap_texel(x: i32, size: u32, wrap: u32) -> u32 {
    let n = i32(size);
    if (wrap == WRAP_CLAMP) {
        return u32(clamp(x, 0, n - 1));
    }
    if (wrap == WRAP_MIRROR) {
        let period = 2 * n;
        var m = x % period;
        if (m < 0) {
            m += period;
        }
        return u32(select(m, period - 1 - m, m >= n));
    }
    var m = x % n;
    if (m < 0) {
        m += n;
    }
    return u32(m);
}

fn image_texel(image: u32, x: i32, y: i32, wraps: u32) -> vec3<f32> {
    let info = params.texture_info + 3u * image;
    let offset = table_u32(info);
    let width = table_u32(info + 1u);
    let height = table_u32(info + 2u);
    let cx = wrap_texel(x, width, wraps & 15u);
    let cy = wrap_texel(y, height, wraps >> 4u);
    return texel_at(offset + cy * width + cx);
}

// The node's uv: the surface's set it reads, through `to_uv`.
fn tex_uv(base: u32, at: TexPoint) -> vec2<f32> {
    let r0 = physical[base + 1u];
    let r1 = physical[base + 2u];
    let uv = select(at.uv, at.uv1, word_u32(r0.w) == 1u);
    return vec2<f32>(r0.x * uv.x + r0.y * uv.y + r0.z, r1.x * uv.x + r1.y * uv.y + r1.z);
}

fn image_size(image: u32) -> vec2<u32> {
    let info = params.texture_info + 3u * image;
    return vec2<u32>(table_u32(info + 1u), table_u32(info + 2u));
}

fn checker_square(uv: vec2<f32>) -> bool {
    let upper_u = uv.x - floor(uv.x) > 0.5;
    let upper_v = uv.y - floor(uv.y) > 0.5;
    return upper_u == upper_v;
}

// Texture node `node`'s colour at `at` (TextureNode::eval).
fn tex_eval(node: u32, at: TexPoint) -> vec3<f32> {
    let base = params.texture_nodes + TEX_STRIDE * node;
    let head = physical[base];
    let kind = word_u32(head.x);
    if (kind == TEX_VERTEX_COLOR) {
        return at.vertex_color;
    }
    if (kind == TEX_FACE_COLOR) {
        return at.face_color;
    }
    let uv = tex_uv(base, at);
    if (kind == TEX_CHECKERBOARD) {
        return select(physical[base + 4u].xyz, physical[base + 3u].xyz, checker_square(uv));
    }
    let image = word_u32(head.y);
    let size = image_size(image);
    if (size.x == 0u || size.y == 0u) {
        return vec3<f32>(0.0);
    }
    let wraps = word_u32(head.w);
    // Far outside [0, 1] only the wrap matters; the clamp keeps the conversions defined.
    let limit = 1.0e9;
    let x = clamp(uv.x * f32(size.x), -limit, limit);
    let y = clamp(uv.y * f32(size.y), -limit, limit);
    if (!(abs(x) <= limit && abs(y) <= limit)) {
        return vec3<f32>(0.0);
    }
    if (word_u32(head.z) == 0u) {
        return image_texel(image, i32(floor(x)), i32(floor(y)), wraps);
    }
    let xs = x - 0.5;
    let ys = y - 0.5;
    let x0 = floor(xs);
    let y0 = floor(ys);
    let fx = xs - x0;
    let fy = ys - y0;
    let ix = i32(x0);
    let iy = i32(y0);
    let top = image_texel(image, ix, iy, wraps) * (1.0 - fx) + image_texel(image, ix + 1, iy, wraps) * fx;
    let bottom = image_texel(image, ix, iy + 1, wraps) * (1.0 - fx) + image_texel(image, ix + 1, iy + 1, wraps) * fx;
    return top * (1.0 - fy) + bottom * fy;
}

// The node read as a float (TextureNode::eval_float): the luminance, but a checkerboard
// puts colour 0 on the other squares, as Mitsuba 3.9's `eval_1` does.
fn tex_eval_float(node: u32, at: TexPoint) -> f32 {
    let base = params.texture_nodes + TEX_STRIDE * node;
    if (word_u32(physical[base].x) == TEX_CHECKERBOARD) {
        // The first uv set, as the CPU reads it here.
        let r0 = physical[base + 1u];
        let r1 = physical[base + 2u];
        let uv = vec2<f32>(r0.x * at.uv.x + r0.y * at.uv.y + r0.z, r1.x * at.uv.x + r1.y * at.uv.y + r1.z);
        return luminance(select(physical[base + 3u].xyz, physical[base + 4u].xyz, checker_square(uv)));
    }
    return luminance(tex_eval(node, at));
}

// The gradient of the node's luminance in the surface's (u, v) (TextureNode::gradient): that
// of the bilinear interpolant for a bilinear bitmap, zero otherwise.
fn tex_gradient(node: u32, at: TexPoint) -> vec2<f32> {
    let base = params.texture_nodes + TEX_STRIDE * node;
    let head = physical[base];
    if (word_u32(head.x) != TEX_BITMAP || word_u32(head.z) != 1u) {
        return vec2<f32>(0.0);
    }
    let image = word_u32(head.y);
    let size = image_size(image);
    if (size.x == 0u || size.y == 0u) {
        return vec2<f32>(0.0);
    }
    let wraps = word_u32(head.w);
    let r0 = physical[base + 1u];
    let r1 = physical[base + 2u];
    let uv = tex_uv(base, at);
    let limit = 1.0e9;
    let x = clamp(uv.x * f32(size.x), -limit, limit) - 0.5;
    let y = clamp(uv.y * f32(size.y), -limit, limit) - 0.5;
    if (!(abs(x) <= 2.0 * limit && abs(y) <= 2.0 * limit)) {
        return vec2<f32>(0.0);
    }
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let ix = i32(x0);
    let iy = i32(y0);
    let f00 = luminance(image_texel(image, ix, iy, wraps));
    let f10 = luminance(image_texel(image, ix + 1, iy, wraps));
    let f01 = luminance(image_texel(image, ix, iy + 1, wraps));
    let f11 = luminance(image_texel(image, ix + 1, iy + 1, wraps));
    let dfx = ((1.0 - fy) * (f10 - f00) + fy * (f11 - f01)) * f32(size.x);
    let dfy = ((1.0 - fx) * (f01 - f00) + fx * (f11 - f10)) * f32(size.y);
    return vec2<f32>(r0.x * dfx + r1.x * dfy, r0.y * dfx + r1.y * dfy);
}

// A parameter word [r, g, b, texture node or NONE] (physical.rs `param`): its colour at `at`.
fn param_color(word: u32, at: TexPoint) -> vec3<f32> {
    let w = physical[word];
    let node = word_u32(w.w);
    if (node == NONE) {
        return w.xyz;
    }
    return tex_eval(node, at);
}

// A float parameter: a constant's first channel, a texture's luminance (Param::eval_float).
fn param_float(word: u32, at: TexPoint) -> f32 {
    let w = physical[word];
    let node = word_u32(w.w);
    if (node == NONE) {
        return w.x;
    }
    return tex_eval_float(node, at);
}

fn param_is_textured(word: u32) -> bool {
    return word_u32(physical[word].w) != NONE;
}

// ---------------------------------------------------------------------------------------
// The shading data of a hit (Scene::physical_surface).

struct PhysSurface {
    point: vec3<f32>,
    // Unit geometric normal, world space.
    normal: vec3<f32>,
    frame: Frame,
    dp_du: vec3<f32>,
    dp_dv: vec3<f32>,
    tex: TexPoint,
    bitangent_sign: f32,
}

// Mitsuba's shading frame from the shading normal and ∂p/∂u (PhysicalSurface::shading_frame).
fn shading_frame(n: vec3<f32>, dp_du: vec3<f32>) -> Frame {
    let s = dp_du - n * dot(n, dp_du);
    let len = length(s);
    if (len > 0.0 && len < INF) {
        let u = s / len;
        return Frame(u, cross(n, u), n);
    }
    return frame_from_normal(n);
}

// Row `r` of the instance's world_from_object (after its object_from_world and info).
fn to_world_vector(m: u32, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(prims[m + 4u].xyz, v), dot(prims[m + 5u].xyz, v), dot(prims[m + 6u].xyz, v));
}

fn to_world_normal(m: u32, n: vec3<f32>) -> vec3<f32> {
    return prims[m].xyz * n.x + prims[m + 1u].xyz * n.y + prims[m + 2u].xyz * n.z;
}

fn attr_vec3(at: u32, b: vec3<f32>) -> vec3<f32> {
    return physical[at].xyz * b.x + physical[at + 1u].xyz * b.y + physical[at + 2u].xyz * b.z;
}

fn attr_uv(at: u32, b: vec3<f32>) -> vec2<f32> {
    let a = physical[at];
    let c = physical[at + 1u];
    return a.xy * b.x + a.zw * b.y + c.xy * b.z;
}

fn physical_surface(ray: Ray, hit: Hit) -> PhysSurface {
    let si = surface(ray, hit, true);
    var ps: PhysSurface;
    ps.point = si.point;
    ps.normal = si.normal;
    ps.tex = TexPoint(si.uv, vec2<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    ps.bitangent_sign = 1.0;
    let base = hit.primitive * PRIM_STRIDE;
    let p0 = prims[base];
    let kind = word_u32(p0.w);
    var m = NONE;
    if ((word_u32(instance_info(hit.instance).z) & FLAG_TRANSFORMED) != 0u) {
        m = instance_base(hit.instance);
    }
    var local = si.point;
    if (m != NONE) {
        local = transform_point(m, si.point);
    }
    var dp_du: vec3<f32>;
    var dp_dv: vec3<f32>;
    var shading = vec3<f32>(0.0);
    var has_shading = false;
    if (kind == PRIM_TRIANGLE) {
        let v0 = p0.xyz;
        let e1 = prims[base + 1u].xyz - v0;
        let e2 = prims[base + 2u].xyz - v0;
        dp_du = e1;
        dp_dv = e2;
        let b = vec3<f32>(1.0 - hit.b1 - hit.b2, hit.b1, hit.b2);
        let record = word_u32(prims[base + 2u].w);
        if (record != NONE) {
            let flags = word_u32(physical[record].x);
            var at = record + 1u;
            if ((flags & ATTR_NORMALS) != 0u) {
                shading = attr_vec3(at, b);
                has_shading = true;
                at += 3u;
            }
            if ((flags & ATTR_UVS) != 0u) {
                let a = physical[at];
                let c = physical[at + 1u];
                ps.tex.uv = attr_uv(at, b);
                let du0 = a.z - a.x;
                let dv0 = a.w - a.y;
                let du1 = c.x - a.x;
                let dv1 = c.y - a.y;
                let det = du0 * dv1 - dv0 * du1;
                if (det != 0.0) {
                    let inv = 1.0 / det;
                    dp_du = (e1 * dv1 - e2 * dv0) * inv;
                    dp_dv = (e2 * du0 - e1 * du1) * inv;
                } else {
                    let f = frame_from_normal(prims[base + 3u].xyz);
                    dp_du = f.u;
                    dp_dv = f.v;
                }
                at += 2u;
            }
            if ((flags & ATTR_UVS1) != 0u) {
                ps.tex.uv1 = attr_uv(at, b);
                at += 2u;
            }
            if ((flags & ATTR_TANGENTS) != 0u) {
                let tangent = attr_vec3(at, b);
                if (is_finite3(tangent) && any(tangent != vec3<f32>(0.0))) {
                    dp_du = tangent;
                    ps.bitangent_sign = select(1.0, -1.0, physical[at].w < 0.0);
                }
                at += 3u;
            }
            if ((flags & ATTR_VERTEX_COLORS) != 0u) {
                ps.tex.vertex_color = attr_vec3(at, b);
                at += 3u;
            }
            if ((flags & ATTR_FACE_COLOR) != 0u) {
                ps.tex.face_color = physical[at].xyz;
            }
        }
    } else if (kind == PRIM_SPHERE && (word_u32(prims[base + 2u].x) & SPHERE_MITSUBA_UV) != 0u) {
        let center = p0.xyz;
        let radius = prims[base + 1u].x;
        let d = (local - center) / radius;
        let cos_theta = clamp(d.z, -1.0, 1.0);
        let theta = acos(cos_theta);
        var phi = atan2(d.y, d.x);
        if (phi < 0.0) {
            phi += TAU;
        }
        ps.tex.uv = vec2<f32>(phi * (0.5 * FRAC_1_PI), theta * FRAC_1_PI);
        dp_du = vec3<f32>(-d.y, d.x, 0.0) * (TAU * radius);
        dp_dv = vec3<f32>(d.z * cos(phi), d.z * sin(phi), -sqrt(max(1.0 - cos_theta * cos_theta, 0.0))) * (PI * radius);
    } else {
        // The course's uv (`surface`), and any tangents about the object-space normal.
        var n_local = si.normal;
        if (m != NONE) {
            let surf = surface_object_normal(hit, local);
            n_local = surf;
        }
        let f = frame_from_normal(n_local);
        dp_du = f.u;
        dp_dv = f.v;
    }
    if (m != NONE) {
        dp_du = to_world_vector(m, dp_du);
        dp_dv = to_world_vector(m, dp_dv);
        if (has_shading) {
            shading = to_world_normal(m, shading);
        }
    }
    var n = ps.normal;
    if (has_shading) {
        let len = length(shading);
        if (len > 0.0 && len < INF) {
            n = shading / len;
        }
    }
    ps.dp_du = dp_du;
    ps.dp_dv = dp_dv;
    ps.frame = shading_frame(n, dp_du);
    return ps;
}

// The object-space geometric normal of a sphere or box hit at object-space `local`.
fn surface_object_normal(hit: Hit, local: vec3<f32>) -> vec3<f32> {
    let base = hit.primitive * PRIM_STRIDE;
    let p0 = prims[base];
    let p1 = prims[base + 1u];
    if (word_u32(p0.w) == PRIM_SPHERE) {
        return normalize((local - p0.xyz) / p1.x);
    }
    if (word_u32(p0.w) == PRIM_BOX) {
        return box_normal(local, p0.xyz, p1.xyz);
    }
    return prims[base + 3u].xyz;
}

// ---------------------------------------------------------------------------------------
// Microfacet distributions (microfacet.rs): Beckmann and GGX, anisotropic, sampled over all
// normals or the visible ones.

struct Microfacet {
    distribution: u32,
    alpha_u: f32,
    alpha_v: f32,
    sample_visible: bool,
}

const DIST_BECKMANN: u32 = 0u;
const DIST_GGX: u32 = 1u;

fn mf_clamp_alpha(a: f32) -> f32 {
    if (abs(a) <= INF) {
        return max(a, MIN_ALPHA);
    }
    return MIN_ALPHA;
}

fn mf_new(distribution: u32, alpha_u: f32, alpha_v: f32, sample_visible: bool) -> Microfacet {
    return Microfacet(distribution, mf_clamp_alpha(alpha_u), mf_clamp_alpha(alpha_v), sample_visible);
}

fn mf_d(mf: Microfacet, m: vec3<f32>) -> f32 {
    let cos2 = m.z * m.z;
    let x = m.x / mf.alpha_u;
    let y = m.y / mf.alpha_v;
    var result: f32;
    if (mf.distribution == DIST_BECKMANN) {
        result = exp(-(x * x + y * y) / cos2) / (PI * mf.alpha_u * mf.alpha_v * cos2 * cos2);
    } else {
        let s = x * x + y * y + m.z * m.z;
        result = 1.0 / (PI * mf.alpha_u * mf.alpha_v * s * s);
    }
    if (result * m.z > 1e-20) {
        return result;
    }
    return 0.0;
}

fn mf_smith_g1(mf: Microfacet, v: vec3<f32>, m: vec3<f32>) -> f32 {
    let xy_alpha_2 = (mf.alpha_u * v.x) * (mf.alpha_u * v.x) + (mf.alpha_v * v.y) * (mf.alpha_v * v.y);
    if (dot(v, m) * v.z <= 0.0) {
        return 0.0;
    }
    if (xy_alpha_2 == 0.0) {
        return 1.0;
    }
    let tan_theta_alpha_2 = xy_alpha_2 / (v.z * v.z);
    if (mf.distribution == DIST_BECKMANN) {
        let a = 1.0 / sqrt(tan_theta_alpha_2);
        if (a >= 1.6) {
            return 1.0;
        }
        let a2 = a * a;
        return (3.535 * a + 2.181 * a2) / (1.0 + 2.276 * a + 2.577 * a2);
    }
    return 2.0 / (1.0 + sqrt(1.0 + tan_theta_alpha_2));
}

fn mf_g(mf: Microfacet, wi: vec3<f32>, wo: vec3<f32>, m: vec3<f32>) -> f32 {
    return mf_smith_g1(mf, wi, m) * mf_smith_g1(mf, wo, m);
}

fn mf_pdf(mf: Microfacet, wo: vec3<f32>, m: vec3<f32>) -> f32 {
    let d = mf_d(mf, m);
    if (mf.sample_visible) {
        return d * mf_smith_g1(mf, wo, m) * abs(dot(wo, m)) / wo.z;
    }
    return d * m.z;
}

fn mf_erf(x: f32) -> f32 {
    let z = abs(x);
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418
        + t * (-0.18628806 + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587
        + t * (-0.82215223 + t * 0.17087277))))))));
    let e = 1.0 - t * exp(poly);
    return select(-e, e, x >= 0.0);
}

fn mf_erfinv(x: f32) -> f32 {
    var w = -log((1.0 - x) * (1.0 + x));
    var p: f32;
    if (w < 5.0) {
        w = w - 2.5;
        p = 2.8102264e-8;
        p = 3.4327394e-7 + p * w;
        p = -3.5233877e-6 + p * w;
        p = -4.3915065e-6 + p * w;
        p = 2.1858087e-4 + p * w;
        p = -1.253725e-3 + p * w;
        p = -4.1776816e-3 + p * w;
        p = 0.24664073 + p * w;
        p = 1.5014094 + p * w;
    } else {
        w = sqrt(w) - 3.0;
        p = -2.0021426e-4;
        p = 1.0095056e-4 + p * w;
        p = 1.3493432e-3 + p * w;
        p = -3.6734284e-3 + p * w;
        p = 5.7395077e-3 + p * w;
        p = -7.6224613e-3 + p * w;
        p = 9.4388705e-3 + p * w;
        p = 1.001674 + p * w;
        p = 2.8329768 + p * w;
    }
    return p * x;
}

fn mf_sample_visible_11(mf: Microfacet, cos_theta_i: f32, u: vec2<f32>) -> vec2<f32> {
    if (mf.distribution == DIST_BECKMANN) {
        let tan_theta_i = sqrt(max(1.0 - cos_theta_i * cos_theta_i, 0.0)) / cos_theta_i;
        let cot_theta_i = 1.0 / tan_theta_i;
        let maxval = mf_erf(cot_theta_i);
        let ux = clamp(u.x, 1e-6, 1.0 - 1e-6);
        let uy = clamp(u.y, 1e-6, 1.0 - 1e-6);
        var x = maxval - (maxval + 1.0) * mf_erf(sqrt(-log(ux)));
        let target_value = ux * (1.0 + maxval + INV_SQRT_PI * tan_theta_i * exp(-cot_theta_i * cot_theta_i));
        for (var i = 0u; i < 3u; i += 1u) {
            let slope = mf_erfinv(x);
            let value = 1.0 + x + INV_SQRT_PI * tan_theta_i * exp(-slope * slope) - target_value;
            let derivative = 1.0 - slope * tan_theta_i;
            x -= value / derivative;
        }
        return vec2<f32>(mf_erfinv(x), mf_erfinv(2.0 * uy - 1.0));
    }
    // Heitz 2018: a uniform point on the half disk the view sees, projected onto the
    // hemisphere, is a visible normal of the alpha = 1 surface.
    let p = sample_uniform_disk_concentric(u);
    let s = 0.5 * (1.0 + cos_theta_i);
    let py = (1.0 - s) * sqrt(max(1.0 - p.x * p.x, 0.0)) + s * p.y;
    let pz = sqrt(max(1.0 - p.x * p.x - py * py, 0.0));
    let sin_theta_i = sqrt(max(1.0 - cos_theta_i * cos_theta_i, 0.0));
    let norm = 1.0 / (sin_theta_i * py + cos_theta_i * pz);
    return vec2<f32>((cos_theta_i * py - sin_theta_i * pz) * norm, p.x * norm);
}

// A microfacet normal (xyz) and its density (w); (0, 0, 1, 0) where sampling failed.
fn mf_sample(mf: Microfacet, wo: vec3<f32>, u: vec2<f32>) -> vec4<f32> {
    var m: vec3<f32>;
    var pdf: f32;
    let au = mf.alpha_u;
    let av = mf.alpha_v;
    if (mf.sample_visible) {
        let stretched = normalize(vec3<f32>(au * wo.x, av * wo.y, wo.z));
        let sin_theta_2 = stretched.x * stretched.x + stretched.y * stretched.y;
        var sin_phi = 0.0;
        var cos_phi = 1.0;
        if (abs(sin_theta_2) > 4.0 * 1.1920929e-7) {
            let inv = 1.0 / sqrt(sin_theta_2);
            sin_phi = clamp(stretched.y * inv, -1.0, 1.0);
            cos_phi = clamp(stretched.x * inv, -1.0, 1.0);
        }
        let slope = mf_sample_visible_11(mf, stretched.z, u);
        let slope_x = (cos_phi * slope.x - sin_phi * slope.y) * au;
        let slope_y = (sin_phi * slope.x + cos_phi * slope.y) * av;
        m = normalize(vec3<f32>(-slope_x, -slope_y, 1.0));
        pdf = mf_pdf(mf, wo, m);
    } else {
        var sin_phi: f32;
        var cos_phi: f32;
        var alpha_2: f32;
        if (au == av) {
            let phi = TAU * u.y;
            sin_phi = sin(phi);
            cos_phi = cos(phi);
            alpha_2 = au * au;
        } else {
            let tmp = (av / au) * tan(TAU * u.y);
            let magnitude = 1.0 / sqrt(tmp * tmp + 1.0);
            cos_phi = select(-magnitude, magnitude, abs(u.y - 0.5) - 0.25 >= 0.0);
            sin_phi = cos_phi * tmp;
            alpha_2 = 1.0 / ((cos_phi / au) * (cos_phi / au) + (sin_phi / av) * (sin_phi / av));
        }
        var cos_theta: f32;
        if (mf.distribution == DIST_BECKMANN) {
            cos_theta = 1.0 / sqrt(1.0 - alpha_2 * log(1.0 - u.x));
            let cos3 = max(cos_theta * cos_theta * cos_theta, 1e-20);
            pdf = (1.0 - u.x) / (PI * au * av * cos3);
        } else {
            let tan2 = alpha_2 * u.x / (1.0 - u.x);
            cos_theta = 1.0 / sqrt(1.0 + tan2);
            let temp = 1.0 + tan2 / alpha_2;
            let cos3 = max(cos_theta * cos_theta * cos_theta, 1e-20);
            pdf = 1.0 / (PI * au * av * cos3 * temp * temp);
        }
        let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
        m = vec3<f32>(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta);
    }
    if (is_finite3(m) && abs(pdf) <= INF) {
        return vec4<f32>(m, pdf);
    }
    return vec4<f32>(0.0, 0.0, 1.0, 0.0);
}

// A microfacet model from a roughness record of physical.rs: [distribution, sample
// visible, 0, 0] at `word`, then the parameter words of alpha_u and alpha_v.
fn mf_from_record(word: u32, at: TexPoint) -> Microfacet {
    let r = physical[word];
    return mf_new(word_u32(r.x), param_float(word + 1u, at), param_float(word + 2u, at), word_u32(r.y) != 0u);
}

// ---------------------------------------------------------------------------------------
// Fresnel equations and the mirror and refraction maps (fresnel.rs), Mitsuba's conventions.

// (reflectance, cos θt, η_it, η_ti) for a dielectric interface of relative index `eta`.
fn fresnel_full(cos_theta_i: f32, eta: f32) -> vec4<f32> {
    let outside = cos_theta_i >= 0.0;
    let rcp_eta = 1.0 / eta;
    let eta_it = select(rcp_eta, eta, outside);
    let eta_ti = select(eta, rcp_eta, outside);
    let cos_theta_t_sqr = 1.0 - (1.0 - cos_theta_i * cos_theta_i) * (eta_ti * eta_ti);
    let cos_i = abs(cos_theta_i);
    let cos_t = sqrt(max(cos_theta_t_sqr, 0.0));
    var reflectance: f32;
    if (eta == 1.0) {
        reflectance = 0.0;
    } else if (cos_i == 0.0) {
        reflectance = 1.0;
    } else {
        let a_s = (cos_i - eta_it * cos_t) / (cos_i + eta_it * cos_t);
        let a_p = (cos_t - eta_it * cos_i) / (cos_t + eta_it * cos_i);
        reflectance = 0.5 * (a_s * a_s + a_p * a_p);
    }
    let cos_theta_t = select(cos_t, -cos_t, cos_theta_i >= 0.0);
    return vec4<f32>(reflectance, cos_theta_t, eta_it, eta_ti);
}

fn fresnel_conductor1(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    let cos2 = cos_theta_i * cos_theta_i;
    let sin2 = 1.0 - cos2;
    let sin4 = sin2 * sin2;
    let temp_1 = eta * eta - k * k - sin2;
    let a2_plus_b2 = sqrt(max(temp_1 * temp_1 + 4.0 * k * k * eta * eta, 0.0));
    let a = sqrt(max(0.5 * (a2_plus_b2 + temp_1), 0.0));
    let term_1 = a2_plus_b2 + cos2;
    let term_2 = 2.0 * cos_theta_i * a;
    let r_s = (term_1 - term_2) / (term_1 + term_2);
    let term_3 = a2_plus_b2 * cos2 + sin4;
    let term_4 = term_2 * sin2;
    let r_p = r_s * (term_3 - term_4) / (term_3 + term_4);
    return 0.5 * (r_s + r_p);
}

fn fresnel_conductor(cos_theta_i: f32, eta: vec3<f32>, k: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        fresnel_conductor1(cos_theta_i, eta.x, k.x),
        fresnel_conductor1(cos_theta_i, eta.y, k.y),
        fresnel_conductor1(cos_theta_i, eta.z, k.z),
    );
}

fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv_eta = 1.0 / eta;
    if (eta < 1.0) {
        return 0.0636 * inv_eta + eta * (eta * -1.4399 + 0.7099) + 0.6681;
    }
    let x = inv_eta;
    return 0.919317 + x * (-3.4793 + x * (6.75335 + x * (-7.80989 + x * (4.98554 + x * -1.36881))));
}

fn reflect_local(w: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(-w.x, -w.y, w.z);
}

fn reflect_about(w: vec3<f32>, m: vec3<f32>) -> vec3<f32> {
    return m * (2.0 * dot(w, m)) - w;
}

fn refract_about(w: vec3<f32>, m: vec3<f32>, cos_theta_t: f32, eta_ti: f32) -> vec3<f32> {
    return m * (dot(w, m) * eta_ti + cos_theta_t) - w * eta_ti;
}

fn refract_local(w: vec3<f32>, cos_theta_t: f32, eta_ti: f32) -> vec3<f32> {
    return vec3<f32>(-eta_ti * w.x, -eta_ti * w.y, cos_theta_t);
}

// ---------------------------------------------------------------------------------------
// Leaves and their resolution (surface.rs).

// A sample of a leaf or of the whole BSDF (bsdf.rs BsdfSample): `wi` local to the leaf's
// frame from a family, world space from `phys_draw`; `weight` is f·|cos θi| / pdf.
struct PhysSample {
    wi: vec3<f32>,
    weight: vec3<f32>,
    pdf: f32,
    is_specular: bool,
    eta: f32,
    valid: bool,
}

fn no_sample() -> PhysSample {
    return PhysSample(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0), 0.0, false, 1.0, false);
}

// A sample is used only where all of it is finite and positive (scatter.rs `usable`).
fn usable(s: PhysSample) -> PhysSample {
    let ok = s.valid && is_finite3(s.wi) && is_finite3(s.weight) && min(s.weight.x, min(s.weight.y, s.weight.z)) >= 0.0
        && s.pdf > 0.0 && s.pdf <= INF && s.eta > 0.0 && s.eta <= INF;
    if (ok) {
        return s;
    }
    return no_sample();
}

struct Tilt {
    // 1 where a normal or bump map tilted the frame.
    on: u32,
    parent: Frame,
    // The tilted normal in the parent frame's coordinates.
    normal: vec3<f32>,
}

fn no_tilt() -> Tilt {
    return Tilt(0u, Frame(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0)), vec3<f32>(0.0, 0.0, 1.0));
}

// Estevez et al.'s shadowing term for `d_parent` (a direction in the parent frame).
fn tilt_shadowing(t: Tilt, d_parent: vec3<f32>) -> f32 {
    let alpha2 = min(0.125 * tan2_local(t.normal), 1.0);
    return 2.0 / (1.0 + sqrt(1.0 + alpha2 * tan2_local(d_parent)));
}

fn tan2_local(v: vec3<f32>) -> f32 {
    let cos2 = v.z * v.z;
    return max(max(1.0 - cos2, 0.0) / cos2, 0.0);
}

struct Leaf {
    family: u32,
    weight: f32,
    // The leaf's shading frame, world space.
    frame: Frame,
    tilt: Tilt,
    // The family's parameters at the hit (each family's file says which word holds what).
    w: array<vec4<f32>, LEAF_WORDS>,
}

var<private> leaves: array<Leaf, MAX_LEAVES>;
var<private> leaf_count: u32;
// What the resolver reads: the hit and the direction towards the viewer (world).
var<private> res_surface: PhysSurface;
var<private> res_wo: vec3<f32>;

// Adds a leaf of `family` (Resolver::push): at the end while there is room, else in place of
// the lightest leaf if that is lighter. Returns its index, NONE where it was dropped; the
// caller fills `leaves[index].w`.
fn push_leaf(family: u32, weight: f32, frame: Frame, tilt: Tilt) -> u32 {
    if (weight <= 0.0) {
        return NONE;
    }
    var index = NONE;
    if (leaf_count < MAX_LEAVES) {
        index = leaf_count;
        leaf_count += 1u;
    } else {
        var lightest = 0u;
        for (var i = 1u; i < MAX_LEAVES; i += 1u) {
            if (leaves[i].weight < leaves[lightest].weight) {
                lightest = i;
            }
        }
        if (leaves[lightest].weight < weight) {
            index = lightest;
        }
    }
    if (index != NONE) {
        leaves[index].family = family;
        leaves[index].weight = weight;
        leaves[index].frame = frame;
        leaves[index].tilt = tilt;
        for (var k = 0u; k < LEAF_WORDS; k += 1u) {
            leaves[index].w[k] = vec4<f32>(0.0);
        }
    }
    return index;
}

// The record of BSDF node `id` in `physical`.
fn bsdf_record(id: u32) -> u32 {
    return word_u32(physical[params.bsdf_index + id].x);
}

struct Pending {
    // A BSDF node, or NONE for a null leaf.
    node: u32,
    weight: f32,
    frame: Frame,
    tilt: Tilt,
    depth: u32,
}

var<private> pending: array<Pending, RESOLVE_STACK>;
var<private> pending_count: u32;

fn defer(node: u32, weight: f32, frame: Frame, tilt: Tilt, depth: u32) {
    if (pending_count < RESOLVE_STACK && weight > 0.0) {
        pending[pending_count] = Pending(node, weight, frame, tilt, depth);
        pending_count += 1u;
    }
}

// The tilted frame of a normal `n` given in `frame`'s coordinates (surface.rs, normalmap):
// its tangent follows the parent's x axis.
fn tilted_frame(frame: Frame, n: vec3<f32>) -> Frame {
    let s = normalize(vec3<f32>(1.0, 0.0, 0.0) - n * n.x);
    let t = cross(n, s);
    return Frame(to_world(frame, s), to_world(frame, t), to_world(frame, n));
}

// Resolves BSDF tree `id` at `surf` seen from world direction `wo` into `leaves`
// (SurfaceBsdf::new): depth first, children in order, as the CPU's recursion visits them.
fn resolve_bsdf(id: u32, surf: PhysSurface, wo: vec3<f32>) {
    res_surface = surf;
    res_wo = wo;
    leaf_count = 0u;
    pending_count = 0u;
    defer(id, 1.0, surf.frame, no_tilt(), 0u);
    let at = surf.tex;
    while (pending_count > 0u) {
        pending_count -= 1u;
        let item = pending[pending_count];
        let frame = item.frame;
        let tilt = item.tilt;
        let weight = item.weight;
        if (item.node == NONE) {
            push_leaf(FAMILY_NULL, weight, frame, tilt);
            continue;
        }
        if (item.node >= params.bsdf_count || item.depth > MAX_NESTING || weight <= 0.0) {
            continue;
        }
        let record = bsdf_record(item.node);
        let head = physical[record];
        let kind = word_u32(head.x);
        let depth = item.depth + 1u;
        switch kind {
            case NODE_NULL: {
                push_leaf(FAMILY_NULL, weight, frame, tilt);
            }
            case NODE_DIFFUSE: {
                diffuse_add(record, weight, frame, tilt);
            }
            case NODE_CONDUCTOR: {
                conductor_add(record, weight, frame, tilt);
            }
            case NODE_DIELECTRIC: {
                dielectric_add(record, weight, frame, tilt);
            }
            case NODE_THIN_DIELECTRIC: {
                thin_dielectric_add(record, weight, frame, tilt);
            }
            case NODE_PLASTIC: {
                plastic_add(record, weight, frame, tilt);
            }
            case NODE_PRINCIPLED: {
                principled_add(record, weight, frame, tilt);
            }
            case NODE_PRINCIPLED_THIN: {
                principled_thin_add(record, weight, frame, tilt);
            }
            case NODE_GLTF: {
                gltf_add(record, weight, frame, tilt);
            }
            case NODE_TWOSIDED: {
                if (to_local(frame, wo).z >= 0.0) {
                    defer(word_u32(head.y), weight, frame, tilt, depth);
                } else {
                    defer(word_u32(head.z), weight, Frame(frame.u, frame.v, -frame.w), tilt, depth);
                }
            }
            case NODE_MASK: {
                let opacity = clamp(param_float(record + 1u, at), 0.0, 1.0);
                // The nested tree's leaves first, then the null leaf: the stack is last in,
                // first out.
                defer(NONE, weight * (1.0 - opacity), frame, tilt, depth);
                defer(word_u32(head.y), weight * opacity, frame, tilt, depth);
            }
            case NODE_BLEND: {
                let b = clamp(param_float(record + 1u, at), 0.0, 1.0);
                defer(word_u32(head.z), weight * b, frame, tilt, depth);
                defer(word_u32(head.y), weight * (1.0 - b), frame, tilt, depth);
            }
            case NODE_NORMALMAP: {
                var n = tex_eval(word_u32(head.y), at) * 2.0 - vec3<f32>(1.0);
                // Shading normals face the viewer (Mitsuba's `flip_invalid_normals`).
                let wo_local = to_local(frame, wo);
                if (wo_local.z * dot(wo_local, n) <= 0.0) {
                    n = vec3<f32>(-n.x, -n.y, n.z);
                }
                n = normalize(n);
                if (is_finite3(n)) {
                    defer(word_u32(head.z), weight, tilted_frame(frame, n), Tilt(1u, frame, n), depth);
                }
            }
            case NODE_BUMPMAP: {
                let g = tex_gradient(word_u32(head.y), at) * head.w;
                let n = frame.w;
                let dp_du = surf.dp_du + n * (g.x - dot(n, surf.dp_du));
                let dp_dv = surf.dp_dv + n * (g.y - dot(n, surf.dp_dv));
                var bumped = normalize(cross(dp_du, dp_dv));
                if (is_finite3(bumped)) {
                    if (dot(surf.normal, bumped) < 0.0) {
                        bumped = -bumped;
                    }
                    var local_n = to_local(frame, bumped);
                    let wo_local = to_local(frame, wo);
                    if (wo_local.z * dot(wo, bumped) <= 0.0) {
                        local_n = vec3<f32>(-local_n.x, -local_n.y, local_n.z);
                    }
                    let world_n = to_world(frame, local_n);
                    let s = normalize(surf.dp_du - world_n * dot(world_n, surf.dp_du));
                    if (is_finite3(s)) {
                        defer(word_u32(head.z), weight, Frame(s, cross(world_n, s), world_n), Tilt(1u, frame, local_n), depth);
                    }
                }
            }
            default: {}
        }
    }
    // Leaves dropped for lack of room leave weights summing to less than one: make the kept
    // ones a distribution again.
    var total = 0.0;
    for (var i = 0u; i < leaf_count; i += 1u) {
        total += leaves[i].weight;
    }
    if (total > 0.0 && abs(total - 1.0) > 1e-6) {
        for (var i = 0u; i < leaf_count; i += 1u) {
            leaves[i].weight /= total;
        }
    }
}

// ---------------------------------------------------------------------------------------
// The families, by leaf (local directions in the leaf's frame).

fn family_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    switch leaves[i].family {
        case FAMILY_DIFFUSE: { return diffuse_eval_pdf(i, wo, wi); }
        case FAMILY_CONDUCTOR: { return conductor_eval_pdf(i, wo, wi); }
        case FAMILY_ROUGH_CONDUCTOR: { return rough_conductor_eval_pdf(i, wo, wi); }
        case FAMILY_DIELECTRIC: { return dielectric_eval_pdf(i, wo, wi); }
        case FAMILY_THIN_DIELECTRIC: { return thin_dielectric_eval_pdf(i, wo, wi); }
        case FAMILY_ROUGH_DIELECTRIC: { return rough_dielectric_eval_pdf(i, wo, wi); }
        case FAMILY_PLASTIC: { return plastic_eval_pdf(i, wo, wi); }
        case FAMILY_ROUGH_PLASTIC: { return rough_plastic_eval_pdf(i, wo, wi); }
        case FAMILY_PRINCIPLED: { return principled_eval_pdf(i, wo, wi); }
        case FAMILY_PRINCIPLED_THIN: { return principled_thin_eval_pdf(i, wo, wi); }
        case FAMILY_GLTF: { return gltf_eval_pdf(i, wo, wi); }
        default: { return vec4<f32>(0.0); }
    }
}

fn family_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    switch leaves[i].family {
        case FAMILY_NULL: { return PhysSample(-wo, vec3<f32>(1.0), 1.0, true, 1.0, true); }
        case FAMILY_DIFFUSE: { return diffuse_sample(i, wo, u_lobe, u); }
        case FAMILY_CONDUCTOR: { return conductor_sample(i, wo, u_lobe, u); }
        case FAMILY_ROUGH_CONDUCTOR: { return rough_conductor_sample(i, wo, u_lobe, u); }
        case FAMILY_DIELECTRIC: { return dielectric_sample(i, wo, u_lobe, u); }
        case FAMILY_THIN_DIELECTRIC: { return thin_dielectric_sample(i, wo, u_lobe, u); }
        case FAMILY_ROUGH_DIELECTRIC: { return rough_dielectric_sample(i, wo, u_lobe, u); }
        case FAMILY_PLASTIC: { return plastic_sample(i, wo, u_lobe, u); }
        case FAMILY_ROUGH_PLASTIC: { return rough_plastic_sample(i, wo, u_lobe, u); }
        case FAMILY_PRINCIPLED: { return principled_sample(i, wo, u_lobe, u); }
        case FAMILY_PRINCIPLED_THIN: { return principled_thin_sample(i, wo, u_lobe, u); }
        case FAMILY_GLTF: { return gltf_sample(i, wo, u_lobe, u); }
        default: { return no_sample(); }
    }
}

fn family_albedo(i: u32) -> vec3<f32> {
    switch leaves[i].family {
        case FAMILY_DIFFUSE: { return diffuse_albedo(i); }
        case FAMILY_CONDUCTOR: { return conductor_albedo(i); }
        case FAMILY_ROUGH_CONDUCTOR: { return rough_conductor_albedo(i); }
        case FAMILY_DIELECTRIC: { return dielectric_albedo(i); }
        case FAMILY_THIN_DIELECTRIC: { return thin_dielectric_albedo(i); }
        case FAMILY_ROUGH_DIELECTRIC: { return rough_dielectric_albedo(i); }
        case FAMILY_PLASTIC: { return plastic_albedo(i); }
        case FAMILY_ROUGH_PLASTIC: { return rough_plastic_albedo(i); }
        case FAMILY_PRINCIPLED: { return principled_albedo(i); }
        case FAMILY_PRINCIPLED_THIN: { return principled_thin_albedo(i); }
        case FAMILY_GLTF: { return gltf_albedo(i); }
        default: { return vec3<f32>(0.0); }
    }
}

fn family_has_non_delta(i: u32) -> bool {
    switch leaves[i].family {
        case FAMILY_DIFFUSE: { return true; }
        case FAMILY_CONDUCTOR: { return conductor_has_non_delta(i); }
        case FAMILY_ROUGH_CONDUCTOR: { return rough_conductor_has_non_delta(i); }
        case FAMILY_DIELECTRIC: { return dielectric_has_non_delta(i); }
        case FAMILY_THIN_DIELECTRIC: { return thin_dielectric_has_non_delta(i); }
        case FAMILY_ROUGH_DIELECTRIC: { return rough_dielectric_has_non_delta(i); }
        case FAMILY_PLASTIC: { return plastic_has_non_delta(i); }
        case FAMILY_ROUGH_PLASTIC: { return rough_plastic_has_non_delta(i); }
        case FAMILY_PRINCIPLED: { return principled_has_non_delta(i); }
        case FAMILY_PRINCIPLED_THIN: { return principled_thin_has_non_delta(i); }
        case FAMILY_GLTF: { return gltf_has_non_delta(i); }
        default: { return false; }
    }
}

// ---------------------------------------------------------------------------------------
// The mixture in world directions (SurfaceBsdf).

// f·cos (xyz) and pdf (w) of leaf `i` with a tilt's orientation test and shadowing.
fn leaf_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let frame = leaves[i].frame;
    let lo = to_local(frame, wo);
    let li = to_local(frame, wi);
    var shadow = 1.0;
    let tilt = leaves[i].tilt;
    if (tilt.on != 0u) {
        let parent_wi = to_local(tilt.parent, wi);
        if (parent_wi.z * li.z <= 0.0) {
            return vec4<f32>(0.0);
        }
        shadow = tilt_shadowing(tilt, parent_wi);
    }
    let r = family_eval_pdf(i, lo, li);
    return vec4<f32>(r.xyz * shadow, r.w);
}

fn leaf_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    let frame = leaves[i].frame;
    let lo = to_local(frame, wo);
    var s = family_sample(i, lo, u_lobe, u);
    if (!s.valid) {
        return s;
    }
    let wi = to_world(frame, s.wi);
    let tilt = leaves[i].tilt;
    if (tilt.on != 0u) {
        let parent_wi = to_local(tilt.parent, wi);
        if (parent_wi.z * s.wi.z <= 0.0) {
            return no_sample();
        }
        s.weight *= tilt_shadowing(tilt, parent_wi);
    }
    s.wi = wi;
    return s;
}

fn phys_is_black() -> bool {
    return leaf_count == 0u;
}

fn phys_has_non_delta() -> bool {
    for (var i = 0u; i < leaf_count; i += 1u) {
        if (family_has_non_delta(i)) {
            return true;
        }
    }
    return false;
}

fn phys_albedo() -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < leaf_count; i += 1u) {
        sum += family_albedo(i) * leaves[i].weight;
    }
    return clamp(sum, vec3<f32>(0.0), vec3<f32>(1.0));
}

// A leaf's sample of a world direction for `wo`, before the one-sample MIS of `phys_finish`
// (`mis`: the sample is continuous and there are other leaves to weigh it against).
struct LeafDraw {
    s: PhysSample,
    mis: bool,
}

// The leaf `u_lobe` picks by weight, and its sample (SurfaceBsdf::sample up to the MIS). The
// kernel calls each family's sampling from here alone: llvmpipe inlines every call, and one
// call site keeps the kernel, and its compilation, smaller.
fn phys_draw(wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> LeafDraw {
    if (leaf_count == 0u) {
        return LeafDraw(no_sample(), false);
    }
    var chosen = 0u;
    var u_leaf = u_lobe;
    var weight = 1.0;
    if (leaf_count > 1u) {
        var start = 0.0;
        chosen = leaf_count - 1u;
        for (var i = 0u; i < leaf_count; i += 1u) {
            if (u_lobe < start + leaves[i].weight) {
                chosen = i;
                break;
            }
            start += leaves[i].weight;
        }
        weight = leaves[chosen].weight;
        if (weight <= 0.0) {
            return LeafDraw(no_sample(), false);
        }
        u_leaf = clamp((u_lobe - start) / weight, 0.0, 1.0 - 5.9604645e-8);
    }
    var s = leaf_sample(chosen, wo, u_leaf, u);
    if (!s.valid || leaf_count == 1u) {
        return LeafDraw(s, false);
    }
    if (s.is_specular) {
        // A delta is not in the other leaves' densities: its weight stands, and its
        // probability includes the choice of the leaf.
        s.pdf *= weight;
        return LeafDraw(s, false);
    }
    return LeafDraw(s, true);
}

// `draw` finished with `fp`, the mixture's f·cos and density in its direction: a
// continuous sample weighed against every leaf (one-sample MIS, SurfaceBsdf::sample).
fn phys_finish(draw: LeafDraw, fp: vec4<f32>) -> PhysSample {
    if (!draw.mis) {
        return draw.s;
    }
    if (fp.w <= 0.0) {
        return no_sample();
    }
    var s = draw.s;
    s.weight = fp.xyz / fp.w;
    s.pdf = fp.w;
    return s;
}

// f·|cos θi| (xyz) and the density (w) for world directions (SurfaceBsdf::eval_pdf), in two
// directions, each where asked for (the path loop's light sample and BSDF sample), from one
// call site of the families' evaluation (see `phys_draw`).
fn phys_eval_pdf_pair(wo: vec3<f32>, a: vec3<f32>, want_a: bool, b: vec3<f32>, want_b: bool) -> array<vec4<f32>, 2> {
    var out = array<vec4<f32>, 2>(vec4<f32>(0.0), vec4<f32>(0.0));
    let directions = array<vec3<f32>, 2>(a, b);
    let wanted = array<bool, 2>(want_a, want_b);
    for (var d = 0u; d < 2u; d += 1u) {
        if (!wanted[d]) {
            continue;
        }
        var sum = vec4<f32>(0.0);
        for (var i = 0u; i < leaf_count; i += 1u) {
            sum += leaf_eval_pdf(i, wo, directions[d]) * leaves[i].weight;
        }
        out[d] = sum;
    }
    return out;
}

// ---------------------------------------------------------------------------------------
// diffuse (diffuse.rs). Record: [kind], [reflectance]. Leaf: w[0].xyz the reflectance.

fn diffuse_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let i = push_leaf(FAMILY_DIFFUSE, weight, frame, tilt);
    if (i != NONE) {
        leaves[i].w[0] = vec4<f32>(param_color(record + 1u, res_surface.tex), 0.0);
    }
}

fn diffuse_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    if (wo.z > 0.0 && wi.z > 0.0) {
        return vec4<f32>(leaves[i].w[0].xyz * (FRAC_1_PI * wi.z), cosine_hemisphere_pdf(wi.z));
    }
    return vec4<f32>(0.0);
}

fn diffuse_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    if (!(wo.z > 0.0)) {
        return no_sample();
    }
    let wi = sample_cosine_hemisphere(u);
    let pdf = cosine_hemisphere_pdf(wi.z);
    if (!(pdf > 0.0)) {
        return no_sample();
    }
    return PhysSample(wi, leaves[i].w[0].xyz, pdf, false, 1.0, true);
}

fn diffuse_albedo(i: u32) -> vec3<f32> {
    return clamp(leaves[i].w[0].xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

// ---------------------------------------------------------------------------------------
// The BSDF probe: tests/bsdf_agreement.rs writes cases into `accum` (PROBE_STRIDE vec4 each)
// and reads back what the resolved BSDF gives, to compare with the CPU's `SurfaceBsdf`.
// In: [bsdf id, u_lobe, u], [geometric normal], [frame u], [frame v], [frame w], [dp_du],
// [dp_dv], [uv, uv1], [vertex colour, bitangent sign], [face colour], [wo], [wi].
// Out (from word 12): [f·cos, pdf], [sample wi, sample pdf], [sample weight, flags:
// 1 valid, 2 specular], [albedo, leaf count | has_non_delta << 8], [eta, 0, 0, 0].
const PROBE_STRIDE: u32 = 17u;

@compute @workgroup_size(64, 1, 1)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if (index >= params.width) {
        return;
    }
    let b = index * PROBE_STRIDE;
    let head = accum[b];
    var surf: PhysSurface;
    surf.point = vec3<f32>(0.0);
    surf.normal = accum[b + 1u].xyz;
    surf.frame = Frame(accum[b + 2u].xyz, accum[b + 3u].xyz, accum[b + 4u].xyz);
    surf.dp_du = accum[b + 5u].xyz;
    surf.dp_dv = accum[b + 6u].xyz;
    let uvs = accum[b + 7u];
    surf.tex = TexPoint(uvs.xy, uvs.zw, accum[b + 8u].xyz, accum[b + 9u].xyz);
    surf.bitangent_sign = accum[b + 8u].w;
    let wo = accum[b + 10u].xyz;
    let wi = accum[b + 11u].xyz;
    resolve_bsdf(bitcast<u32>(head.x), surf, wo);
    // As the path loop does it: one draw, both directions evaluated in one pass.
    let draw = phys_draw(wo, head.y, head.zw);
    let pair = phys_eval_pdf_pair(wo, wi, true, draw.s.wi, draw.mis);
    let fp = pair[0];
    let s = phys_finish(draw, pair[1]);
    var flags = 0u;
    if (s.valid) {
        flags |= 1u;
    }
    if (s.is_specular) {
        flags |= 2u;
    }
    var counts = leaf_count;
    if (phys_has_non_delta()) {
        counts |= 256u;
    }
    accum[b + 12u] = fp;
    accum[b + 13u] = vec4<f32>(s.wi, s.pdf);
    accum[b + 14u] = vec4<f32>(s.weight, bitcast<f32>(flags));
    accum[b + 15u] = vec4<f32>(phys_albedo(), bitcast<f32>(counts));
    accum[b + 16u] = vec4<f32>(s.eta, 0.0, 0.0, 0.0);
}

// The microfacet probe: tests/microfacet_agreement.rs writes cases (MICROFACET_STRIDE vec4
// each): [GGX?, alpha_u, alpha_v, sample visible?], [wo], [m], [u]; out: [D(m), G1(wo, m),
// G(wo, reflect(wo, m), m), pdf(wo, m)], [sampled m, its pdf].
const MICROFACET_STRIDE: u32 = 6u;

@compute @workgroup_size(64, 1, 1)
fn probe_microfacet(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if (index >= params.width) {
        return;
    }
    let b = index * MICROFACET_STRIDE;
    let head = accum[b];
    let mf = mf_new(select(DIST_BECKMANN, DIST_GGX, bitcast<u32>(head.x) != 0u), head.y, head.z, bitcast<u32>(head.w) != 0u);
    let wo = accum[b + 1u].xyz;
    let m = accum[b + 2u].xyz;
    let u = accum[b + 3u].xy;
    let wi = reflect_about(wo, m);
    accum[b + 4u] = vec4<f32>(mf_d(mf, m), mf_smith_g1(mf, wo, m), mf_g(mf, wi, wo, m), mf_pdf(mf, wo, m));
    accum[b + 5u] = mf_sample(mf, wo, u);
}
