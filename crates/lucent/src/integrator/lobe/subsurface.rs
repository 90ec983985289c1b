//! The lobes of subsurface materials and media at a path vertex: the
//! entry lobe at xi, the random walk's exit lobe and the rough coat at xo
//! (`docs/bssrdf.md` §6).

use super::sample::LobeSample;
use crate::geometry::Vec3;
use crate::integrator::aov::Event;
use crate::integrator::diffuse_boundary::ExitLobe;
use crate::materials::microfacet::RoughCoat;
use crate::materials::Subsurface;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};

/// A subsurface material's or medium's lobe at a path vertex.
#[derive(Clone, Copy)]
pub(crate) enum SubsurfaceLobe<'a> {
    /// The entry-point lobe of a subsurface material (Sw or 1/π), outward
    /// side only; its spectral weight was already applied by the probe.
    Entry(&'a Subsurface),
    /// Where a random walk left the medium through a diffuse Fresnel
    /// boundary ([`ExitLobe`]).
    WalkExit(ExitLobe),
    /// A subsurface material's rough coat at xo, sampled with probability
    /// `select` (its pdf, for MIS, is select × the visible-normal pdf).
    Coat { coat: &'a RoughCoat, select: f32 },
}

impl SubsurfaceLobe<'_> {
    pub(super) fn event(&self) -> Event {
        match self {
            SubsurfaceLobe::Entry(_) | SubsurfaceLobe::WalkExit(_) => Event::Subsurface,
            SubsurfaceLobe::Coat { .. } => Event::Specular,
        }
    }

    pub(super) fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            SubsurfaceLobe::Entry(ss) => Vec3::splat(ss.lobe(wi.z)),
            SubsurfaceLobe::WalkExit(exit) => Vec3::splat(exit.eval(wi)),
            SubsurfaceLobe::Coat { coat, .. } => Vec3::splat(coat.eval(wo, wi)),
        }
    }

    pub(super) fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            SubsurfaceLobe::Entry(_) => cosine_hemisphere_pdf(wi.z),
            SubsurfaceLobe::WalkExit(exit) => exit.pdf(wi),
            SubsurfaceLobe::Coat { coat, select } => select * coat.pdf(wo, wi),
        }
    }

    pub(super) fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<LobeSample> {
        match self {
            SubsurfaceLobe::Entry(ss) => {
                let wi = cosine_hemisphere(u);
                let pdf = cosine_hemisphere_pdf(wi.z);
                (pdf > 0.0)
                    .then(|| LobeSample::new((wi, Vec3::splat(ss.lobe(wi.z) * wi.z / pdf), pdf)))
            }
            SubsurfaceLobe::WalkExit(exit) => exit
                .sample(u)
                .map(|(wi, w, pdf)| LobeSample::new((wi, Vec3::splat(w), pdf))),
            SubsurfaceLobe::Coat { coat, select } => {
                let (wi, w, pdf) = coat.sample(wo, u)?;
                (*select > 0.0)
                    .then(|| LobeSample::new((wi, Vec3::splat(w / select), select * pdf)))
            }
        }
    }
}
