// The plastic and roughplastic (plastic.rs) on the GPU: not yet ported; these stand-ins scatter nothing.

fn plastic_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
}

fn plastic_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn plastic_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn plastic_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn plastic_has_non_delta(i: u32) -> bool {
    return false;
}

fn rough_plastic_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn rough_plastic_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn rough_plastic_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn rough_plastic_has_non_delta(i: u32) -> bool {
    return false;
}
