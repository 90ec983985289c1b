//! Next-event estimation of the `[[lights]]` (sphere, spot, distant): one
//! light picked uniformly, one direction sampled in the cone it subtends
//! and a shadow ray to it, weighted by the power heuristic against sampling
//! the vertex's lobe (Veach 1997, §9.2); and the matching weight of their
//! light found by a lobe-sampled ray: one crossing a sphere light, or one
//! escaping inside a distant light's cone. A distant light of angle 0 is a
//! delta: only sampled. `docs/scene-format.md`, "`[[lights]]`".

use super::aov::{self, Event, Recorder, Source};
use super::branch::Branch;
use super::interaction::offset_along;
use super::lobe::{PrevVertex, Vertex};
use super::state::PathState;
use super::{Clock, Context, Counters, Effect};
use crate::analytic_lights::Light;
use crate::film::passes::Pass;
use crate::geometry::{Ray, Vec3};
use crate::sampling::{power, Draw, SampleRng};

/// The probability of picking each light.
#[inline(always)]
fn pick_pmf(ctx: &Context) -> f32 {
    1.0 / ctx.scene.lights.len() as f32
}

/// Samples the lights at `v` (three randoms), timed as [`Effect::Direct`],
/// and returns their light × `beta`, recorded as the picked light's,
/// sampled after `event` at `depth`.
#[inline(always)]
pub(crate) fn record_analytic<R: Recorder, T: Clock>(
    ctx: &Context,
    v: &Vertex,
    st: &mut PathState<R>,
    beta: Vec3,
    event: Event,
    depth: u32,
) -> Vec3 {
    let t0 = T::now();
    let (d, light) = analytic_light(ctx, v, st.rng, st.counters);
    T::lap(st.counters, Effect::Direct, t0);
    let c = beta * d;
    st.rec
        .light(c, aov::sampled(event, depth), Source::Analytic(light));
    c
}

/// One light sample at `v`: f · L · |cos θ| · w / (pmf · pdf), 0 where the
/// direction is below the vertex, the lobe is 0 or the ray is blocked;
/// and the light picked.
#[inline(never)]
pub(crate) fn analytic_light(
    ctx: &Context,
    v: &Vertex,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> (Vec3, u32) {
    let lights = &ctx.scene.lights;
    let (u_pick, [u0, u1]) = rng.choice_and_point();
    let i = ((u_pick * lights.len() as f32) as usize).min(lights.len() - 1);
    let Some(s) = lights[i].sample(v.p, [u0, u1]) else {
        return (Vec3::ZERO, i as u32);
    };
    if s.wi.dot(v.ng) <= 0.0 || s.weight == Vec3::ZERO {
        return (Vec3::ZERO, i as u32);
    }
    let wi = v.frame.to_local(s.wi);
    let (f, pdf_lobe) = (v.lobe.eval(v.wo_local, wi), v.lobe.pdf(v.wo_local, wi));
    if f == Vec3::ZERO {
        return (Vec3::ZERO, i as u32);
    }
    counters.ray(Effect::Direct);
    let origin = offset_along(v.p, v.ng, ctx.ray_epsilon);
    if ctx.occluded(
        &Ray::new(origin, s.wi),
        s.dist,
        [v.outside_of, None],
        counters,
    ) {
        return (Vec3::ZERO, i as u32);
    }
    let pmf = pick_pmf(ctx);
    let w = power(pmf * s.pdf, pdf_lobe);
    (f * s.weight * (wi.z.abs() * w / pmf), i as u32)
}

/// The MIS weight of light found by a ray the lobe at `prev` sampled,
/// against the light sample taken there (`pdf_light`: the light's density
/// of the direction, before picking); 1 after the camera or a specular
/// bounce.
#[inline(always)]
fn weight(ctx: &Context, prev: Option<PrevVertex>, pdf_light: impl Fn(Vec3) -> f32) -> f32 {
    match prev {
        Some(p) => power(p.pdf, pick_pmf(ctx) * pdf_light(p.p)),
        None => 1.0,
    }
}

/// The light of the `[[lights]]` the path's ray finds before `t_hit` (its
/// nearest surface; None: it escapes): the sphere lights it crosses and,
/// escaping, the distant lights whose cone holds its direction; each
/// MIS-weighted and recorded as found after `depth` hits.
#[inline(never)]
pub(crate) fn found<R: Recorder>(
    ctx: &Context,
    path: &Branch,
    t_hit: Option<f32>,
    depth: u32,
    rec: &mut R,
) -> Vec3 {
    let mut l = Vec3::ZERO;
    let ray = &path.ray;
    for (i, light) in ctx.scene.lights.iter().enumerate() {
        let (le, w, at_camera) = match light {
            Light::Sphere(s) => {
                if s.hit(ray, t_hit.unwrap_or(f32::INFINITY)).is_none() {
                    continue;
                }
                let le = s.radiance_towards(-ray.d.normalize());
                (le, weight(ctx, path.prev, |p| s.pdf(p)), Pass::Emission)
            }
            Light::Distant(d) => {
                // a transparent film leaves the sky seen directly out,
                // suns with it
                let seen = t_hit.is_none() && !(depth == 0 && ctx.plan.transparent);
                let Some((le, pdf)) = seen.then(|| d.escaped(ray.d.normalize())).flatten() else {
                    continue;
                };
                (le, weight(ctx, path.prev, |_| pdf), Pass::Background)
            }
        };
        let c = path.beta * le * w;
        if c == Vec3::ZERO {
            continue;
        }
        rec.light(
            c,
            aov::found(path.event, depth, at_camera),
            Source::Analytic(i as u32),
        );
        l += c;
    }
    l
}
