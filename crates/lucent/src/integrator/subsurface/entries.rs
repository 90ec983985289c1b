//! The entry points xi of a subsurface hit: one probe, or an antithetic
//! pair, each with the control variate's part where it applies; or, where
//! the footprint is wide, xo itself (`docs/bssrdf.md` §5, §10, §11).

use super::cv_model::{ahead, mirror_choice, Lights};
use super::probe_at::ProbeAt;
use crate::bssrdf::{ProbeRandoms, ProbeSegment};
use crate::geometry::curvature::TriangleCurvature;
use crate::geometry::{Frame, Vec3};
use crate::integrator::aov::Recorder;
use crate::integrator::coated::{Ahead, Coated, Weighted};
use crate::integrator::control_variate::{self, MirrorChoice};
use crate::integrator::lobe::{Bounce, Lobe, SubsurfaceLobe, Vertex};
use crate::integrator::nee::draw_light;
use crate::integrator::probe::{entry_on_segment, ProbeTarget};
use crate::integrator::scatter::{Scatter, SubsurfaceHit};
use crate::integrator::state::PathState;
use crate::integrator::{Context, Effect, Interaction};
use crate::materials::Subsurface;
use crate::sampling::Draw;

/// What the probes of a hit found: the entry vertex (the path's throughput
/// already scaled by its weight), its pair's twin, and the control
/// variate's part.
pub(super) struct Entries<'s> {
    entry: Option<Vertex<'s>>,
    pair: Option<Weighted<'s>>,
    /// [`Coated::paths_each`].
    paths_each: u32,
    ahead: Ahead,
}

impl<'s> Entries<'s> {
    /// No entry point and no control variate.
    pub(super) fn none() -> Self {
        Entries::new(None, Ahead::default())
    }

    fn new(entry: Option<Vertex<'s>>, ahead: Ahead) -> Self {
        Entries {
            entry,
            pair: None,
            paths_each: 0,
            ahead,
        }
    }

    /// As what the hit turns into, with no coat: the entry vertex, or the
    /// end of the path, unless a pair or the control variate adds more.
    pub(super) fn into_scatter(self) -> Scatter<'s> {
        match self {
            Entries {
                entry: Some(v),
                pair: None,
                ahead,
                ..
            } if ahead.lights.is_none() => Scatter::Vertex(v),
            Entries {
                entry: None, ahead, ..
            } if ahead.lights.is_none() => Scatter::Absorbed,
            e => Scatter::Coated(e.under(None, None)),
        }
    }

    /// Under a coat with the lit vertex `coat` and the reflection
    /// `reflected`.
    pub(super) fn under(self, coat: Option<Weighted<'s>>, reflected: Option<Bounce>) -> Coated<'s> {
        Coated {
            coat,
            reflected,
            entry: self.entry,
            pair: self.pair,
            paths_each: self.paths_each,
            ahead: self.ahead,
        }
    }
}

/// The entry vertices the path goes on from at a subsurface hit, `beta`
/// scaled by the chosen one's probe weight: one probe, or below
/// `ctx.pair_depth` where the material asks for it an antithetic pair;
/// else below `ctx.cv_depth` where the material asks for it the probe or
/// its mirror as the plane model chooses, with the light sample it drew. Where the material's
/// level-of-detail rule applies to the footprint, no probe: xo itself.
pub(super) fn entries<'s, R: Recorder>(
    ctx: &Context,
    hit: &SubsurfaceHit<'_, 's>,
    beta: &mut Vec3,
    st: &mut PathState<R>,
) -> Entries<'s> {
    let (ss, si) = (hit.ss, hit.si);
    let frame_o = si.shading_frame_facing(hit.wo);
    let TriangleCurvature {
        exit: kappa,
        mean: k_mean,
    } = ctx.curvatures(si.geom, si.prim);
    if ss.lod().applies(hit.width, kappa) {
        return Entries::new(
            Some(lod_entry(ctx, ss, si, frame_o, beta)),
            Ahead::default(),
        );
    }
    // The probe axes also see sharp edges near xo (`sharp_edges`); level
    // of detail above and the curvature correction read the triangle's.
    // Only the axis probabilities read it: no search beyond their ¼.
    let saturated = ss.probe().saturated_curvature();
    let kappa = ctx.axes_curvature_up_to(si.geom, si.prim, si.p, saturated);
    let pair = ss.probe_pair() && hit.depth < ctx.pair_depth;
    // The plane model chooses between a probe and its mirror; the pair
    // traces both, so there it has nothing to choose.
    let cv = !pair
        && ss.control_variate()
        && control_variate::applies(ctx.cv_depth, ctx.plan.area_lights, hit.depth);
    // The control variate's light samples, drawn before the probe's randoms.
    let lights = cv.then(|| [draw_light(ctx, st.rng), None]);
    let u = ProbeRandoms::from_sample(st.rng);
    // The curvature correction's exit half, once for both probes of a pair.
    let exit = ss.curvature_correction().map(|cc| {
        (
            cc,
            cc.at_exit_with(k_mean, ctx.curvature_factor(si.geom, si.prim, cc)),
        )
    });
    let at = ProbeAt {
        ss,
        si,
        frame_o,
        kappa,
        k_mean,
        u,
        exit,
    };
    if !pair {
        return one_probe(ctx, &at, cv, lights, beta, st);
    }
    // Paths split only at the camera vertex: the stack holds them.
    let paths = if hit.depth == 0 { ss.pair_paths() } else { 1 };
    self::pair(ctx, &at, paths, beta, st)
}

/// One probe from xo: its entry vertex, with the control variate's part.
fn one_probe<'s, R: Recorder>(
    ctx: &Context,
    at: &ProbeAt<'_, 's>,
    cv: bool,
    lights: Lights,
    beta: &mut Vec3,
    st: &mut PathState<R>,
) -> Entries<'s> {
    let (p, frame_o, kappa, u) = (at.si.p, &at.frame_o, at.kappa, &at.u);
    let probe = at.ss.probe();
    // With the model: the probe or its mirror (the pair's twin), as the
    // model's light at each asks, the followed one's weight scaled.
    let (seg, choice) = if cv {
        match probe.sample_probe_pair_and_plane(p, frame_o, kappa, u) {
            Some(([a, b], plane)) => {
                let c = mirror_choice(at, &lights, plane.as_ref(), || st.rng.uniform());
                (if c.mirror { b } else { a }, c)
            }
            None => return Entries::new(None, Ahead::default()),
        }
    } else {
        match probe.sample_probe(p, frame_o, kappa, u) {
            Some(seg) => (seg, MirrorChoice::PROBE),
            None => return Entries::new(None, Ahead::default()),
        }
    };
    let ahead = ahead(lights);
    match probe_entry(ctx, at, &seg, st) {
        Some((v, w)) => {
            *beta *= w * choice.factor;
            Entries::new(Some(v), ahead)
        }
        None => Entries::new(None, ahead),
    }
}

/// The antithetic pair from xo: the twin's randoms are u's with the angle
/// at φ + π (ProbeSampler::sample_probe_pair), which changes none of what
/// entry_on_segment reads. Light is sampled at both, each weighted ½. With
/// `paths` 1 the path goes on from one of the two, chosen with probability
/// ½ (weight 2 × ½); with 2 or 4, `paths / 2` go on from each, weighted
/// ½ here and split further by [`super::split`].
fn pair<'s, R: Recorder>(
    ctx: &Context,
    at: &ProbeAt<'_, 's>,
    paths: u32,
    beta: &mut Vec3,
    st: &mut PathState<R>,
) -> Entries<'s> {
    let (p, frame_o, kappa, u) = (at.si.p, &at.frame_o, at.kappa, &at.u);
    let probe = at.ss.probe();
    let Some([seg_a, seg_b]) = probe.sample_probe_pair(p, frame_o, kappa, u) else {
        return Entries::new(None, Ahead::default());
    };
    let ahead = Ahead::default();
    let a = probe_entry(ctx, at, &seg_a, st);
    let b = probe_entry(ctx, at, &seg_b, st);
    match (a, b) {
        (Some((va, wa)), Some((vb, wb))) => {
            let beta0 = *beta;
            let paths_each = paths / 2;
            let (go, (other, w_other), w_go) = if paths_each > 0 || st.rng.uniform() < 0.5 {
                (va, (vb, wb), wa)
            } else {
                (vb, (va, wa), wb)
            };
            // Followed alone, the entry point stands for both (2 × ½).
            let share = if paths_each > 0 { 0.5 } else { 1.0 };
            *beta = share * beta0 * w_go;
            let twin = Weighted {
                vertex: other,
                beta: 0.5 * beta0 * w_other,
            };
            Entries {
                entry: Some(go),
                pair: Some(twin),
                paths_each,
                ahead,
            }
        }
        (Some((v, w)), None) | (None, Some((v, w))) => {
            *beta *= 0.5 * w;
            Entries::new(Some(v), ahead)
        }
        (None, None) => Entries::new(None, ahead),
    }
}

/// The level-of-detail entry vertex: xo itself with the entry lobe, `beta`
/// scaled by the profile's plane integral A_plane and, on a convex surface
/// with the curvature correction on, f(κo) — the full estimator's mean on
/// a flat or spherical surface ([`crate::materials::lod`]).
#[inline(never)]
fn lod_entry<'s>(
    ctx: &Context,
    ss: &'s Subsurface,
    si: &Interaction,
    frame_o: Frame,
    beta: &mut Vec3,
) -> Vertex<'s> {
    let mut w = ss.lod().albedo;
    if let Some(cc) = ss.curvature_correction() {
        let k_o = ctx.curvatures(si.geom, si.prim).mean;
        if let Some(f) = cc.weight(k_o, k_o) {
            w *= f;
        }
    }
    *beta *= w;
    Vertex {
        p: si.p,
        ng: if si.front { si.ng } else { -si.ng },
        frame: frame_o,
        wo_local: Vec3::Z,
        lobe: Lobe::Subsurface(SubsurfaceLobe::Entry(ss)),
        outside_of: ctx.leaving(si.geom, si.front),
    }
}

/// The area integral at xo: one entry point xi from the probe segment
/// `seg`, and the probe's weight (with the curvature correction's, if
/// the material has one); None when the probe finds nothing.
fn probe_entry<'s, R: Recorder>(
    ctx: &Context,
    at: &ProbeAt<'_, 's>,
    seg: &ProbeSegment,
    st: &mut PathState<R>,
) -> Option<(Vertex<'s>, Vec3)> {
    let (ss, si) = (at.ss, at.si);
    st.counters.ray(Effect::Probe);
    let target = ProbeTarget {
        accel: ctx.accel,
        geom: si.geom,
        mesh: &ctx.scene.meshes[si.geom as usize],
    };
    let ps = entry_on_segment(ss.probe(), seg, &at.u, &target, &mut st.scratch.probe_hits)?;
    // The curvature correction (bssrdf::curvature_correction): None, and
    // the weight untouched, on flat and concave surfaces.
    let mut weight = ps.weight;
    if let Some((cc, exit)) = &at.exit {
        let k_i = ctx.curvatures(si.geom, ps.hit.prim).mean;
        let f_i = ctx.curvature_factor(si.geom, ps.hit.prim, cc);
        if let Some(f) = cc.weight_from_factor(exit, k_i, f_i) {
            weight *= f;
        }
    }
    let n_in = if si.front { ps.normal } else { -ps.normal };
    let vertex = Vertex {
        p: ps.point,
        ng: n_in,
        frame: Frame::from_normal(n_in),
        wo_local: Vec3::Z,
        lobe: Lobe::Subsurface(SubsurfaceLobe::Entry(ss)),
        // n_in faces the side xo was seen from, as ng does at xo.
        outside_of: ctx.leaving(si.geom, si.front),
    };
    Some((vertex, weight))
}
