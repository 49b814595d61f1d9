// The glTF's metallic-roughness material (gltf.rs, surface.rs add_gltf) on the GPU: not yet ported; these stand-ins scatter nothing.

fn gltf_add(record: u32, weight: f32, frame: Frame, tilt: Tilt) {
}

fn gltf_eval_pdf(i: u32, wo: vec3<f32>, wi: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn gltf_sample(i: u32, wo: vec3<f32>, u_lobe: f32, u: vec2<f32>) -> PhysSample {
    return no_sample();
}

fn gltf_albedo(i: u32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn gltf_has_non_delta(i: u32) -> bool {
    return false;
}
