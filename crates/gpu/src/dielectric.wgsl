// The dielectric, thindielectric and roughdielectric (dielectric.rs) on the GPU, formula for
// formula. Records (physical.rs): dielectric [kind, rough, η, 0], [specular reflectance],
// [specular transmittance], roughness words; thin dielectric [kind, 0, η, 0], [specular
// reflectance], [specular transmittance]. Leaf: w[0] = [specular reflectance, η], w[1].xyz
// the specular transmittance, w[2] the microfacet model (`metal_mf_words`), rough leaves only.

fn dielectric_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let head = physical[record];
    let rough = word_u32(head.y) != 0u;
    let at = res_surface.tex;
    let i = push_leaf(select(FAMILY_DIELECTRIC, FAMILY_ROUGH_DIELECTRIC, rough), weight, frame, tilt);
    if (i == NONE) {
        return;
    }
    leaves[i].w[0] = vec4<f32>(param_color(record + 1u, at), head.z);
    leaves[i].w[1] = vec4<f32>(param_color(record + 2u, at), 0.0);
    if (rough) {
        leaves[i].w[2] = metal_mf_words(mf_from_record(record + 3u, at));
    }
}

fn thin_dielectric_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let head = physical[record];
    let at = res_surface.tex;
    let i = push_leaf(FAMILY_THIN_DIELECTRIC, weight, frame, tilt);
    if (i != NONE) {
        leaves[i].w[0] = vec4<f32>(param_color(record + 1u, at), head.z);
        leaves[i].w[1] = vec4<f32>(param_color(record + 2u, at), 0.0);
    }
}

fn dielectric_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn dielectric_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    let fr = fresnel_full(wo.z, leaves[i].w[0].w);
    let r = fr.x;
    if (u_lobe <= r) {
        return usable(PhysSample(reflect_local(wo), leaves[i].w[0].xyz, r, true, 1.0, true));
    }
    let eta_ti = fr.w;
    let wi = refract_local(wo, fr.y, eta_ti);
    return usable(PhysSample(wi, leaves[i].w[1].xyz * (eta_ti * eta_ti), 1.0 - r, true, fr.z, true));
}

fn dielectric_albedo(i: u32) -> vec3<f32> {
    return clamp(leaves[i].w[1].xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn dielectric_has_non_delta(i: u32) -> bool {
    return false;
}

// R' = 2R / (1 + R) at |cos θ| (ThinDielectric::reflectance).
fn thin_dielectric_reflectance(eta: f32, cos_theta: f32) -> f32 {
    let r = fresnel_full(abs(cos_theta), eta).x;
    return r * 2.0 / (1.0 + r);
}

fn thin_dielectric_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

// The pass-through is Mitsuba's null transmission: ωi = −ωo, flagged specular.
fn thin_dielectric_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    let r = thin_dielectric_reflectance(leaves[i].w[0].w, wo.z);
    if (u_lobe <= r) {
        return usable(PhysSample(reflect_local(wo), leaves[i].w[0].xyz, r, true, 1.0, true));
    }
    return usable(PhysSample(-wo, leaves[i].w[1].xyz, 1.0 - r, true, 1.0, true));
}

fn thin_dielectric_albedo(i: u32) -> vec3<f32> {
    return dielectric_albedo(i);
}

fn thin_dielectric_has_non_delta(i: u32) -> bool {
    return false;
}

// The distribution that sampling draws from at cos θo: without visible normals, Walter et
// al.'s widening by 1.2 − 0.2 √|cos θo| (Microfacet::scaled: no clamp after it).
fn rough_dielectric_sampling_mf(mf: Microfacet, cos_theta_o: f32) -> Microfacet {
    if (mf.sample_visible) {
        return mf;
    }
    let factor = 1.2 - 0.2 * sqrt(abs(cos_theta_o));
    return Microfacet(mf.distribution, mf.alpha_u * factor, mf.alpha_v * factor, mf.sample_visible);
}

fn rough_dielectric_usable_eta(eta: f32) -> bool {
    return abs(eta) <= INF && eta > 0.0 && eta != 1.0;
}

fn rough_dielectric_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let cos_o = wo.z;
    let self_eta = leaves[i].w[0].w;
    if (cos_o == 0.0 || !rough_dielectric_usable_eta(self_eta)) {
        return vec4<f32>(0.0);
    }
    let mf = metal_mf(leaves[i].w[2]);
    // The generalised half vector on the macro-normal's side (RoughDielectric::half_vector).
    let is_reflect = wo.z * wi.z > 0.0;
    let eta = select(1.0 / self_eta, self_eta, wo.z > 0.0);
    var m = metal_normalized(wo + wi * select(eta, 1.0, is_reflect));
    if (m.z < 0.0) {
        m = -m;
    }
    let dot_o = dot(wo, m);
    let dot_i = dot(wi, m);
    let d = mf_d(mf, m);
    let f = fresnel_full(dot_o, self_eta).x;
    let g = mf_g(mf, wo, wi, m);
    var value: vec3<f32>;
    if (is_reflect) {
        value = leaves[i].w[0].xyz * (f * d * g / (4.0 * abs(cos_o)));
    } else {
        let scale = 1.0 / (eta * eta);
        let denominator = dot_o + eta * dot_i;
        let t = abs(scale * (1.0 - f) * d * g * eta * eta * dot_o * dot_i / (cos_o * denominator * denominator));
        value = leaves[i].w[1].xyz * t;
    }
    let value_ok = metal_finite_or_zero(value);
    // The side tests that smith_g1 makes in eval and sample.
    if (!(dot_o * cos_o > 0.0 && dot_i * wi.z > 0.0)) {
        return vec4<f32>(value_ok, 0.0);
    }
    var jacobian: f32;
    if (is_reflect) {
        jacobian = 1.0 / (4.0 * dot_i);
    } else {
        let denominator = dot_o + eta * dot_i;
        jacobian = eta * eta * dot_i / (denominator * denominator);
    }
    let side = select(-wo, wo, cos_o > 0.0);
    let choice = select(1.0 - f, f, is_reflect);
    let pdf = metal_finite_pdf(mf_pdf(rough_dielectric_sampling_mf(mf, cos_o), side, m) * choice * abs(jacobian));
    return vec4<f32>(value_ok, pdf);
}

fn rough_dielectric_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    let cos_o = wo.z;
    let self_eta = leaves[i].w[0].w;
    if (cos_o == 0.0 || !rough_dielectric_usable_eta(self_eta)) {
        return no_sample();
    }
    let mf = metal_mf(leaves[i].w[2]);
    let side = select(-wo, wo, cos_o > 0.0);
    let s = mf_sample(rough_dielectric_sampling_mf(mf, cos_o), side, u);
    let m = s.xyz;
    let pdf_m = s.w;
    if (pdf_m == 0.0) {
        return no_sample();
    }
    let dot_o = dot(wo, m);
    let fr = fresnel_full(dot_o, self_eta);
    let f = fr.x;
    var wi: vec3<f32>;
    var weight: vec3<f32>;
    var choice: f32;
    var jacobian: f32;
    var eta = 1.0;
    if (u_lobe <= f) {
        wi = reflect_about(wo, m);
        jacobian = 1.0 / (4.0 * dot(wi, m));
        weight = leaves[i].w[0].xyz;
        choice = f;
    } else {
        let eta_it = fr.z;
        let eta_ti = fr.w;
        wi = refract_about(wo, m, fr.y, eta_ti);
        let dot_i = dot(wi, m);
        let denominator = dot_o + eta_it * dot_i;
        jacobian = eta_it * eta_it * dot_i / (denominator * denominator);
        weight = leaves[i].w[1].xyz * (eta_ti * eta_ti);
        choice = 1.0 - f;
        eta = eta_it;
    }
    // eval / pdf without the event's factors (see dielectric.rs on Mitsuba 0.6's formula).
    var masking: f32;
    if (mf.sample_visible) {
        masking = mf_smith_g1(mf, wi, m);
    } else {
        masking = mf_g(mf, wo, wi, m) * abs(dot_o) * mf_d(mf, m) / (abs(cos_o) * pdf_m);
    }
    // A direction on the wrong side of the macro-surface for its event carries no light.
    if (!(masking > 0.0 && masking <= INF)) {
        return no_sample();
    }
    return usable(PhysSample(wi, weight * masking, pdf_m * choice * abs(jacobian), false, eta, true));
}

fn rough_dielectric_albedo(i: u32) -> vec3<f32> {
    return dielectric_albedo(i);
}

fn rough_dielectric_has_non_delta(i: u32) -> bool {
    return true;
}
