// The plastic and roughplastic (plastic.rs) on the GPU, formula for formula. Record
// (physical.rs): [kind, rough, η, nonlinear], [diffuse], [specular], roughness words; a rough
// plastic's record goes on with PLASTIC_TABLE_WORD [internal reflectance, α, 0, 0] and its
// transmittance table (PLASTIC_TABLE_RES floats, four a word), tabulated on the host by
// glint-render's own `prepare_rough_plastics`.
// Leaf: w[0] = [diffuse, η], w[1] = [specular, nonlinear], w[2] = [F_dr inside (smooth) or
// internal reflectance (rough), specular sampling weight, table record word (rough), 0],
// w[3] the microfacet model (rough; `metal_mf_words`).

// Where a rough plastic's tables start in its record, and the table's length (plastic.rs
// TRANSMITTANCE_RES).
const PLASTIC_TABLE_WORD: u32 = 6u;
const PLASTIC_TABLE_RES: u32 = 64u;

// mean(specular) / (mean(diffuse) + mean(specular)), 0.5 where that is not finite
// (plastic.rs specular_sampling_weight of the colours' channel means).
fn plastic_sampling_weight(diffuse: vec3<f32>, specular: vec3<f32>) -> f32 {
    let d = (diffuse.x + diffuse.y + diffuse.z) / 3.0;
    let s = (specular.x + specular.y + specular.z) / 3.0;
    let w = s / (d + s);
    if (abs(w) <= INF) {
        return clamp(w, 0.0, 1.0);
    }
    return 0.5;
}

// The diffuse base's value after the coating: ρ / (1 − F ρ) or ρ / (1 − F).
fn plastic_multiply_scattered(diffuse: vec3<f32>, internal: f32, nonlinear: bool) -> vec3<f32> {
    var denominator = vec3<f32>(1.0 - internal);
    if (nonlinear) {
        denominator = vec3<f32>(1.0) - diffuse * internal;
    }
    return diffuse / denominator;
}

fn plastic_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let head = physical[record];
    let rough = word_u32(head.y) != 0u;
    let at = res_surface.tex;
    let i = push_leaf(select(FAMILY_PLASTIC, FAMILY_ROUGH_PLASTIC, rough), weight, frame, tilt);
    if (i == NONE) {
        return;
    }
    let diffuse = param_color(record + 1u, at);
    let specular = param_color(record + 2u, at);
    let eta = head.z;
    leaves[i].w[0] = vec4<f32>(diffuse, eta);
    leaves[i].w[1] = vec4<f32>(specular, head.w);
    let ssw = plastic_sampling_weight(diffuse, specular);
    if (rough) {
        let table = physical[record + PLASTIC_TABLE_WORD];
        // The coating's microfacet model is the tables' own: isotropic, α read once on the
        // host (RoughPlastic::microfacet).
        let r = physical[record + 3u];
        let mf = mf_new(word_u32(r.x), table.y, table.y, word_u32(r.y) != 0u);
        leaves[i].w[2] = vec4<f32>(table.x, ssw, bitcast<f32>(record + PLASTIC_TABLE_WORD + 1u), 0.0);
        leaves[i].w[3] = metal_mf_words(mf);
    } else {
        leaves[i].w[2] = vec4<f32>(fresnel_diffuse_reflectance(1.0 / eta), ssw, 0.0, 0.0);
    }
}

// The probability of the specular lobe with Fresnel reflectance f (Plastic).
fn plastic_specular_probability(i: u32, f: f32) -> f32 {
    let ssw = leaves[i].w[2].y;
    let s = f * ssw;
    let d = (1.0 - f) * (1.0 - ssw);
    return s / (s + d);
}

fn plastic_diffuse(i: u32) -> vec3<f32> {
    return plastic_multiply_scattered(leaves[i].w[0].xyz, leaves[i].w[2].x, word_u32(leaves[i].w[1].w) != 0u);
}

fn plastic_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    if (!(wo.z > 0.0 && wi.z > 0.0)) {
        return vec4<f32>(0.0);
    }
    let eta = leaves[i].w[0].w;
    let f_o = fresnel_full(wo.z, eta).x;
    let f_i = fresnel_full(wi.z, eta).x;
    let scale = cosine_hemisphere_pdf(wi.z) / (eta * eta) * (1.0 - f_o) * (1.0 - f_i);
    let f = metal_finite_or_zero(plastic_diffuse(i) * scale);
    let p_diffuse = 1.0 - plastic_specular_probability(i, f_o);
    return vec4<f32>(f, metal_finite_pdf(cosine_hemisphere_pdf(wi.z) * p_diffuse));
}

fn plastic_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    if (!(wo.z > 0.0)) {
        return no_sample();
    }
    let eta = leaves[i].w[0].w;
    let f_o = fresnel_full(wo.z, eta).x;
    let p_specular = plastic_specular_probability(i, f_o);
    if (u_lobe < p_specular) {
        return usable(PhysSample(reflect_local(wo), leaves[i].w[1].xyz * (f_o / p_specular), p_specular, true, 1.0, true));
    }
    let p_diffuse = 1.0 - p_specular;
    let wi = sample_cosine_hemisphere(u);
    let f_i = fresnel_full(wi.z, eta).x;
    let weight = plastic_diffuse(i) * ((1.0 - f_o) * (1.0 - f_i) / (eta * eta * p_diffuse));
    return usable(PhysSample(wi, weight, p_diffuse * cosine_hemisphere_pdf(wi.z), false, 1.0, true));
}

fn plastic_albedo(i: u32) -> vec3<f32> {
    return clamp(leaves[i].w[0].xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn plastic_has_non_delta(i: u32) -> bool {
    return true;
}

// t(cos θ), linearly interpolated in the leaf's table (RoughPlastic::transmittance).
fn rough_plastic_transmittance(i: u32, cos_theta: f32) -> f32 {
    let base = word_u32(leaves[i].w[2].z);
    let x = clamp(cos_theta, 0.0, 1.0) * f32(PLASTIC_TABLE_RES - 1u);
    // Rust's `as usize` takes NaN to 0.
    var index = 0u;
    if (x > 0.0) {
        index = min(u32(x), PLASTIC_TABLE_RES - 2u);
    }
    let v0 = physical[base + index / 4u][index % 4u];
    let v1 = physical[base + (index + 1u) / 4u][(index + 1u) % 4u];
    return v0 + (v1 - v0) * (x - f32(index));
}

fn rough_plastic_specular_probability(i: u32, cos_theta_o: f32) -> f32 {
    let t = rough_plastic_transmittance(i, cos_theta_o);
    let ssw = leaves[i].w[2].y;
    let s = (1.0 - t) * ssw;
    let d = t * (1.0 - ssw);
    return s / (s + d);
}

fn rough_plastic_eval(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if (!(wo.z > 0.0 && wi.z > 0.0)) {
        return vec3<f32>(0.0);
    }
    let mf = metal_mf(leaves[i].w[3]);
    let eta = leaves[i].w[0].w;
    let h = metal_normalized(wo + wi);
    let d = mf_d(mf, h);
    let f = fresnel_full(dot(wo, h), eta).x;
    let g = mf_g(mf, wo, wi, h);
    let specular = leaves[i].w[1].xyz * (f * d * g / (4.0 * wo.z));
    let t_o = rough_plastic_transmittance(i, wo.z);
    let t_i = rough_plastic_transmittance(i, wi.z);
    let scale = FRAC_1_PI / (eta * eta) * wi.z * t_o * t_i;
    return metal_finite_or_zero(specular + plastic_diffuse(i) * scale);
}

fn rough_plastic_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (!(wo.z > 0.0 && wi.z > 0.0)) {
        return 0.0;
    }
    let p_specular = rough_plastic_specular_probability(i, wo.z);
    let h = metal_normalized(wo + wi);
    let mf = metal_mf(leaves[i].w[3]);
    var specular: f32;
    if (mf.sample_visible) {
        specular = mf_d(mf, h) * mf_smith_g1(mf, wo, h) / (4.0 * wo.z);
    } else {
        specular = mf_pdf(mf, wo, h) / (4.0 * dot(wi, h));
    }
    return metal_finite_pdf(specular * p_specular + (1.0 - p_specular) * cosine_hemisphere_pdf(wi.z));
}

fn rough_plastic_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(rough_plastic_eval(i, wo, wi), rough_plastic_pdf(i, wo, wi));
}

fn rough_plastic_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    if (!(wo.z > 0.0)) {
        return no_sample();
    }
    var wi: vec3<f32>;
    if (u_lobe < rough_plastic_specular_probability(i, wo.z)) {
        wi = reflect_about(wo, mf_sample(metal_mf(leaves[i].w[3]), wo, u).xyz);
    } else {
        wi = sample_cosine_hemisphere(u);
    }
    let pdf = rough_plastic_pdf(i, wo, wi);
    if (!(pdf > 0.0)) {
        return no_sample();
    }
    return usable(PhysSample(wi, rough_plastic_eval(i, wo, wi) * (1.0 / pdf), pdf, false, 1.0, true));
}

fn rough_plastic_albedo(i: u32) -> vec3<f32> {
    return plastic_albedo(i);
}

fn rough_plastic_has_non_delta(i: u32) -> bool {
    return true;
}
