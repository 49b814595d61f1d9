// glTF 2.0's metallic-roughness material with KHR_materials_ior, _specular, _transmission,
// _volume and _clearcoat on the GPU: a port of crates/render/src/material/gltf.rs (`GltfPbr`)
// and of surface.rs `Resolver::add_gltf`, formula for formula and guard for guard.
//
// Record (physical.rs `node_record`): header [kind, flags (GLTF_*), alpha cutoff, 0], then
// [base colour, alpha], [metallic, roughness, ior, specular], [specular colour,
// transmission], [clearcoat, clearcoat roughness, normal scale, 0], texture nodes [base
// colour, alpha, metallic-roughness, normal], [specular, specular colour, transmission,
// clearcoat], [clearcoat roughness, 0, 0, 0].
//
// Leaf (the material at the hit, `GltfPbr`): w[0] [base colour, metallic], w[1] [roughness,
// ior, specular, transmission], w[2] [specular colour, thin walled (1 or 0)], w[3]
// [clearcoat, clearcoat roughness, 0, 0].

// Flags of a glTF record (physical.rs GLTF_*).
const GLTF_VERTEX_COLOR: u32 = 1u;
const GLTF_THIN_WALLED: u32 = 2u;
const GLTF_DOUBLE_SIDED: u32 = 4u;
const GLTF_ALPHA_MASK: u32 = 8u;
const GLTF_ALPHA_BLEND: u32 = 16u;

// How transmitted light leaves (gltf.rs Transmit).
const GLTF_TRANSMIT_NONE: u32 = 0u;
const GLTF_TRANSMIT_MIRROR: u32 = 1u;
const GLTF_TRANSMIT_REFRACT: u32 = 2u;

// Below this GGX α a lobe is a Dirac delta (gltf.rs DELTA_ALPHA).
const GLTF_DELTA_ALPHA: f32 = 1e-4;
const GLTF_COAT_F0: f32 = 0.04;
const GLTF_MIN_SPECULAR_CHOICE: f32 = 0.02;

// A texture of the record (a texture word), white where there is none (Resolver::texel).
fn gltf_texel(word: f32) -> vec3<f32> {
    let node = word_u32(word);
    if (node == NONE) {
        return vec3<f32>(1.0);
    }
    return tex_eval(node, res_surface.tex);
}

// Vec3::normalized: zero for a zero vector, where WGSL's normalize is undefined.
fn gltf_normalized(v: vec3<f32>) -> vec3<f32> {
    let len = length(v);
    if (len > 0.0) {
        return v / len;
    }
    return vec3<f32>(0.0);
}

// `x` clamped to [0, 1], NaN read as 0 (gltf.rs unit).
fn gltf_unit(x: f32) -> f32 {
    if (!(x >= 0.0)) {
        return 0.0;
    }
    return min(x, 1.0);
}

fn gltf_mean(c: vec3<f32>) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

fn gltf_schlick_weight(cos: f32) -> f32 {
    let m = clamp(1.0 - cos, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

fn gltf_coat_fresnel(cos: f32) -> f32 {
    return GLTF_COAT_F0 + (1.0 - GLTF_COAT_F0) * gltf_schlick_weight(abs(cos));
}

// The height-correlated Smith visibility of GGX (gltf.rs visibility).
fn gltf_visibility(alpha: f32, cos_o: f32, cos_i: f32) -> f32 {
    let a2 = alpha * alpha;
    let lambda_o = cos_i * sqrt(a2 + (1.0 - a2) * cos_o * cos_o);
    let lambda_i = cos_o * sqrt(a2 + (1.0 - a2) * cos_i * cos_i);
    let denominator = 2.0 * (lambda_o + lambda_i);
    if (denominator > 0.0) {
        return 1.0 / denominator;
    }
    return 0.0;
}

fn gltf_ggx(alpha: f32) -> Microfacet {
    return mf_new(DIST_GGX, alpha, alpha, true);
}

// The parameters made safe (gltf.rs Params).
struct GltfParams {
    base: vec3<f32>,
    metallic: f32,
    alpha: f32,
    ior: f32,
    f0: vec3<f32>,
    f90: f32,
    transmission: f32,
    transmit: u32,
    clearcoat: f32,
    coat_alpha: f32,
    // The material's own flag (GltfPbr::thin_walled), which `side` reads.
    thin_walled: bool,
}

fn gltf_params(i: u32) -> GltfParams {
    let w0 = leaves[i].w[0];
    let w1 = leaves[i].w[1];
    let w2 = leaves[i].w[2];
    let w3 = leaves[i].w[3];
    var p: GltfParams;
    p.base = vec3<f32>(gltf_unit(w0.x), gltf_unit(w0.y), gltf_unit(w0.z));
    let ior_in = w1.y;
    p.ior = select(1.5, ior_in, ior_in >= 0.0 && ior_in <= INF);
    let specular = gltf_unit(w1.z);
    let r = (p.ior - 1.0) / (p.ior + 1.0);
    let r0 = r * r;
    let c = w2.xyz;
    let spec_colour = select(vec3<f32>(0.0), max(c, vec3<f32>(0.0)), abs(c) <= vec3<f32>(INF));
    p.f0 = min(spec_colour * r0, vec3<f32>(1.0)) * specular;
    p.metallic = gltf_unit(w0.w);
    let transmission = gltf_unit(w1.w);
    p.thin_walled = w2.w != 0.0;
    p.transmit = GLTF_TRANSMIT_NONE;
    if (transmission == 0.0 || p.metallic == 1.0) {
        p.transmit = GLTF_TRANSMIT_NONE;
    } else if (p.thin_walled || p.ior == 1.0) {
        p.transmit = GLTF_TRANSMIT_MIRROR;
    } else if (p.ior > 0.0) {
        p.transmit = GLTF_TRANSMIT_REFRACT;
    }
    let roughness = gltf_unit(w1.x);
    let coat_roughness = gltf_unit(w3.y);
    p.alpha = roughness * roughness;
    p.f90 = specular;
    p.transmission = select(transmission, 0.0, p.transmit == GLTF_TRANSMIT_NONE);
    p.clearcoat = gltf_unit(w3.x);
    p.coat_alpha = coat_roughness * coat_roughness;
    return p;
}

fn gltf_specular_is_delta(p: GltfParams) -> bool {
    return p.alpha < GLTF_DELTA_ALPHA;
}

fn gltf_coat_is_delta(p: GltfParams) -> bool {
    return p.coat_alpha < GLTF_DELTA_ALPHA;
}

fn gltf_metal_fresnel(p: GltfParams, cos: f32) -> vec3<f32> {
    let w = gltf_schlick_weight(abs(cos));
    return p.base + (vec3<f32>(1.0) - p.base) * w;
}

// The dielectric's Fresnel with KHR_materials_volume's cases (Params::dielectric_fresnel).
fn gltf_dielectric_fresnel(p: GltfParams, cos_in: f32, eta: f32) -> vec3<f32> {
    let cos = min(abs(cos_in), 1.0);
    var w: f32;
    if (eta >= 1.0) {
        w = gltf_schlick_weight(cos);
    } else {
        let sin2_t = (1.0 - cos * cos) / (eta * eta);
        if (sin2_t >= 1.0) {
            return vec3<f32>(1.0);
        }
        w = gltf_schlick_weight(sqrt(1.0 - sin2_t));
    }
    return p.f0 + (vec3<f32>(p.f90) - p.f0) * w;
}

// What scatters for one ωo, in the frame turned so that ωo lies above (gltf.rs Side);
// `valid` false where nothing does.
struct GltfSide {
    sign: f32,
    eta: f32,
    metal: f32,
    dielectric: f32,
    transmission: f32,
    diffuse: f32,
    coat: f32,
    exits_coat: bool,
    valid: bool,
}

fn gltf_up(s: GltfSide, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(v.x, v.y, v.z * s.sign);
}

fn gltf_side(p: GltfParams, wo: vec3<f32>) -> GltfSide {
    var s = GltfSide(1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, false, false);
    if (!(abs(wo.z) <= INF && wo.z != 0.0)) {
        return s;
    }
    if (wo.z > 0.0) {
        let coat = p.clearcoat * gltf_coat_fresnel(wo.z);
        let k = 1.0 - coat;
        let dielectric = k * (1.0 - p.metallic);
        s.eta = select(1.0, p.ior, p.transmit == GLTF_TRANSMIT_REFRACT);
        s.metal = k * p.metallic;
        s.dielectric = dielectric;
        s.transmission = dielectric * p.transmission;
        s.diffuse = dielectric * (1.0 - p.transmission);
        s.coat = coat;
        s.valid = true;
    } else if (p.transmit == GLTF_TRANSMIT_REFRACT || (p.transmit == GLTF_TRANSMIT_MIRROR && !p.thin_walled)) {
        // Inside a volume only the interface (its transmissive share) is seen.
        let share = (1.0 - p.metallic) * p.transmission;
        s.sign = -1.0;
        s.eta = select(1.0, 1.0 / p.ior, p.transmit == GLTF_TRANSMIT_REFRACT);
        s.dielectric = share;
        s.transmission = share;
        s.exits_coat = p.clearcoat > 0.0;
        s.valid = true;
    }
    return s;
}

// The probability of reflecting rather than transmitting by a micro-normal with ωo·m = cos.
fn gltf_reflect_share(p: GltfParams, s: GltfSide, cos: f32) -> f32 {
    let f = gltf_dielectric_fresnel(p, cos, s.eta);
    let r = s.metal * gltf_mean(gltf_metal_fresnel(p, cos)) + s.dielectric * gltf_mean(f);
    let t = s.transmission * gltf_mean(p.base) * (1.0 - max_component(f));
    if (r + t > 0.0) {
        return r / (r + t);
    }
    return 1.0;
}

// Lobe probabilities (diffuse, specular, coat) and whether there are any (w: 1 or 0).
fn gltf_choice(p: GltfParams, s: GltfSide, wo: vec3<f32>) -> vec4<f32> {
    let f = gltf_dielectric_fresnel(p, wo.z, s.eta);
    let base = gltf_mean(p.base);
    var specular = s.metal * gltf_mean(gltf_metal_fresnel(p, wo.z)) + s.dielectric * gltf_mean(f)
        + s.transmission * base * (1.0 - max_component(f));
    // Total internal reflection (η < 1) reflects even where specular is 0.
    let present = s.metal > 0.0 || (s.dielectric > 0.0 && (p.f90 > 0.0 || s.eta < 1.0))
        || s.transmission * max_component(p.base) > 0.0;
    if (present) {
        specular = max(specular, GLTF_MIN_SPECULAR_CHOICE);
    }
    let diffuse = s.diffuse * base * (1.0 - max_component(f));
    let coat = s.coat;
    let total = diffuse + specular + coat;
    if (!(total <= INF && total > 0.0)) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(diffuse / total, specular / total, coat / total, 1.0);
}

// f·cos with ωo and ωi in the turned frame (GltfPbr::eval_up).
fn gltf_eval_up(p: GltfParams, s: GltfSide, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    let cos_o = wo.z;
    let cos_i = wi.z;
    var value = vec3<f32>(0.0);
    if (cos_i > 0.0) {
        let h = gltf_normalized(wo + wi);
        let cos_oh = dot(wo, h);
        if (!gltf_specular_is_delta(p) && (s.metal > 0.0 || s.dielectric > 0.0)) {
            let dv = mf_d(gltf_ggx(p.alpha), h) * gltf_visibility(p.alpha, cos_o, cos_i) * cos_i;
            let f = gltf_metal_fresnel(p, cos_oh) * s.metal + gltf_dielectric_fresnel(p, cos_oh, s.eta) * s.dielectric;
            value += f * dv;
        }
        if (s.diffuse > 0.0) {
            // Appendix B's fresnel_mix: the base keeps 1 − max F of the pair's half vector.
            let f_h = max_component(gltf_dielectric_fresnel(p, cos_oh, 1.0));
            value += p.base * (s.diffuse * (1.0 - f_h) * FRAC_1_PI * cos_i);
        }
        if (s.coat > 0.0 && !gltf_coat_is_delta(p)) {
            let d = mf_d(gltf_ggx(p.coat_alpha), h);
            value += vec3<f32>(s.coat * d * gltf_visibility(p.coat_alpha, cos_o, cos_i) * cos_i);
        }
    } else if (cos_i < 0.0 && s.transmission > 0.0 && !gltf_specular_is_delta(p)) {
        let mf = gltf_ggx(p.alpha);
        var t = 0.0;
        if (p.transmit == GLTF_TRANSMIT_MIRROR) {
            let l = vec3<f32>(wi.x, wi.y, -cos_i);
            let h = gltf_normalized(wo + l);
            let f = gltf_dielectric_fresnel(p, dot(wo, h), s.eta);
            t = (1.0 - max_component(f)) * mf_d(mf, h) * mf_g(mf, wo, l, h) / (4.0 * cos_o);
        } else if (p.transmit == GLTF_TRANSMIT_REFRACT) {
            var h = gltf_normalized(wo + wi * s.eta);
            if (h.z < 0.0) {
                h = -h;
            }
            let dot_o = dot(wo, h);
            let dot_i = dot(wi, h);
            if (dot_o <= 0.0 || dot_i >= 0.0) {
                return vec3<f32>(0.0);
            }
            let f = gltf_dielectric_fresnel(p, dot_o, s.eta);
            let denominator = dot_o + s.eta * dot_i;
            // Walter et al.'s BTDF for radiance: its η² and the radiance scale 1/η² cancel.
            t = (1.0 - max_component(f)) * mf_d(mf, h) * mf_g(mf, wo, wi, h) * dot_o * -dot_i
                / (cos_o * denominator * denominator);
        }
        var exit = 1.0;
        if (s.exits_coat) {
            exit = 1.0 - p.clearcoat * gltf_coat_fresnel(cos_i);
        }
        value = p.base * (s.transmission * t * exit);
    }
    if (is_finite3(value)) {
        return value;
    }
    return vec3<f32>(0.0);
}

// The density with ωo and ωi in the turned frame (GltfPbr::pdf_up); `c` from gltf_choice.
fn gltf_pdf_up(p: GltfParams, s: GltfSide, c: vec4<f32>, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let cos_i = wi.z;
    var pdf = 0.0;
    if (cos_i > 0.0) {
        let h = gltf_normalized(wo + wi);
        let jacobian = 1.0 / (4.0 * dot(wi, h));
        pdf += c.x * cos_i * FRAC_1_PI;
        if (c.y > 0.0 && !gltf_specular_is_delta(p)) {
            let q = gltf_reflect_share(p, s, dot(wo, h));
            pdf += c.y * q * mf_pdf(gltf_ggx(p.alpha), wo, h) * jacobian;
        }
        if (c.z > 0.0 && !gltf_coat_is_delta(p)) {
            pdf += c.z * mf_pdf(gltf_ggx(p.coat_alpha), wo, h) * jacobian;
        }
    } else if (cos_i < 0.0 && c.y > 0.0 && !gltf_specular_is_delta(p)) {
        let mf = gltf_ggx(p.alpha);
        if (p.transmit == GLTF_TRANSMIT_MIRROR) {
            let l = vec3<f32>(wi.x, wi.y, -cos_i);
            let h = gltf_normalized(wo + l);
            let q = gltf_reflect_share(p, s, dot(wo, h));
            pdf += c.y * (1.0 - q) * mf_pdf(mf, wo, h) / (4.0 * dot(l, h));
        } else if (p.transmit == GLTF_TRANSMIT_REFRACT) {
            var h = gltf_normalized(wo + wi * s.eta);
            if (h.z < 0.0) {
                h = -h;
            }
            let dot_o = dot(wo, h);
            let dot_i = dot(wi, h);
            if (dot_o > 0.0 && dot_i < 0.0) {
                let q = gltf_reflect_share(p, s, dot_o);
                let denominator = dot_o + s.eta * dot_i;
                let jacobian = s.eta * s.eta * -dot_i / (denominator * denominator);
                pdf += c.y * (1.0 - q) * mf_pdf(mf, wo, h) * jacobian;
            }
        }
    }
    // finite_pdf: zero where not a finite positive density.
    if (pdf > 0.0 && pdf <= INF) {
        return pdf;
    }
    return 0.0;
}

// The specular lobe's Dirac sample (GltfPbr::sample_specular_delta); ωo up, the sample's
// wi in the turned frame.
fn gltf_sample_specular_delta(p: GltfParams, s: GltfSide, probability: f32, wo: vec3<f32>, u: f32) -> PhysSample {
    let q = gltf_reflect_share(p, s, wo.z);
    let f = gltf_dielectric_fresnel(p, wo.z, s.eta);
    if (u < q) {
        let value = gltf_metal_fresnel(p, wo.z) * s.metal + f * s.dielectric;
        let pdf = probability * q;
        return PhysSample(vec3<f32>(-wo.x, -wo.y, wo.z), value / pdf, pdf, true, 1.0, true);
    }
    let pdf = probability * (1.0 - q);
    let t = p.base * (s.transmission * (1.0 - max_component(f)));
    if (p.transmit == GLTF_TRANSMIT_MIRROR) {
        return PhysSample(-wo, t / pdf, pdf, true, 1.0, true);
    }
    if (p.transmit == GLTF_TRANSMIT_REFRACT) {
        let fr = fresnel_full(wo.z, s.eta);
        let eta_it = fr.z;
        let eta_ti = fr.w;
        let wi = refract_local(wo, fr.y, eta_ti);
        var exit = 1.0;
        if (s.exits_coat) {
            exit = 1.0 - p.clearcoat * gltf_coat_fresnel(wi.z);
        }
        // Radiance is compressed by 1/η² on entering the denser side.
        return PhysSample(wi, t * (exit * eta_ti * eta_ti / pdf), pdf, true, eta_it, true);
    }
    return no_sample();
}

// ---------------------------------------------------------------------------------------
// The family's entry points (physical.wgsl's dispatch).

// Resolver::add_gltf: the alpha (a null leaf for the part light passes), the sides, the
// normal map, then the leaf with every factor times its texture.
fn gltf_add(record: u32, weight_in: f32, frame_in: Frame, tilt_in: Tilt) {
    let head = physical[record];
    let flags = word_u32(head.y);
    let cutoff = head.z;
    let base_alpha = physical[record + 1u];
    let factors = physical[record + 2u];
    let spec = physical[record + 3u];
    let coat = physical[record + 4u];
    let tex0 = physical[record + 5u];
    let tex1 = physical[record + 6u];
    let tex2 = physical[record + 7u];
    var opacity = 1.0;
    if ((flags & (GLTF_ALPHA_MASK | GLTF_ALPHA_BLEND)) != 0u) {
        let alpha = clamp(base_alpha.w * gltf_texel(tex0.y).x, 0.0, 1.0);
        if ((flags & GLTF_ALPHA_MASK) != 0u) {
            opacity = select(0.0, 1.0, alpha >= cutoff);
        } else {
            opacity = alpha;
        }
    }
    // The part light passes first, as the CPU pushes it.
    push_leaf(FAMILY_NULL, weight_in * (1.0 - opacity), frame_in, tilt_in);
    let weight = weight_in * opacity;
    if (weight <= 0.0) {
        return;
    }
    var frame = frame_in;
    var sign = res_surface.bitangent_sign;
    let has_transmission = spec.w > 0.0;
    let thin_walled = (flags & GLTF_THIN_WALLED) != 0u;
    let volume = !thin_walled && has_transmission;
    if (to_local(frame, res_wo).z < 0.0 && !volume) {
        if ((flags & GLTF_DOUBLE_SIDED) != 0u || has_transmission) {
            // The back face is the front with its normal reversed.
            frame.w = -frame.w;
            sign = -sign;
        } else {
            // Culled: light passes the back face as if it were not there.
            push_leaf(FAMILY_NULL, weight_in * opacity, frame_in, tilt_in);
            return;
        }
    }
    // A volume's boundary seen from inside keeps its frame: the family refracts out.
    var tilt = tilt_in;
    let normal_texture = word_u32(tex0.w);
    if (normal_texture != NONE) {
        let t = gltf_texel(tex0.w) * 2.0 - vec3<f32>(1.0);
        let scale = coat.z;
        var n = vec3<f32>(t.x * scale, t.y * scale * sign, t.z);
        if (dot(frame.w, res_surface.frame.w) < 0.0) {
            // The reversed back face: reversing the perturbed normal negates its tangential
            // part in the flipped frame.
            n = vec3<f32>(-n.x, -n.y, n.z);
        }
        let wo_local = to_local(frame, res_wo);
        if (wo_local.z * dot(wo_local, n) <= 0.0) {
            n = vec3<f32>(-n.x, -n.y, n.z);
        }
        n = gltf_normalized(n);
        if (is_finite3(n) && n.z > 0.0) {
            let s = gltf_normalized(vec3<f32>(1.0, 0.0, 0.0) - n * n.x);
            let v = cross(n, s);
            tilt = Tilt(1u, frame, n);
            frame = Frame(to_world(frame, s), to_world(frame, v), to_world(frame, n));
        }
    }
    var base_color = base_alpha.xyz * gltf_texel(tex0.x);
    if ((flags & GLTF_VERTEX_COLOR) != 0u) {
        base_color *= res_surface.tex.vertex_color;
    }
    let mr = gltf_texel(tex0.z);
    let i = push_leaf(FAMILY_GLTF, weight, frame, tilt);
    if (i == NONE) {
        return;
    }
    let metallic = clamp(factors.x * mr.z, 0.0, 1.0);
    let roughness = clamp(factors.y * mr.y, 0.0, 1.0);
    let specular = clamp(factors.w * gltf_texel(tex1.x).x, 0.0, 1.0);
    let specular_color = max(spec.xyz * gltf_texel(tex1.y), vec3<f32>(0.0));
    let transmission = clamp(spec.w * gltf_texel(tex1.z).x, 0.0, 1.0);
    let clearcoat = clamp(coat.x * gltf_texel(tex1.w).x, 0.0, 1.0);
    let coat_roughness = clamp(coat.y * gltf_texel(tex2.x).y, 0.0, 1.0);
    leaves[i].w[0] = vec4<f32>(clamp(base_color, vec3<f32>(0.0), vec3<f32>(1.0)), metallic);
    leaves[i].w[1] = vec4<f32>(roughness, factors.z, specular, transmission);
    leaves[i].w[2] = vec4<f32>(specular_color, select(0.0, 1.0, thin_walled));
    leaves[i].w[3] = vec4<f32>(clearcoat, coat_roughness, 0.0, 0.0);
}

fn gltf_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let p = gltf_params(i);
    let s = gltf_side(p, wo);
    if (!s.valid) {
        return vec4<f32>(0.0);
    }
    let wo_up = gltf_up(s, wo);
    let wi_up = gltf_up(s, wi);
    let value = gltf_eval_up(p, s, wo_up, wi_up);
    let c = gltf_choice(p, s, wo_up);
    var pdf = 0.0;
    if (c.w != 0.0) {
        pdf = gltf_pdf_up(p, s, c, wo_up, wi_up);
    }
    return vec4<f32>(value, pdf);
}

fn gltf_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    let p = gltf_params(i);
    let s = gltf_side(p, wo);
    if (!s.valid) {
        return no_sample();
    }
    let wo_up = gltf_up(s, wo);
    let c = gltf_choice(p, s, wo_up);
    if (c.w == 0.0) {
        return no_sample();
    }
    var wi: vec3<f32>;
    if (u_lobe < c.x) {
        wi = sample_cosine_hemisphere(u);
    } else if (u_lobe < c.x + c.y) {
        // The rest of u_lobe chooses between reflection and transmission.
        let u_event = clamp((u_lobe - c.x) / c.y, 0.0, 1.0);
        if (gltf_specular_is_delta(p)) {
            var d = gltf_sample_specular_delta(p, s, c.y, wo_up, u_event);
            if (!d.valid) {
                return d;
            }
            d.wi = gltf_up(s, d.wi);
            return usable(d);
        }
        let ms = mf_sample(gltf_ggx(p.alpha), wo_up, u);
        if (ms.w == 0.0) {
            return no_sample();
        }
        let m = ms.xyz;
        let cos_om = dot(wo_up, m);
        // Each event keeps to its side: a draw that crosses over would add density where
        // the pdf counts only the other event's.
        if (u_event < gltf_reflect_share(p, s, cos_om)) {
            wi = reflect_about(wo_up, m);
            if (wi.z <= 0.0) {
                return no_sample();
            }
        } else {
            if (p.transmit == GLTF_TRANSMIT_MIRROR) {
                let r = reflect_about(wo_up, m);
                wi = vec3<f32>(r.x, r.y, -r.z);
            } else if (p.transmit == GLTF_TRANSMIT_REFRACT) {
                let fr = fresnel_full(cos_om, s.eta);
                wi = refract_about(wo_up, m, fr.y, fr.w);
            } else {
                return no_sample();
            }
            if (wi.z >= 0.0) {
                return no_sample();
            }
        }
    } else {
        if (gltf_coat_is_delta(p)) {
            return usable(PhysSample(vec3<f32>(-wo.x, -wo.y, wo.z), vec3<f32>(s.coat / c.z), c.z, true, 1.0, true));
        }
        let ms = mf_sample(gltf_ggx(p.coat_alpha), wo_up, u);
        if (ms.w == 0.0) {
            return no_sample();
        }
        wi = reflect_about(wo_up, ms.xyz);
        if (wi.z <= 0.0) {
            return no_sample();
        }
    }
    if (wi.z == 0.0 || !is_finite3(wi)) {
        return no_sample();
    }
    let value = gltf_eval_up(p, s, wo_up, wi);
    let pdf = gltf_pdf_up(p, s, c, wo_up, wi);
    if (pdf <= 0.0) {
        return no_sample();
    }
    let eta = select(1.0, s.eta, wi.z < 0.0 && p.transmit == GLTF_TRANSMIT_REFRACT);
    return usable(PhysSample(gltf_up(s, wi), value / pdf, pdf, false, eta, true));
}

fn gltf_albedo(i: u32) -> vec3<f32> {
    let b = leaves[i].w[0];
    return vec3<f32>(gltf_unit(b.x), gltf_unit(b.y), gltf_unit(b.z));
}

fn gltf_has_non_delta(i: u32) -> bool {
    let p = gltf_params(i);
    let diffuse = (1.0 - p.metallic) * (1.0 - p.transmission) * max_component(p.base) > 0.0;
    let specular = !gltf_specular_is_delta(p) && (p.metallic > 0.0 || p.f90 > 0.0 || p.transmission > 0.0);
    let coat = p.clearcoat > 0.0 && !gltf_coat_is_delta(p);
    return diffuse || specular || coat;
}
