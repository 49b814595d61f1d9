//! The two-level structure over a scene's geometry: one bottom-level structure per unique
//! geometry (`GeometryDesc`), shared by every `Instance` that places it, under a top-level
//! binary BVH over the instances (skipped when there is one instance). Traversal returns tiny
//! hits (`Hit`, or `PreliminaryHit` without barycentrics); `Scene::surface` completes them.

use rayon::prelude::*;

use crate::accel::binary::Bvh;
use crate::accel::build::{BuildPhases, SplitMethod};
use crate::accel::wide::{TreeStats, WalkCounts, BLOCK};
use crate::accel::{LocalHit, WideBvh, PACKET};
use crate::geometry::{Aabb, Shape};
use crate::material::MaterialId;
use crate::math::{Transform, Vec3};
use crate::ray::Ray;

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

/// One geometry's bottom-level structure and the materials of its primitives.
pub(crate) struct Geometry {
    pub blas: Blas,
    pub materials: Materials,
    /// The unit geometric normal of each triangle by primitive index (`Shape::normal`,
    /// computed once at build rather than at every hit); zero for other primitives.
    pub normals: Vec<Vec3>,
    /// How long each phase of the wide BVH's build took; `None` for the binary reference.
    pub phases: Option<BuildPhases>,
}

/// A bottom-level structure: the wide BVH, or the reference binary BVH over the shapes.
pub(crate) enum Blas {
    Wide(WideBvh),
    Binary {
        bvh: Bvh,
        /// Shapes in BVH order (leaf ranges index this), and each one's index as given.
        shapes: Vec<Shape>,
        source: Vec<u32>,
    },
}

/// Materials by primitive index; one value when a geometry uses one material (meshes do).
pub(crate) enum Materials {
    Uniform(MaterialId),
    PerPrimitive(Vec<MaterialId>),
}

impl Materials {
    fn new(given: &[MaterialId], source: &[u32]) -> Materials {
        match given.first() {
            Some(&first) if given.iter().all(|&m| m == first) => Materials::Uniform(first),
            None => Materials::Uniform(0),
            Some(_) => Materials::PerPrimitive(
                source
                    .iter()
                    .map(|&i| given.get(i as usize).copied().unwrap_or(0))
                    .collect(),
            ),
        }
    }

    #[inline]
    pub(crate) fn get(&self, primitive: u32) -> MaterialId {
        match self {
            Materials::Uniform(m) => *m,
            Materials::PerPrimitive(v) => v[primitive as usize],
        }
    }

    fn bytes(&self) -> usize {
        match self {
            Materials::Uniform(_) => 0,
            Materials::PerPrimitive(v) => v.len() * std::mem::size_of::<MaterialId>(),
        }
    }
}

impl Geometry {
    fn build(desc: GeometryDesc, accel: AccelKind, split: SplitMethod) -> Geometry {
        match accel {
            AccelKind::Wide => {
                let (bvh, phases) = crate::accel::build::build_timed(&desc.shapes, split);
                let materials = Materials::new(&desc.materials, &bvh.source);
                // Each primitive slot's `triangle_normal(&bvh.shape(p))`, read from the blocks
                // directly rather than through a `Shape` per slot, a block a task (serial, this
                // was 0.7 ms of the instanced dragon's build on any number of threads).
                let mut normals = bvh
                    .blocks
                    .par_iter()
                    .with_min_len(1024)
                    .map(|block| {
                        std::array::from_fn::<Vec3, BLOCK, _>(|lane| {
                            let [a, b, c] = block.triangle(lane).map(Vec3::from_array);
                            (b - a).cross(c - a).normalized()
                        })
                    })
                    .collect::<Vec<_>>()
                    .into_flattened();
                normals.extend(bvh.shapes.iter().map(triangle_normal));
                Geometry {
                    blas: Blas::Wide(bvh),
                    materials,
                    normals,
                    phases: Some(phases),
                }
            }
            AccelKind::Binary => {
                let bounds: Vec<Aabb> = desc.shapes.iter().map(Shape::bounds).collect();
                let (bvh, order) = Bvh::build(&bounds);
                let shapes: Vec<Shape> = order.iter().map(|&i| desc.shapes[i as usize]).collect();
                let materials = Materials::new(&desc.materials, &order);
                let normals = shapes.iter().map(triangle_normal).collect();
                Geometry {
                    blas: Blas::Binary {
                        bvh,
                        shapes,
                        source: order,
                    },
                    materials,
                    normals,
                    phases: None,
                }
            }
        }
    }

    fn bounds(&self) -> Aabb {
        match &self.blas {
            Blas::Wide(bvh) => bvh.bounds(),
            Blas::Binary { bvh, .. } => bvh.bounds(),
        }
    }

    /// The shape of the wide BVH; `None` for the binary reference.
    fn tree_stats(&self) -> Option<TreeStats> {
        match &self.blas {
            Blas::Wide(bvh) => Some(bvh.tree_stats()),
            Blas::Binary { .. } => None,
        }
    }

    /// `intersect_preliminary`, counting the wide BVH's node and block tests (none counted for
    /// the binary reference).
    fn count_closest(&self, ray: &Ray, counts: &mut WalkCounts) -> Option<(f32, u32)> {
        match &self.blas {
            Blas::Wide(bvh) => bvh.count_closest(ray, counts).map(|h| (h.t, h.primitive)),
            Blas::Binary { .. } => self.intersect_preliminary(ray),
        }
    }

    fn primitive_count(&self) -> usize {
        match &self.blas {
            Blas::Wide(bvh) => bvh.source.iter().filter(|&&s| s != u32::MAX).count(),
            Blas::Binary { shapes, .. } => shapes.len(),
        }
    }

    /// The closest hit in object space with t in `[ray.t_min, ray.t_max]`.
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<LocalHit> {
        match &self.blas {
            Blas::Wide(bvh) => bvh.intersect(ray),
            Blas::Binary { bvh, shapes, .. } => Geometry::intersect_binary(bvh, shapes, ray),
        }
    }

    /// `intersect` on the reference binary BVH, out of line: inlined, its frame and saved
    /// registers were paid on every call, also by the wide BVH's (3.4 ns of the 25 ns a
    /// missing ray took).
    #[inline(never)]
    fn intersect_binary(bvh: &Bvh, shapes: &[Shape], ray: &Ray) -> Option<LocalHit> {
        let mut best: Option<LocalHit> = None;
        let mut local = *ray;
        bvh.traverse(ray, |prim, t_prim| {
            local.t_max = t_prim;
            match shapes[prim as usize].intersect(&local) {
                Some(h) => {
                    best = Some(LocalHit {
                        t: h.t,
                        primitive: prim,
                        b1: h.b1,
                        b2: h.b2,
                    });
                    h.t
                }
                None => t_prim,
            }
        });
        best
    }

    /// `intersect` without the barycentrics: (t, primitive).
    #[inline]
    fn intersect_preliminary(&self, ray: &Ray) -> Option<(f32, u32)> {
        match &self.blas {
            Blas::Wide(bvh) => bvh.intersect_preliminary(ray),
            Blas::Binary { .. } => self.intersect(ray).map(|h| (h.t, h.primitive)),
        }
    }

    /// The barycentrics `intersect` reports for its hit (t, primitive) of `ray`.
    fn barycentrics(&self, ray: &Ray, t: f32, primitive: u32) -> (f32, f32) {
        match &self.blas {
            Blas::Wide(bvh) => {
                let h = bvh.finish(ray, t, primitive);
                (h.b1, h.b2)
            }
            Blas::Binary { shapes, .. } => shapes[primitive as usize]
                .intersect(&Ray {
                    t_min: t,
                    t_max: t,
                    ..*ray
                })
                .map_or((0.0, 0.0), |h| (h.b1, h.b2)),
        }
    }

    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        match &self.blas {
            Blas::Wide(bvh) => bvh.occluded(ray),
            Blas::Binary { bvh, shapes, .. } => {
                let mut any = false;
                bvh.traverse_any(ray, |prim| {
                    any = shapes[prim as usize].intersect(ray).is_some();
                    any
                });
                any
            }
        }
    }

    /// `intersect` for the rays of `lanes` (bit l for `rays[l]`), as a packet where it pays.
    #[inline]
    fn intersect_packet(&self, rays: &[Ray; PACKET], lanes: u8) -> [Option<LocalHit>; PACKET] {
        match &self.blas {
            Blas::Wide(bvh) if lanes.count_ones() > 1 => bvh.intersect_packet(rays, lanes),
            _ => std::array::from_fn(|l| {
                if lanes & (1 << l) != 0 {
                    self.intersect(&rays[l])
                } else {
                    None
                }
            }),
        }
    }

    /// `occluded` for the rays of `lanes`: the mask of those occluded.
    #[inline]
    fn occluded_packet(&self, rays: &[Ray; PACKET], lanes: u8) -> u8 {
        match &self.blas {
            Blas::Wide(bvh) if lanes.count_ones() > 1 => bvh.occluded_packet(rays, lanes),
            _ => (0..PACKET)
                .filter(|&l| lanes & (1 << l) != 0 && self.occluded(&rays[l]))
                .fold(0, |m, l| m | 1 << l),
        }
    }

    pub(crate) fn shape(&self, primitive: u32) -> Shape {
        match &self.blas {
            Blas::Wide(bvh) => bvh.shape(primitive),
            Blas::Binary { shapes, .. } => shapes[primitive as usize],
        }
    }

    /// The index in `GeometryDesc::shapes` of the shape in slot `primitive`.
    pub(crate) fn source_index(&self, primitive: u32) -> u32 {
        match &self.blas {
            Blas::Wide(bvh) => bvh.source_index(primitive),
            Blas::Binary { source, .. } => source[primitive as usize],
        }
    }

    fn node_bytes(&self) -> usize {
        match &self.blas {
            Blas::Wide(bvh) => bvh.node_bytes(),
            Blas::Binary { bvh, .. } => std::mem::size_of_val(bvh.nodes()),
        }
    }

    fn primitive_bytes(&self) -> usize {
        self.materials.bytes()
            + match &self.blas {
                Blas::Wide(bvh) => bvh.primitive_bytes(),
                Blas::Binary { shapes, source, .. } => {
                    std::mem::size_of_val(shapes.as_slice())
                        + std::mem::size_of_val(source.as_slice())
                }
            }
    }
}

/// Memory of a scene's acceleration structures (`Scene::accel_stats`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AccelStats {
    /// Primitives stored, over all geometries (instancing does not multiply them).
    pub unique_primitives: usize,
    pub instances: usize,
    /// Bytes of BVH nodes, both levels.
    pub node_bytes: usize,
    /// Bytes of primitive data the traversal reads (shapes or triangle blocks, their
    /// materials, the instances).
    pub primitive_bytes: usize,
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

/// What traversal alone finds: the closest hit without its barycentrics (Mitsuba 3's
/// `PreliminaryIntersection`), for callers that need them only at some hits, such as the path
/// tracer at untextured surfaces. `Scene::complete` turns it into the `Hit` that `intersect`
/// returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreliminaryHit {
    pub t: f32,
    pub instance: u32,
    pub primitive: u32,
}

/// The bottom-level trees of a scene together (`Instances::tree_stats`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BottomLevelStats {
    /// Geometries with a wide BVH.
    pub trees: usize,
    /// Inner nodes and leaves over all of them.
    pub nodes: usize,
    pub leaves: usize,
    /// The deepest of them.
    pub depth: usize,
    /// Their SAH costs averaged with each tree weighted by its primitives (for one geometry,
    /// its tree's cost).
    pub sah_cost: f64,
    /// The primitives of the tree with the most, and how long each phase of its build took.
    pub largest: Option<(usize, BuildPhases)>,
}

/// Which structure the bottom level (one per geometry) is built as.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AccelKind {
    /// 8-wide BVH with SIMD traversal and watertight triangle blocks (the default).
    #[default]
    Wide,
    /// The reference binary BVH (`accel::binary`) over the shapes, tested one by one.
    Binary,
}

/// The instances of a scene's geometries, ready to trace.
pub struct Instances {
    pub(crate) geometries: Vec<Geometry>,
    pub(crate) instances: Vec<Instance>,
    pub(crate) tlas: Bvh,
    bounds: Aabb,
}

impl Instances {
    /// Builds every geometry's bottom level (large ones in parallel inside, many small ones
    /// side by side) and the top level over the instances.
    pub(crate) fn build(
        geometries: Vec<GeometryDesc>,
        instances: Vec<Instance>,
        accel: AccelKind,
        split: SplitMethod,
    ) -> Instances {
        let geometries: Vec<Geometry> = geometries
            .into_par_iter()
            .map(|g| Geometry::build(g, accel, split))
            .collect();
        let instance_bounds: Vec<Aabb> = instances
            .iter()
            .map(|inst| instance_bounds(inst, geometries[inst.geometry as usize].bounds()))
            .collect();
        let (tlas, order) = Bvh::build(&instance_bounds);
        let instances: Vec<Instance> = order.iter().map(|&i| instances[i as usize]).collect();
        let bounds = instance_bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        Instances {
            geometries,
            instances,
            tlas,
            bounds,
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Chooses the kernel of every wide bottom level (benchmarks time the walks on one tree;
    /// the binary bottom levels and the top level have one walk each).
    #[cfg(feature = "bench")]
    pub fn set_isa(&mut self, isa: crate::accel::Isa) {
        for geometry in &mut self.geometries {
            if let Blas::Wide(bvh) = &mut geometry.blas {
                bvh.set_isa(isa);
            }
        }
    }

    /// The kernel of the first wide bottom level, if there is one.
    #[cfg(feature = "bench")]
    pub fn isa(&self) -> Option<crate::accel::Isa> {
        self.geometries
            .iter()
            .find_map(|geometry| match &geometry.blas {
                Blas::Wide(bvh) => Some(bvh.isa()),
                Blas::Binary { .. } => None,
            })
    }

    /// Number of primitives over all geometries (not multiplied by instancing).
    pub fn unique_primitive_count(&self) -> usize {
        self.geometries.iter().map(Geometry::primitive_count).sum()
    }

    #[cfg(feature = "bench")]
    pub fn instance_count(&self) -> usize {
        self.instances.len()
    }

    /// What the acceleration structures hold and how much memory they take.
    pub fn accel_stats(&self) -> AccelStats {
        let mut stats = AccelStats {
            unique_primitives: self.unique_primitive_count(),
            instances: self.instances.len(),
            node_bytes: std::mem::size_of_val(self.tlas.nodes()),
            primitive_bytes: std::mem::size_of_val(self.instances.as_slice()),
        };
        for g in &self.geometries {
            stats.node_bytes += g.node_bytes();
            stats.primitive_bytes += g.primitive_bytes();
        }
        stats
    }

    /// The bottom-level trees' shape, together.
    pub fn tree_stats(&self) -> BottomLevelStats {
        let mut out = BottomLevelStats::default();
        let mut weighted = 0.0f64;
        let mut weights = 0usize;
        for g in &self.geometries {
            if let Some(t) = g.tree_stats() {
                out.trees += 1;
                out.nodes += t.nodes;
                out.leaves += t.leaves;
                out.depth = out.depth.max(t.depth);
                let primitives = g.primitive_count();
                weighted += t.sah_cost * primitives as f64;
                weights += primitives;
                if let Some(phases) = g.phases {
                    if out.largest.is_none_or(|(most, _)| primitives > most) {
                        out.largest = Some((primitives, phases));
                    }
                }
            }
        }
        out.sah_cost = if weights > 0 {
            weighted / weights as f64
        } else {
            0.0
        };
        out
    }

    /// `intersect_preliminary`'s t, counting the bottom-level node and block tests into
    /// `counts` (the top level is not counted: it does not depend on the split method).
    pub fn count_closest(&self, ray: &Ray, counts: &mut WalkCounts) -> Option<f32> {
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            let geometry = &self.geometries[inst.geometry as usize];
            return Instances::in_object_space(inst, ray, |local| {
                geometry.count_closest(local, counts)
            })
            .map(|(t, _)| t);
        }
        let mut best = None;
        self.tlas.traverse(ray, |inst_index, t_limit| {
            let inst = &self.instances[inst_index as usize];
            let local = Instances::object_ray(inst, ray, t_limit);
            match self.geometries[inst.geometry as usize].count_closest(&local, counts) {
                Some((t, _)) => {
                    best = Some(t);
                    t
                }
                None => t_limit,
            }
        });
        best
    }

    #[cfg(feature = "bench")]
    /// The index, in its `GeometryDesc::shapes` as given, of the primitive a hit names
    /// (`Hit::primitive` is the acceleration structure's own numbering).
    pub fn source_primitive(&self, hit: &Hit) -> u32 {
        let inst = &self.instances[hit.instance as usize];
        self.geometries[inst.geometry as usize].source_index(hit.primitive)
    }

    /// `f` of the ray in `inst`'s object space with the ray's own window: the ray itself
    /// where the instance has no transform. A copy of a ray its caller has just written is
    /// read back from the store buffer, which stalls when the copy's loads straddle the
    /// caller's stores (`perf annotate` showed it on every path-traced ray).
    #[inline(always)]
    fn in_object_space<R>(inst: &Instance, ray: &Ray, f: impl FnOnce(&Ray) -> R) -> R {
        if inst.transform.is_none() {
            f(ray)
        } else {
            f(&Instances::object_ray(inst, ray, ray.t_max))
        }
    }

    /// The ray in an instance's object space; t means the same there (no re-normalising).
    #[inline(always)]
    fn object_ray(inst: &Instance, ray: &Ray, t_max: f32) -> Ray {
        match &inst.transform {
            Some(xf) => Ray {
                origin: xf.point_to_object(ray.origin),
                direction: xf.vector_to_object(ray.direction),
                t_min: ray.t_min,
                t_max,
            },
            None => Ray { t_max, ..*ray },
        }
    }

    /// The closest hit with t in `[ray.t_min, ray.t_max]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if let Some(geometry) = self.lone_untransformed() {
            return geometry.intersect(ray).map(|h| Hit {
                t: h.t,
                instance: 0,
                primitive: h.primitive,
                b1: h.b1,
                b2: h.b2,
            });
        }
        self.intersect_placed(ray)
    }

    /// The one geometry of a scene that places it once and untransformed (every stand-alone
    /// mesh): the queries hand it the ray itself. The other cases go out of line
    /// (`intersect_placed` and the like), so that this path's callers do not pay for their
    /// frames and saved registers (a third of a missing ray's time in `glint bench rays`).
    #[inline(always)]
    fn lone_untransformed(&self) -> Option<&Geometry> {
        match self.instances.as_slice() {
            [inst] if inst.transform.is_none() => self.geometries.get(inst.geometry as usize),
            _ => None,
        }
    }

    /// `intersect` for any other placement: a lone transformed instance, or a top level.
    #[inline(never)]
    fn intersect_placed(&self, ray: &Ray) -> Option<Hit> {
        if self.instances.len() == 1 {
            // One instance (every stand-alone mesh): no top level to walk.
            let inst = &self.instances[0];
            let geometry = &self.geometries[inst.geometry as usize];
            return Instances::in_object_space(inst, ray, |local| geometry.intersect(local)).map(
                |h| Hit {
                    t: h.t,
                    instance: 0,
                    primitive: h.primitive,
                    b1: h.b1,
                    b2: h.b2,
                },
            );
        }
        let mut best: Option<Hit> = None;
        self.tlas.traverse(ray, |inst_index, t_limit| {
            let inst = &self.instances[inst_index as usize];
            let local = Instances::object_ray(inst, ray, t_limit);
            match self.geometries[inst.geometry as usize].intersect(&local) {
                Some(h) => {
                    best = Some(Hit {
                        t: h.t,
                        instance: inst_index,
                        primitive: h.primitive,
                        b1: h.b1,
                        b2: h.b2,
                    });
                    h.t
                }
                None => t_limit,
            }
        });
        best
    }

    /// `intersect` without the barycentrics (the same t, instance and primitive).
    #[inline]
    pub fn intersect_preliminary(&self, ray: &Ray) -> Option<PreliminaryHit> {
        if let Some(geometry) = self.lone_untransformed() {
            return geometry
                .intersect_preliminary(ray)
                .map(|(t, primitive)| PreliminaryHit {
                    t,
                    instance: 0,
                    primitive,
                });
        }
        self.intersect_preliminary_placed(ray)
    }

    /// `intersect_preliminary` for any other placement (see `lone_untransformed`).
    #[inline(never)]
    fn intersect_preliminary_placed(&self, ray: &Ray) -> Option<PreliminaryHit> {
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            let geometry = &self.geometries[inst.geometry as usize];
            return Instances::in_object_space(inst, ray, |local| {
                geometry.intersect_preliminary(local)
            })
            .map(|(t, primitive)| PreliminaryHit {
                t,
                instance: 0,
                primitive,
            });
        }
        let mut best: Option<PreliminaryHit> = None;
        self.tlas.traverse(ray, |inst_index, t_limit| {
            let inst = &self.instances[inst_index as usize];
            let local = Instances::object_ray(inst, ray, t_limit);
            match self.geometries[inst.geometry as usize].intersect_preliminary(&local) {
                Some((t, primitive)) => {
                    best = Some(PreliminaryHit {
                        t,
                        instance: inst_index,
                        primitive,
                    });
                    t
                }
                None => t_limit,
            }
        });
        best
    }

    #[cfg(any(test, feature = "bench"))]
    /// The `Hit` that `intersect(ray)` returns, from the `PreliminaryHit` that
    /// `intersect_preliminary(ray)` returned.
    pub fn complete(&self, ray: &Ray, hit: &PreliminaryHit) -> Hit {
        let (b1, b2) = self.barycentrics(ray, hit);
        Hit {
            t: hit.t,
            instance: hit.instance,
            primitive: hit.primitive,
            b1,
            b2,
        }
    }

    /// The barycentrics that `intersect(ray)` reports with the hit `intersect_preliminary(ray)`
    /// returned.
    pub(crate) fn barycentrics(&self, ray: &Ray, hit: &PreliminaryHit) -> (f32, f32) {
        let inst = &self.instances[hit.instance as usize];
        let local = Instances::object_ray(inst, ray, ray.t_max);
        self.geometries[inst.geometry as usize].barycentrics(&local, hit.t, hit.primitive)
    }

    /// True when anything blocks the ray within its window (shadow rays). Instances that do not
    /// cast shadows are skipped.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if let Some(geometry) = self.lone_untransformed() {
            return self.instances[0].casts_shadow && geometry.occluded(ray);
        }
        self.occluded_placed(ray)
    }

    /// `occluded` for any other placement (see `lone_untransformed`).
    #[inline(never)]
    fn occluded_placed(&self, ray: &Ray) -> bool {
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            let geometry = &self.geometries[inst.geometry as usize];
            return inst.casts_shadow
                && Instances::in_object_space(inst, ray, |local| geometry.occluded(local));
        }
        let mut hit = false;
        self.tlas.traverse_any(ray, |inst_index| {
            let inst = &self.instances[inst_index as usize];
            if !inst.casts_shadow {
                return false;
            }
            hit = self.geometries[inst.geometry as usize]
                .occluded(&Instances::object_ray(inst, ray, ray.t_max));
            hit
        });
        hit
    }

    #[cfg(feature = "bench")]
    /// The closest hits of eight rays traced together as a packet: in each lane exactly what
    /// `intersect` returns for that ray alone (t, instance, primitive and barycentrics, bit for
    /// bit). Pays for coherent rays, such as the camera rays of a 4x2 pixel block.
    #[inline]
    pub fn intersect_packet(&self, rays: &[Ray; PACKET]) -> [Option<Hit>; PACKET] {
        self.intersect_lanes(rays, crate::accel::ALL_LANES)
    }

    /// `intersect_packet` for the rays of `lanes` only (bit l for `rays[l]`); `None` in the
    /// other lanes. For partial packets at image edges.
    pub fn intersect_lanes(&self, rays: &[Ray; PACKET], lanes: u8) -> [Option<Hit>; PACKET] {
        let mut out = [None; PACKET];
        // Rays the structures reject (NaN, infinite, an empty window) take the single-ray
        // path, which answers them; the rest travel together.
        let mut packet = 0u8;
        for (l, ray) in rays.iter().enumerate() {
            if lanes & (1 << l) != 0 {
                if crate::accel::wide::ray_is_valid(ray) {
                    packet |= 1 << l;
                } else {
                    out[l] = self.intersect(ray);
                }
            }
        }
        if packet == 0 {
            return out;
        }
        let hit = |h: LocalHit, instance: u32| Hit {
            t: h.t,
            instance,
            primitive: h.primitive,
            b1: h.b1,
            b2: h.b2,
        };
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            let geometry = &self.geometries[inst.geometry as usize];
            let hits = match inst.transform {
                // `object_ray` would copy the rays unchanged.
                None => geometry.intersect_packet(rays, packet),
                Some(_) => {
                    let local = rays
                        .each_ref()
                        .map(|r| Instances::object_ray(inst, r, r.t_max));
                    geometry.intersect_packet(&local, packet)
                }
            };
            for (l, h) in hits.into_iter().enumerate() {
                if packet & (1 << l) != 0 {
                    out[l] = h.map(|h| hit(h, 0));
                }
            }
            return out;
        }
        // The top level decides ties between instances by its visiting order, which depends on
        // the signs of the direction: rays that share them walk it together (each visiting
        // what it would alone, in the same order); a packet that does not goes ray by ray.
        let first = rays[packet.trailing_zeros() as usize].direction.to_array();
        let same_signs = (0..PACKET).all(|l| {
            packet & (1 << l) == 0
                || (0..3)
                    .all(|a| rays[l].direction[a].is_sign_negative() == first[a].is_sign_negative())
        });
        if !same_signs || packet.count_ones() == 1 {
            for (l, ray) in rays.iter().enumerate() {
                if packet & (1 << l) != 0 {
                    out[l] = self.intersect(ray);
                }
            }
            return out;
        }
        let mut t_max = rays.each_ref().map(|r| r.t_max);
        self.tlas
            .traverse_packet(rays, packet, &mut t_max, |inst_index, reached, t_max| {
                let inst = &self.instances[inst_index as usize];
                let local: [Ray; PACKET] =
                    std::array::from_fn(|l| Instances::object_ray(inst, &rays[l], t_max[l]));
                let hits =
                    self.geometries[inst.geometry as usize].intersect_packet(&local, reached);
                for (l, h) in hits.into_iter().enumerate() {
                    if let Some(h) = h {
                        if reached & (1 << l) != 0 {
                            out[l] = Some(hit(h, inst_index));
                            t_max[l] = h.t;
                        }
                    }
                }
            });
        out
    }

    #[cfg(feature = "bench")]
    /// Shadow rays traced together: in each lane exactly what `occluded` returns for that ray.
    #[inline]
    pub fn occluded_packet(&self, rays: &[Ray; PACKET]) -> [bool; PACKET] {
        let mask = self.occluded_lanes(rays, crate::accel::ALL_LANES);
        std::array::from_fn(|l| mask & (1 << l) != 0)
    }

    /// `occluded_packet` for the rays of `lanes` only: the mask of those occluded.
    pub fn occluded_lanes(&self, rays: &[Ray; PACKET], lanes: u8) -> u8 {
        let mut out = 0u8;
        let mut packet = 0u8;
        for (l, ray) in rays.iter().enumerate() {
            if lanes & (1 << l) != 0 {
                if crate::accel::wide::ray_is_valid(ray) {
                    packet |= 1 << l;
                } else if self.occluded(ray) {
                    out |= 1 << l;
                }
            }
        }
        if packet == 0 {
            return out;
        }
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            if !inst.casts_shadow {
                return out;
            }
            let geometry = &self.geometries[inst.geometry as usize];
            return out
                | match inst.transform {
                    None => geometry.occluded_packet(rays, packet),
                    Some(_) => {
                        let local = rays
                            .each_ref()
                            .map(|r| Instances::object_ray(inst, r, r.t_max));
                        geometry.occluded_packet(&local, packet)
                    }
                };
        }
        // Occlusion does not depend on the order of the walk: any ray order will do.
        out | self
            .tlas
            .traverse_any_packet(rays, packet, |inst_index, reached| {
                let inst = &self.instances[inst_index as usize];
                if !inst.casts_shadow {
                    return 0;
                }
                let local = rays
                    .each_ref()
                    .map(|r| Instances::object_ray(inst, r, r.t_max));
                self.geometries[inst.geometry as usize].occluded_packet(&local, reached)
            })
    }
}

/// A triangle's unit geometric normal as `Shape::normal` computes it; zero for other shapes
/// (and for a degenerate triangle, whose normal is zero there too).
fn triangle_normal(shape: &Shape) -> Vec3 {
    match shape {
        Shape::Triangle {
            vertices: [a, b, c],
        } => (*b - *a).cross(*c - *a).normalized(),
        _ => Vec3::ZERO,
    }
}

fn instance_bounds(inst: &Instance, b: Aabb) -> Aabb {
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
