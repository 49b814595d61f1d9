//! The BSDF of a physically based material at one hit: the material's tree of `BsdfNode`s
//! resolved for this point and this viewing direction into at most `MAX_LEAVES` weighted
//! leaves, each a BSDF family of `scatter.rs` in its own shading frame.
//!
//! Resolving the tree once per hit is what makes the wrappers cheap:
//! - `twosided` picks its front or back BSDF by the side ωo (the direction towards the
//!   viewer, fixed for the hit) lies on, and flips the frame for the back;
//! - `normalmap` and `bumpmap` tilt the frame of everything below them, and remember the frame
//!   they tilted, because Mitsuba rejects directions on different sides of the two frames and
//!   scales the response by the shadowing term of Estevez et al. (2019);
//! - `blendbsdf` and `mask` weigh their children (a mask's transparent part is a `Null` leaf,
//!   light passing straight on).
//!
//! The leaves' weights sum to one, and a leaf is sampled with the probability of its weight,
//! as Mitsuba's `blendbsdf` and `mask` choose; a continuous sample is then weighed against
//! every leaf's density (one-sample multiple importance sampling, as `blendbsdf` does), a
//! delta sample by its own probability.

use crate::material::bsdf::BsdfSample;
use crate::material::conductor::{Conductor, RoughConductor};
use crate::material::dielectric::{Dielectric, RoughDielectric, ThinDielectric};
use crate::material::diffuse::Diffuse;
use crate::material::gltf::GltfPbr;
use crate::material::microfacet::{Distribution, Microfacet};
use crate::material::physical::{
    BsdfId, BsdfNode, DistributionKind, GltfAlphaMode, GltfParams, Param, Roughness,
};
use crate::material::plastic::{specular_sampling_weight, Plastic, RoughPlastic};
use crate::material::principled::{Principled, PrincipledThin};
use crate::material::scatter::Scatter;
use crate::math::{Color, Frame, Vec3};
use crate::texture::{Image, TextureNode, TexturePoint};

/// Shading data of a hit on a physically based material, as Mitsuba 3.9 computes it
/// (`Scene::physical_surface`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicalSurface {
    pub point: Vec3,
    /// Unit geometric normal (world): by the winding for triangles, outward for spheres.
    pub normal: Vec3,
    /// The shading frame: `w` the interpolated vertex normal (or the geometric normal), `u`
    /// along ∂p/∂u made orthogonal to it, `v` = w × u.
    pub frame: Frame,
    /// ∂p/∂u and ∂p/∂v in world space (bump mapping needs them).
    pub dp_du: Vec3,
    pub dp_dv: Vec3,
    /// What textures read here.
    pub texture: TexturePoint,
    /// The sign of the bitangent relative to `frame.v` (glTF's tangent `w`): a tangent-space
    /// normal map's y is read along `bitangent_sign · frame.v`. 1 without tangents.
    pub bitangent_sign: f32,
}

impl PhysicalSurface {
    /// Mitsuba's shading frame from the shading normal `n` and ∂p/∂u: the tangent is ∂p/∂u
    /// made orthogonal to `n`, or any tangent where that vanishes.
    pub fn shading_frame(n: Vec3, dp_du: Vec3) -> Frame {
        let s = dp_du - n * n.dot(dp_du);
        let length = s.length();
        if length > 0.0 && length.is_finite() {
            let s = s / length;
            Frame {
                u: s,
                v: n.cross(s),
                w: n,
            }
        } else {
            Frame::from_normal(n)
        }
    }
}

/// The most leaves a resolved tree keeps; deeper mixtures drop their lightest leaves.
pub const MAX_LEAVES: usize = 4;
/// How deep wrappers may nest before the tree is cut (the loader refuses cycles; this bounds
/// the recursion on any tree).
const MAX_NESTING: u32 = 16;

/// One BSDF family with its parameters resolved.
// A rough plastic carries its 64-entry transmittance table; the leaves live on the stack per
// hit, where boxing the large variant would allocate on every hit.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Family {
    Diffuse(Diffuse),
    Conductor(Conductor),
    RoughConductor(RoughConductor),
    Dielectric(Dielectric),
    ThinDielectric(ThinDielectric),
    RoughDielectric(RoughDielectric),
    Plastic(Plastic),
    RoughPlastic(RoughPlastic),
    Principled(Principled),
    PrincipledThin(PrincipledThin),
    Gltf(GltfPbr),
    /// Light passes straight on (a mask's transparent part, `null`).
    Null,
}

macro_rules! each_family {
    ($family:expr, $f:ident => $body:expr, $null:expr) => {
        match $family {
            Family::Diffuse($f) => $body,
            Family::Conductor($f) => $body,
            Family::RoughConductor($f) => $body,
            Family::Dielectric($f) => $body,
            Family::ThinDielectric($f) => $body,
            Family::RoughDielectric($f) => $body,
            Family::Plastic($f) => $body,
            Family::RoughPlastic($f) => $body,
            Family::Principled($f) => $body,
            Family::PrincipledThin($f) => $body,
            Family::Gltf($f) => $body,
            Family::Null => $null,
        }
    };
}

/// A tilted frame's record: the frame it tilted and the tilted normal in that frame's
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tilt {
    parent: Frame,
    normal: Vec3,
}

impl Tilt {
    /// Estevez et al.'s shadowing term for `d` (world) in the parent frame.
    #[inline]
    fn shadowing(&self, d_parent: Vec3) -> f32 {
        let alpha2 = (0.125 * tan2(self.normal)).min(1.0);
        2.0 / (1.0 + (1.0 + alpha2 * tan2(d_parent)).sqrt())
    }
}

#[inline]
fn tan2(v: Vec3) -> f32 {
    let cos2 = v.z * v.z;
    ((1.0 - cos2).max(0.0) / cos2).max(0.0)
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Leaf {
    family: Family,
    weight: f32,
    /// The leaf's shading frame in world space (its `w` negated on a two-sided BSDF's back).
    frame: Frame,
    tilt: Option<Tilt>,
}

impl Leaf {
    /// f·cos and the density of the leaf for directions in world space, with a tilt's
    /// orientation test and shadowing.
    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        let mut shadow = 1.0;
        if let Some(tilt) = &self.tilt {
            let parent_wi = tilt.parent.to_local(wi);
            if parent_wi.z * li.z <= 0.0 {
                return (Color::ZERO, 0.0);
            }
            shadow = tilt.shadowing(parent_wi);
        }
        let (f, pdf) = each_family!(&self.family, s => s.eval_pdf(lo, li), (Color::ZERO, 0.0));
        (f * shadow, pdf)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let lo = self.frame.to_local(wo);
        let mut sample = match &self.family {
            Family::Null => BsdfSample {
                wi: -lo,
                weight: Color::ONE,
                pdf: 1.0,
                is_specular: true,
                eta: 1.0,
            },
            family => each_family!(family, s => s.sample(lo, u_lobe, u), None)?,
        };
        let wi = self.frame.to_world(sample.wi);
        if let Some(tilt) = &self.tilt {
            let parent_wi = tilt.parent.to_local(wi);
            if parent_wi.z * sample.wi.z <= 0.0 {
                return None;
            }
            sample.weight *= tilt.shadowing(parent_wi);
        }
        sample.wi = wi;
        Some(sample)
    }

    fn has_non_delta(&self) -> bool {
        each_family!(&self.family, s => s.has_non_delta(), false)
    }

    /// Whether `sample` (world ωi) of this leaf passes straight through it: a null leaf, or a
    /// thin dielectric's transmission (Mitsuba's `Null` events).
    #[inline]
    fn is_null(&self, wo: Vec3, sample: &BsdfSample) -> bool {
        match &self.family {
            Family::Null => true,
            // Its transmission leaves on the other side; its reflection, even at grazing
            // angles where ωi and ωo point apart, on the same one.
            Family::ThinDielectric(_) => self.frame.w.dot(sample.wi) * self.frame.w.dot(wo) < 0.0,
            _ => false,
        }
    }

    /// What passes straight through the leaf towards −ωo (Mitsuba's
    /// `eval_null_transmission`).
    #[inline]
    fn null_transmission(&self, wo: Vec3) -> Color {
        match &self.family {
            Family::Null => Color::ONE,
            Family::ThinDielectric(thin) => {
                let cos = self.frame.to_local(wo).z;
                thin.specular_transmittance * (1.0 - thin.reflectance(cos))
            }
            _ => Color::ZERO,
        }
    }

    fn albedo(&self) -> Color {
        each_family!(&self.family, s => s.albedo(), Color::ZERO)
    }
}

/// A physically based material's BSDF at one hit, for directions in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceBsdf {
    leaves: [Leaf; MAX_LEAVES],
    count: usize,
}

/// What resolving a tree reads.
struct Resolver<'a> {
    bsdfs: &'a [BsdfNode],
    textures: &'a [TextureNode],
    prepared: &'a [Option<RoughPlastic>],
    images: &'a [Image],
    surface: &'a PhysicalSurface,
    /// Towards the viewer, world space.
    wo: Vec3,
}

/// The tables of every rough plastic of `bsdfs` by BSDF id (`None` elsewhere): Mitsuba's
/// rough transmittance, tabulated once per material because it takes a million microfacet
/// evaluations. Its colours are the hit's; its roughness and index must be constants
/// (Mitsuba's are), read at uv (0, 0).
pub fn prepare_rough_plastics(
    bsdfs: &[BsdfNode],
    textures: &[TextureNode],
    images: &[Image],
) -> Vec<Option<RoughPlastic>> {
    let at = TexturePoint::default();
    bsdfs
        .iter()
        .map(|node| match node {
            BsdfNode::Plastic {
                eta,
                nonlinear,
                roughness: Some(r),
                ..
            } => Some(RoughPlastic::new(
                match r.distribution {
                    DistributionKind::Beckmann => Distribution::Beckmann,
                    DistributionKind::Ggx => Distribution::Ggx,
                },
                r.alpha_u.eval_float(textures, images, &at),
                r.sample_visible,
                *eta,
                Color::splat(0.5),
                Color::ONE,
                *nonlinear,
            )),
            _ => None,
        })
        .collect()
}

impl SurfaceBsdf {
    /// The BSDF of tree `id` of `bsdfs` (whose `Param::Texture`s index `textures`) at
    /// `surface`, seen from world direction `wo`; `prepared` is `prepare_rough_plastics` of
    /// the same trees.
    pub fn new(
        bsdfs: &[BsdfNode],
        textures: &[TextureNode],
        prepared: &[Option<RoughPlastic>],
        images: &[Image],
        id: BsdfId,
        surface: &PhysicalSurface,
        wo: Vec3,
    ) -> SurfaceBsdf {
        let mut bsdf = SurfaceBsdf {
            leaves: [Leaf {
                family: Family::Null,
                weight: 0.0,
                frame: surface.frame,
                tilt: None,
            }; MAX_LEAVES],
            count: 0,
        };
        let resolver = Resolver {
            bsdfs,
            textures,
            prepared,
            images,
            surface,
            wo,
        };
        resolver.add(&mut bsdf, id, 1.0, surface.frame, None, 0);
        // Leaves dropped for lack of room leave weights summing to less than one: make the
        // kept ones a distribution again.
        let total: f32 = bsdf.leaves[..bsdf.count].iter().map(|l| l.weight).sum();
        if total > 0.0 && (total - 1.0).abs() > 1e-6 {
            for leaf in &mut bsdf.leaves[..bsdf.count] {
                leaf.weight /= total;
            }
        }
        bsdf
    }

    /// True when the BSDF scatters nothing.
    pub fn is_black(&self) -> bool {
        self.count == 0
    }

    /// True when every leaf lets light pass straight on (a mask's cut-out, a culled back
    /// face): the surface is not there for this ray.
    pub fn passes_all(&self) -> bool {
        self.count > 0
            && self.leaves[..self.count]
                .iter()
                .all(|leaf| matches!(leaf.family, Family::Null))
    }

    /// Whether light sampling can find some leaf (Mitsuba's `Smooth` flag).
    pub fn has_non_delta(&self) -> bool {
        self.leaves[..self.count].iter().any(Leaf::has_non_delta)
    }

    /// The weighted mean of the leaves' albedos (the denoiser's feature).
    pub fn albedo(&self) -> Color {
        self.leaves[..self.count]
            .iter()
            .fold(Color::ZERO, |sum, leaf| sum + leaf.albedo() * leaf.weight)
            .clamp01()
    }

    /// f·|cos θi| and the sampling density for world directions `wo` (towards the viewer)
    /// and `wi` (towards the light).
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Color, f32) {
        let mut f = Color::ZERO;
        let mut pdf = 0.0;
        for leaf in &self.leaves[..self.count] {
            let (leaf_f, leaf_pdf) = leaf.eval_pdf(wo, wi);
            f += leaf_f * leaf.weight;
            pdf += leaf_pdf * leaf.weight;
        }
        (f, pdf)
    }

    /// What passes straight through the surface towards −ωo without changing direction (the
    /// null leaves and thin dielectrics' transmission, weighted): what a shadow ray keeps
    /// when it crosses the surface.
    pub fn null_transmission(&self, wo: Vec3) -> Color {
        self.leaves[..self.count]
            .iter()
            .fold(Color::ZERO, |sum, leaf| {
                sum + leaf.null_transmission(wo) * leaf.weight
            })
    }

    /// `sample`, and whether the sample passes straight through the surface (a null event:
    /// the volumetric path tracer does not count it as a bounce).
    pub fn sample_event(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<(BsdfSample, bool)> {
        let (leaf, u_leaf) = self.choose(u_lobe)?;
        let sample = self.sample_leaf(leaf, wo, u_leaf, u)?;
        let null = sample.is_specular && self.leaves[leaf].is_null(wo, &sample);
        Some((sample, null))
    }

    /// Draws a world direction ωi for `wo`; `BsdfSample::wi` is in world space.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: (f32, f32)) -> Option<BsdfSample> {
        let (leaf, u_leaf) = self.choose(u_lobe)?;
        self.sample_leaf(leaf, wo, u_leaf, u)
    }

    /// The leaf `u_lobe` picks (by weight) and the number left for the leaf's own choice.
    #[inline]
    fn choose(&self, u_lobe: f32) -> Option<(usize, f32)> {
        if self.count == 1 {
            return Some((0, u_lobe));
        }
        let mut start = 0.0;
        let mut chosen = self.count.checked_sub(1)?;
        for (index, leaf) in self.leaves[..self.count].iter().enumerate() {
            if u_lobe < start + leaf.weight {
                chosen = index;
                break;
            }
            start += leaf.weight;
        }
        let leaf = &self.leaves[chosen];
        if leaf.weight <= 0.0 {
            return None;
        }
        let u_leaf = ((u_lobe - start) / leaf.weight).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        Some((chosen, u_leaf))
    }

    /// A sample of leaf `index` (chosen by `choose`), weighed against the whole BSDF.
    #[inline]
    fn sample_leaf(
        &self,
        index: usize,
        wo: Vec3,
        u_leaf: f32,
        u: (f32, f32),
    ) -> Option<BsdfSample> {
        let leaf = &self.leaves[index];
        if self.count == 1 {
            return leaf.sample(wo, u_leaf, u);
        }
        let mut sample = leaf.sample(wo, u_leaf, u)?;
        if sample.is_specular {
            // A delta is not in the other leaves' densities: its weight stands, and its
            // probability includes the choice of the leaf.
            sample.pdf *= leaf.weight;
            return Some(sample);
        }
        let (f, pdf) = self.eval_pdf(wo, sample.wi);
        if pdf <= 0.0 {
            return None;
        }
        sample.weight = f / pdf;
        sample.pdf = pdf;
        Some(sample)
    }
}

impl Resolver<'_> {
    fn float(&self, p: &Param) -> f32 {
        p.eval_float(self.textures, self.images, &self.surface.texture)
    }

    fn color(&self, p: &Param) -> Color {
        p.eval(self.textures, self.images, &self.surface.texture)
    }

    /// A texture's value at the hit; `None` reads as white.
    fn texel(&self, texture: Option<u32>) -> Color {
        texture.map_or(Color::ONE, |i| {
            self.textures.get(i as usize).map_or(Color::ZERO, |node| {
                node.eval(self.images, &self.surface.texture)
            })
        })
    }

    /// A glTF material: its alpha (a null leaf for the part light passes), its sides, its
    /// normal map, then the family with every factor times its texture.
    fn add_gltf(
        &self,
        bsdf: &mut SurfaceBsdf,
        p: &GltfParams,
        weight: f32,
        mut frame: Frame,
        tilt: Option<Tilt>,
    ) {
        let opacity = match p.alpha_mode {
            GltfAlphaMode::Opaque => 1.0,
            mode => {
                let alpha = (p.alpha * self.texel(p.alpha_texture).x).clamp(0.0, 1.0);
                match mode {
                    GltfAlphaMode::Mask { cutoff } => f32::from(alpha >= cutoff),
                    _ => alpha,
                }
            }
        };
        let pass = |bsdf: &mut SurfaceBsdf, share: f32| {
            self.push(
                bsdf,
                Leaf {
                    family: Family::Null,
                    weight: weight * share,
                    frame,
                    tilt,
                },
            )
        };
        pass(bsdf, 1.0 - opacity);
        let weight = weight * opacity;
        if weight <= 0.0 {
            return;
        }
        let mut sign = self.surface.bitangent_sign;
        let volume = !p.thin_walled && p.has_transmission();
        if frame.to_local(self.wo).z < 0.0 && !volume {
            if p.double_sided || p.has_transmission() {
                // The back face is the front with its normal reversed.
                frame.w = -frame.w;
                sign = -sign;
            } else {
                // Culled: light passes the back face as if it were not there.
                pass(bsdf, opacity);
                return;
            }
        }
        // A volume's boundary seen from inside keeps its frame: the family refracts out.
        let mut tilt = tilt;
        if let Some(texture) = p.normal_texture {
            let t = self.texel(Some(texture)) * 2.0 - Color::ONE;
            let mut n = Vec3::new(t.x * p.normal_scale, t.y * p.normal_scale * sign, t.z);
            if frame.w.dot(self.surface.frame.w) < 0.0 {
                // The reversed back face: reversing the perturbed normal negates its
                // tangential part in the flipped frame.
                n = Vec3::new(-n.x, -n.y, n.z);
            }
            let wo_local = frame.to_local(self.wo);
            if wo_local.z * wo_local.dot(n) <= 0.0 {
                n = Vec3::new(-n.x, -n.y, n.z);
            }
            let n = n.normalized();
            if n.is_finite() && n.z > 0.0 {
                let s = (Vec3::X - n * n.x).normalized();
                let local = Frame {
                    u: s,
                    v: n.cross(s),
                    w: n,
                };
                tilt = Some(Tilt {
                    parent: frame,
                    normal: n,
                });
                frame = Frame {
                    u: frame.to_world(local.u),
                    v: frame.to_world(local.v),
                    w: frame.to_world(local.w),
                };
            }
        }
        let mut base_color = p.base_color.mul_elem(self.texel(p.base_color_texture));
        if p.vertex_color {
            base_color = base_color.mul_elem(self.surface.texture.vertex_color);
        }
        let mr = self.texel(p.metallic_roughness_texture);
        let family = Family::Gltf(GltfPbr {
            base_color: base_color.clamp01(),
            metallic: (p.metallic * mr.z).clamp(0.0, 1.0),
            roughness: (p.roughness * mr.y).clamp(0.0, 1.0),
            ior: p.ior,
            specular: (p.specular * self.texel(p.specular_texture).x).clamp(0.0, 1.0),
            specular_color: (p
                .specular_color
                .mul_elem(self.texel(p.specular_color_texture)))
            .max(Color::ZERO),
            transmission: (p.transmission * self.texel(p.transmission_texture).x).clamp(0.0, 1.0),
            thin_walled: p.thin_walled,
            clearcoat: (p.clearcoat * self.texel(p.clearcoat_texture).x).clamp(0.0, 1.0),
            clearcoat_roughness: (p.clearcoat_roughness
                * self.texel(p.clearcoat_roughness_texture).y)
                .clamp(0.0, 1.0),
        });
        self.push(
            bsdf,
            Leaf {
                family,
                weight,
                frame,
                tilt,
            },
        );
    }

    fn microfacet(&self, r: &Roughness) -> Microfacet {
        let distribution = match r.distribution {
            DistributionKind::Beckmann => Distribution::Beckmann,
            DistributionKind::Ggx => Distribution::Ggx,
        };
        Microfacet::new(
            distribution,
            self.float(&r.alpha_u),
            self.float(&r.alpha_v),
            r.sample_visible,
        )
    }

    fn push(&self, bsdf: &mut SurfaceBsdf, leaf: Leaf) {
        if leaf.weight <= 0.0 {
            return;
        }
        if bsdf.count < MAX_LEAVES {
            bsdf.leaves[bsdf.count] = leaf;
            bsdf.count += 1;
        } else if let Some(lightest) = bsdf.leaves.iter_mut().min_by(|a, b| {
            a.weight
                .partial_cmp(&b.weight)
                .unwrap_or(std::cmp::Ordering::Equal)
        }) {
            if lightest.weight < leaf.weight {
                *lightest = leaf;
            }
        }
    }

    /// Adds the leaves of node `id` with mixture weight `weight` in `frame`.
    fn add(
        &self,
        bsdf: &mut SurfaceBsdf,
        id: BsdfId,
        weight: f32,
        frame: Frame,
        tilt: Option<Tilt>,
        depth: u32,
    ) {
        let Some(node) = self.bsdfs.get(id as usize) else {
            return;
        };
        if depth > MAX_NESTING || weight <= 0.0 {
            return;
        }
        let leaf = |family: Family| Leaf {
            family,
            weight,
            frame,
            tilt,
        };
        match node {
            BsdfNode::Diffuse { reflectance } => self.push(
                bsdf,
                leaf(Family::Diffuse(Diffuse {
                    reflectance: self.color(reflectance),
                })),
            ),
            BsdfNode::Conductor {
                eta_k,
                specular_reflectance,
                roughness,
            } => {
                let specular = self.color(specular_reflectance);
                let eta_k = eta_k.map(|(eta, k)| (self.color(&eta), self.color(&k)));
                let family = match (roughness, eta_k) {
                    (None, Some((eta, k))) => Family::Conductor(Conductor {
                        eta,
                        k,
                        specular_reflectance: specular,
                    }),
                    (None, None) => Family::Conductor(Conductor::mirror(specular)),
                    (Some(r), Some((eta, k))) => Family::RoughConductor(RoughConductor {
                        eta,
                        k,
                        specular_reflectance: specular,
                        microfacet: self.microfacet(r),
                    }),
                    (Some(r), None) => {
                        Family::RoughConductor(RoughConductor::mirror(specular, self.microfacet(r)))
                    }
                };
                self.push(bsdf, leaf(family));
            }
            BsdfNode::Dielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
                roughness,
            } => {
                let (r, t) = (
                    self.color(specular_reflectance),
                    self.color(specular_transmittance),
                );
                let family = match roughness {
                    None => Family::Dielectric(Dielectric {
                        eta: *eta,
                        specular_reflectance: r,
                        specular_transmittance: t,
                    }),
                    Some(rough) => Family::RoughDielectric(RoughDielectric {
                        eta: *eta,
                        specular_reflectance: r,
                        specular_transmittance: t,
                        microfacet: self.microfacet(rough),
                    }),
                };
                self.push(bsdf, leaf(family));
            }
            BsdfNode::ThinDielectric {
                eta,
                specular_reflectance,
                specular_transmittance,
            } => self.push(
                bsdf,
                leaf(Family::ThinDielectric(ThinDielectric {
                    eta: *eta,
                    specular_reflectance: self.color(specular_reflectance),
                    specular_transmittance: self.color(specular_transmittance),
                })),
            ),
            BsdfNode::Plastic {
                eta,
                diffuse_reflectance,
                specular_reflectance,
                nonlinear,
                roughness,
            } => {
                let (d, sp) = (
                    self.color(diffuse_reflectance),
                    self.color(specular_reflectance),
                );
                let family = match (roughness, self.prepared.get(id as usize)) {
                    (Some(_), Some(Some(tables))) => {
                        let mean = |c: Color| (c.x + c.y + c.z) / 3.0;
                        Family::RoughPlastic(RoughPlastic {
                            diffuse_reflectance: d,
                            specular_reflectance: sp,
                            specular_sampling_weight: specular_sampling_weight(mean(d), mean(sp)),
                            ..*tables
                        })
                    }
                    // A rough plastic nobody prepared (never from `SurfaceBsdf::new`'s
                    // callers) scatters nothing rather than tabulate per hit.
                    (Some(_), _) => return,
                    (None, _) => Family::Plastic(Plastic::new(d, sp, *eta, *nonlinear)),
                };
                self.push(bsdf, leaf(family));
            }
            BsdfNode::Principled(p) => {
                let has_spec_trans = p.spec_trans.is_textured() || self.float(&p.spec_trans) != 0.0;
                let family = Family::Principled(
                    Principled {
                        base_color: self.color(&p.base_color),
                        roughness: self.float(&p.roughness),
                        anisotropic: self.float(&p.anisotropic),
                        metallic: self.float(&p.metallic),
                        spec_trans: self.float(&p.spec_trans),
                        spec_tint: self.float(&p.spec_tint),
                        sheen: self.float(&p.sheen),
                        sheen_tint: self.float(&p.sheen_tint),
                        flatness: self.float(&p.flatness),
                        clearcoat: self.float(&p.clearcoat),
                        clearcoat_gloss: self.float(&p.clearcoat_gloss),
                        sample_visible: p.sample_visible,
                        ..Principled::new()
                    }
                    .with_eta(self.float(&p.eta), has_spec_trans),
                );
                self.push(bsdf, leaf(family));
            }
            BsdfNode::PrincipledThin(p) => {
                let family = Family::PrincipledThin(PrincipledThin {
                    base_color: self.color(&p.base_color),
                    roughness: self.float(&p.roughness),
                    anisotropic: self.float(&p.anisotropic),
                    spec_trans: self.float(&p.spec_trans),
                    diff_trans: self.float(&p.diff_trans),
                    eta: self.float(&p.eta),
                    spec_tint: self.float(&p.spec_tint),
                    sheen: self.float(&p.sheen),
                    sheen_tint: self.float(&p.sheen_tint),
                    flatness: self.float(&p.flatness),
                    sample_visible: p.sample_visible,
                    ..PrincipledThin::new()
                });
                self.push(bsdf, leaf(family));
            }
            BsdfNode::Null => self.push(bsdf, leaf(Family::Null)),
            BsdfNode::Gltf(p) => self.add_gltf(bsdf, p, weight, frame, tilt),
            BsdfNode::TwoSided { front, back } => {
                if frame.to_local(self.wo).z >= 0.0 {
                    self.add(bsdf, *front, weight, frame, tilt, depth + 1);
                } else {
                    let flipped = Frame {
                        u: frame.u,
                        v: frame.v,
                        w: -frame.w,
                    };
                    self.add(bsdf, *back, weight, flipped, tilt, depth + 1);
                }
            }
            BsdfNode::Mask { opacity, nested } => {
                let opacity = self.float(opacity).clamp(0.0, 1.0);
                self.add(bsdf, *nested, weight * opacity, frame, tilt, depth + 1);
                self.push(
                    bsdf,
                    Leaf {
                        family: Family::Null,
                        weight: weight * (1.0 - opacity),
                        frame,
                        tilt,
                    },
                );
            }
            BsdfNode::Blend {
                weight: blend,
                first,
                second,
            } => {
                let w = self.float(blend).clamp(0.0, 1.0);
                self.add(bsdf, *first, weight * (1.0 - w), frame, tilt, depth + 1);
                self.add(bsdf, *second, weight * w, frame, tilt, depth + 1);
            }
            BsdfNode::NormalMap { normals, nested } => {
                let texel = self
                    .textures
                    .get(*normals as usize)
                    .map_or(Vec3::new(0.5, 0.5, 1.0), |node| {
                        node.eval(self.images, &self.surface.texture)
                    });
                let mut n = texel * 2.0 - Vec3::ONE;
                // Shading normals face the viewer (Mitsuba's `flip_invalid_normals`).
                let wo_local = frame.to_local(self.wo);
                if wo_local.z * wo_local.dot(n) <= 0.0 {
                    n = Vec3::new(-n.x, -n.y, n.z);
                }
                let n = n.normalized();
                if !n.is_finite() {
                    return;
                }
                let s = (Vec3::X - n * n.x).normalized();
                let local = Frame {
                    u: s,
                    v: n.cross(s),
                    w: n,
                };
                let tilted = Frame {
                    u: frame.to_world(local.u),
                    v: frame.to_world(local.v),
                    w: frame.to_world(local.w),
                };
                let tilt = Some(Tilt {
                    parent: frame,
                    normal: n,
                });
                self.add(bsdf, *nested, weight, tilted, tilt, depth + 1);
            }
            BsdfNode::BumpMap {
                height,
                scale,
                nested,
            } => {
                let Some(node) = self.textures.get(*height as usize) else {
                    return;
                };
                let (gu, gv) = node.gradient(self.images, &self.surface.texture);
                let (gu, gv) = (gu * scale, gv * scale);
                let n = frame.w;
                let dp_du = self.surface.dp_du + n * (gu - n.dot(self.surface.dp_du));
                let dp_dv = self.surface.dp_dv + n * (gv - n.dot(self.surface.dp_dv));
                let mut bumped = dp_du.cross(dp_dv).normalized();
                if !bumped.is_finite() {
                    return;
                }
                if self.surface.normal.dot(bumped) < 0.0 {
                    bumped = -bumped;
                }
                let mut local_n = frame.to_local(bumped);
                let wo_local = frame.to_local(self.wo);
                if wo_local.z * self.wo.dot(bumped) <= 0.0 {
                    local_n = Vec3::new(-local_n.x, -local_n.y, local_n.z);
                }
                let world_n = frame.to_world(local_n);
                let s =
                    (self.surface.dp_du - world_n * world_n.dot(self.surface.dp_du)).normalized();
                if !s.is_finite() {
                    return;
                }
                let tilted = Frame {
                    u: s,
                    v: world_n.cross(s),
                    w: world_n,
                };
                let tilt = Some(Tilt {
                    parent: frame,
                    normal: local_n,
                });
                self.add(bsdf, *nested, weight, tilted, tilt, depth + 1);
            }
        }
    }
}
