//! The non-specular lobes a path vertex scatters with, and the vertex
//! itself: pbrt-v4's BSDF at a surface interaction, reduced to the lobes
//! this renderer has (`docs/bssrdf.md` §1, §6 "The coat").

mod sample;
#[cfg(feature = "subsurface")]
mod subsurface;

use super::aov::Event;
use super::interaction::offset_along;
use crate::geometry::{Frame, Ray, Vec3};
use crate::materials::{diffuse, Conductor, Plastic};
pub(crate) use sample::LobeSample;
#[cfg(feature = "subsurface")]
pub(crate) use subsurface::SubsurfaceLobe;

/// A build without the `subsurface` feature has no subsurface material:
/// the bounce loop's handler of subsurface hits takes this uninhabited
/// type, so it can never be called, and the compiler drops it and every
/// path through it (docs/performance.md, "Zero cost for what is off").
#[cfg(not(feature = "subsurface"))]
#[derive(Clone, Copy)]
pub(crate) enum Subsurface {}

/// Without the `subsurface` feature: no subsurface lobe (it borrows the
/// uninhabited [`Subsurface`]).
#[cfg(not(feature = "subsurface"))]
#[derive(Clone, Copy)]
pub(crate) struct SubsurfaceLobe<'a>(&'a Subsurface);

#[cfg(not(feature = "subsurface"))]
impl SubsurfaceLobe<'_> {
    fn event(&self) -> Event {
        match *self.0 {}
    }
    fn eval(&self, _: Vec3, _: Vec3) -> Vec3 {
        match *self.0 {}
    }
    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        match *self.0 {}
    }
    fn sample(&self, _: Vec3, _: [f32; 2]) -> Option<LobeSample> {
        match *self.0 {}
    }
}

/// A non-specular lobe at a path vertex, in a local frame whose z axis is
/// the normal on the side light leaves towards.
#[derive(Clone, Copy)]
pub(crate) enum Lobe<'a> {
    /// Lambertian reflection, ρ/π.
    Diffuse(Vec3),
    /// A rough conductor's GGX reflection.
    Conductor(&'a Conductor),
    /// A plastic's coat and base (the base alone under a smooth coat).
    Plastic(&'a Plastic),
    /// A subsurface material's or medium's lobe.
    #[cfg_attr(not(feature = "subsurface"), allow(dead_code))]
    Subsurface(SubsurfaceLobe<'a>),
}

impl Lobe<'_> {
    /// The light-path class of scattering by this lobe ([`super::aov`]).
    pub(crate) fn event(&self) -> Event {
        match self {
            Lobe::Diffuse(_) | Lobe::Plastic(_) => Event::Diffuse,
            Lobe::Conductor(_) => Event::Specular,
            Lobe::Subsurface(s) => s.event(),
        }
    }

    /// f(ωo, ωi) per steradian (ωo, ωi local; z > 0 is the lit side).
    pub(crate) fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Lobe::Diffuse(albedo) => diffuse::eval(*albedo, wo, wi),
            Lobe::Conductor(c) => c.eval(wo, wi),
            Lobe::Plastic(p) => p.eval(wo, wi),
            Lobe::Subsurface(s) => s.eval(wo, wi),
        }
    }

    /// The solid-angle pdf with which [`Lobe::sample`] picks ωi.
    pub(crate) fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Lobe::Diffuse(_) => diffuse::pdf(wo, wi),
            Lobe::Conductor(c) => c.pdf(wo, wi),
            Lobe::Plastic(p) => p.pdf(wo, wi),
            Lobe::Subsurface(s) => s.pdf(wo, wi),
        }
    }

    /// Samples ωi with the randoms `u`; None where the lobe loses the
    /// sample.
    pub(crate) fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<LobeSample> {
        match self {
            Lobe::Diffuse(albedo) => diffuse::sample(*albedo, wo, u).map(LobeSample::new),
            Lobe::Conductor(c) => c.sample(wo, u).map(LobeSample::glossy),
            Lobe::Plastic(p) => p.sample(wo, u).map(LobeSample::glossy),
            Lobe::Subsurface(s) => s.sample(wo, u),
        }
    }
}

/// A vertex where a non-specular lobe scatters: position, geometric normal
/// facing the lit side, and the shading frame.
pub(crate) struct Vertex<'a> {
    pub(crate) p: Vec3,
    pub(crate) ng: Vec3,
    pub(crate) frame: Frame,
    pub(crate) wo_local: Vec3,
    pub(crate) lobe: Lobe<'a>,
    /// The object the vertex lies on, when rays leaving it on the side of
    /// `ng` cannot meet that object again ([`super::Context::leaving`]);
    /// None where that is not known.
    pub(crate) outside_of: Option<u32>,
}

/// The last non-specular vertex of a path and the solid-angle pdf with
/// which its lobe sampled the current ray, for the emission MIS weight.
#[derive(Clone, Copy)]
pub(crate) struct PrevVertex {
    pub(crate) p: Vec3,
    pub(crate) pdf: f32,
}

/// A path's next ray, with its throughput and the vertex its lobe sampled
/// it from (None for a specular bounce).
#[derive(Clone, Copy)]
pub(crate) struct Bounce {
    pub(crate) ray: Ray,
    pub(crate) beta: Vec3,
    pub(crate) prev: Option<PrevVertex>,
}

impl Vertex<'_> {
    /// The ray its lobe samples with the randoms `u`, the throughput `beta`
    /// times the sample's weight; None when the sample is lost (by the lobe,
    /// or below the geometric surface, where a shading normal would leak
    /// light through it).
    #[inline(always)]
    pub(crate) fn bounce(&self, ray_epsilon: f32, beta: Vec3, u: [f32; 2]) -> Option<Bounce> {
        let s = self.lobe.sample(self.wo_local, u)?;
        let wi = self.frame.to_world(s.wi);
        if wi.dot(self.ng) <= 0.0 {
            return None;
        }
        Some(Bounce {
            ray: Ray::new(offset_along(self.p, self.ng, ray_epsilon), wi),
            beta: beta * s.weight,
            prev: Some(PrevVertex {
                p: self.p,
                pdf: s.pdf,
            }),
        })
    }
}
