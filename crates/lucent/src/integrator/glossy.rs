//! What a hit on a conductor, a plastic or a rough dielectric scatters
//! into. Rough conductors and plastics are lobes at a vertex (light
//! sampling and lobe sampling combined by MIS, [`super::nee`]); mirrors
//! (smooth conductors, a smooth plastic's coat) continue the path as a
//! specular bounce. A rough dielectric reflects and refracts, which the
//! vertex's light sampling (one side only) does not cover: it continues
//! the path by sampling its interface alone, like a specular bounce, so
//! emission it finds counts in full (`docs/scene-format.md`, "rough
//! dielectric").

use super::aov::{Event, Recorder};
use super::branch::{At, Branch};
use super::lobe::{Lobe, Vertex};
use super::scatter::Scatter;
use super::{Context, Interaction};
use crate::geometry::{Frame, Vec3};
use crate::materials::{Conductor, Plastic, RoughDielectric};
use crate::sampling::{Draw, SampleRng};

/// A conductor: its GGX lobe at a vertex, or a mirror bounce.
#[inline(never)]
pub(crate) fn conductor<'s, R: Recorder>(
    ctx: &Context,
    c: &'s Conductor,
    at: &At,
    path: &mut Branch,
    rec: &mut R,
) -> Scatter<'s> {
    if R::ON {
        rec.surface(c.fresnel(1.0), at.si.shading_frame_facing(at.wo).n);
    }
    if !c.is_smooth() {
        return Scatter::Vertex(vertex(ctx, at.si, at.wo, Lobe::Conductor(c)));
    }
    let frame = at.si.shading_frame_facing(at.wo);
    let (wi, f) = c.mirror(frame.to_local(at.wo));
    path.beta *= f;
    mirror(ctx, at, path, frame.to_world(wi))
}

/// A plastic: its coat and base at a vertex (rough coat); with a smooth
/// coat, the mirror with probability q (weight F/q) or the base at a
/// vertex (weight 1/(1 − q)).
#[inline(never)]
pub(crate) fn plastic<'s, R: Recorder>(
    ctx: &Context,
    p: &'s Plastic,
    at: &At,
    path: &mut Branch,
    rng: &mut SampleRng,
    rec: &mut R,
) -> Scatter<'s> {
    let frame = at.si.shading_frame_facing(at.wo);
    if R::ON {
        rec.surface(p.albedo, frame.n);
    }
    if p.is_smooth() {
        let wo = frame.to_local(at.wo);
        let q = p.mirror_probability(wo.z);
        if rng.uniform() < q {
            path.beta *= crate::fresnel::dielectric(wo.z, p.eta) / q;
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return mirror(ctx, at, path, frame.to_world(wi));
        }
        path.beta /= 1.0 - q;
    }
    Scatter::Vertex(vertex(ctx, at.si, at.wo, Lobe::Plastic(p)))
}

/// A rough dielectric: one sampled reflection or refraction, in the frame
/// of the outward shading normal; lost where the shading normal sends it
/// to the other side of the geometric surface than it should go.
#[inline(never)]
pub(crate) fn rough_dielectric<'s>(
    ctx: &Context,
    d: &RoughDielectric,
    at: &At,
    path: &mut Branch,
    rng: &mut SampleRng,
) -> Scatter<'s> {
    let frame = Frame::from_normal(at.si.ns);
    let Some(s) = d.sample(frame.to_local(at.wo), rng.uniform3()) else {
        return Scatter::Absorbed;
    };
    let wi = frame.to_world(s.wi);
    let crossed = (wi.dot(at.si.ng) > 0.0) != (at.wo.dot(at.si.ng) > 0.0);
    if crossed != s.transmitted {
        return Scatter::Absorbed;
    }
    path.beta *= s.weight;
    path.from = ctx.leaving_towards(at.si, wi);
    let e = if s.transmitted {
        Event::Transmission
    } else {
        Event::Specular
    };
    Scatter::Continue(at.si.spawn(wi, ctx.ray_epsilon), e)
}

/// A mirror bounce into `wi`, lost below the geometric surface.
fn mirror<'s>(ctx: &Context, at: &At, path: &mut Branch, wi: Vec3) -> Scatter<'s> {
    if wi.dot(at.si.ng) * at.wo.dot(at.si.ng) <= 0.0 {
        return Scatter::Absorbed;
    }
    path.from = ctx.leaving_towards(at.si, wi);
    Scatter::Continue(at.si.spawn(wi, ctx.ray_epsilon), Event::Specular)
}

/// The vertex of a two-sided reflecting `lobe` at `si`, seen from `wo`.
fn vertex<'s>(ctx: &Context, si: &Interaction, wo: Vec3, lobe: Lobe<'s>) -> Vertex<'s> {
    let frame = si.shading_frame_facing(wo);
    let front = wo.dot(si.ng) >= 0.0;
    Vertex {
        p: si.p,
        ng: if front { si.ng } else { -si.ng },
        wo_local: frame.to_local(wo),
        frame,
        lobe,
        outside_of: ctx.leaving(si.geom, front),
    }
}
