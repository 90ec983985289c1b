//! Next-event estimation: a light sample at a path vertex, weighted by the
//! power heuristic against sampling the vertex's lobe (Veach 1997, §9.2),
//! and the matching weight of emission a lobe sample finds.

use super::aov::{self, Event, Recorder, Source};
use super::interaction::offset_along;
use super::lobe::{Lobe, PrevVertex, Vertex};
use super::state::PathState;
use super::{Clock, Context, Counters, Effect, Interaction};
use crate::geometry::{Ray, Vec3};
use crate::lights::LightSample;
use crate::materials::diffuse;
use crate::sampling::{power, Draw, SampleRng};

/// How light sampled at a path vertex counts: its scale (½ at an entry
/// point of an antithetic pair, whose twin is sampled too) and the light
/// sample drawn ahead for it, if any (the control variate's `Ahead`).
#[derive(Clone, Copy)]
pub(crate) struct NeeAt {
    pub(crate) scale: f32,
    #[cfg(feature = "subsurface")]
    pub(crate) ahead: Option<Option<LightSample>>,
}

impl NeeAt {
    /// One light sample drawn at the vertex, counted once.
    pub(crate) const PLAIN: NeeAt = NeeAt {
        scale: 1.0,
        #[cfg(feature = "subsurface")]
        ahead: None,
    };

    /// Next-event estimation at `v` with the light sample this asks for.
    #[inline(always)]
    pub(crate) fn light(
        &self,
        ctx: &Context,
        v: &Vertex,
        rng: &mut SampleRng,
        counters: &mut Counters,
    ) -> (Vec3, u32) {
        #[cfg(feature = "subsurface")]
        return direct_lighting_ahead(ctx, v, self.ahead, rng, counters);
        #[cfg(not(feature = "subsurface"))]
        return direct_lighting(ctx, v, rng, counters);
    }
}

/// Runs next-event estimation `nee`, timed as [`Effect::Direct`], and
/// returns its light × `beta`, recorded as light sampled after `event`
/// at `depth`.
#[inline(always)]
pub(crate) fn record_direct<R: Recorder, T: Clock>(
    st: &mut PathState<R>,
    beta: Vec3,
    event: Event,
    depth: u32,
    nee: impl FnOnce(&mut SampleRng, &mut Counters) -> (Vec3, u32),
) -> Vec3 {
    let t0 = T::now();
    let (d, light) = nee(st.rng, st.counters);
    T::lap(st.counters, Effect::Direct, t0);
    let c = beta * d;
    st.rec
        .light(c, aov::sampled(event, depth), Source::Light(light));
    c
}

/// The MIS weight of emission found by lobe sampling from `prev` (1 after
/// the camera or a specular bounce: no light sample competed).
#[inline(never)]
pub(crate) fn emission_weight(
    ctx: &Context,
    si: &Interaction,
    wo: Vec3,
    prev: Option<PrevVertex>,
) -> f32 {
    match prev {
        None => 1.0,
        Some(PrevVertex {
            p: p0,
            pdf: pdf_lobe,
        }) => {
            let cos_l = wo.dot(si.ng);
            let pdf_light =
                ctx.lights.pdf_area(si.geom, si.prim) * (si.p - p0).length_squared() / cos_l;
            power(pdf_lobe, pdf_light)
        }
    }
}

/// One light sample for next-event estimation (three randoms); None
/// without lights or on a degenerate emitter.
#[inline(always)]
pub(crate) fn draw_light(ctx: &Context, rng: &mut SampleRng) -> Option<LightSample> {
    let (u_pick, [u0, u1]) = rng.choice_and_point();
    ctx.lights.sample(u_pick, [u0, u1])
}

/// Next-event estimation at a vertex: one light sample, weighted by the
/// power heuristic against lobe sampling of the same direction; and the
/// light triangle it sampled ([`aov::NO_LIGHT`] when none). (A plain index,
/// not an [`aov::Source`]: the pair then still fits in two registers.)
pub(crate) fn direct_lighting(
    ctx: &Context,
    v: &Vertex,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> (Vec3, u32) {
    let Some(ls) = draw_light(ctx, rng) else {
        return (Vec3::ZERO, aov::NO_LIGHT);
    };
    lit_by(ctx, v, &ls, counters)
}

/// [`direct_lighting`] with the light sample drawn ahead (`Some`; its
/// `None`: no light was found), or drawn now (`None`).
#[cfg(feature = "subsurface")]
pub(crate) fn direct_lighting_ahead(
    ctx: &Context,
    v: &Vertex,
    ahead: Option<Option<LightSample>>,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> (Vec3, u32) {
    match ahead {
        None => direct_lighting(ctx, v, rng, counters),
        Some(Some(ls)) => lit_by(ctx, v, &ls, counters),
        Some(None) => (Vec3::ZERO, aov::NO_LIGHT),
    }
}

/// Next-event estimation at `v` with the light sample `ls`.
///
/// The lobe is matched once here, not in both its `eval` and its `pdf`: the
/// diffuse lobe (every vertex of a diffuse scene) gets an instance of its
/// own, so a scene without subsurface materials executes what a build
/// without the `subsurface` feature does (docs/performance.md, "Zero cost
/// for what is off").
#[inline(always)]
fn lit_by(ctx: &Context, v: &Vertex, ls: &LightSample, counters: &mut Counters) -> (Vec3, u32) {
    match v.lobe {
        Lobe::Diffuse(albedo) => light_sample(
            ctx,
            v,
            ls,
            counters,
            |wo, wi| diffuse::eval(albedo, wo, wi),
            diffuse::pdf,
        ),
        _ => light_sample(
            ctx,
            v,
            ls,
            counters,
            |wo, wi| v.lobe.eval(wo, wi),
            |wo, wi| v.lobe.pdf(wo, wi),
        ),
    }
}

/// [`lit_by`] with the lobe's `eval` and `pdf`: [`unshadowed`], then the
/// shadow ray.
#[inline(always)]
fn light_sample(
    ctx: &Context,
    v: &Vertex,
    ls: &LightSample,
    counters: &mut Counters,
    eval: impl Fn(Vec3, Vec3) -> Vec3,
    pdf: impl Fn(Vec3, Vec3) -> f32,
) -> (Vec3, u32) {
    let source = ls.index;
    let Some(c) = unshadowed(v, ls, eval, pdf) else {
        return (Vec3::ZERO, source);
    };
    counters.ray(Effect::Direct);
    let origin = offset_along(v.p, v.ng, ctx.ray_epsilon);
    // t is in units of |d| = the distance to the light point; stop just short
    // of it so the light's own triangle does not shadow itself.
    // The segment arrives at the light's front face (cos_l > 0 above).
    let light = ctx.leaving(ctx.lights.geom_of(source), true);
    if ctx.occluded(
        &Ray::new(origin, ls.point - origin),
        1.0 - 1e-4,
        [v.outside_of, light],
        counters,
    ) {
        return (Vec3::ZERO, source);
    }
    (c, source)
}

/// What light sample `ls` brings to `v` through its lobe (`eval`, `pdf`),
/// MIS-weighted by the power heuristic, were nothing in between; None where
/// it brings nothing (behind the vertex or the light, or the lobe is 0),
/// so no shadow ray is needed.
#[inline(always)]
fn unshadowed(
    v: &Vertex,
    ls: &LightSample,
    eval: impl Fn(Vec3, Vec3) -> Vec3,
    pdf: impl Fn(Vec3, Vec3) -> f32,
) -> Option<Vec3> {
    unshadowed_at(
        v.p,
        v.ng,
        ls,
        |wi| v.frame.to_local(wi),
        |wi_local| eval(v.wo_local, wi_local),
        |wi_local| pdf(v.wo_local, wi_local),
    )
}

/// [`unshadowed`] at the point `p` with geometric normal `ng` (facing the
/// lit side), for a lobe that reads ωi through `to_local` (whose z is
/// cos θ): `eval` and `pdf` of the local direction.
#[inline(always)]
pub(crate) fn unshadowed_at(
    p: Vec3,
    ng: Vec3,
    ls: &LightSample,
    to_local: impl Fn(Vec3) -> Vec3,
    eval: impl Fn(Vec3) -> Vec3,
    pdf: impl Fn(Vec3) -> f32,
) -> Option<Vec3> {
    let to_light = ls.point - p;
    let dist2 = to_light.length_squared();
    if dist2 <= 0.0 {
        return None;
    }
    let wi = to_light / dist2.sqrt();
    let cos_l = -wi.dot(ls.normal);
    if cos_l <= 0.0 || wi.dot(ng) <= 0.0 {
        return None;
    }
    let wi_local = to_local(wi);
    let f = eval(wi_local);
    if f == Vec3::ZERO {
        return None;
    }
    let pdf_light = ls.pdf_area * dist2 / cos_l;
    let w = power(pdf_light, pdf(wi_local));
    Some(f * ls.radiance * (wi_local.z.abs() * w / pdf_light))
}
