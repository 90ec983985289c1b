//! Next-event estimation of the environment image: one direction drawn
//! from the map's distribution and a shadow ray to infinity, weighted by
//! the power heuristic against sampling the vertex's lobe (Veach 1997,
//! §9.2); and the matching weight of the image's light found by an
//! escaping ray. A constant environment is not light-sampled (its escaping
//! rays weigh 1). `docs/scene-format.md`, "`[environment]`".

use super::aov::{self, Event, Recorder, Source};
use super::interaction::offset_along;
use super::lobe::{PrevVertex, Vertex};
use super::state::PathState;
use super::{Clock, Context, Counters, Effect};
use crate::environment::EnvMap;
use crate::geometry::{Ray, Vec3};
use crate::sampling::{power, Draw, SampleRng};

/// The environment image, if the scene has one.
#[inline(always)]
fn map<'a>(ctx: &'a Context) -> Option<&'a EnvMap> {
    ctx.scene.environment.as_ref().and_then(|e| e.map())
}

/// Samples the environment image at `v` (two randoms from one draw), timed as
/// [`Effect::Direct`], and returns its light × `beta`, recorded as the
/// environment's light sampled after `event` at `depth`.
#[inline(always)]
pub(crate) fn record_environment<R: Recorder, T: Clock>(
    ctx: &Context,
    v: &Vertex,
    st: &mut PathState<R>,
    beta: Vec3,
    event: Event,
    depth: u32,
) -> Vec3 {
    let t0 = T::now();
    let d = environment_light(ctx, v, st.rng, st.counters);
    T::lap(st.counters, Effect::Direct, t0);
    let c = beta * d;
    st.rec
        .light(c, aov::sampled(event, depth), Source::Environment);
    c
}

/// One environment sample at `v`: f · L · |cos θ| · w / pdf, 0 where the
/// direction is below the vertex, the lobe is 0 or the ray is blocked.
#[inline(never)]
pub(crate) fn environment_light(
    ctx: &Context,
    v: &Vertex,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Vec3 {
    let Some(map) = map(ctx) else {
        return Vec3::ZERO;
    };
    let Some(s) = map.sample(rng.uniform2_packed()) else {
        return Vec3::ZERO;
    };
    if s.wi.dot(v.ng) <= 0.0 {
        return Vec3::ZERO;
    }
    let wi = v.frame.to_local(s.wi);
    let (f, pdf_lobe) = (v.lobe.eval(v.wo_local, wi), v.lobe.pdf(v.wo_local, wi));
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    counters.ray(Effect::Direct);
    let origin = offset_along(v.p, v.ng, ctx.ray_epsilon);
    let ray = Ray::new(origin, s.wi);
    if ctx.occluded(&ray, f32::INFINITY, [v.outside_of, None], counters) {
        return Vec3::ZERO;
    }
    f * s.radiance * (wi.z.abs() * power(s.pdf, pdf_lobe) / s.pdf)
}

/// The environment's radiance along the escaping direction `d`, weighted
/// by MIS against the light sample taken at `prev` (1 after the camera or
/// a specular bounce, and for a constant environment).
#[inline(always)]
pub(crate) fn escaped(ctx: &Context, d: Vec3, prev: Option<PrevVertex>) -> Vec3 {
    let Some(env) = &ctx.scene.environment else {
        return Vec3::ZERO;
    };
    let Some(map) = env.map() else {
        return env.radiance(d);
    };
    let d = d.normalize();
    let le = map.radiance(d);
    match prev {
        Some(p) => le * power(p.pdf, map.pdf(d)),
        None => le,
    }
}
