// Mitsuba 3's `principled` and `principledthin` (principled.rs) on the GPU, formula for
// formula and branch for branch, so that the probe agrees case by case.
//
// Record (physical.rs): [kind, sample visible, 0, 0], then the parameter words base colour,
// roughness, anisotropic, metallic, spec_trans, eta, spec_tint, sheen, sheen_tint,
// clearcoat, clearcoat_gloss, flatness, diff_trans.
//
// principled leaf: w[0] = [base colour, roughness], w[1] = [anisotropic, metallic,
// spec_trans, eta], w[2] = [spec_tint, sheen, sheen_tint, flatness], w[3] = [clearcoat,
// clearcoat_gloss, sample visible (0 or 1), 0].
// principledthin leaf: w[0] = [base colour, roughness], w[1] = [anisotropic, spec_trans,
// diff_trans, eta], w[2] = [spec_tint, sheen, sheen_tint, flatness], w[3] = [sample
// visible, 0, 0, 0].

// The record's parameter words, after the header (physical.rs `PrincipledParams` order).
const PRINCIPLED_BASE_COLOR: u32 = 1u;
const PRINCIPLED_ROUGHNESS: u32 = 2u;
const PRINCIPLED_ANISOTROPIC: u32 = 3u;
const PRINCIPLED_METALLIC: u32 = 4u;
const PRINCIPLED_SPEC_TRANS: u32 = 5u;
const PRINCIPLED_ETA: u32 = 6u;
const PRINCIPLED_SPEC_TINT: u32 = 7u;
const PRINCIPLED_SHEEN: u32 = 8u;
const PRINCIPLED_SHEEN_TINT: u32 = 9u;
const PRINCIPLED_CLEARCOAT: u32 = 10u;
const PRINCIPLED_CLEARCOAT_GLOSS: u32 = 11u;
const PRINCIPLED_FLATNESS: u32 = 12u;
const PRINCIPLED_DIFF_TRANS: u32 = 13u;

// The lobe-selection rates: Mitsuba's defaults, which scenes cannot change here (the CPU's
// `Principled::new`, `PrincipledThin::new`).
const PR_DIFFUSE_RATE: f32 = 1.0;
const PR_MAIN_SPECULAR_RATE: f32 = 1.0;
const PR_CLEARCOAT_RATE: f32 = 1.0;
const PR_THIN_SPEC_R_RATE: f32 = 1.0;
const PR_THIN_SPEC_T_RATE: f32 = 1.0;
const PR_THIN_DIFF_R_RATE: f32 = 1.0;
const PR_THIN_DIFF_T_RATE: f32 = 1.0;
// The clearcoat's masking roughness (CLEARCOAT_G_ALPHA).
const PR_CLEARCOAT_G_ALPHA: f32 = 0.25;

// ---------------------------------------------------------------------------------------
// Helpers (principled.rs's free functions).

// Mitsuba's luminance weights, unrounded: the tints divide by this one.
fn pr_luminance(c: vec3<f32>) -> f32 {
    return 0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z;
}

// Vec3 / f32 on the CPU multiplies by the reciprocal; so does this.
fn pr_div(v: vec3<f32>, s: f32) -> vec3<f32> {
    return v * (1.0 / s);
}

// Vec3::normalized: zero stays zero rather than NaN.
fn pr_normalized(v: vec3<f32>) -> vec3<f32> {
    let len = sqrt(dot(v, v));
    if (len > 0.0) {
        return pr_div(v, len);
    }
    return vec3<f32>(0.0);
}

fn pr_is_finite(x: f32) -> bool {
    return abs(x) <= INF;
}

fn pr_tint_colour(base_color: vec3<f32>) -> vec3<f32> {
    let lum = pr_luminance(base_color);
    if (lum > 0.0) {
        return pr_div(base_color, lum);
    }
    return vec3<f32>(1.0);
}

// a + t (b − a) (WGSL's `mix` rounds differently).
fn pr_lerp(a: f32, b: f32, t: f32) -> f32 {
    return a + t * (b - a);
}

fn pr_lerp3(a: vec3<f32>, b: vec3<f32>, t: f32) -> vec3<f32> {
    return a + (b - a) * t;
}

fn pr_schlick_weight(c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

fn pr_schlick_r0(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    return r * r;
}

fn pr_schlick(r0: f32, cos_theta: f32, eta: f32) -> f32 {
    let eta_ti = select(eta, 1.0 / eta, cos_theta >= 0.0);
    let eta_it = 1.0 / eta_ti;
    var w: f32;
    if (eta_it > 1.0) {
        w = pr_schlick_weight(abs(cos_theta));
    } else {
        let cos_t_sqr = 1.0 - (1.0 - cos_theta * cos_theta) * eta_ti * eta_ti;
        w = pr_schlick_weight(sqrt(max(cos_t_sqr, 0.0)));
    }
    return pr_lerp(w, 1.0, r0);
}

fn pr_schlick3(r0: vec3<f32>, cos_theta: f32, eta: f32) -> vec3<f32> {
    return vec3<f32>(pr_schlick(r0.x, cos_theta, eta), pr_schlick(r0.y, cos_theta, eta), pr_schlick(r0.z, cos_theta, eta));
}

fn pr_clamp_alpha(a: f32) -> f32 {
    if (pr_is_finite(a)) {
        return max(a, 0.001);
    }
    return 0.001;
}

// Disney's roughness remapping into a GGX distribution (`alphas`, `ggx`).
fn pr_ggx(anisotropic: f32, roughness: f32, sample_visible: bool) -> Microfacet {
    let r2 = roughness * roughness;
    let aspect = sqrt(max(1.0 - 0.9 * anisotropic, 0.0));
    return mf_new(DIST_GGX, pr_clamp_alpha(r2 / aspect), pr_clamp_alpha(r2 * aspect), sample_visible);
}

fn pr_compatible(m_in: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>, side: f32, reflection: bool) -> bool {
    let m = select(m_in, -m_in, side < 0.0);
    let towards_wi = select(-m, m, reflection);
    return dot(wo, m) > 0.0 && dot(wi, towards_wi) > 0.0;
}

// drjit's `mulsign`: the sign bit decides, so −0 flips.
fn pr_mulsign(v: vec3<f32>, s: f32) -> vec3<f32> {
    if ((bitcast<u32>(s) >> 31u) != 0u) {
        return -v;
    }
    return v;
}

// Burley's GTR1 of the clearcoat (`Gtr1`).
fn pr_gtr1_d(alpha: f32, m: vec3<f32>) -> f32 {
    let a2 = alpha * alpha;
    let c = m.z;
    let result = (a2 - 1.0) / (PI * log(a2) * (1.0 + (a2 - 1.0) * c * c));
    if (result * c > 1e-20) {
        return result;
    }
    return 0.0;
}

fn pr_gtr1_pdf(alpha: f32, m: vec3<f32>) -> f32 {
    if (m.z < 0.0) {
        return 0.0;
    }
    return m.z * pr_gtr1_d(alpha, m);
}

fn pr_gtr1_sample(alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let phi = TAU * u.x;
    let sin_phi = sin(phi);
    let cos_phi = cos(phi);
    let a2 = alpha * alpha;
    let cos2 = (1.0 - pow(a2, 1.0 - u.y)) / (1.0 - a2);
    let sin_theta = sqrt(max(1.0 - cos2, 0.0));
    let cos_theta = sqrt(max(cos2, 0.0));
    return vec3<f32>(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta);
}

fn pr_clearcoat_g1(v: vec3<f32>, m: vec3<f32>, alpha: f32) -> f32 {
    if (dot(v, m) * v.z <= 0.0) {
        return 0.0;
    }
    if (v.z == 1.0) {
        return 1.0;
    }
    let c2 = v.z * v.z;
    let tan2 = (1.0 - c2) / c2;
    return 2.0 / (1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

fn pr_clearcoat_alpha(clearcoat_gloss: f32) -> f32 {
    return pr_lerp(0.1, 0.001, clearcoat_gloss);
}

fn pr_disney_diffuse(roughness: f32, flatness: f32, cos_o: f32, cos_i: f32, cos_d: f32) -> f32 {
    let f_o = pr_schlick_weight(cos_o);
    let f_i = pr_schlick_weight(cos_i);
    let f_diff = (1.0 - 0.5 * f_i) * (1.0 - 0.5 * f_o);
    let rr = 2.0 * roughness * cos_d * cos_d;
    let f_retro = rr * (f_o + f_i + f_o * f_i * (rr - 1.0));
    let lambert_retro = f_diff + f_retro;
    if (flatness == 0.0) {
        return lambert_retro;
    }
    let fss90 = rr / 2.0;
    let fss = pr_lerp(1.0, fss90, f_o) * pr_lerp(1.0, fss90, f_i);
    let f_ss = 1.25 * (fss * (1.0 / (cos_o + cos_i) - 0.5) + 0.5);
    return pr_lerp(lambert_retro, f_ss, flatness);
}

fn pr_sheen_colour(base_color: vec3<f32>, sheen_tint: f32) -> vec3<f32> {
    if (sheen_tint == 0.0) {
        return vec3<f32>(1.0);
    }
    return pr_lerp3(vec3<f32>(1.0), pr_tint_colour(base_color), sheen_tint);
}

fn pr_finite_or_zero(c: vec3<f32>) -> vec3<f32> {
    if (is_finite3(c)) {
        return c;
    }
    return vec3<f32>(0.0);
}

fn pr_density(p: f32) -> f32 {
    if (pr_is_finite(p) && p > 0.0) {
        return p;
    }
    return 0.0;
}

// Four lobe rates made a distribution (zero where they do not sum to a finite non-zero).
fn pr_normalize_probabilities(p: vec4<f32>) -> vec4<f32> {
    let total = p.x + p.y + p.z + p.w;
    if (pr_is_finite(total) && total != 0.0) {
        return p / total;
    }
    return vec4<f32>(0.0);
}

// ---------------------------------------------------------------------------------------
// principled (`Principled`).

struct Principled {
    base_color: vec3<f32>,
    roughness: f32,
    anisotropic: f32,
    metallic: f32,
    spec_trans: f32,
    eta: f32,
    spec_tint: f32,
    sheen: f32,
    sheen_tint: f32,
    flatness: f32,
    clearcoat: f32,
    clearcoat_gloss: f32,
    sample_visible: bool,
}

fn principled_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let i = push_leaf(FAMILY_PRINCIPLED, weight, frame, tilt);
    if (i == NONE) {
        return;
    }
    let at = res_surface.tex;
    let spec_trans = param_float(record + PRINCIPLED_SPEC_TRANS, at);
    let has_spec_trans = param_is_textured(record + PRINCIPLED_SPEC_TRANS) || spec_trans != 0.0;
    // `with_eta`: with transmission an index of exactly 1 (which cannot transmit) is 1.001.
    var eta = param_float(record + PRINCIPLED_ETA, at);
    if (has_spec_trans && eta == 1.0) {
        eta = 1.001;
    }
    let sample_visible = select(0.0, 1.0, word_u32(physical[record].y) != 0u);
    leaves[i].w[0] = vec4<f32>(param_color(record + PRINCIPLED_BASE_COLOR, at), param_float(record + PRINCIPLED_ROUGHNESS, at));
    leaves[i].w[1] = vec4<f32>(param_float(record + PRINCIPLED_ANISOTROPIC, at), param_float(record + PRINCIPLED_METALLIC, at), spec_trans, eta);
    leaves[i].w[2] = vec4<f32>(param_float(record + PRINCIPLED_SPEC_TINT, at), param_float(record + PRINCIPLED_SHEEN, at), param_float(record + PRINCIPLED_SHEEN_TINT, at), param_float(record + PRINCIPLED_FLATNESS, at));
    leaves[i].w[3] = vec4<f32>(param_float(record + PRINCIPLED_CLEARCOAT, at), param_float(record + PRINCIPLED_CLEARCOAT_GLOSS, at), sample_visible, 0.0);
}

fn principled_leaf(i: u32) -> Principled {
    let w0 = leaves[i].w[0];
    let w1 = leaves[i].w[1];
    let w2 = leaves[i].w[2];
    let w3 = leaves[i].w[3];
    return Principled(w0.xyz, w0.w, w1.x, w1.y, w1.z, w1.w, w2.x, w2.y, w2.z, w2.w, w3.x, w3.y, w3.z != 0.0);
}

// (brdf, bsdf): the weights of the opaque base and of the transmissive part.
fn pr_weights(p: Principled) -> vec2<f32> {
    let dielectric = 1.0 - p.metallic;
    return vec2<f32>(dielectric * (1.0 - p.spec_trans), dielectric * p.spec_trans);
}

// (diffuse, clearcoat, specular transmission, specular reflection).
fn pr_lobe_probabilities(p: Principled, front: bool, f: f32) -> vec4<f32> {
    let w = pr_weights(p);
    let brdf = w.x;
    let bsdf = w.y;
    var q: vec4<f32>;
    if (front) {
        let spec = PR_MAIN_SPECULAR_RATE;
        q = vec4<f32>(
            brdf * PR_DIFFUSE_RATE,
            0.25 * p.clearcoat * PR_CLEARCOAT_RATE,
            spec * bsdf * (1.0 - f),
            spec * (1.0 - bsdf * (1.0 - f)),
        );
    } else {
        q = vec4<f32>(0.0, 0.0, 1.0 - f, f);
    }
    return pr_normalize_probabilities(q);
}

fn pr_principled_fresnel(p: Principled, f_dielectric: f32, cos_oh: f32, front: bool) -> vec3<f32> {
    let bsdf = pr_weights(p).y;
    if (!front) {
        return vec3<f32>(bsdf * f_dielectric);
    }
    let eta_it = select(1.0 / p.eta, p.eta, cos_oh >= 0.0);
    var f = vec3<f32>(0.0);
    if (p.metallic != 0.0) {
        f += pr_schlick3(p.base_color, cos_oh, p.eta) * p.metallic;
    }
    if (p.spec_tint != 0.0) {
        let r0 = pr_tint_colour(p.base_color) * pr_schlick_r0(eta_it);
        f += pr_schlick3(r0, cos_oh, p.eta) * ((1.0 - p.metallic) * p.spec_tint);
    }
    return f + vec3<f32>((1.0 - p.metallic) * (1.0 - p.spec_tint) * f_dielectric);
}

fn pr_half_vector(p: Principled, wo: vec3<f32>, wi: vec3<f32>, is_reflect: bool) -> vec3<f32> {
    let eta_path = select(1.0 / p.eta, p.eta, wo.z > 0.0);
    let h = pr_normalized(wo + wi * select(eta_path, 1.0, is_reflect));
    return pr_mulsign(h, h.z);
}

fn pr_eval_unchecked(p: Principled, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    let cos_o = wo.z;
    let cos_i = wi.z;
    let is_reflect = cos_o * cos_i > 0.0;
    let is_refract = cos_o * cos_i < 0.0;
    if (!(is_reflect || is_refract)) {
        return vec3<f32>(0.0);
    }
    let w = pr_weights(p);
    let brdf = w.x;
    let bsdf = w.y;
    let front = cos_o > 0.0;
    let eta_path = select(1.0 / p.eta, p.eta, front);
    let wh = pr_half_vector(p, wo, wi, is_reflect);
    let cos_oh = dot(wo, wh);
    let cos_ih = dot(wi, wh);
    let f_dielectric = fresnel_full(cos_oh, p.eta).x;
    let spec = pr_ggx(p.anisotropic, p.roughness, p.sample_visible);

    var value = vec3<f32>(0.0);
    if (is_reflect && pr_compatible(wh, wo, wi, cos_o, true)) {
        if (f_dielectric > 0.0) {
            let f = pr_principled_fresnel(p, f_dielectric, cos_oh, front);
            let dg = mf_d(spec, wh) * mf_g(spec, wo, wi, wh);
            value += f * (dg / (4.0 * abs(cos_o)));
        }
        if (p.clearcoat > 0.0 && front) {
            let fcc = pr_schlick(0.04, cos_oh, p.eta);
            let dcc = pr_gtr1_d(pr_clearcoat_alpha(p.clearcoat_gloss), wh);
            let gcc = pr_clearcoat_g1(wo, wh, PR_CLEARCOAT_G_ALPHA) * pr_clearcoat_g1(wi, wh, PR_CLEARCOAT_G_ALPHA);
            // Mitsuba's clearcoat has no 1/(4 cos θo cos θi): it is f · cos θi as written.
            value += vec3<f32>(0.25 * p.clearcoat * fcc * dcc * gcc * abs(cos_i));
        }
    }
    if (is_refract && bsdf > 0.0 && f_dielectric < 1.0 && pr_compatible(wh, wo, wi, cos_o, false)) {
        let dg = mf_d(spec, wh) * mf_g(spec, wo, wi, wh);
        let denom = cos_oh + eta_path * cos_ih;
        let t = abs((1.0 - f_dielectric) * dg * cos_oh * cos_ih / (cos_o * denom * denom));
        value += sqrt(p.base_color) * (bsdf * t);
    }
    if (is_reflect && front && brdf > 0.0) {
        let cos_d = dot(wh, wi);
        let diffuse = pr_disney_diffuse(p.roughness, p.flatness, abs(cos_o), abs(cos_i), cos_d);
        value += p.base_color * (brdf * abs(cos_i) * FRAC_1_PI * diffuse);
        if (p.sheen > 0.0 && 1.0 - p.metallic > 0.0) {
            let fd = pr_schlick_weight(abs(cos_d));
            value += pr_sheen_colour(p.base_color, p.sheen_tint) * (p.sheen * (1.0 - p.metallic) * fd * abs(cos_i));
        }
    }
    return value;
}

fn pr_pdf_unchecked(p: Principled, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    let cos_o = wo.z;
    let cos_i = wi.z;
    let front = cos_o > 0.0;
    let bsdf = pr_weights(p).y;
    let is_reflect = cos_o * cos_i > 0.0;
    let is_refract = cos_o * cos_i < 0.0;
    // From below only the transmissive part scatters (NaN weights count as none).
    let transmits = bsdf > 0.0;
    if (!(is_reflect || is_refract) || (!front && !transmits)) {
        return 0.0;
    }
    let eta_path = select(1.0 / p.eta, p.eta, front);
    let wh = pr_half_vector(p, wo, wi, is_reflect);
    let cos_oh = dot(wo, wh);
    let cos_ih = dot(wi, wh);
    let f_dielectric = fresnel_full(cos_oh, p.eta).x;
    let probs = pr_lobe_probabilities(p, front, f_dielectric);
    let p_diffuse = probs.x;
    let p_clearcoat = probs.y;
    let p_trans = probs.z;
    let p_reflect = probs.w;
    var dwh_dwi: f32;
    if (is_reflect) {
        dwh_dwi = abs(1.0 / (4.0 * cos_ih));
    } else {
        let denom = cos_oh + eta_path * cos_ih;
        dwh_dwi = abs(eta_path * eta_path * cos_ih / (denom * denom));
    }
    let spec = pr_ggx(p.anisotropic, p.roughness, p.sample_visible);
    let wo_up = pr_mulsign(wo, cos_o);

    var pdf = 0.0;
    if (is_reflect) {
        if (pr_compatible(wh, wo, wi, cos_o, true)) {
            pdf += p_reflect * mf_pdf(spec, wo_up, wh) * dwh_dwi;
            if (p_clearcoat > 0.0) {
                pdf += p_clearcoat * pr_gtr1_pdf(pr_clearcoat_alpha(p.clearcoat_gloss), wh) * dwh_dwi;
            }
        }
        if (p_diffuse > 0.0) {
            pdf += p_diffuse * cos_i * FRAC_1_PI;
        }
    } else if (p_trans > 0.0 && pr_compatible(wh, wo, wi, cos_o, false)) {
        pdf += p_trans * mf_pdf(spec, wo_up, wh) * dwh_dwi;
    }
    return pdf;
}

fn principled_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let p = principled_leaf(i);
    return vec4<f32>(pr_finite_or_zero(pr_eval_unchecked(p, wo, wi)), pr_density(pr_pdf_unchecked(p, wo, wi)));
}

fn principled_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    let p = principled_leaf(i);
    let cos_o = wo.z;
    if (cos_o == 0.0 || !pr_is_finite(cos_o)) {
        return no_sample();
    }
    let front = cos_o > 0.0;
    let transmits = pr_weights(p).y > 0.0;
    if (!front && !transmits) {
        return no_sample();
    }
    let spec = pr_ggx(p.anisotropic, p.roughness, p.sample_visible);
    // One micro-normal serves both the lobe choice (through its Fresnel) and the specular
    // directions, as in Mitsuba.
    let m = mf_sample(spec, pr_mulsign(wo, cos_o), u).xyz;
    let fr = fresnel_full(dot(wo, m), p.eta);
    let probs = pr_lobe_probabilities(p, front, fr.x);
    let p_diffuse = probs.x;
    let p_clearcoat = probs.y;
    let p_trans = probs.z;

    var eta = 1.0;
    var wi: vec3<f32>;
    if (u_lobe < p_diffuse) {
        wi = sample_cosine_hemisphere(u);
        if (cos_o * wi.z <= 0.0) {
            return no_sample();
        }
    } else if (u_lobe < p_diffuse + p_clearcoat) {
        let m_cc = pr_gtr1_sample(pr_clearcoat_alpha(p.clearcoat_gloss), u);
        wi = reflect_about(wo, m_cc);
        if (!(cos_o * wi.z > 0.0 && pr_compatible(m_cc, wo, wi, cos_o, true))) {
            return no_sample();
        }
    } else if (u_lobe < p_diffuse + p_clearcoat + p_trans) {
        wi = refract_about(wo, m, fr.y, fr.w);
        if (!(cos_o * wi.z < 0.0 && pr_compatible(m, wo, wi, cos_o, false))) {
            return no_sample();
        }
        eta = fr.z;
    } else {
        wi = reflect_about(wo, m);
        if (!(cos_o * wi.z > 0.0 && pr_compatible(m, wo, wi, cos_o, true))) {
            return no_sample();
        }
    }
    let pdf = pr_density(pr_pdf_unchecked(p, wo, wi));
    if (pdf <= 0.0) {
        return no_sample();
    }
    let value = pr_finite_or_zero(pr_eval_unchecked(p, wo, wi));
    return PhysSample(wi, pr_finite_or_zero(pr_div(value, pdf)), pdf, false, eta, true);
}

fn principled_albedo(i: u32) -> vec3<f32> {
    return clamp(leaves[i].w[0].xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn principled_has_non_delta(i: u32) -> bool {
    return true;
}

// ---------------------------------------------------------------------------------------
// principledthin (`PrincipledThin`).

struct PrincipledThin {
    base_color: vec3<f32>,
    roughness: f32,
    anisotropic: f32,
    spec_trans: f32,
    diff_trans: f32,
    eta: f32,
    spec_tint: f32,
    sheen: f32,
    sheen_tint: f32,
    flatness: f32,
    sample_visible: bool,
}

fn principled_thin_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
    let i = push_leaf(FAMILY_PRINCIPLED_THIN, weight, frame, tilt);
    if (i == NONE) {
        return;
    }
    let at = res_surface.tex;
    let sample_visible = select(0.0, 1.0, word_u32(physical[record].y) != 0u);
    leaves[i].w[0] = vec4<f32>(param_color(record + PRINCIPLED_BASE_COLOR, at), param_float(record + PRINCIPLED_ROUGHNESS, at));
    leaves[i].w[1] = vec4<f32>(param_float(record + PRINCIPLED_ANISOTROPIC, at), param_float(record + PRINCIPLED_SPEC_TRANS, at), param_float(record + PRINCIPLED_DIFF_TRANS, at), param_float(record + PRINCIPLED_ETA, at));
    leaves[i].w[2] = vec4<f32>(param_float(record + PRINCIPLED_SPEC_TINT, at), param_float(record + PRINCIPLED_SHEEN, at), param_float(record + PRINCIPLED_SHEEN_TINT, at), param_float(record + PRINCIPLED_FLATNESS, at));
    leaves[i].w[3] = vec4<f32>(sample_visible, 0.0, 0.0, 0.0);
}

fn principled_thin_leaf(i: u32) -> PrincipledThin {
    let w0 = leaves[i].w[0];
    let w1 = leaves[i].w[1];
    let w2 = leaves[i].w[2];
    return PrincipledThin(w0.xyz, w0.w, w1.x, w1.y, w1.z, w1.w, w2.x, w2.y, w2.z, w2.w, leaves[i].w[3].x != 0.0);
}

// (specular reflection, specular transmission, diffuse reflection, diffuse transmission).
fn prt_lobe_probabilities(p: PrincipledThin) -> vec4<f32> {
    let st = p.spec_trans;
    // diff_trans on Mitsuba's internal [0, 1] scale.
    let dt = p.diff_trans / 2.0;
    return pr_normalize_probabilities(vec4<f32>(
        st * PR_THIN_SPEC_R_RATE / 2.0,
        st * PR_THIN_SPEC_T_RATE / 2.0,
        PR_THIN_DIFF_R_RATE * (1.0 - st) * (1.0 - dt),
        PR_THIN_DIFF_T_RATE * (1.0 - st) * dt,
    ));
}

fn prt_reflection_distribution(p: PrincipledThin) -> Microfacet {
    return pr_ggx(p.anisotropic, p.roughness, p.sample_visible);
}

// The transmission's roughness is scaled by the index (Burley 2015, figure 15).
fn prt_transmission_distribution(p: PrincipledThin) -> Microfacet {
    let scaled = (0.65 * p.eta - 0.35) * p.roughness;
    return pr_ggx(p.anisotropic, scaled, p.sample_visible);
}

// `thin_frame`: ωo turned above (v), ωi turned with it (l), and the half vector of v and l
// mirrored up.
struct ThinFrame {
    v: vec3<f32>,
    l: vec3<f32>,
    wh: vec3<f32>,
}

fn prt_thin_frame(wo: vec3<f32>, wi: vec3<f32>) -> ThinFrame {
    let v = pr_mulsign(wo, wo.z);
    let l = pr_mulsign(wi, wo.z);
    let l_up = vec3<f32>(l.x, l.y, abs(l.z));
    return ThinFrame(v, l, pr_normalized(v + l_up));
}

fn prt_grazing(wo: vec3<f32>) -> bool {
    return wo.z == 0.0 || !pr_is_finite(wo.z);
}

fn prt_eval_unchecked(p: PrincipledThin, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if (prt_grazing(wo)) {
        return vec3<f32>(0.0);
    }
    let tf = prt_thin_frame(wo, wi);
    let v = tf.v;
    let l = tf.l;
    let wh = tf.wh;
    let st = p.spec_trans;
    let dt = p.diff_trans / 2.0;
    let cos_v = v.z;
    let cos_l = l.z;
    let is_reflect = cos_l > 0.0;
    let is_refract = cos_l < 0.0;
    var value = vec3<f32>(0.0);
    if (st > 0.0) {
        let cos_vh = dot(v, wh);
        let f_dielectric = fresnel_full(cos_vh, p.eta).x;
        if (is_reflect && pr_compatible(wh, v, l, cos_v, true)) {
            var f_schlick = vec3<f32>(0.0);
            if (p.spec_tint != 0.0) {
                let r0 = pr_tint_colour(p.base_color) * pr_schlick_r0(p.eta);
                f_schlick = pr_schlick3(r0, cos_vh, p.eta);
            }
            let f = pr_lerp3(vec3<f32>(f_dielectric), f_schlick, p.spec_tint);
            let spec = prt_reflection_distribution(p);
            let dg = mf_d(spec, wh) * mf_g(spec, v, l, wh);
            value += f * (st * dg / (4.0 * cos_v));
        }
        if (is_refract && pr_compatible(wh, v, l, cos_v, false)) {
            let spec = prt_transmission_distribution(p);
            let dg = mf_d(spec, wh) * mf_g(spec, v, l, wh);
            value += p.base_color * (st * (1.0 - f_dielectric) * dg / (4.0 * cos_v));
        }
    }
    if (is_reflect && st < 1.0 && dt < 1.0) {
        let cos_d = dot(wh, l);
        let diffuse = pr_disney_diffuse(p.roughness, p.flatness, cos_v, cos_l, cos_d);
        value += p.base_color * ((1.0 - st) * (1.0 - dt) * cos_l * FRAC_1_PI * diffuse);
        if (p.sheen > 0.0) {
            let fd = pr_schlick_weight(abs(cos_d));
            value += pr_sheen_colour(p.base_color, p.sheen_tint) * (p.sheen * (1.0 - st) * (1.0 - dt) * fd * cos_l);
        }
    }
    if (is_refract && st < 1.0 && dt > 0.0) {
        value += p.base_color * ((1.0 - st) * dt * FRAC_1_PI * -cos_l);
    }
    return value;
}

fn prt_pdf_unchecked(p: PrincipledThin, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (prt_grazing(wo)) {
        return 0.0;
    }
    let tf = prt_thin_frame(wo, wi);
    let v = tf.v;
    let l = tf.l;
    let wh = tf.wh;
    let probs = prt_lobe_probabilities(p);
    let cos_l = l.z;
    let is_reflect = cos_l > 0.0;
    let is_refract = cos_l < 0.0;
    var pdf = 0.0;
    if (probs.x > 0.0 || probs.y > 0.0) {
        // Both specular lobes reflect about h; the transmission then mirrors through the
        // sheet, which keeps the Jacobian of reflection.
        let l_up = vec3<f32>(l.x, l.y, abs(l.z));
        let dwh_dwi = abs(1.0 / (4.0 * dot(l_up, wh)));
        if (is_reflect && pr_compatible(wh, v, l, v.z, true)) {
            pdf += probs.x * mf_pdf(prt_reflection_distribution(p), v, wh) * dwh_dwi;
        }
        if (is_refract && pr_compatible(wh, v, l, v.z, false)) {
            pdf += probs.y * mf_pdf(prt_transmission_distribution(p), v, wh) * dwh_dwi;
        }
    }
    if (is_reflect) {
        pdf += probs.z * cos_l * FRAC_1_PI;
    }
    if (is_refract) {
        pdf += probs.w * -cos_l * FRAC_1_PI;
    }
    return pdf;
}

fn principled_thin_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    let p = principled_thin_leaf(i);
    return vec4<f32>(pr_finite_or_zero(prt_eval_unchecked(p, wo, wi)), pr_density(prt_pdf_unchecked(p, wo, wi)));
}

fn principled_thin_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    if (prt_grazing(wo)) {
        return no_sample();
    }
    let p = principled_thin_leaf(i);
    let v = pr_mulsign(wo, wo.z);
    let probs = prt_lobe_probabilities(p);
    var l: vec3<f32>;
    if (u_lobe < probs.x) {
        let m = mf_sample(prt_reflection_distribution(p), v, u).xyz;
        l = reflect_about(v, m);
        if (!(l.z > 0.0 && pr_compatible(m, v, l, v.z, true))) {
            return no_sample();
        }
    } else if (u_lobe < probs.x + probs.y) {
        let m = mf_sample(prt_transmission_distribution(p), v, u).xyz;
        let r = reflect_about(v, m);
        l = vec3<f32>(r.x, r.y, -r.z);
        if (!(l.z < 0.0 && pr_compatible(m, v, l, v.z, false))) {
            return no_sample();
        }
    } else if (u_lobe < probs.x + probs.y + probs.z) {
        l = sample_cosine_hemisphere(u);
    } else if (probs.w > 0.0) {
        l = -sample_cosine_hemisphere(u);
    } else {
        return no_sample();
    }
    let wi = pr_mulsign(l, wo.z);
    let pdf = pr_density(prt_pdf_unchecked(p, wo, wi));
    if (pdf <= 0.0) {
        return no_sample();
    }
    let value = pr_finite_or_zero(prt_eval_unchecked(p, wo, wi));
    return PhysSample(wi, pr_finite_or_zero(pr_div(value, pdf)), pdf, false, 1.0, true);
}

fn principled_thin_albedo(i: u32) -> vec3<f32> {
    return clamp(leaves[i].w[0].xyz, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn principled_thin_has_non_delta(i: u32) -> bool {
    return true;
}
