//! The plane control variate's model at a subsurface exit point xo
//! (`docs/bssrdf.md` §5; the estimator's math: [`crate::integrator::control_variate`]):
//! g, the light a sample brings through the entry lobe at a model point,
//! unshadowed, and the terms it adds at one probe or a pair.

use super::probe_at::ProbeAt;
use crate::bssrdf::PlaneModel;
use crate::geometry::Vec3;
use crate::integrator::coated::Ahead;
use crate::integrator::control_variate;
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
    /// A_plane per channel.
    a_plane: Vec3,
    /// f(κo): the curvature correction of the model surface (1 without).
    f_o: Vec3,
}

impl<'s> CvModel<'s> {
    /// The model at the hit of `at` (its shading frame and mean
    /// curvature), with the curvature correction's exit half if any.
    fn new(at: &ProbeAt<'_, 's>) -> Self {
        let ss = at.ss;
        CvModel {
            ss,
            xo: at.si.p,
            n: at.frame_o.n,
            kappa: at.k_mean,
            a_plane: Vec3::from_array(ss.probe().planar_reflectance().map(|a| a as f32)),
            f_o: at
                .exit
                .map(|e| e.1)
                .map_or(Vec3::ONE, |e| e.at_exit_alone()),
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

    /// C of one probe along N with plane model `pm` and light sample `ls`.
    fn one_probe(&self, pm: &PlaneModel, ls: &LightSample) -> Vec3 {
        let d = pm.offset;
        control_variate::one_probe(
            pm,
            self.a_plane,
            self.g(Vec3::ZERO, ls),
            self.g(d, ls),
            self.g(-d, ls),
        )
    }
}

/// The control variate's part at one probe with plane model `plane`,
/// its term × the throughput `beta_in` before the probe.
pub(super) fn one_probe_ahead(
    at: &ProbeAt,
    lights: Lights,
    plane: Option<&PlaneModel>,
    beta_in: Vec3,
) -> Ahead {
    let mut ahead = Ahead::default();
    if let Some(lights) = lights {
        ahead.lights = Some(lights);
        if let (Some(ls), Some(pm)) = (&lights[0], plane) {
            let model = CvModel::new(at);
            let c = model.one_probe(pm, ls);
            ahead.terms[0] = (-(beta_in * model.f_o) * c, ls.index);
        }
    }
    ahead
}

/// The control variate's part at an antithetic pair: the term split by
/// light sample (it is linear in the g_k), so each part is recorded with
/// the light it sampled.
pub(super) fn pair_ahead(
    at: &ProbeAt,
    lights: Lights,
    plane: Option<&PlaneModel>,
    beta_in: Vec3,
) -> Ahead {
    let mut ahead = Ahead::default();
    if let Some(lights) = lights {
        ahead.lights = Some(lights);
        if let Some(pm) = plane {
            let model = CvModel::new(at);
            let g0 = lights.map(|l| l.map_or(Vec3::ZERO, |ls| model.g(Vec3::ZERO, &ls)));
            for (k, light) in lights.iter().enumerate() {
                if let Some(ls) = light {
                    let mut gk = [Vec3::ZERO; 2];
                    gk[k] = g0[k];
                    let c = control_variate::pair(pm, model.a_plane, gk);
                    ahead.terms[k] = (-(beta_in * model.f_o) * c, ls.index);
                }
            }
        }
    }
    ahead
}
