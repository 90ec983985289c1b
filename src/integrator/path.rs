//! Unidirectional path tracing (Kajiya 1986) of the rendering equation
//!
//!   L(x, ωo) = Le(x, ωo) + ∫ f(x, ωo, ωi) L(x, ωi) |cos θi| dωi,
//!
//! extended at subsurface objects by the BSSRDF's area integral
//!
//!   L(xo, ωo) = ∫_A ∫ S(xi, ωi; xo, ωo) L(xi, ωi) cos θi dωi dA(xi),
//!
//! both estimated along one path per sample. At each vertex with a
//! non-specular lobe the direct part of the inner integral is estimated
//! twice — by sampling a point on an area light (next-event estimation)
//! and by sampling the lobe — and the two are combined with the power
//! heuristic (Veach 1997, §9.2). The area integral is estimated with one
//! probe ray (King et al. 2013; [`crate::bssrdf::probe`]). Paths end at
//! `max_depth` bounces or by Russian roulette once their throughput is
//! small (pbrt-v4 §13.1.1).

use super::interaction::offset_along;
use super::probe::{curvature, sample_entry, ProbeTarget};
use super::{Context, Counters, Interaction};
use crate::accel::ProbeHits;
use crate::bssrdf::ProbeRandoms;
use crate::fresnel;
use crate::geometry::{Frame, Ray, Vec3};
use crate::materials::{dielectric, diffuse, Material, Subsurface};
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf, power, Draw, SampleRng};

/// Bounces after which Russian roulette may end a path.
const RR_START: u32 = 3;

/// Per-thread buffers the integrator reuses so the hot path never allocates.
#[derive(Default)]
pub struct Scratch {
    pub probe_hits: ProbeHits,
}

/// A non-specular lobe at a path vertex, in a local frame whose z axis is
/// the normal on the side light leaves towards.
#[derive(Clone, Copy)]
pub(crate) enum Lobe<'a> {
    /// Lambertian reflection, ρ/π.
    Diffuse(Vec3),
    /// The entry-point lobe of a subsurface material (Sw or 1/π), outward
    /// side only; its spectral weight was already applied by the probe.
    SubsurfaceEntry(&'a Subsurface),
    /// Where a random walk left the medium through a diffuse Fresnel
    /// boundary ([`super::diffuse_boundary::ExitLobe`]).
    WalkExit(super::diffuse_boundary::ExitLobe),
}

impl Lobe<'_> {
    /// f(ωo, ωi) per steradian (ωo, ωi local; z > 0 is the lit side).
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Lobe::Diffuse(albedo) => diffuse::eval(*albedo, wo, wi),
            Lobe::SubsurfaceEntry(ss) => Vec3::splat(ss.lobe(wi.z)),
            Lobe::WalkExit(exit) => Vec3::splat(exit.eval(wi)),
        }
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Lobe::Diffuse(_) => diffuse::pdf(wo, wi),
            Lobe::SubsurfaceEntry(_) => cosine_hemisphere_pdf(wi.z),
            Lobe::WalkExit(exit) => exit.pdf(wi),
        }
    }
    /// Samples ωi; returns (ωi, f |cos| / pdf, pdf).
    pub(crate) fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<(Vec3, Vec3, f32)> {
        match self {
            Lobe::Diffuse(albedo) => diffuse::sample(*albedo, wo, u),
            Lobe::SubsurfaceEntry(ss) => {
                let wi = cosine_hemisphere(u);
                let pdf = cosine_hemisphere_pdf(wi.z);
                (pdf > 0.0).then(|| (wi, Vec3::splat(ss.lobe(wi.z) * wi.z / pdf), pdf))
            }
            Lobe::WalkExit(exit) => exit.sample(u).map(|(wi, w, pdf)| (wi, Vec3::splat(w), pdf)),
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
}

/// What a subsurface hit turns into: a vertex that scatters light with a
/// lobe (next-event estimation, then lobe sampling), a ray that continues
/// without one (a specular bounce, or leaving a medium), or the end of the
/// path. Both integrators share one bounce loop, [`trace`], and differ only
/// in how they produce this.
pub(crate) enum Scatter<'a> {
    Vertex(Vertex<'a>),
    Continue(Ray),
    Absorbed,
}

/// The radiance arriving along `camera_ray`: one sample of L, with the
/// BSSRDF estimated by one probe ray per subsurface hit.
pub fn radiance(
    ctx: &Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
) -> Vec3 {
    trace(
        ctx,
        camera_ray,
        rng,
        counters,
        |ss, si, wo, beta, rng, counters| {
            subsurface_probe(ctx, ss, si, wo, beta, rng, scratch, counters)
        },
    )
}

/// The bounce loop both integrators share; `subsurface` handles hits on
/// subsurface objects (and may scale the throughput `beta`).
pub(crate) fn trace<'s>(
    ctx: &'s Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    counters: &mut Counters,
    mut subsurface: impl FnMut(
        &'s Subsurface,
        &Interaction,
        Vec3,
        &mut Vec3,
        &mut SampleRng,
        &mut Counters,
    ) -> Scatter<'s>,
) -> Vec3 {
    let scene = ctx.scene;
    // The estimate of L, summed over the path's vertices.
    let mut l = Vec3::ZERO;
    // Path throughput: the product of f |cos| / pdf (and BSSRDF weights).
    let mut beta = Vec3::ONE;
    let mut ray = camera_ray;
    // The last non-specular vertex and the solid-angle pdf with which its
    // lobe sampled the current ray; None after the camera or a specular
    // bounce, where no light sample competed for this direction.
    let mut prev: Option<(Vec3, f32)> = None;

    let max_depth = scene.settings.max_depth;
    for depth in 0..=max_depth {
        counters.rays += 1;
        let Some(hit) = ctx.accel.intersect(&ray, 0.0, f32::INFINITY) else {
            if ctx.plan.environment {
                l += beta * scene.environment.unwrap_or(Vec3::ZERO);
            }
            break;
        };
        let object = &scene.objects[hit.geom as usize];
        let si = ctx.interaction(&ray, &hit);
        let wo = -ray.d;

        // Le, MIS-weighted against next-event estimation.
        if let (Some(le), true) = (object.emission, si.front) {
            l += beta * le * emission_weight(ctx, &si, wo, prev);
        }
        if depth == max_depth {
            break;
        }

        let scatter = match &scene.materials[object.material] {
            Material::Diffuse { albedo } => {
                let frame = si.shading_frame_facing(wo);
                let ng = if wo.dot(si.ng) >= 0.0 { si.ng } else { -si.ng };
                Scatter::Vertex(Vertex {
                    p: si.p,
                    ng,
                    wo_local: frame.to_local(wo),
                    frame,
                    lobe: Lobe::Diffuse(*albedo),
                })
            }
            Material::Dielectric { eta } => {
                Scatter::Continue(dielectric_bounce(ctx, *eta, &si, wo, &mut beta, rng))
            }
            Material::Subsurface(ss) => subsurface(ss, &si, wo, &mut beta, rng, counters),
        };
        // Borrowed, not moved out: the vertex stays where it was built.
        let vertex = match &scatter {
            Scatter::Vertex(v) => v,
            Scatter::Continue(next) => {
                prev = None;
                ray = *next;
                if !roulette(depth, &mut beta, rng) {
                    break;
                }
                continue;
            }
            Scatter::Absorbed => break,
        };

        // Next-event estimation, then continue by sampling the lobe.
        if ctx.plan.area_lights {
            l += beta * direct_lighting(ctx, vertex, rng, counters);
        }
        let Some((wi_local, weight, pdf)) =
            vertex.lobe.sample(vertex.wo_local, rng.uniform2_packed())
        else {
            break;
        };
        let wi = vertex.frame.to_world(wi_local);
        // A shading normal can send ωi through the geometric surface; such a
        // path would leak light through it, so it ends here.
        if wi.dot(vertex.ng) <= 0.0 {
            break;
        }
        beta *= weight;
        prev = Some((vertex.p, pdf));
        ray = Ray::new(offset_along(vertex.p, vertex.ng, ctx.ray_epsilon), wi);
        if !roulette(depth, &mut beta, rng) {
            break;
        }
    }
    l
}

/// A specular bounce off or through a dielectric.
// Out of line, as are the probe step and the emission weight: a measured
// gain, see `crate::kernels`.
#[inline(never)]
fn dielectric_bounce(
    ctx: &Context,
    eta: f32,
    si: &Interaction,
    wo: Vec3,
    beta: &mut Vec3,
    rng: &mut SampleRng,
) -> Ray {
    let frame = Frame::from_normal(si.ng);
    let s = dielectric::sample(eta, frame.to_local(wo), rng.uniform());
    *beta *= s.weight;
    si.spawn(frame.to_world(s.wi), ctx.ray_epsilon)
}

/// A subsurface hit at xo under the diffusion model: the Fresnel split at
/// xo, then one probe ray for the entry point xi, where the path continues
/// with the entry lobe.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn subsurface_probe<'s>(
    ctx: &Context,
    ss: &'s Subsurface,
    si: &Interaction,
    wo: Vec3,
    beta: &mut Vec3,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
) -> Scatter<'s> {
    // Boundary at xo: the normal facing the camera is "outside"
    // (a mesh wound inside-out is read consistently the other way).
    let n_out = if si.front { si.ng } else { -si.ng };
    let fr = fresnel::dielectric(wo.dot(n_out).max(0.0), ss.eta());
    if ss.specular && rng.uniform() < fr {
        // Specular reflection with probability Fr: weight 1. The
        // shading normal keeps highlights smooth on tessellated
        // meshes; where it would reflect below the surface the
        // geometric normal is used instead.
        let ns_out = if si.ns.dot(n_out) >= 0.0 {
            si.ns
        } else {
            -si.ns
        };
        let mut wi = (2.0 * wo.dot(ns_out)) * ns_out - wo;
        if wi.dot(n_out) <= 0.0 {
            wi = (2.0 * wo.dot(n_out)) * n_out - wo;
        }
        return Scatter::Continue(si.spawn(wi, ctx.ray_epsilon));
    }
    if !ss.specular {
        *beta *= 1.0 - fr;
    }
    // The area integral: one entry point xi from a probe ray.
    let frame_o = si.shading_frame_facing(wo);
    let u = ProbeRandoms::from_rng(rng);
    counters.rays += 1;
    let target = ProbeTarget {
        accel: ctx.accel,
        geom: si.geom,
        mesh: &ctx.scene.meshes[si.geom as usize],
    };
    let Some(ps) = sample_entry(
        &ss.probe,
        si.p,
        &frame_o,
        curvature(target.mesh, si.prim),
        &u,
        &target,
        &mut scratch.probe_hits,
    ) else {
        return Scatter::Absorbed;
    };
    *beta *= ps.weight;
    let n_in = if si.front { ps.normal } else { -ps.normal };
    Scatter::Vertex(Vertex {
        p: ps.point,
        ng: n_in,
        frame: Frame::from_normal(n_in),
        wo_local: Vec3::Z,
        lobe: Lobe::SubsurfaceEntry(ss),
    })
}

/// Russian roulette after `RR_START` bounces: survive with probability
/// min(1, max β) and reweight; false ends the path.
fn roulette(depth: u32, beta: &mut Vec3, rng: &mut SampleRng) -> bool {
    if depth < RR_START {
        return true;
    }
    let survive = beta.max_element().min(1.0);
    if survive <= 0.0 || rng.uniform() >= survive {
        return false;
    }
    *beta /= survive;
    true
}

/// The MIS weight of emission found by lobe sampling from `prev`.
#[inline(never)]
fn emission_weight(ctx: &Context, si: &Interaction, wo: Vec3, prev: Option<(Vec3, f32)>) -> f32 {
    match prev {
        None => 1.0,
        Some((p0, pdf_lobe)) => {
            let cos_l = wo.dot(si.ng);
            let pdf_light =
                ctx.lights.pdf_area(si.geom, si.prim) * (si.p - p0).length_squared() / cos_l;
            power(pdf_lobe, pdf_light)
        }
    }
}

/// Next-event estimation at a vertex: one light sample, weighted by the
/// power heuristic against lobe sampling of the same direction.
fn direct_lighting(
    ctx: &Context,
    v: &Vertex,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Vec3 {
    let [u_pick, u0, u1] = rng.uniform3();
    let Some(ls) = ctx.lights.sample(u_pick, [u0, u1]) else {
        return Vec3::ZERO;
    };
    let to_light = ls.point - v.p;
    let dist2 = to_light.length_squared();
    if dist2 <= 0.0 {
        return Vec3::ZERO;
    }
    let wi = to_light / dist2.sqrt();
    let cos_l = -wi.dot(ls.normal);
    if cos_l <= 0.0 || wi.dot(v.ng) <= 0.0 {
        return Vec3::ZERO;
    }
    let wi_local = v.frame.to_local(wi);
    let f = v.lobe.eval(v.wo_local, wi_local);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let pdf_light = ls.pdf_area * dist2 / cos_l;
    counters.rays += 1;
    let origin = offset_along(v.p, v.ng, ctx.ray_epsilon);
    // t is in units of |d| = the distance to the light point; stop just short
    // of it so the light's own triangle does not shadow itself.
    if ctx
        .accel
        .occluded(&Ray::new(origin, ls.point - origin), 0.0, 1.0 - 1e-4)
    {
        return Vec3::ZERO;
    }
    let w = power(pdf_light, v.lobe.pdf(v.wo_local, wi_local));
    f * ls.radiance * (wi_local.z.abs() * w / pdf_light)
}
