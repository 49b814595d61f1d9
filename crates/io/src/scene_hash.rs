//! A name for a loaded scene by its content: what farm parts and images carry as metadata so
//! that parts of different scenes are never merged.

use std::fmt::Write as _;

use glint_render::{Background, Image, Medium, SceneParts, Shape, Volume};
use xxhash_rust::xxh3::Xxh3;

/// A hex XXH3-128 of the loaded scene (after `--background`): every value the renderer is
/// given, so the content of the scene file and of every asset it loaded. The small parts
/// (camera, materials, lights, instances) go in as their `Debug` text, the bulky ones (mesh
/// triangles, texture and environment-map texels) as the bits of their numbers: formatting
/// millions of floats would take seconds. It names the scene by content, not by path: moving
/// the folder keeps it, editing the file or any asset changes it.
pub fn scene_hash(parts: &SceneParts) -> String {
    /// XXH3 over the bytes given, gathered in a buffer first: a digest depends on the bytes
    /// alone, not on how they were split among `update` calls. With an `update` for each
    /// float and each token of the `Debug` text, a mesh of a million triangles took 80 ms to
    /// hash (serial, at any thread count); buffered, with each shape's bytes gathered and
    /// the material ids written without `Debug`, 25 ms, the bytes unchanged
    /// (`the_hash_is_what_earlier_builds_wrote`).
    struct Hasher {
        xxh3: Xxh3,
        buffer: Vec<u8>,
    }
    impl std::fmt::Write for Hasher {
        fn write_str(&mut self, text: &str) -> std::fmt::Result {
            self.bytes(text.as_bytes());
            Ok(())
        }
    }
    impl Hasher {
        const BUFFER: usize = 1 << 16;
        fn bytes(&mut self, bytes: &[u8]) {
            if bytes.len() >= Self::BUFFER {
                // Long runs (an image's texels) go to XXH3 as they are.
                self.flush();
                self.xxh3.update(bytes);
                return;
            }
            self.buffer.extend_from_slice(bytes);
            if self.buffer.len() >= Self::BUFFER {
                self.flush();
            }
        }
        fn flush(&mut self) {
            self.xxh3.update(&self.buffer);
            self.buffer.clear();
        }
        fn text(&mut self, label: &str, value: &dyn std::fmt::Debug) {
            // Writing to a hasher cannot fail.
            let _ = write!(self, "{label}={value:?};");
        }
        /// `text(label, &(ids, count))` without `Debug`'s machinery (about 260 instructions an
        /// id; a mesh has one a triangle): the same bytes, `label=([a, b, c], count);`, the
        /// integers in decimal.
        fn ids(&mut self, label: &str, ids: &[u32], count: usize) {
            let mut decimal = itoa::Buffer::new();
            self.bytes(label.as_bytes());
            self.bytes(b"=([");
            for (i, &id) in ids.iter().enumerate() {
                if i > 0 {
                    self.bytes(b", ");
                }
                self.bytes(decimal.format(id).as_bytes());
            }
            self.bytes(b"], ");
            self.bytes(decimal.format(count).as_bytes());
            self.bytes(b");");
        }
        /// A shape: its kind's tag byte, then its floats' bits, gathered first (a mesh's
        /// triangles are most of the bytes hashed).
        fn shape(&mut self, tag: u8, floats: &[f32]) {
            let mut record = [0u8; 1 + 4 * 9];
            record[0] = tag;
            for (bytes, value) in record[1..].chunks_exact_mut(4).zip(floats) {
                bytes.copy_from_slice(&value.to_bits().to_le_bytes());
            }
            self.bytes(&record[..1 + 4 * floats.len()]);
        }
        /// An image's size, then each texel's x, y and z bits (little-endian): on a
        /// little-endian machine the texels' own bytes, hashed where they lie (gathered 256
        /// texels at a time, as big-endian machines still do, the course's 6 M-texel reef cube
        /// map took 16 ms, serial at any thread count).
        /// Floats' bits, little-endian, as `image` writes texels.
        fn floats(&mut self, values: &[f32]) {
            if cfg!(target_endian = "little") {
                self.bytes(bytemuck::cast_slice(values));
                return;
            }
            for chunk in values.chunks(1024) {
                let bytes: Vec<u8> = chunk
                    .iter()
                    .flat_map(|v| v.to_bits().to_le_bytes())
                    .collect();
                self.bytes(&bytes);
            }
        }
        /// A volume: a constant as its `Debug` text, a grid's size and placement so, and its
        /// samples as bits.
        fn volume(&mut self, volume: &Volume) {
            match volume {
                Volume::Constant { .. } => self.text("volume", volume),
                Volume::Grid { grid, to_world, .. } => {
                    self.text("grid", &(grid.size, grid.channels, to_world));
                    self.floats(&grid.data);
                }
            }
        }
        fn image(&mut self, image: &Image) {
            self.text("image", &(image.width, image.height, image.texels.len()));
            if cfg!(target_endian = "little") {
                self.bytes(bytemuck::cast_slice(&image.texels));
                return;
            }
            const TEXELS: usize = 256;
            let mut record = [0u8; 12 * TEXELS];
            for texels in image.texels.chunks(TEXELS) {
                for (bytes, texel) in record.chunks_exact_mut(12).zip(texels) {
                    bytes[..4].copy_from_slice(&texel.x.to_bits().to_le_bytes());
                    bytes[4..8].copy_from_slice(&texel.y.to_bits().to_le_bytes());
                    bytes[8..].copy_from_slice(&texel.z.to_bits().to_le_bytes());
                }
                self.bytes(&record[..12 * texels.len()]);
            }
        }
    }
    let mut hasher = Hasher {
        xxh3: Xxh3::new(),
        buffer: Vec::with_capacity(Hasher::BUFFER + 64),
    };
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
        Background::Environment {
            image,
            scale,
            to_world,
        } => {
            hasher.text("background", &("envmap", scale, to_world));
            hasher.image(image);
        }
    }
    // Course scenes have no physical parts, and keep the digests earlier builds wrote.
    if parts.physical != glint_render::PhysicalParts::default() {
        let physical = &parts.physical;
        hasher.text("bsdfs", &physical.bsdfs);
        hasher.text("textures", &physical.textures);
        hasher.text("defaults", &physical.defaults);
        // Mesh attributes hold floats per triangle: their bits, not their Debug text (which
        // took most of a second on the suite's 16k-triangle sphere).
        for (geometry, attributes) in physical.attributes.iter().enumerate() {
            let Some(a) = attributes else { continue };
            hasher.text("attributes", &(geometry, a.mitsuba_sphere_uv));
            let vec3s = |v: &[glint_render::Vec3; 3]| {
                [
                    v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z,
                ]
            };
            for (tag, list) in [(10, &a.normals), (11, &a.vertex_colors)] {
                hasher.text("count", &list.as_ref().map(Vec::len));
                for corners in list.iter().flatten() {
                    hasher.shape(tag, &vec3s(corners));
                }
            }
            hasher.text("count", &a.uvs.as_ref().map(Vec::len));
            for [a0, a1, a2] in a.uvs.iter().flatten() {
                hasher.shape(12, &[a0.0, a0.1, a1.0, a1.1, a2.0, a2.1]);
            }
            hasher.text("count", &a.face_colors.as_ref().map(Vec::len));
            for c in a.face_colors.iter().flatten() {
                hasher.shape(13, &[c.x, c.y, c.z]);
            }
        }
        // Only scenes with media hash them, so that the digests of the others stand.
        if !physical.media.is_empty()
            || !physical.boundaries.is_empty()
            || physical.camera_medium.is_some()
        {
            for medium in &physical.media {
                match medium {
                    Medium::Homogeneous { .. } => hasher.text("medium", medium),
                    Medium::Heterogeneous {
                        sigma_t,
                        albedo,
                        scale,
                        phase,
                        sample_emitters,
                    } => {
                        hasher.text("medium", &(scale, phase, sample_emitters));
                        hasher.volume(sigma_t);
                        hasher.volume(albedo);
                    }
                }
            }
            hasher.text("boundaries", &physical.boundaries);
            hasher.text("camera_medium", &physical.camera_medium);
        }
    }
    for geometry in &parts.geometries {
        hasher.ids("geometry", &geometry.materials, geometry.shapes.len());
        for shape in &geometry.shapes {
            match *shape {
                Shape::Sphere { center, radius } => {
                    hasher.shape(0, &[center.x, center.y, center.z, radius]);
                }
                Shape::Triangle {
                    vertices: [a, b, c],
                } => {
                    hasher.shape(1, &[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z]);
                }
                Shape::Box { min, max } => {
                    hasher.shape(2, &[min.x, min.y, min.z, max.x, max.y, max.z]);
                }
            }
        }
    }
    hasher.flush();
    format!("{:032x}", hasher.xxh3.digest128())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_render::{Camera, Color, GeometryDesc, Instance, Material, Projection, Vec3};

    fn parts(radius: f32, texel: f32) -> SceneParts {
        SceneParts {
            physical: Default::default(),
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
    fn media_change_the_hash() {
        use glint_render::{Matrix4, MediumBoundary, PhaseFunction, Transform, VolumeGrid};
        let grid = |sample: f32| {
            Volume::grid(
                VolumeGrid {
                    size: [2, 1, 1],
                    channels: 1,
                    data: vec![0.5, sample],
                },
                Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
            )
        };
        let with = |sample: f32, g: f32, interior: u32, camera: Option<u32>| {
            let mut scene = parts(1.0, 0.5);
            scene.physical.media = vec![
                Medium::Homogeneous {
                    sigma_t: Color::ONE,
                    albedo: Color::splat(0.5),
                    phase: PhaseFunction::HenyeyGreenstein { g },
                    sample_emitters: true,
                },
                Medium::Heterogeneous {
                    sigma_t: grid(sample),
                    albedo: Volume::constant(
                        Color::ONE,
                        &Transform::from_matrix(&Matrix4::IDENTITY).unwrap(),
                    ),
                    scale: 2.0,
                    phase: PhaseFunction::Isotropic,
                    sample_emitters: true,
                },
            ];
            scene.physical.boundaries = vec![Some(MediumBoundary {
                interior: Some(interior),
                exterior: None,
            })];
            scene.physical.camera_medium = camera;
            scene_hash(&scene)
        };
        let base = with(1.0, 0.5, 0, None);
        assert_eq!(base, with(1.0, 0.5, 0, None));
        assert_ne!(base, with(1.0000001, 0.5, 0, None), "a grid sample");
        assert_ne!(base, with(1.0, 0.6, 0, None), "a phase function");
        assert_ne!(base, with(1.0, 0.5, 1, None), "a boundary");
        assert_ne!(base, with(1.0, 0.5, 0, Some(1)), "the camera's medium");
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

    /// Images and checkpoints carry the hash, and `glint merge` and `--resume` compare it with
    /// the scene's: the bytes hashed must not change from one build to the next. A scene of
    /// every kind of value (a texture, triangles, a sphere, a box, a long material list) hashes
    /// to the value the builds before 2026-11-26 wrote.
    #[test]
    fn the_hash_is_what_earlier_builds_wrote() {
        let mut scene = parts(1.0, 0.5);
        let shapes: Vec<Shape> = (0..5000)
            .map(|i| {
                let f = i as f32 * 0.001;
                match i % 3 {
                    0 => Shape::Triangle {
                        vertices: [Vec3::new(f, 0.0, 1.0), Vec3::X, Vec3::new(0.0, -f, 2.0)],
                    },
                    1 => Shape::Sphere {
                        center: Vec3::new(f, f, -f),
                        radius: 0.25 + f,
                    },
                    _ => Shape::Box {
                        min: Vec3::splat(-f),
                        max: Vec3::splat(f + 1.0),
                    },
                }
            })
            .collect();
        let materials = (0..shapes.len() as u32).map(|i| i * 37 % 1009).collect();
        scene.geometries.push(GeometryDesc { shapes, materials });
        scene.textures[0]
            .texels
            .extend((0..300).map(|i| Color::splat(i as f32 / 300.0)));
        scene.textures[0].width = 301;
        assert_eq!(scene_hash(&scene), "1f12682266f9b81b63ee714f2a956134");
    }

    /// Images of more texels than the hasher's buffer holds (a texture of 300 x 200 and a cube
    /// map of 80 x 80 faces, texels of every bit pattern the course's images give and a few
    /// more), to the value the builds before 2026-11-28 wrote, when every texel was copied into
    /// the buffer first.
    #[test]
    fn long_images_hash_to_what_earlier_builds_wrote() {
        let image = |width: u32, height: u32, seed: u32| {
            let texels = (0..width * height)
                .map(|i| {
                    let k = i.wrapping_mul(2_654_435_761).wrapping_add(seed);
                    Color::new(
                        (k % 256) as f32 / 255.0,
                        (k >> 8) as f32 * 1e-7,
                        if k % 7 == 0 {
                            -0.0
                        } else {
                            (k % 1000) as f32 * 0.25
                        },
                    )
                })
                .collect();
            Image {
                width,
                height,
                texels,
            }
        };
        let mut scene = parts(1.0, 0.5);
        scene.textures.push(image(300, 200, 1));
        scene.background = Background::CubeMap(Box::new(glint_render::CubeMap {
            faces: std::array::from_fn(|face| image(80, 80, 10 + face as u32)),
        }));
        assert_eq!(scene_hash(&scene), "96186b2de0143e33debdb38c9c6be473");
    }
}
