// The dielectric, thindielectric and roughdielectric (dielectric.rs) on the GPU: not yet ported; these stand-ins scatter nothing.

fn dielectric_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
}

fn thin_dielectric_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
}

fn dielectric_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn dielectric_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn dielectric_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn dielectric_has_non_delta(i: u32) -> bool {
    return false;
}

fn thin_dielectric_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn thin_dielectric_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn thin_dielectric_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn thin_dielectric_has_non_delta(i: u32) -> bool {
    return false;
}

fn rough_dielectric_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn rough_dielectric_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn rough_dielectric_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn rough_dielectric_has_non_delta(i: u32) -> bool {
    return false;
}
