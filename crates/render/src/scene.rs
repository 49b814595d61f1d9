//! The renderable scene: geometry grouped into shared bottom-level BVHs, instances of them
//! under a top-level BVH, materials, textures, lights, camera and background.

use crate::bvh::Bvh;
use crate::camera::Camera;
use crate::geometry::{Aabb, PrimitiveHit, Shape};
use crate::light::Light;
use crate::material::{Material, MaterialId};
use crate::math::{Color, Transform, Vec3};
use crate::ray::Ray;
use crate::texture::{CubeMap, Image};

/// What rays that leave the scene see.
#[derive(Clone, Debug, PartialEq)]
pub enum Background {
    /// A constant colour (`bgColor`).
    Color(Color),
    /// An environment cube map (`envMapPrefix`, or `envMapVertCross` cut into faces).
    CubeMap(Box<CubeMap>),
}

/// A group of shapes with one bottom-level BVH, shared by every instance that places it: an
/// OBJ mesh, an instance definition, or all the scene's plain shapes together.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GeometryDesc {
    pub shapes: Vec<Shape>,
    /// The material of each shape (same length as `shapes`).
    pub materials: Vec<MaterialId>,
}

/// One placement of a geometry in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index into `SceneParts::geometries`.
    pub geometry: u32,
    /// Object-to-world transform; `None` means the geometry is already in world space.
    pub transform: Option<Transform>,
    /// Replaces the shapes' own materials when set (an instance shape's `shader` ref).
    pub material: Option<MaterialId>,
    /// False for the emissive stand-ins of area lights, which must not block shadow rays
    /// (FORMAT.md A10).
    pub casts_shadow: bool,
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
}

pub(crate) struct Geometry {
    pub shapes: Vec<Shape>,
    pub materials: Vec<MaterialId>,
    pub bvh: Bvh,
}

/// A scene ready to trace. Built once from `SceneParts`; immutable and shared by all threads.
pub struct Scene {
    pub camera: Camera,
    pub materials: Vec<Material>,
    pub textures: Vec<Image>,
    pub lights: Vec<Light>,
    pub background: Background,
    pub(crate) geometries: Vec<Geometry>,
    pub(crate) instances: Vec<Instance>,
    pub(crate) tlas: Bvh,
    bounds: Aabb,
}

/// The closest hit found by traversal: small on purpose; shading data is built only for the
/// winner (`Scene::surface`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub instance: u32,
    pub primitive: u32,
    pub b1: f32,
    pub b2: f32,
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

impl Scene {
    pub fn new(parts: SceneParts) -> Scene {
        let SceneParts {
            camera,
            materials,
            textures,
            lights,
            background,
            geometries,
            instances,
        } = parts;
        let geometries: Vec<Geometry> = geometries
            .into_iter()
            .map(|g| {
                let bounds: Vec<Aabb> = g.shapes.iter().map(Shape::bounds).collect();
                let (bvh, order) = Bvh::build(&bounds);
                let shapes = order.iter().map(|&i| g.shapes[i as usize]).collect();
                let materials = order.iter().map(|&i| g.materials[i as usize]).collect();
                Geometry {
                    shapes,
                    materials,
                    bvh,
                }
            })
            .collect();
        let instance_bounds: Vec<Aabb> = instances
            .iter()
            .map(|inst| instance_bounds(inst, &geometries[inst.geometry as usize].bvh))
            .collect();
        let (tlas, order) = Bvh::build(&instance_bounds);
        let instances: Vec<Instance> = order.iter().map(|&i| instances[i as usize]).collect();
        let bounds = instance_bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        Scene {
            camera,
            materials,
            textures,
            lights,
            background,
            geometries,
            instances,
            tlas,
            bounds,
        }
    }

    /// The world-space bounds of everything in the scene.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of primitives over all geometries (not multiplied by instancing).
    pub fn unique_primitive_count(&self) -> usize {
        self.geometries.iter().map(|g| g.shapes.len()).sum()
    }

    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// The closest hit with t in `[ray.t_min, ray.t_max]`.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        self.tlas.traverse(ray, |inst_index, t_limit| {
            let inst = &self.instances[inst_index as usize];
            let geom = &self.geometries[inst.geometry as usize];
            let mut local = match &inst.transform {
                Some(xf) => Ray {
                    origin: xf.point_to_object(ray.origin),
                    direction: xf.vector_to_object(ray.direction),
                    t_min: ray.t_min,
                    t_max: t_limit,
                },
                None => Ray {
                    t_max: t_limit,
                    ..*ray
                },
            };
            let mut found = false;
            let start = local;
            geom.bvh.traverse(&start, |prim, t_prim| {
                local.t_max = t_prim;
                if let Some(h) = geom.shapes[prim as usize].intersect(&local) {
                    local.t_max = h.t;
                    best = Some(Hit {
                        t: h.t,
                        instance: inst_index,
                        primitive: prim,
                        b1: h.b1,
                        b2: h.b2,
                    });
                    found = true;
                    h.t
                } else {
                    t_prim
                }
            });
            if found {
                t_max = local.t_max;
            }
            t_max.min(t_limit)
        });
        best
    }

    /// True when anything blocks the ray within its window (shadow rays). Instances that do not
    /// cast shadows are skipped.
    pub fn occluded(&self, ray: &Ray) -> bool {
        let mut hit = false;
        self.tlas.traverse_any(ray, |inst_index| {
            let inst = &self.instances[inst_index as usize];
            if !inst.casts_shadow {
                return false;
            }
            let geom = &self.geometries[inst.geometry as usize];
            let local = match &inst.transform {
                Some(xf) => Ray {
                    origin: xf.point_to_object(ray.origin),
                    direction: xf.vector_to_object(ray.direction),
                    ..*ray
                },
                None => *ray,
            };
            let mut any = false;
            geom.bvh.traverse_any(&local, |prim| {
                any = geom.shapes[prim as usize].intersect(&local).is_some();
                any
            });
            hit |= any;
            any
        });
        hit
    }

    /// Full shading data for a hit found by `intersect`.
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        let inst = &self.instances[hit.instance as usize];
        let geom = &self.geometries[inst.geometry as usize];
        let shape = &geom.shapes[hit.primitive as usize];
        let prim_hit = PrimitiveHit {
            t: hit.t,
            b1: hit.b1,
            b2: hit.b2,
        };
        let point = ray.at(hit.t);
        let (local_point, normal) = match &inst.transform {
            Some(xf) => {
                let lp = xf.point_to_object(point);
                let n = shape.normal(lp, &prim_hit);
                (lp, xf.normal_to_world(n).normalized())
            }
            None => (point, shape.normal(point, &prim_hit)),
        };
        let uv = shape.uv(local_point, &prim_hit);
        let material = inst
            .material
            .unwrap_or(geom.materials[hit.primitive as usize]);
        SurfaceInteraction {
            point,
            normal,
            uv,
            material,
        }
    }

    /// Radiance seen along a direction that leaves the scene.
    pub fn background_radiance(&self, direction: Vec3) -> Color {
        match &self.background {
            Background::Color(c) => *c,
            Background::CubeMap(map) => map.lookup(direction),
        }
    }
}

fn instance_bounds(inst: &Instance, bvh: &Bvh) -> Aabb {
    let b = bvh.bounds();
    match &inst.transform {
        None => b,
        Some(xf) => {
            if b.is_empty() {
                return b;
            }
            let mut out = Aabb::EMPTY;
            for i in 0..8 {
                let p = Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                );
                out = out.grow(xf.point_to_world(p));
            }
            out
        }
    }
}
