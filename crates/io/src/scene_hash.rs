//! A name for a loaded scene by its content: what farm parts and images carry as metadata so
//! that parts of different scenes are never merged.

use std::fmt::Write as _;

use glint_render::{Background, Image, SceneParts, Shape, Vec3};
use xxhash_rust::xxh3::Xxh3;

/// A hex XXH3-128 of the loaded scene (after `--background`): every value the renderer is
/// given, so the content of the scene file and of every asset it loaded. The small parts
/// (camera, materials, lights, instances) go in as their `Debug` text, the bulky ones (mesh
/// triangles, texture and environment-map texels) as the bits of their numbers: formatting
/// millions of floats would take seconds. It names the scene by content, not by path: moving
/// the folder keeps it, editing the file or any asset changes it.
pub fn scene_hash(parts: &SceneParts) -> String {
    struct Hasher(Xxh3);
    impl std::fmt::Write for Hasher {
        fn write_str(&mut self, text: &str) -> std::fmt::Result {
            self.0.update(text.as_bytes());
            Ok(())
        }
    }
    impl Hasher {
        fn text(&mut self, label: &str, value: &dyn std::fmt::Debug) {
            // Writing to a hasher cannot fail.
            let _ = write!(self, "{label}={value:?};");
        }
        fn floats(&mut self, values: impl IntoIterator<Item = f32>) {
            for value in values {
                self.0.update(&value.to_bits().to_le_bytes());
            }
        }
        fn vec3(&mut self, v: Vec3) {
            self.floats([v.x, v.y, v.z]);
        }
        fn image(&mut self, image: &Image) {
            self.text("image", &(image.width, image.height, image.texels.len()));
            // One update for the whole image rather than one a texel.
            let mut bytes = Vec::with_capacity(image.texels.len() * 12);
            for texel in &image.texels {
                bytes.extend_from_slice(&texel.x.to_le_bytes());
                bytes.extend_from_slice(&texel.y.to_le_bytes());
                bytes.extend_from_slice(&texel.z.to_le_bytes());
            }
            self.0.update(&bytes);
        }
    }
    let mut hasher = Hasher(Xxh3::new());
    hasher.text("camera", &parts.camera);
    hasher.text("materials", &parts.materials);
    hasher.text("lights", &parts.lights);
    hasher.text("instances", &parts.instances);
    hasher.text("textures", &parts.textures.len());
    for image in &parts.textures {
        hasher.image(image);
    }
    match &parts.background {
        Background::Color(color) => hasher.text("background", color),
        Background::CubeMap(map) => {
            hasher.text("background", &"cube map");
            for face in &map.faces {
                hasher.image(face);
            }
        }
    }
    for geometry in &parts.geometries {
        hasher.text("geometry", &(&geometry.materials, geometry.shapes.len()));
        for shape in &geometry.shapes {
            match *shape {
                Shape::Sphere { center, radius } => {
                    hasher.0.update(&[0]);
                    hasher.vec3(center);
                    hasher.floats([radius]);
                }
                Shape::Triangle { vertices } => {
                    hasher.0.update(&[1]);
                    vertices.into_iter().for_each(|v| hasher.vec3(v));
                }
                Shape::Box { min, max } => {
                    hasher.0.update(&[2]);
                    hasher.vec3(min);
                    hasher.vec3(max);
                }
            }
        }
    }
    format!("{:032x}", hasher.0.digest128())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_render::{Camera, Color, GeometryDesc, Instance, Material, Projection};

    fn parts(radius: f32, texel: f32) -> SceneParts {
        SceneParts {
            camera: Camera::new(Projection::Perspective, Vec3::Z, -Vec3::Z, 1.0, 1.0),
            materials: vec![Material::Lambertian {
                diffuse: Color::splat(0.5).into(),
            }],
            textures: vec![Image {
                width: 1,
                height: 1,
                texels: vec![Color::splat(texel)],
            }],
            lights: vec![],
            background: Background::Color(Color::ZERO),
            geometries: vec![GeometryDesc {
                shapes: vec![Shape::Sphere {
                    center: Vec3::ZERO,
                    radius,
                }],
                materials: vec![0],
            }],
            instances: vec![Instance {
                geometry: 0,
                transform: None,
                material: None,
                casts_shadow: true,
            }],
        }
    }

    #[test]
    fn the_hash_follows_every_value() {
        let base = scene_hash(&parts(1.0, 0.5));
        assert_eq!(base.len(), 32);
        assert_eq!(base, scene_hash(&parts(1.0, 0.5)));
        assert_ne!(base, scene_hash(&parts(1.0000001, 0.5)), "geometry");
        assert_ne!(base, scene_hash(&parts(1.0, 0.5000001)), "a texel");
        let mut other = parts(1.0, 0.5);
        other.background = Background::Color(Color::splat(0.2));
        assert_ne!(base, scene_hash(&other), "background");
    }
}
