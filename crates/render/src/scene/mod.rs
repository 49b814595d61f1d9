//! The renderable scene: what the loader hands over (`SceneParts`), and the `Scene` built from
//! it: camera, materials, textures, lights and background beside the two-level acceleration
//! structure (`accel::instances`). `Scene::surface` completes any hit into shading data.

// std's clock natively; in the browser std has none (`web_time` is std's re-export elsewhere).
use web_time::{Duration, Instant};

use crate::accel::build::{BuildPhases, SplitMethod};
use crate::accel::instances::{AccelKind, AccelStats, Geometry, Hit, Instances, PreliminaryHit};
use crate::accel::wide::WalkCounts;
use crate::accel::PACKET;
use crate::camera::Camera;
use crate::geometry::Shape;
use crate::geometry::{Aabb, PrimitiveHit};
use crate::light::Light;
use crate::material::{Material, MaterialId};
use crate::math::{Color, Transform, Vec3};
use crate::ray::Ray;
use crate::texture::{CubeMap, Image, TexturePoint};

pub use crate::accel::instances::{GeometryDesc, Instance};

pub mod physical;

use physical::{PhysicalParts, PhysicalSurface};

/// What rays that leave the scene see.
#[derive(Clone, Debug, PartialEq)]
pub enum Background {
    /// A constant colour (`bgColor`).
    Color(Color),
    /// An environment cube map (`envMapPrefix`, or `envMapVertCross` cut into faces).
    CubeMap(Box<CubeMap>),
    /// Mitsuba's `envmap`: a latitude-longitude image times `scale`, turned by `to_world`
    /// (a rotation). In the map's own frame +y is up (row 0 of the image), u = 0 looks along
    /// −z and u = 1/2 along +z, as Mitsuba's `envmap` maps directions to the image
    /// (`light::envmap`).
    Environment {
        image: Box<Image>,
        scale: f32,
        to_world: Transform,
    },
}

/// Everything the loader hands the renderer: plain data, already validated.
#[derive(Clone, Debug)]
pub struct SceneParts {
    pub camera: Camera,
    pub materials: Vec<Material>,
    pub textures: Vec<Image>,
    pub lights: Vec<Light>,
    pub background: Background,
    pub geometries: Vec<GeometryDesc>,
    pub instances: Vec<Instance>,
    /// What Mitsuba scenes and glTF models add; empty for the course's.
    pub physical: PhysicalParts,
}

/// How `Scene::with_options` builds the acceleration structures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SceneOptions {
    /// How the bottom-level BVHs (one per geometry) choose their splits (`-s`); the top level
    /// over instances stays binned SAH. Any method gives the same image.
    pub split: SplitMethod,
}

/// What the bottom-level BVHs of a scene look like (`Scene::bvh_stats`): what `--stats`
/// compares split methods by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhStats {
    pub split: SplitMethod,
    /// Wall time of building every acceleration structure (both levels).
    pub build_time: Duration,
    /// Geometries with their own BVH.
    pub trees: usize,
    /// 8-wide inner nodes and leaves, over all the trees.
    pub nodes: usize,
    pub leaves: usize,
    /// Inner nodes on the longest root-to-leaf path of the deepest tree.
    pub depth: usize,
    /// Expected node visits plus block (or shape) tests for a ray meeting a tree's root box,
    /// by the surface area heuristic; averaged over the trees weighted by their primitives.
    pub sah_cost: f64,
    /// The primitives of the wide tree with the most, and how long each phase of its build
    /// took; `None` without wide trees.
    pub largest: Option<(usize, BuildPhases)>,
}

/// A scene ready to trace. Built once from `SceneParts`; immutable and shared by all threads.
pub struct Scene {
    pub camera: Camera,
    pub materials: Vec<Material>,
    pub textures: Vec<Image>,
    pub lights: Vec<Light>,
    pub background: Background,
    /// BSDF trees, textures and the scene's render defaults (mesh attributes are moved into
    /// the acceleration structure's geometries).
    pub physical: PhysicalParts,
    pub(crate) accel: Instances,
    split: SplitMethod,
    build_time: Duration,
}

/// Shading data at the closest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    pub point: Vec3,
    /// Unit geometric normal in world space: outward for spheres and boxes, by the winding for
    /// triangles. Not flipped towards the viewer; integrators decide.
    pub normal: Vec3,
    pub uv: (f32, f32),
    pub material: MaterialId,
}

/// What `Scene::surface` computes beyond the point, the normal and the material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceNeeds {
    /// No texture coordinates (`uv` is (0, 0)): what an untextured material needs.
    Geometry,
    /// Texture coordinates too, completing the barycentrics of a `PreliminaryHit`.
    Uv,
    /// Texture coordinates where the hit's material reads them (`Material::reads_uv`), else
    /// (0, 0) as for `Geometry`: what the course integrator's shading needs. A sphere's
    /// coordinates take an `acos` and an `atan2`, which every hit of an untextured sphere
    /// would otherwise pay.
    Shading,
}

/// A hit from any of the scene's queries: with barycentrics (`Hit`) or without
/// (`PreliminaryHit`).
pub trait AnyHit {
    fn preliminary(&self) -> PreliminaryHit;
    /// The barycentrics, when traversal found them.
    fn barycentrics(&self) -> Option<(f32, f32)>;
}

impl AnyHit for Hit {
    #[inline]
    fn preliminary(&self) -> PreliminaryHit {
        PreliminaryHit {
            t: self.t,
            instance: self.instance,
            primitive: self.primitive,
        }
    }
    #[inline]
    fn barycentrics(&self) -> Option<(f32, f32)> {
        Some((self.b1, self.b2))
    }
}

impl AnyHit for PreliminaryHit {
    #[inline]
    fn preliminary(&self) -> PreliminaryHit {
        *self
    }
    #[inline]
    fn barycentrics(&self) -> Option<(f32, f32)> {
        None
    }
}

impl Scene {
    /// Builds the scene with the default options (SAH splits).
    pub fn new(parts: SceneParts) -> Scene {
        Scene::with_options(parts, SceneOptions::default())
    }

    /// Builds the scene as `options` say (the split method of its BVHs).
    pub fn with_options(parts: SceneParts, options: SceneOptions) -> Scene {
        Scene::build(parts, AccelKind::default(), options.split)
    }

    /// Builds with a chosen bottom-level structure (tests and benches compare them).
    pub fn with_accel(parts: SceneParts, accel: AccelKind) -> Scene {
        Scene::build(parts, accel, SplitMethod::default())
    }

    fn build(parts: SceneParts, accel: AccelKind, split: SplitMethod) -> Scene {
        let SceneParts {
            camera,
            materials,
            textures,
            lights,
            background,
            geometries,
            instances,
            physical,
        } = parts;
        let start = Instant::now();
        let accel = Instances::build(geometries, instances, accel, split);
        Scene {
            camera,
            materials,
            textures,
            lights,
            background,
            physical,
            accel,
            split,
            build_time: start.elapsed(),
        }
    }

    /// The shape of the bottom-level BVHs and how long building the structures took.
    pub fn bvh_stats(&self) -> BvhStats {
        let trees = self.accel.tree_stats();
        BvhStats {
            split: self.split,
            build_time: self.build_time,
            trees: trees.trees,
            nodes: trees.nodes,
            leaves: trees.leaves,
            depth: trees.depth,
            sah_cost: trees.sah_cost,
            largest: trees.largest,
        }
    }

    /// `intersect`'s t, adding the bottom-level node and block tests of the walk to `counts`
    /// (a separate, slower traversal: for statistics only).
    pub(crate) fn count_closest(&self, ray: &Ray, counts: &mut WalkCounts) -> Option<f32> {
        self.accel.count_closest(ray, counts)
    }

    /// The two-level structure itself (benchmarks and the ray engine's tests).
    #[cfg(feature = "bench")]
    pub fn instances(&self) -> &Instances {
        &self.accel
    }

    /// `instances` to change (benchmarks choose the walk with `Instances::set_isa`).
    #[cfg(feature = "bench")]
    pub fn instances_mut(&mut self) -> &mut Instances {
        &mut self.accel
    }

    /// The world-space bounds of everything in the scene.
    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }

    /// What the acceleration structures hold and how much memory they take.
    pub fn accel_stats(&self) -> AccelStats {
        self.accel.accel_stats()
    }

    /// The closest hit with t in `[ray.t_min, ray.t_max]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.accel.intersect(ray)
    }

    /// `intersect` without the barycentrics (the same t, instance and primitive).
    #[inline]
    pub fn intersect_preliminary(&self, ray: &Ray) -> Option<PreliminaryHit> {
        self.accel.intersect_preliminary(ray)
    }

    /// True when anything that casts shadows blocks the ray within its window.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.accel.occluded(ray)
    }

    /// `intersect` for the rays of `lanes` (bit l for `rays[l]`), traced as a packet where it
    /// pays; the same hits as ray by ray.
    #[inline]
    pub fn intersect_lanes(&self, rays: &[Ray; PACKET], lanes: u8) -> [Option<Hit>; PACKET] {
        self.accel.intersect_lanes(rays, lanes)
    }

    /// `occluded` for the rays of `lanes`: the mask of those occluded.
    #[inline]
    pub fn occluded_lanes(&self, rays: &[Ray; PACKET], lanes: u8) -> u8 {
        self.accel.occluded_lanes(rays, lanes)
    }

    /// The material at a hit: `surface(..).material` without the rest (`surface` repeats
    /// these lines: calling this from there made it too big to inline in the path tracer).
    #[inline]
    pub(crate) fn material_at(&self, hit: &impl AnyHit) -> MaterialId {
        let prelim = hit.preliminary();
        let inst = &self.accel.instances[prelim.instance as usize];
        let geom = &self.accel.geometries[inst.geometry as usize];
        inst.material
            .unwrap_or(geom.materials.get(prelim.primitive))
    }

    /// Shading data for any hit the queries return: point, geometric normal, material, and
    /// with `SurfaceNeeds::Uv` the texture coordinates (completing a preliminary hit's
    /// barycentrics, exactly as `intersect` would have found them).
    #[inline]
    pub fn surface(&self, ray: &Ray, hit: &impl AnyHit, needs: SurfaceNeeds) -> SurfaceInteraction {
        let prelim = hit.preliminary();
        let inst = &self.accel.instances[prelim.instance as usize];
        let geom = &self.accel.geometries[inst.geometry as usize];
        let point = ray.at(prelim.t);
        let local_point = match &inst.transform {
            Some(xf) => xf.point_to_object(point),
            None => point,
        };
        let material = inst
            .material
            .unwrap_or(geom.materials.get(prelim.primitive));
        let reads_uv = match needs {
            SurfaceNeeds::Geometry => false,
            SurfaceNeeds::Uv => true,
            SurfaceNeeds::Shading => Material::get(&self.materials, material).reads_uv(),
        };
        let uv = if reads_uv {
            let (b1, b2) = hit
                .barycentrics()
                .unwrap_or_else(|| self.accel.barycentrics(ray, &prelim));
            let prim_hit = PrimitiveHit {
                t: prelim.t,
                b1,
                b2,
            };
            geom.shape(prelim.primitive).uv(local_point, &prim_hit)
        } else {
            (0.0, 0.0)
        };
        SurfaceInteraction {
            point,
            normal: normal_at(inst, geom, prelim.primitive, local_point),
            uv,
            material,
        }
    }

    /// Shading data of a hit as Mitsuba computes it for its BSDFs: texture coordinates from the
    /// mesh's own (or the barycentrics), the interpolated shading normal, ∂p/∂u and ∂p/∂v, and
    /// the mesh's colours, all from `physical.attributes`.
    /// The media the surface of `hit`'s geometry separates, if it bounds any.
    #[inline]
    pub fn medium_boundary(&self, hit: &impl AnyHit) -> Option<crate::medium::MediumBoundary> {
        if self.physical.boundaries.is_empty() {
            return None;
        }
        let inst = &self.accel.instances[hit.preliminary().instance as usize];
        self.physical
            .boundaries
            .get(inst.geometry as usize)
            .copied()
            .flatten()
    }

    pub fn physical_surface(&self, ray: &Ray, hit: &impl AnyHit) -> PhysicalSurface {
        let prelim = hit.preliminary();
        let inst = &self.accel.instances[prelim.instance as usize];
        let geom = &self.accel.geometries[inst.geometry as usize];
        let point = ray.at(prelim.t);
        let local_point = match &inst.transform {
            Some(xf) => xf.point_to_object(point),
            None => point,
        };
        let normal = normal_at(inst, geom, prelim.primitive, local_point);
        let attributes = self
            .physical
            .attributes
            .get(inst.geometry as usize)
            .and_then(Option::as_ref);
        let shape = geom.shape(prelim.primitive);
        let mut texture = TexturePoint::default();
        let mut bitangent_sign = 1.0;
        // Object-space derivatives and shading normal; None: the geometric normal.
        let (dp_du, dp_dv, shading) = match shape {
            Shape::Triangle {
                vertices: [p0, p1, p2],
            } => {
                let (b1, b2) = hit
                    .barycentrics()
                    .unwrap_or_else(|| self.accel.barycentrics(ray, &prelim));
                let b0 = 1.0 - b1 - b2;
                let source = geom.source_index(prelim.primitive) as usize;
                let corner = |v: Option<&Vec<[Vec3; 3]>>| {
                    v.and_then(|v| v.get(source))
                        .map(|[a, b, c]| *a * b0 + *b * b1 + *c * b2)
                };
                let (e1, e2) = (p1 - p0, p2 - p0);
                let mut derivatives = (e1, e2);
                texture.uv = (b1, b2);
                if let Some([uv0, uv1, uv2]) = attributes
                    .and_then(|a| a.uvs.as_ref())
                    .and_then(|uvs| uvs.get(source))
                {
                    texture.uv = (
                        uv0.0 * b0 + uv1.0 * b1 + uv2.0 * b2,
                        uv0.1 * b0 + uv1.1 * b1 + uv2.1 * b2,
                    );
                    let (du0, dv0) = (uv1.0 - uv0.0, uv1.1 - uv0.1);
                    let (du1, dv1) = (uv2.0 - uv0.0, uv2.1 - uv0.1);
                    let det = du0 * dv1 - dv0 * du1;
                    derivatives = if det != 0.0 {
                        let inv = 1.0 / det;
                        ((e1 * dv1 - e2 * dv0) * inv, (e2 * du0 - e1 * du1) * inv)
                    } else {
                        // A degenerate parameterisation: any tangent basis.
                        let frame = crate::math::Frame::from_normal(
                            geom.shape(prelim.primitive)
                                .normal(local_point, &unused_hit()),
                        );
                        (frame.u, frame.v)
                    };
                }
                if let Some(a) = attributes {
                    texture.vertex_color = corner(a.vertex_colors.as_ref()).unwrap_or(Color::ZERO);
                    texture.face_color = a
                        .face_colors
                        .as_ref()
                        .and_then(|c| c.get(source))
                        .copied()
                        .unwrap_or(Color::ZERO);
                }
                if let Some([t0, t1, t2]) = attributes
                    .and_then(|a| a.uvs1.as_ref())
                    .and_then(|uvs| uvs.get(source))
                {
                    texture.uv1 = (
                        t0.0 * b0 + t1.0 * b1 + t2.0 * b2,
                        t0.1 * b0 + t1.1 * b1 + t2.1 * b2,
                    );
                }
                if let Some(t) = attributes
                    .and_then(|a| a.tangents.as_ref())
                    .and_then(|t| t.get(source))
                {
                    let at = |i: usize| Vec3::new(t[i][0], t[i][1], t[i][2]);
                    let tangent = at(0) * b0 + at(1) * b1 + at(2) * b2;
                    if tangent.is_finite() && tangent != Vec3::ZERO {
                        derivatives.0 = tangent;
                        bitangent_sign = if t[0][3] < 0.0 { -1.0 } else { 1.0 };
                    }
                }
                let shading = corner(attributes.and_then(|a| a.normals.as_ref()));
                (derivatives.0, derivatives.1, shading)
            }
            Shape::Sphere { center, radius } if attributes.is_some_and(|a| a.mitsuba_sphere_uv) => {
                // Mitsuba's sphere: u the azimuth around +z from +x, v the polar angle from +z.
                let d = (local_point - center) / radius;
                let cos_theta = d.z.clamp(-1.0, 1.0);
                let theta = cos_theta.acos();
                let mut phi = d.y.atan2(d.x);
                if phi < 0.0 {
                    phi += std::f32::consts::TAU;
                }
                texture.uv = (
                    phi * (0.5 * std::f32::consts::FRAC_1_PI),
                    theta * std::f32::consts::FRAC_1_PI,
                );
                let (sin_phi, cos_phi) = phi.sin_cos();
                let dp_du = Vec3::new(-d.y, d.x, 0.0) * (std::f32::consts::TAU * radius);
                let dp_dv = Vec3::new(
                    d.z * cos_phi,
                    d.z * sin_phi,
                    -(1.0 - cos_theta * cos_theta).max(0.0).sqrt(),
                ) * (std::f32::consts::PI * radius);
                (dp_du, dp_dv, None)
            }
            other => {
                let needs = SurfaceNeeds::Uv;
                texture.uv = self.surface(ray, hit, needs).uv;
                let frame =
                    crate::math::Frame::from_normal(other.normal(local_point, &unused_hit()));
                (frame.u, frame.v, None)
            }
        };
        let (dp_du, dp_dv, shading_normal) = match &inst.transform {
            Some(xf) => (
                xf.vector_to_world(dp_du),
                xf.vector_to_world(dp_dv),
                shading.map(|n| xf.normal_to_world(n)),
            ),
            None => (dp_du, dp_dv, shading),
        };
        let shading_normal = shading_normal
            .map(Vec3::normalized)
            .filter(|n| n.is_finite() && *n != Vec3::ZERO)
            .unwrap_or(normal);
        PhysicalSurface {
            point,
            normal,
            frame: PhysicalSurface::shading_frame(shading_normal, dp_du),
            dp_du,
            dp_dv,
            texture,
            bitangent_sign,
        }
    }

    /// Radiance seen along a direction that leaves the scene.
    pub fn background_radiance(&self, direction: Vec3) -> Color {
        match &self.background {
            Background::Color(c) => *c,
            Background::CubeMap(map) => map.lookup(direction),
            Background::Environment {
                image,
                scale,
                to_world,
            } => crate::light::envmap::environment_radiance(image, *scale, to_world, direction),
        }
    }
}

/// A hit whose t and barycentrics are not read (spheres' and boxes' normals ignore them).
fn unused_hit() -> PrimitiveHit {
    PrimitiveHit {
        t: 0.0,
        b1: 0.0,
        b2: 0.0,
    }
}

/// The world-space unit geometric normal of a primitive at `local_point` (object space).
#[inline]
fn normal_at(inst: &Instance, geom: &Geometry, primitive: u32, local_point: Vec3) -> Vec3 {
    let stored = geom.normals[primitive as usize];
    let n = if stored != Vec3::ZERO {
        stored
    } else {
        // Spheres and boxes (their normal depends on the point; the hit's t and barycentrics
        // do not enter it).
        let unused = PrimitiveHit {
            t: 0.0,
            b1: 0.0,
            b2: 0.0,
        };
        geom.shape(primitive).normal(local_point, &unused)
    };
    match &inst.transform {
        Some(xf) => xf.normal_to_world(n).normalized(),
        None => n,
    }
}
