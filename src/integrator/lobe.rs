//! The non-specular lobes a path vertex scatters with, and the vertex
//! itself: pbrt-v4's BSDF at a surface interaction, reduced to the lobes
//! this renderer has (`docs/bssrdf.md` §1, §6 "The coat").

use super::aov::Event;
use super::interaction::offset_along;
use crate::geometry::{Frame, Ray, Vec3};
use crate::materials::diffuse;
#[cfg(feature = "subsurface")]
use crate::materials::microfacet::RoughCoat;
#[cfg(feature = "subsurface")]
use crate::materials::Subsurface;
#[cfg(feature = "subsurface")]
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};

/// A build without the `subsurface` feature has no subsurface material:
/// the bounce loop's handler of subsurface hits takes this uninhabited
/// type, so it can never be called, and the compiler drops it and every
/// path through it (docs/performance.md, "Zero cost for what is off").
#[cfg(not(feature = "subsurface"))]
#[derive(Clone, Copy)]
pub(crate) enum Subsurface {}

/// A non-specular lobe at a path vertex, in a local frame whose z axis is
/// the normal on the side light leaves towards.
#[derive(Clone, Copy)]
pub(crate) enum Lobe<'a> {
    /// Lambertian reflection, ρ/π.
    Diffuse(Vec3),
    /// The entry-point lobe of a subsurface material (Sw or 1/π), outward
    /// side only; its spectral weight was already applied by the probe.
    #[cfg(feature = "subsurface")]
    SubsurfaceEntry(&'a Subsurface),
    /// Where a random walk left the medium through a diffuse Fresnel
    /// boundary ([`super::diffuse_boundary::ExitLobe`]).
    #[cfg(feature = "subsurface")]
    WalkExit(super::diffuse_boundary::ExitLobe),
    /// A subsurface material's rough coat at xo, sampled with probability
    /// `select` (its pdf, for MIS, is select × the visible-normal pdf).
    #[cfg(feature = "subsurface")]
    Coat { coat: &'a RoughCoat, select: f32 },
    /// Without the `subsurface` feature: no lobe (uninhabited), keeping
    /// the lifetime the subsurface lobes borrow with.
    #[cfg(not(feature = "subsurface"))]
    #[allow(dead_code)]
    Absent(&'a Subsurface),
}

/// A direction sampled from a lobe (local frame), with f |cos θ| / pdf
/// and the solid-angle pdf.
#[derive(Clone, Copy)]
pub(crate) struct LobeSample {
    pub(crate) wi: Vec3,
    pub(crate) weight: Vec3,
    pub(crate) pdf: f32,
}

impl LobeSample {
    fn new((wi, weight, pdf): (Vec3, Vec3, f32)) -> Self {
        LobeSample { wi, weight, pdf }
    }
}

impl Lobe<'_> {
    /// The light-path class of scattering by this lobe ([`super::aov`]).
    pub(crate) fn event(&self) -> Event {
        match self {
            Lobe::Diffuse(_) => Event::Diffuse,
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(_) | Lobe::WalkExit(_) => Event::Subsurface,
            #[cfg(feature = "subsurface")]
            Lobe::Coat { .. } => Event::Specular,
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
        }
    }

    /// f(ωo, ωi) per steradian (ωo, ωi local; z > 0 is the lit side).
    pub(crate) fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Lobe::Diffuse(albedo) => diffuse::eval(*albedo, wo, wi),
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(ss) => Vec3::splat(ss.lobe(wi.z)),
            #[cfg(feature = "subsurface")]
            Lobe::WalkExit(exit) => Vec3::splat(exit.eval(wi)),
            #[cfg(feature = "subsurface")]
            Lobe::Coat { coat, .. } => Vec3::splat(coat.eval(wo, wi)),
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
        }
    }

    /// The solid-angle pdf with which [`Lobe::sample`] picks ωi.
    pub(crate) fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Lobe::Diffuse(_) => diffuse::pdf(wo, wi),
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(_) => cosine_hemisphere_pdf(wi.z),
            #[cfg(feature = "subsurface")]
            Lobe::WalkExit(exit) => exit.pdf(wi),
            #[cfg(feature = "subsurface")]
            Lobe::Coat { coat, select } => select * coat.pdf(wo, wi),
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
        }
    }

    /// Samples ωi with the randoms `u`; None where the lobe loses the
    /// sample.
    pub(crate) fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<LobeSample> {
        match self {
            Lobe::Diffuse(albedo) => diffuse::sample(*albedo, wo, u).map(LobeSample::new),
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(ss) => {
                let wi = cosine_hemisphere(u);
                let pdf = cosine_hemisphere_pdf(wi.z);
                (pdf > 0.0)
                    .then(|| LobeSample::new((wi, Vec3::splat(ss.lobe(wi.z) * wi.z / pdf), pdf)))
            }
            #[cfg(feature = "subsurface")]
            Lobe::WalkExit(exit) => exit
                .sample(u)
                .map(|(wi, w, pdf)| LobeSample::new((wi, Vec3::splat(w), pdf))),
            #[cfg(feature = "subsurface")]
            Lobe::Coat { coat, select } => {
                let (wi, w, pdf) = coat.sample(wo, u)?;
                (*select > 0.0)
                    .then(|| LobeSample::new((wi, Vec3::splat(w / select), select * pdf)))
            }
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
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
