//! The plane model at a subsurface exit point xo (`docs/bssrdf.md` §5;
//! the estimator's math: [`crate::integrator::control_variate`]): g, the
//! light a sample brings through the entry lobe at a model point,
//! unshadowed, and the choice between a probe and its mirror it makes.

use super::probe_at::ProbeAt;
use crate::bssrdf::PlaneModel;
use crate::geometry::Vec3;
use crate::integrator::coated::Ahead;
use crate::integrator::control_variate::{self, MirrorChoice};
use crate::integrator::nee::unshadowed_at;
use crate::lights::LightSample;
use crate::materials::Subsurface;
use crate::sampling::cosine_hemisphere_pdf;

/// The light samples drawn ahead for the entry point and its twin, when
/// the control variate applies.
pub(super) type Lights = Option<[Option<LightSample>; 2]>;

/// The model at xo and the constants of its term.
struct CvModel<'s> {
    ss: &'s Subsurface,
    xo: Vec3,
    n: Vec3,
    kappa: f32,
}

impl<'s> CvModel<'s> {
    /// The model at the hit of `at` (its shading frame and mean
    /// curvature).
    fn new(at: &ProbeAt<'_, 's>) -> Self {
        let ss = at.ss;
        CvModel {
            ss,
            xo: at.si.p,
            n: at.frame_o.n,
            kappa: at.k_mean,
        }
    }

    /// g at the model point over the disk offset `d`: what light sample
    /// `ls` brings through the entry lobe there, MIS-weighted as next-event
    /// estimation weighs it, without a shadow ray.
    fn g(&self, d: Vec3, ls: &LightSample) -> Vec3 {
        let (p, n) = control_variate::model_point(self.xo, self.n, self.kappa, d);
        // The entry lobe reads only cos θ = ωi·n: no frame is built.
        unshadowed_at(
            p,
            n,
            ls,
            |wi| Vec3::new(0.0, 0.0, wi.dot(n)),
            |wi_local| Vec3::splat(self.ss.lobe(wi_local.z)),
            |wi_local| cosine_hemisphere_pdf(wi_local.z),
        )
        .unwrap_or(Vec3::ZERO)
    }

    /// The probability of following the probe at offset `d` rather than
    /// its mirror under light sample `ls`.
    fn probability_of_probe(&self, d: Vec3, ls: &LightSample) -> f32 {
        control_variate::probability_of_probe(self.g(Vec3::ZERO, ls), self.g(d, ls), self.g(-d, ls))
    }
}

/// What the model adds to a hit's entries: the light samples drawn ahead
/// (the entry point's next-event estimation uses the one the model used).
pub(super) fn ahead(lights: Lights) -> Ahead {
    Ahead { lights }
}

/// Which of a probe along N with plane model `plane` and its mirror the
/// path follows, under the entry point's light sample; `u` draws the
/// uniform number, only where there is a choice. The probe itself where
/// the model does not apply (no light sample, no plane model: T and B).
pub(super) fn mirror_choice(
    at: &ProbeAt,
    lights: &Lights,
    plane: Option<&PlaneModel>,
    u: impl FnOnce() -> f32,
) -> MirrorChoice {
    match (lights, plane) {
        (Some([Some(ls), _]), Some(pm)) => {
            let p = CvModel::new(at).probability_of_probe(pm.offset, ls);
            control_variate::choose(p, u())
        }
        _ => MirrorChoice::PROBE,
    }
}
