// The conductor and roughconductor (conductor.rs) on the GPU, formula for formula.
// Record (physical.rs): header [kind, has η and k, rough, 0], [η], [k], [specular
// reflectance], roughness words. Leaf: w[0].xyz η, w[1].xyz k, w[2].xyz specular
// reflectance, w[3] the microfacet model (`metal_mf_words`), rough leaves only.

// Mitsuba's `material="none"` (conductor.rs MIRROR_ETA, MIRROR_K): a Fresnel reflectance of 1.
const MIRROR_ETA: f32 = 0.0;
const MIRROR_K: f32 = 1.0;

// `v` scaled to unit length, or zero where it has none (Vec3::normalized).
fn metal_normalized(v: vec3<f32>) -> vec3<f32> {
    let len = length(v);
    if (len > 0.0) {
        return v * (1.0 / len);
    }
    return vec3<f32>(0.0);
}

// `c`, or zero where a channel is not finite (scatter.rs finite_or_zero).
fn metal_finite_or_zero(c: vec3<f32>) -> vec3<f32> {
    return select(vec3<f32>(0.0), c, is_finite3(c));
}

// `p`, or zero where it is not a finite positive density (scatter.rs finite_pdf).
fn metal_finite_pdf(p: f32) -> f32 {
    return select(0.0, p, p > 0.0 && p <= INF);
}

// A microfacet model in one leaf word, and back.
fn metal_mf_words(mf: Microfacet) -> vec4<f32> {
    return vec4<f32>(bitcast<f32>(mf.distribution), mf.alpha_u, mf.alpha_v, bitcast<f32>(u32(mf.sample_visible)));
}

fn metal_mf(w: vec4<f32>) -> Microfacet {
    return Microfacet(word_u32(w.x), w.y, w.z, word_u32(w.w) != 0u);
}

fn conductor_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let head = physical[record];
    let rough = word_u32(head.z) != 0u;
    let at = res_surface.tex;
    let i = push_leaf(select(FAMILY_CONDUCTOR, FAMILY_ROUGH_CONDUCTOR, rough), weight, frame, tilt);
    if (i == NONE) {
        return;
    }
    var eta = vec3<f32>(MIRROR_ETA);
    var k = vec3<f32>(MIRROR_K);
    if (word_u32(head.y) != 0u) {
        eta = param_color(record + 1u, at);
        k = param_color(record + 2u, at);
    }
    leaves[i].w[0] = vec4<f32>(eta, 0.0);
    leaves[i].w[1] = vec4<f32>(k, 0.0);
    leaves[i].w[2] = vec4<f32>(param_color(record + 3u, at), 0.0);
    if (rough) {
        leaves[i].w[3] = metal_mf_words(mf_from_record(record + 4u, at));
    }
}

fn conductor_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn conductor_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    if (!(wo.z > 0.0)) {
        return no_sample();
    }
    let f = fresnel_conductor(wo.z, leaves[i].w[0].xyz, leaves[i].w[1].xyz);
    return usable(PhysSample(reflect_local(wo), leaves[i].w[2].xyz * f, 1.0, true, 1.0, true));
}

fn conductor_albedo(i: u32) -> vec3<f32> {
    let f = fresnel_conductor(1.0, leaves[i].w[0].xyz, leaves[i].w[1].xyz);
    return clamp(metal_finite_or_zero(leaves[i].w[2].xyz * f), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn conductor_has_non_delta(i: u32) -> bool {
    return false;
}

// The pdf of ωi given the half vector, Mitsuba's two cases (RoughConductor::pdf_with_half).
fn rough_conductor_pdf_with_half(mf: Microfacet, wo: vec3<f32>, wi: vec3<f32>, h: vec3<f32>) -> f32 {
    if (mf.sample_visible) {
        return mf_d(mf, h) * mf_smith_g1(mf, wo, h) / (4.0 * wo.z);
    }
    return mf_pdf(mf, wo, h) / (4.0 * dot(wi, h));
}

fn rough_conductor_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    if (!(wo.z > 0.0 && wi.z > 0.0)) {
        return vec4<f32>(0.0);
    }
    let mf = metal_mf(leaves[i].w[3]);
    let h = metal_normalized(wo + wi);
    var f = vec3<f32>(0.0);
    let d = mf_d(mf, h);
    if (d != 0.0) {
        let value = d * mf_g(mf, wo, wi, h) / (4.0 * wo.z);
        let fresnel = fresnel_conductor(dot(wo, h), leaves[i].w[0].xyz, leaves[i].w[1].xyz);
        f = metal_finite_or_zero(fresnel * leaves[i].w[2].xyz * value);
    }
    // The side tests that smith_g1 makes in eval and sample, repeated for the density.
    var pdf = 0.0;
    if (dot(wo, h) > 0.0 && dot(wi, h) > 0.0) {
        pdf = metal_finite_pdf(rough_conductor_pdf_with_half(mf, wo, wi, h));
    }
    return vec4<f32>(f, pdf);
}

fn rough_conductor_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    if (!(wo.z > 0.0)) {
        return no_sample();
    }
    let mf = metal_mf(leaves[i].w[3]);
    let s = mf_sample(mf, wo, u);
    let m = s.xyz;
    let pdf_m = s.w;
    let wi = reflect_about(wo, m);
    // Without visible normals m may face away from ωo; Mitsuba's weight is then zero.
    if (pdf_m == 0.0 || !(wi.z > 0.0) || !(dot(wi, m) > 0.0)) {
        return no_sample();
    }
    var weight: f32;
    if (mf.sample_visible) {
        weight = mf_smith_g1(mf, wi, m);
    } else {
        weight = mf_g(mf, wo, wi, m) * dot(wo, m) / (wo.z * m.z);
    }
    let f = fresnel_conductor(dot(wo, m), leaves[i].w[0].xyz, leaves[i].w[1].xyz);
    return usable(PhysSample(wi, f * leaves[i].w[2].xyz * weight, pdf_m / (4.0 * dot(wi, m)), false, 1.0, true));
}

fn rough_conductor_albedo(i: u32) -> vec3<f32> {
    return conductor_albedo(i);
}

fn rough_conductor_has_non_delta(i: u32) -> bool {
    return true;
}
