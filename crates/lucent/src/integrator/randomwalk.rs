//! The volumetric reference for subsurface materials: a brute-force random
//! walk through the homogeneous medium inside each subsurface object
//! (`docs/bssrdf.md` §7, ground truth 3).
//!
//! Surfaces, lights and the environment are handled exactly as in
//! [`super::path`]: the same bounce loop (`path::trace`), lobes, next-event
//! estimation with MIS and Russian roulette. At a subsurface object the
//! BSSRDF is replaced by the physics it approximates:
//!
//! - the boundary is, per material (`boundary`,
//!   [`crate::materials::WalkBoundary`]), either the exact smooth
//!   dielectric of index η — Fresnel reflection or refraction, sampled like
//!   [`crate::materials::dielectric`] — or the diffuse Fresnel boundary of
//!   [`super::diffuse_boundary`], a different model with the same Fresnel
//!   probabilities whose transmission forgets the direction;
//! - inside, the medium ([`crate::bssrdf::params::Medium`]: σs, σa, a
//!   Henyey–Greenstein phase function with mean cosine g) is simulated by
//!   analog free-flight sampling, one event after another, until the
//!   walk reaches the boundary and leaves, after which the path continues
//!   as usual. This is volumetric path tracing of a homogeneous
//!   medium (pbrt-v4 §14.2) used as subsurface scattering (Chiang et al.
//!   2016, "Practical and Controllable Subsurface Scattering for
//!   Production Path Tracing"; Wrenninge et al. 2017, "Path Traced
//!   Subsurface Scattering using Anisotropic Phase Functions and
//!   Non-Exponential Free Flights").
//!
//! **Chromatic media.** σt differs per channel, so one distance cannot be
//! sampled from all three exponentials at once. Each free flight picks a
//! channel c with probability q_c proportional to the walk's current
//! throughput in that channel and samples t ~ σt_c e^{−σt_c t}; all three
//! channels are then weighted by the one-sample balance-heuristic pdf
//! Σ_k q_k σt_k e^{−σt_k t} (or Σ_k q_k e^{−σt_k t} for a flight reaching the
//! boundary). This is spectral MIS (Miller, Georgiev & Jarosz 2019, "A
//! Null-Scattering Path Integral Formulation of Light Transport", §5;
//! pbrt-v4 §14.1.3 with the hero channel chosen by throughput, as Cycles
//! does). Choosing by throughput never spends samples on a channel that can
//! no longer contribute, and keeps every weight bounded by 1/q_c.
//!
//! The material's diffusion-only options (probe sampling, the exit lobe
//! `exit_sw`, the `specular` coat) do not apply here: the boundary is always
//! the full Fresnel interface, which is what those options approximate.
//!
//! **Light sampling.** Through the dielectric boundary light reaches the
//! medium by the walk refracting out and the path finding the light: a
//! refracted direction is a delta, so no light can be sampled at the exit,
//! and small lights are noisy (`docs/bssrdf.md` §7). With `dielectric-nee`
//! each scattering point also samples the lights through the boundary, by
//! a refracted connection ([`super::walk_nee`]), and the walk's exits
//! leave the paths the connection counts to it. Through the diffuse boundary the
//! exit point is a path vertex with the exit lobe (`SubsurfaceLobe::WalkExit`),
//! where the shared bounce loop samples the lights with MIS (≈ 0.5 on the
//! same scene, for its own model, at the same cost per sample). Inside, Russian
//! roulette on the walk's throughput ends absorbed walks early; walks longer
//! than [`MAX_WALK_EVENTS`] are stopped (counted in
//! [`Counters::walks_capped`]). On an open mesh a walk may leave through a
//! hole: a flight whose ray meets no boundary at all has no bounded medium
//! around it, so the walk ends there with zero radiance (counted in
//! [`Counters::walks_escaped`]) instead of scattering through infinite space.
//!
//! **Cost.** A flight shorter than the distance from its origin to the
//! nearest surface needs no ray query (`docs/bssrdf.md` §7, "The walk's
//! cost"): the samples are the same, with far fewer queries deep inside.
//! Per event, the channel MIS weights cancel the hero's transmittance
//! (`ChannelMis`: two `exp`, one division), one uniform picks the hero
//! and its distance (`pick_channel`), and the phase function is
//! sampled in f32 ([`super::phase`]).

use super::aov::{Event, Recorder};
use super::diffuse_boundary::DiffuseBoundary;
use super::interaction::offset_along;
use super::lobe::{Lobe, SubsurfaceLobe, Vertex};
use super::path::sample;
pub use super::phase::sample_hg;
use super::scatter::{Scatter, SubsurfaceHit, SubsurfaceScatter};
use super::state::{PathState, Scratch};
use super::walk_nee::WalkLight;
use super::{Clock, Context, Counters, Effect, Interaction};
use crate::accel::Hit;
use crate::bssrdf::params::Medium;
use crate::geometry::distance::DistanceGrid;
use crate::geometry::{Frame, Ray, Vec3};
use crate::materials::microfacet::reflect;
use crate::materials::{dielectric, WalkBoundary};
use crate::sampling::{Draw, SampleRng};

/// Events (scatterings and internal reflections) after which a walk is
/// stopped. Marble-like media (single-scattering albedo 0.999) need a few
/// thousand events to reach the boundary from deep inside; the cap only
/// guards against walks that never end (σa = 0 in a large object).
pub const MAX_WALK_EVENTS: u32 = 10_000;

/// Events inside the medium before Russian roulette may end the walk.
const WALK_RR_START: u32 = 16;

/// The radiance arriving along `camera_ray`: one sample of L, with
/// subsurface objects simulated as media. Same contract as
/// [`super::path::radiance`], and the same bounce loop (`trace`); only
/// subsurface hits differ.
pub fn radiance<R: Recorder, T: Clock>(
    ctx: &Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
    rec: &mut R,
) -> Vec3 {
    sample::<R, T, _>(
        ctx,
        camera_ray,
        rng,
        scratch,
        counters,
        rec,
        &mut RandomWalk,
    )
}

/// The random walk as the bounce loop's estimator of subsurface hits (and
/// the path integrator's at materials the accuracy budget gave the walk).
pub(crate) struct RandomWalk;

impl SubsurfaceScatter for RandomWalk {
    const EFFECT: Effect = Effect::Walk;

    #[inline(always)]
    fn scatter<'s, R: Recorder>(
        &mut self,
        ctx: &'s Context,
        hit: &SubsurfaceHit<'_, 's>,
        beta: &mut Vec3,
        st: &mut PathState<R>,
    ) -> Scatter<'s> {
        walk_hit(ctx, hit.ss, hit.si, hit.wo, beta, st.rng, st.counters)
    }
}

/// A subsurface hit under the random walk: the boundary at the hit, the
/// walk inside, and what leaves.
#[inline(always)]
fn walk_hit<'s>(
    ctx: &'s Context,
    ss: &'s crate::materials::Subsurface,
    si: &Interaction,
    wo: Vec3,
    beta: &mut Vec3,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Scatter<'s> {
    // Parameters built by hand without a medium leave nothing to
    // simulate; the path ends as at a black surface.
    let Some(medium) = ss.params().medium else {
        return Scatter::Absorbed;
    };
    // As in the path tracer, the side the ray arrives from is
    // "outside", so a mesh wound inside-out still works.
    let n_out = if si.front { si.ng } else { -si.ng };
    match ss.boundary() {
        WalkBoundary::Dielectric { connect } => {
            let frame = Frame::from_normal(n_out);
            let s = dielectric::sample(ss.eta(), frame.to_local(wo), rng.uniform());
            *beta *= s.weight;
            let wi = frame.to_world(s.wi).normalize();
            if !s.transmitted {
                return Scatter::Continue(si.spawn(wi, ctx.ray_epsilon), Event::Specular);
            }
            let inside = si.spawn(wi, ctx.ray_epsilon);
            let law = Boundary::Dielectric(ss.eta());
            if connect {
                return connected_walk(ctx, &medium, ss.eta(), inside, beta, rng, counters);
            }
            match walk(ctx, &medium, law, inside, rng, counters) {
                Some((WalkEnd::Refracted(exit), w)) => {
                    *beta *= w;
                    Scatter::Continue(exit, Event::Subsurface)
                }
                _ => Scatter::Absorbed,
            }
        }
        WalkBoundary::Diffuse { exit_nee } => diffuse_hit(
            ctx,
            &medium,
            ss.eta(),
            exit_nee,
            si,
            n_out,
            wo,
            beta,
            rng,
            counters,
        ),
    }
}

/// A walk through the smooth dielectric of index `eta` from `inside`,
/// sampling the lights through the boundary at its scattering points
/// ([`super::walk_nee`]); `beta` is the path's throughput on entry.
fn connected_walk<'s>(
    ctx: &Context,
    medium: &Medium,
    eta: f32,
    inside: Ray,
    beta: &mut Vec3,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Scatter<'s> {
    let mut nl = WalkLight::new(eta);
    let law = Boundary::Dielectric(eta);
    // The connections' light is the walk's (in the walk's throughput), so
    // the path's throughput on entry weighs it.
    let end = walk_lit(ctx, medium, law, inside, rng, counters, Some(&mut nl));
    let light = *beta * throughput(&nl.light);
    let exit = match end {
        Some((WalkEnd::Refracted(exit), w)) => {
            *beta *= w;
            Some((exit, nl.exit))
        }
        _ => None,
    };
    Scatter::WalkLit {
        light,
        source: nl.source,
        exit,
    }
}

/// A subsurface hit under the diffuse Fresnel boundary
/// ([`super::diffuse_boundary`]): mirror reflection with probability Fr, or
/// entry in a diffuse direction, a walk, and the exit point as a vertex
/// with the exit lobe (where the bounce loop samples the lights). With
/// `exit_nee` false the exit lobe is sampled here instead, so the path
/// leaves without a light sample: the same model, estimated without
/// next-event estimation at the exit.
#[allow(clippy::too_many_arguments)]
fn diffuse_hit<'s>(
    ctx: &Context,
    medium: &Medium,
    eta: f32,
    exit_nee: bool,
    si: &Interaction,
    n_out: Vec3,
    wo: Vec3,
    beta: &mut Vec3,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Scatter<'s> {
    let b = DiffuseBoundary::new(eta);
    let mu = wo.dot(n_out).max(0.0);
    let Some((w_in, weight)) = b.enter(mu, rng) else {
        let wi = (2.0 * mu) * n_out - wo;
        return Scatter::Continue(si.spawn(wi, ctx.ray_epsilon), Event::Specular);
    };
    *beta *= weight;
    let inward = Frame::from_normal(-n_out).to_world(w_in).normalize();
    let inside = si.spawn(inward, ctx.ray_epsilon);
    let Some((WalkEnd::Exit { p, n_out }, w)) =
        walk(ctx, medium, Boundary::Diffuse(&b), inside, rng, counters)
    else {
        return Scatter::Absorbed;
    };
    *beta *= w;
    let frame = Frame::from_normal(n_out);
    let lobe = b.exit_lobe();
    if exit_nee {
        return Scatter::Vertex(Vertex {
            p,
            ng: n_out,
            frame,
            wo_local: Vec3::Z,
            lobe: Lobe::Subsurface(SubsurfaceLobe::WalkExit(lobe)),
            // The walk's exit is not culled from (the reference stays as
            // it was).
            outside_of: None,
        });
    }
    match lobe.sample(rng.uniform2_packed()) {
        Some((wi, w, _)) => {
            *beta *= w;
            let origin = offset_along(p, n_out, ctx.ray_epsilon);
            Scatter::Continue(Ray::new(origin, frame.to_world(wi)), Event::Subsurface)
        }
        None => Scatter::Absorbed,
    }
}

/// The boundary law a walk obeys when it reaches the surface from inside.
#[derive(Clone, Copy)]
pub enum Boundary<'a> {
    /// The smooth dielectric of index η: reflect or refract out.
    Dielectric(f32),
    /// The diffuse Fresnel boundary: reflect, or stop at the exit point.
    Diffuse(&'a DiffuseBoundary),
}

/// How a walk left the medium.
pub enum WalkEnd {
    /// Through the smooth dielectric: the refracted ray, outside.
    Refracted(Ray),
    /// Through the diffuse boundary: the exit point and the outward normal
    /// there; the direction is the exit lobe's to choose.
    Exit { p: Vec3, n_out: Vec3 },
}

/// Walks from `ray` (just inside the boundary, unit direction) through the
/// medium until it leaves. Returns how it left and the walk's throughput
/// (per channel, including the exit refraction's), or None when the walk
/// was absorbed (Russian roulette), capped or escaped.
///
/// **Scattering points stay inside.** A scattering point sampled closer to
/// the boundary than float rounding resolves can round to the outside;
/// the next flight from there in an outward direction then meets no
/// surface, and a closed mesh reported escaped walks (a few per million
/// walks in a dense medium). A point closer to the boundary plane than the
/// spawn offset of [`offset_along`] is therefore pushed inwards, along the
/// normal of the triangle the flight was heading for, to that offset: the
/// same margin every spawned ray keeps (a displacement ≤ 4·10⁻⁶ |p|, far
/// below any mean free path the supported ranges allow).
///
/// **Flights without a query.** A flight shorter than the distance from
/// its origin to the nearest surface (`clear_flight`: the bound of
/// [`crate::geometry::distance`]) cannot meet the boundary, so it scatters
/// without asking the accelerator: the walk's randoms, weights and points
/// are the ones the query would have given. Such a point keeps twice the
/// spawn margin from every surface, so the push above never moves it on a
/// convex body; on another, only a far triangle whose plane passes within
/// the margin could have (the bunny's samples are the same bit for bit,
/// `tests/physics/randomwalk.rs`).
pub fn walk(
    ctx: &Context,
    m: &Medium,
    boundary: Boundary,
    ray: Ray,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Option<(WalkEnd, Vec3)> {
    walk_lit(ctx, m, boundary, ray, rng, counters, None)
}

/// [`walk`], and with `nee` (the smooth dielectric only) each scattering
/// point samples the lights through the boundary ([`super::walk_nee`]),
/// `nee` summing their light and recording the last scattering point
/// before the walk leaves.
fn walk_lit(
    ctx: &Context,
    m: &Medium,
    boundary: Boundary,
    mut ray: Ray,
    rng: &mut SampleRng,
    counters: &mut Counters,
    mut nee: Option<&mut WalkLight>,
) -> Option<(WalkEnd, Vec3)> {
    let sigma_t = m.sigma_t();
    let grid = ctx.distance_grid();
    let mut beta = [1.0f64; 3];
    for event in 0..MAX_WALK_EVENTS {
        // A walk with nothing left to carry (a black medium's first
        // scattering) ends before its next query.
        let total: f64 = beta.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        // Hero channel by throughput: channel k with probability
        // q_k = β_k / total; the same uniform, rescaled, for the distance.
        let (c, u) = pick_channel(&beta, total, rng.uniform_f64());
        let t = free_flight(sigma_t[c], u);
        let mis = ChannelMis {
            beta: &mut beta,
            sigma_t: &sigma_t,
            hero: c,
            total,
        };

        let p = if t < clear_flight(ctx, grid, ray.o) {
            ray.at(t as f32)
        } else {
            counters.ray(Effect::Walk);
            // Inside a closed mesh every direction meets the boundary. No
            // hit means the walk is in the open (through a hole of an open
            // mesh, or on the wrong side of a single sheet): there is no
            // bounded medium, and scattering on in an unbounded one would
            // never end.
            let Some(hit) = ctx.accel.intersect(&ray, 0.0, f32::INFINITY) else {
                counters.walks_escaped += 1;
                return None;
            };
            let t_max = hit.t as f64;
            if t >= t_max {
                mis.transmit(t_max)?;
                match at_boundary(ctx, boundary, &ray, &hit, rng) {
                    Ok((end, weight)) => {
                        if let Some(nl) = nee.as_deref_mut() {
                            nl.left(&hit);
                        }
                        return Some((end, weight * throughput(&beta)));
                    }
                    Err(next) => {
                        if let Some(nl) = nee.as_deref_mut() {
                            nl.reflected();
                        }
                        ray = next;
                    }
                }
                continue;
            }
            inside_point(ctx, &ray, &hit, t, t_max)
        };

        // A real scattering event at distance t.
        mis.scatter(&m.sigma_s, t)?;
        if let Some(nl) = nee.as_deref_mut() {
            nl.at_scatter(ctx, m, p, ray.d, &beta, rng, counters);
        }
        // The phase function is sampled exactly: its weight is 1.
        ray = Ray::new(p, sample_hg(ray.d, m.g, rng.uniform2_packed()));
        if event >= WALK_RR_START {
            // Roulette with the largest channel's throughput: a walk that
            // survives carries 1 there again.
            let survive = beta.iter().copied().fold(0.0, f64::max);
            if survive.is_nan() || survive <= 0.0 {
                return None;
            }
            if survive < 1.0 {
                if rng.uniform_f64() >= survive {
                    return None;
                }
                let inv = 1.0 / survive;
                beta = beta.map(|b| b * inv);
            }
        }
    }
    counters.walks_capped += 1;
    None
}

/// How far a flight from `o` can go without meeting a surface: the
/// scene's distance bound there ([`crate::geometry::distance`]) less twice
/// the spawn margin of [`inside_point`] (once for the flight's own
/// rounding, once for the accelerator's), or 0.
#[inline]
fn clear_flight(ctx: &Context, grid: Option<&DistanceGrid>, o: Vec3) -> f64 {
    let Some(grid) = grid else {
        return 0.0;
    };
    let d = grid.bound(o);
    if d.is_nan() || d <= 0.0 {
        return 0.0;
    }
    let margin = ctx.ray_epsilon.max((o.abs().max_element() + d) * 4e-6);
    (d - 2.0 * margin) as f64
}

/// The one-sample balance heuristic over the channels for one flight
/// sampled from the hero channel's exponential (`docs/bssrdf.md` §7,
/// "The walk's cost"): the pdf Σ_k q_k p_k(t) with q_k = β_k / total. Every
/// channel's density carries the factor e^{−σt_c t} of the hero's, which
/// cancels in the weights, so only the other channels' ratios
/// e^{−(σt_k − σt_c) t} are computed: two `exp`, none for a channel of the
/// hero's σt. The ratios stay below e^{σt_c t} ≤ 2^53 for any t the
/// flight's 53-bit uniform gives (a transmitted flight stops sooner).
struct ChannelMis<'a> {
    beta: &'a mut [f64; 3],
    sigma_t: &'a [f64; 3],
    hero: usize,
    total: f64,
}

impl ChannelMis<'_> {
    /// e^{−σt_k t} / e^{−σt_c t} per channel k, c the hero.
    #[inline]
    fn ratios(&self, t: f64) -> [f64; 3] {
        let st_c = self.sigma_t[self.hero];
        std::array::from_fn(|k| {
            if self.sigma_t[k] == st_c {
                1.0
            } else {
                (-(self.sigma_t[k] - st_c) * t).exp()
            }
        })
    }

    /// Weighs a flight that scattered at distance `t`: σs e^{−σt t} over the
    /// pdf Σ_k q_k σt_k e^{−σt_k t}. None when that pdf is not positive
    /// (the walk ends).
    #[inline]
    fn scatter(self, sigma_s: &[f64; 3], t: f64) -> Option<()> {
        let r = self.ratios(t);
        let b = &mut *self.beta;
        let pdf = b[0] * self.sigma_t[0] * r[0]
            + b[1] * self.sigma_t[1] * r[1]
            + b[2] * self.sigma_t[2] * r[2];
        let scale = self.total / pdf;
        if !(scale.is_finite() && pdf > 0.0) {
            return None;
        }
        for k in 0..3 {
            b[k] *= sigma_s[k] * r[k] * scale;
        }
        Some(())
    }

    /// Weighs a flight that reached the boundary at `t_max`: probability
    /// e^{−σt t_max} per channel, over Σ_k q_k e^{−σt_k t_max}.
    #[inline]
    fn transmit(self, t_max: f64) -> Option<()> {
        let r = self.ratios(t_max);
        let b = &mut *self.beta;
        let pdf = b[0] * r[0] + b[1] * r[1] + b[2] * r[2];
        let scale = self.total / pdf;
        if !(scale.is_finite() && pdf > 0.0) {
            return None;
        }
        for k in 0..3 {
            b[k] *= r[k] * scale;
        }
        Some(())
    }
}

fn throughput(beta: &[f64; 3]) -> Vec3 {
    Vec3::new(beta[0] as f32, beta[1] as f32, beta[2] as f32)
}

/// The boundary law at `hit`, reached from inside along `ray`: Ok with how
/// the walk leaves and the crossing's weight, or Err with the ray
/// reflected back in.
fn at_boundary(
    ctx: &Context,
    boundary: Boundary,
    ray: &Ray,
    hit: &Hit,
    rng: &mut SampleRng,
) -> Result<(WalkEnd, f32), Ray> {
    match boundary {
        Boundary::Dielectric(eta) => {
            let (exit, next, weight) = cross_boundary(ctx, eta, ray, hit, rng);
            if exit {
                Ok((WalkEnd::Refracted(next), weight))
            } else {
                Err(next)
            }
        }
        Boundary::Diffuse(b) => {
            let si = ctx.interaction(ray, hit);
            let n_out = if ray.d.dot(si.ng) > 0.0 {
                si.ng
            } else {
                -si.ng
            };
            let mu_in = ray.d.dot(n_out);
            if rng.uniform() >= b.reflect_in(mu_in) {
                return Ok((WalkEnd::Exit { p: si.p, n_out }, 1.0));
            }
            let wi = reflect(-ray.d, n_out).normalize();
            Err(si.spawn(wi, ctx.ray_epsilon))
        }
    }
}

/// The scattering point at distance `t` < `t_max` along `ray`, whose flight
/// was heading for `hit` at `t_max`, kept at least the spawn offset inside
/// the plane of the hit triangle (see [`walk`]).
#[inline]
fn inside_point(ctx: &Context, ray: &Ray, hit: &Hit, t: f64, t_max: f64) -> Vec3 {
    let p = ray.at(t as f32);
    let ng = ctx.scene.meshes[hit.geom as usize].face_normals()[hit.prim as usize];
    let cos = ray.d.dot(ng);
    let gap = (t_max - t) as f32 * cos.abs();
    let margin = ctx.ray_epsilon.max(p.abs().max_element() * 4e-6);
    if gap < margin {
        let n_out = if cos > 0.0 { ng } else { -ng };
        p - n_out * (margin - gap)
    } else {
        p
    }
}

/// Fresnel at the boundary seen from inside: refract out (true) or reflect
/// back in (false, including total internal reflection). Returns the new ray
/// and the dielectric's throughput weight.
fn cross_boundary(
    ctx: &Context,
    eta: f32,
    ray: &Ray,
    hit: &Hit,
    rng: &mut SampleRng,
) -> (bool, Ray, f32) {
    let si = ctx.interaction(ray, hit);
    // Outside is where the ray is heading.
    let n_out = if ray.d.dot(si.ng) > 0.0 {
        si.ng
    } else {
        -si.ng
    };
    let frame = Frame::from_normal(n_out);
    let s = dielectric::sample(eta, frame.to_local(-ray.d), rng.uniform());
    let wi = frame.to_world(s.wi).normalize();
    // spawn offsets to the side wi goes: outside on exit, inside on reflection.
    (s.transmitted, si.spawn(wi, ctx.ray_epsilon), s.weight)
}

/// A free-flight distance t ~ σt e^{−σt t} from one uniform `u` ∈ [0, 1)
/// (inverted CDF); infinite when σt = 0.
pub fn free_flight(sigma_t: f64, u: f64) -> f64 {
    if sigma_t > 0.0 {
        -(1.0 - u).ln() / sigma_t
    } else {
        f64::INFINITY
    }
}

/// The channel whose interval of the cumulative throughputs holds
/// `u`·`total` (channel k with probability β_k / total), and where in
/// that interval: a uniform in [0, 1) independent of the choice, with the
/// bits of `u` the choice did not use (53 less log2(1/q_k), so 30 or more
/// for any channel the walk picks more often than once in 10⁷).
#[inline]
fn pick_channel(beta: &[f64; 3], total: f64, u: f64) -> (usize, f64) {
    let x = u * total;
    let (mut lo, mut last) = (0.0, 0);
    for (k, &bk) in beta.iter().enumerate() {
        if bk > 0.0 {
            if x < lo + bk {
                return (k, within(x, lo, bk));
            }
            last = k;
            lo += bk;
        }
    }
    // Rounding left x past the sum: the last live channel.
    (last, within(x, lo - beta[last], beta[last]))
}

/// Where `x` lies in [lo, lo + width), as a uniform below 1.
#[inline]
fn within(x: f64, lo: f64, width: f64) -> f64 {
    const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;
    ((x - lo) / width).clamp(0.0, BELOW_ONE)
}
