// The principled and principledthin (principled.rs) on the GPU: not yet ported; these stand-ins scatter nothing.

fn principled_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
}

fn principled_thin_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
}

fn principled_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn principled_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn principled_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn principled_has_non_delta(i: u32) -> bool {
    return false;
}

fn principled_thin_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn principled_thin_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn principled_thin_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn principled_thin_has_non_delta(i: u32) -> bool {
    return false;
}
