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
//! probe ray (King et al. 2013; [`crate::bssrdf::probe`]); at the camera
//! vertex its next-event estimate gets the plane control variate
//! ([`super::control_variate`]: the light a model of the surface predicts
//! at the probe's disk point, less its known mean, is subtracted; the light
//! sample is drawn ahead, in `entries`, so the model and the entry point
//! use the same one). An antithetic pair of probes (below) is the other
//! option, off by default. Paths end at `max_depth` bounces or by Russian
//! roulette once their throughput is small (pbrt-v4 §13.1.1).
//!
//! **The antithetic probe pair** ([`PAIR_DEPTH`], off by default). At a
//! subsurface hit xo of the camera path, one probe's random numbers
//! (channel, radius r, axis V, angle φ) give two probes, at φ and at φ + π, and so two entry points
//! x₁, x₂ with the probe weights W_k = Rd(|xo − x_k|) / p(x_k) × (hits on
//! its segment). With β the throughput into the medium,
//!
//!   L̂(xo) = β · [ ½ Σ_k W_k · L̂_nee(x_k)  +  W_K · L̂_lobe(x_K) ],
//!   K ∈ {1, 2} with probability ½ each,
//!
//! L̂_nee the light sampled at x_k (MIS-weighted) and L̂_lobe the path
//! continued from x_K by sampling its lobe (emission it finds MIS-weighted
//! against the light sample at x_K). A probe that finds nothing
//! contributes 0: when only x_k exists, L̂ = β · ½ W_k · (L̂_nee(x_k) +
//! L̂_lobe(x_k)). Unbiased: φ + π is uniform when φ is, so each x_k alone
//! has the density p the one-probe estimator divides by, and the two
//! halves average two such estimators (the continuation by choosing one,
//! weight 2 · ½). Why: light at the entry point that changes linearly
//! across the profile, L(xo + δ) ≈ L(xo) + ∇L·δ, cancels exactly between
//! δ and −δ on a plane (to first order in κr on a surface of curvature
//! κ), and that change — the irradiance turning across a lit curved body,
//! and the probe weights' own spread — is most of one probe's noise on a
//! smoothly lit body: on scenes/smooth-sphere.toml the pair has 0.36× one
//! plain probe's relMSE per sample for 1.34× the rays. The control
//! variate takes most of the same noise for no ray (0.43×), and so
//! replaced the pair as the default: per unit of work the two are within
//! 5 % (the control variate ahead), and the pair with the control variate
//! too is best by another 5 % at 1.36× the default's work per sample
//! (docs/accuracy.md, "The plane control variate"). Deeper vertices use
//! one probe: their share of the image is small and the second probe and
//! light sample cost the same there.
//!
//! **Coated subsurface hits.** The coat at xo reflects a fraction (Fr for
//! the smooth coat, E(μo) for the rough one) and passes the rest into the
//! medium. For the smooth coat, at vertices shallower than
//! `COAT_SPLIT_DEPTH` both parts are followed (splitting: the mirror
//! reflection becomes a second path, kept on a small stack, so the
//! reflection of a small light is no longer a rare event); deeper, one of
//! them is chosen with probability Fr. A rough coat is a lobe with
//! next-event estimation at xo every time, combined by the power heuristic
//! with sampling its visible normals, whose density counts the probability
//! E of choosing it (so the emission weight at the next hit agrees); the
//! path then goes on by the coat with probability E, else into the medium.
//! Light sampling already finds the highlight there, and splitting the
//! rough coat measured worse per unit time (see `COAT_SPLIT_DEPTH`).
//!
//! **Level of detail.** Each path carries its footprint, a ray cone
//! ([`Cone`]: width and spread, from the camera pixel; kept through
//! specular bounces, widened after lobes). Where a subsurface material's
//! rule says the footprint is wide against its profile, the entry point is
//! xo itself, weighted by the profile's plane integral, and no probe is
//! cast ([`crate::materials::lod`]); the coat is unchanged.

use super::aov::{self, Event, Recorder, Source};
#[cfg(feature = "subsurface")]
use super::control_variate;
use super::footprint::Cone;
use super::interaction::offset_along;
#[cfg(feature = "subsurface")]
use super::probe::{entry_on_segment, ProbeTarget};
use super::{Clock, Context, Counters, Effect, Interaction};
use crate::accel::ProbeHits;
#[cfg(feature = "subsurface")]
use crate::bssrdf::curvature_correction::{CurvatureCorrection, ExitFactor};
#[cfg(feature = "subsurface")]
use crate::bssrdf::{PlaneModel, ProbeRandoms, ProbeSegment};
use crate::film::passes::Pass;
#[cfg(feature = "subsurface")]
use crate::geometry::curvature::TriangleCurvature;
use crate::geometry::{Frame, Ray, Vec3};
use crate::lights::LightSample;
use crate::materials::{dielectric, diffuse, Material};
#[cfg(feature = "subsurface")]
use crate::materials::{
    microfacet::{reflect, RoughCoat},
    Subsurface,
};
use crate::sampling::{power, Draw, SampleRng};
#[cfg(feature = "subsurface")]
use crate::{
    fresnel,
    sampling::{cosine_hemisphere, cosine_hemisphere_pdf},
};

/// A build without the `subsurface` feature has no subsurface material:
/// the bounce loop's handler of subsurface hits takes this uninhabited
/// type, so it can never be called, and the compiler drops it and every
/// path through it (docs/performance.md, "Zero cost for what is off").
#[cfg(not(feature = "subsurface"))]
#[derive(Clone, Copy)]
pub(crate) enum Subsurface {}

/// Bounces after which Russian roulette may end a path.
pub(crate) const RR_START: u32 = 3;

/// Smooth-coated subsurface hits at depths below this split into the
/// mirror reflection and the medium (both followed); deeper ones choose
/// one. 1: the camera vertex only. Measured on a smooth-shaded marble
/// sphere under one small light (256², 64 spp, vs 1024-spp references):
/// with probes along the normal, splitting cuts relMSE by 41 % (the
/// highlight's share of it from ~20 % to 0.5 %) for ~24 % more CPU time
/// per sample, a 27 % gain in time to a given error; with `mis3` probes,
/// whose own noise dominates, −20 % error for ~30 % more time, even. Deeper
/// vertices rarely see a coat worth splitting (on a convex object, none),
/// and each split level adds a path. Splitting the rough coat as well (its
/// reflection sampled every time, besides next-event estimation) lowered
/// relMSE by 8–10 % for 24 % more rays, a loss, so it chooses.
#[cfg(feature = "subsurface")]
pub(crate) const COAT_SPLIT_DEPTH: u32 = 1;

pub use super::context::PAIR_DEPTH;

/// Paths waiting to be traced after the current one ends. A path pushes
/// at most one branch per depth below [`COAT_SPLIT_DEPTH`], and a branch
/// starts one depth below the vertex that pushed it, so at most
/// `COAT_SPLIT_DEPTH` wait at once: the stack is never full.
const MAX_BRANCHES: usize = 4;
#[cfg(feature = "subsurface")]
const _: () = assert!(COAT_SPLIT_DEPTH as usize <= MAX_BRANCHES);

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
    #[cfg(feature = "subsurface")]
    SubsurfaceEntry(&'a Subsurface),
    /// Where a random walk left the medium through a diffuse Fresnel
    /// boundary ([`super::diffuse_boundary::ExitLobe`]).
    #[cfg(feature = "subsurface")]
    WalkExit(super::diffuse_boundary::ExitLobe),
    /// A subsurface material's rough coat at xo, sampled with probability
    /// `select` (its pdf, for MIS, is select × the visible-normal pdf).
    #[cfg(feature = "subsurface")]
    Coat { coat: &'a RoughCoat, select: f32 },
    /// Without the `subsurface` feature: no lobe (uninhabited), keeping
    /// the lifetime the subsurface lobes borrow with.
    #[cfg(not(feature = "subsurface"))]
    #[allow(dead_code)]
    Absent(&'a Subsurface),
}

impl Lobe<'_> {
    /// The light-path class of scattering by this lobe ([`aov`]).
    fn event(&self) -> Event {
        match self {
            Lobe::Diffuse(_) => Event::Diffuse,
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(_) | Lobe::WalkExit(_) => Event::Subsurface,
            #[cfg(feature = "subsurface")]
            Lobe::Coat { .. } => Event::Specular,
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
        }
    }
    /// f(ωo, ωi) per steradian (ωo, ωi local; z > 0 is the lit side).
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            Lobe::Diffuse(albedo) => diffuse::eval(*albedo, wo, wi),
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(ss) => Vec3::splat(ss.lobe(wi.z)),
            #[cfg(feature = "subsurface")]
            Lobe::WalkExit(exit) => Vec3::splat(exit.eval(wi)),
            #[cfg(feature = "subsurface")]
            Lobe::Coat { coat, .. } => Vec3::splat(coat.eval(wo, wi)),
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
        }
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Lobe::Diffuse(_) => diffuse::pdf(wo, wi),
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(_) => cosine_hemisphere_pdf(wi.z),
            #[cfg(feature = "subsurface")]
            Lobe::WalkExit(exit) => exit.pdf(wi),
            #[cfg(feature = "subsurface")]
            Lobe::Coat { coat, select } => select * coat.pdf(wo, wi),
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
        }
    }
    /// Samples ωi; returns (ωi, f |cos| / pdf, pdf).
    pub(crate) fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<(Vec3, Vec3, f32)> {
        match self {
            Lobe::Diffuse(albedo) => diffuse::sample(*albedo, wo, u),
            #[cfg(feature = "subsurface")]
            Lobe::SubsurfaceEntry(ss) => {
                let wi = cosine_hemisphere(u);
                let pdf = cosine_hemisphere_pdf(wi.z);
                (pdf > 0.0).then(|| (wi, Vec3::splat(ss.lobe(wi.z) * wi.z / pdf), pdf))
            }
            #[cfg(feature = "subsurface")]
            Lobe::WalkExit(exit) => exit.sample(u).map(|(wi, w, pdf)| (wi, Vec3::splat(w), pdf)),
            #[cfg(feature = "subsurface")]
            Lobe::Coat { coat, select } => {
                let (wi, w, pdf) = coat.sample(wo, u)?;
                (*select > 0.0).then(|| (wi, Vec3::splat(w / select), select * pdf))
            }
            #[cfg(not(feature = "subsurface"))]
            Lobe::Absent(s) => match **s {},
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
    /// The object the vertex lies on, when rays leaving it on the side of
    /// `ng` cannot meet that object again ([`Context::leaving`]); None
    /// where that is not known.
    pub(crate) outside_of: Option<u32>,
}

/// What a subsurface hit turns into: a vertex that scatters light with a
/// lobe (next-event estimation, then lobe sampling), a ray that continues
/// without one (a specular bounce, or leaving a medium; with the class of
/// that event for the light-path passes, [`aov`]), or the end of the
/// path. Both integrators share one bounce loop, [`trace`], and differ only
/// in how they produce this.
// Returned by value once per subsurface hit and read in place (the loop
// borrows the vertex from it); boxing the large variant would allocate in
// the hot path.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Scatter<'a> {
    Vertex(Vertex<'a>),
    Continue(Ray, Event),
    #[cfg(feature = "subsurface")]
    Absorbed,
    /// A subsurface hit under a coat ([`subsurface_probe`]).
    #[cfg(feature = "subsurface")]
    Coated(Coated<'a>),
}

/// What a coated subsurface hit at xo turns into: the coat's lobe at xo
/// (next-event estimation there), a path the coat reflected, and the
/// entry vertex xi where this path goes on.
#[cfg(feature = "subsurface")]
pub(crate) struct Coated<'a> {
    /// The rough coat's vertex at xo and the throughput light sampled
    /// there is weighted by (β before the hit).
    pub(crate) coat: Option<(Vertex<'a>, Vec3)>,
    /// The coat's reflected ray, its throughput and the pdf its lobe
    /// sampled it with (None for the mirror).
    pub(crate) reflected: Option<Reflected>,
    /// The entry vertex xi (its throughput already in β): this path goes on
    /// there and `reflected` waits on the stack; None: this path goes on
    /// along `reflected`, or ends.
    pub(crate) entry: Option<Vertex<'a>>,
    /// The other entry point of an antithetic pair ([`PAIR_DEPTH`]) and the
    /// throughput light sampled there is weighted by; when Some, light
    /// sampled at `entry` counts ½ too.
    pub(crate) pair: Option<(Vertex<'a>, Vec3)>,
    /// What the plane control variate drew and adds ([`Ahead`]).
    pub(crate) ahead: Ahead,
}

/// The plane control variate's part of a subsurface hit
/// ([`super::control_variate`]): when it applies, the light samples drawn
/// ahead for next-event estimation at the entry point (and at its pair's
/// twin), which its model used, and its terms, each × the throughput, with
/// the light they sampled ([`aov::NO_LIGHT`]: none). The terms count
/// whether or not the probes found an entry point.
#[cfg(feature = "subsurface")]
#[derive(Clone, Copy, Default)]
pub(crate) struct Ahead {
    pub(crate) lights: Option<[Option<LightSample>; 2]>,
    pub(crate) terms: [(Vec3, u32); 2],
}

/// What [`entries`] found: the entry vertex, its pair's twin with its
/// throughput, and the control variate's part.
#[cfg(feature = "subsurface")]
type Entries<'s> = (Option<Vertex<'s>>, Option<(Vertex<'s>, Vec3)>, Ahead);

/// A ray the coat reflected: the ray, its throughput, and the vertex and
/// lobe pdf it was sampled with (None for the mirror).
#[cfg(feature = "subsurface")]
pub(crate) type Reflected = (Ray, Vec3, Option<(Vec3, f32)>);

/// A path to trace: its ray, throughput, the last non-specular vertex and
/// its lobe pdf (for the emission MIS weight), its depth, the class of
/// its first event (for the light-path passes), and its footprint cone
/// (for subsurface level of detail, [`crate::materials::lod`]).
#[derive(Clone, Copy)]
struct Branch {
    ray: Ray,
    /// The object `ray` leaves, if it cannot meet it ([`Context::leaving`]).
    from: Option<u32>,
    beta: Vec3,
    prev: Option<(Vec3, f32)>,
    depth: u32,
    event: Event,
    cone: Cone,
}

/// A fixed-capacity stack of [`Branch`]es (no allocation per sample).
#[derive(Default)]
struct Branches {
    items: [Option<Branch>; MAX_BRANCHES],
    len: usize,
}

impl Branches {
    /// Never full (see [`MAX_BRANCHES`]).
    #[cfg(feature = "subsurface")]
    fn push(&mut self, b: Branch) {
        self.items[self.len] = Some(b);
        self.len += 1;
    }
    fn pop(&mut self) -> Option<Branch> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        self.items[self.len].take()
    }
}

/// The radiance arriving along `camera_ray`: one sample of L, with the
/// BSSRDF estimated by one probe ray per subsurface hit (with the plane
/// control variate at the camera vertex); its parts go to `rec` ([`aov`]), its effects'
/// time to `T` ([`super::effects`]).
pub fn radiance<R: Recorder, T: Clock>(
    ctx: &Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
    rec: &mut R,
) -> Vec3 {
    trace_at::<R, T>(
        ctx,
        camera_ray,
        rng,
        counters,
        rec,
        |ss, si, wo, beta, rng, counters, depth, width| {
            let t0 = T::now();
            let s = subsurface_probe(ctx, ss, si, wo, beta, rng, scratch, counters, depth, width);
            T::lap(counters, Effect::Probe, t0);
            s
        },
    )
}

/// The bounce loop both integrators share; `subsurface` handles hits on
/// subsurface objects (and may scale the throughput `beta`).
#[cfg(feature = "subsurface")]
pub(crate) fn trace<'s, R: Recorder, T: Clock>(
    ctx: &'s Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    counters: &mut Counters,
    rec: &mut R,
    mut subsurface: impl FnMut(
        &'s Subsurface,
        &Interaction,
        Vec3,
        &mut Vec3,
        &mut SampleRng,
        &mut Counters,
    ) -> Scatter<'s>,
) -> Vec3 {
    trace_at::<R, T>(
        ctx,
        camera_ray,
        rng,
        counters,
        rec,
        |ss, si, wo, beta, rng, counters, _depth, _width| {
            subsurface(ss, si, wo, beta, rng, counters)
        },
    )
}

/// [`trace`] whose `subsurface` also receives the depth of the hit and the
/// width of the path's footprint there ([`Cone`]).
fn trace_at<'s, R: Recorder, T: Clock>(
    ctx: &'s Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    counters: &mut Counters,
    rec: &mut R,
    mut subsurface: impl FnMut(
        &'s Subsurface,
        &Interaction,
        Vec3,
        &mut Vec3,
        &mut SampleRng,
        &mut Counters,
        u32,
        f32,
    ) -> Scatter<'s>,
) -> Vec3 {
    // The paths a coat split off wait here; L sums over all of them.
    let mut stack = Branches::default();
    let mut first = Some(Branch {
        ray: camera_ray,
        from: None,
        beta: Vec3::ONE,
        prev: None,
        depth: 0,
        // Set at the first hit.
        event: Event::Diffuse,
        cone: Cone::camera(&ctx.camera_spread, camera_ray.d),
    });
    let mut l = Vec3::ZERO;
    while let Some(start) = first.take().or_else(|| stack.pop()) {
        l += follow::<R, T>(ctx, start, rng, counters, rec, &mut subsurface, &mut stack);
    }
    l
}

/// One path from `start` until it ends; paths split off on the way are
/// pushed on `stack`. (Without the `subsurface` feature neither
/// `subsurface` nor `stack` is used: no material calls for them.)
#[inline(always)]
#[cfg_attr(not(feature = "subsurface"), allow(unused_variables))]
fn follow<'s, R: Recorder, T: Clock>(
    ctx: &'s Context,
    start: Branch,
    rng: &mut SampleRng,
    counters: &mut Counters,
    rec: &mut R,
    subsurface: &mut impl FnMut(
        &'s Subsurface,
        &Interaction,
        Vec3,
        &mut Vec3,
        &mut SampleRng,
        &mut Counters,
        u32,
        f32,
    ) -> Scatter<'s>,
    stack: &mut Branches,
) -> Vec3 {
    let scene = ctx.scene;
    // The estimate of L, summed over the path's vertices.
    let mut l = Vec3::ZERO;
    // Path throughput: the product of f |cos| / pdf (and BSSRDF weights).
    let mut beta = start.beta;
    let mut ray = start.ray;
    // The object the ray leaves, which it cannot meet (culling).
    let mut from = start.from;
    // The last non-specular vertex and the solid-angle pdf with which its
    // lobe sampled the current ray; None after the camera or a specular
    // bounce, where no light sample competed for this direction.
    let mut prev: Option<(Vec3, f32)> = start.prev;
    // The class of the path's first event, known after its first hit.
    let mut event = start.event;
    // The footprint cone of the current ray.
    let mut cone = start.cone;

    let max_depth = scene.settings.max_depth;
    for depth in start.depth..=max_depth {
        // camera rays too: the tile loop moves one a sample to Effect::Camera
        counters.ray(Effect::Indirect);
        let t0 = T::now();
        let found = ctx.intersect(&ray, from, counters);
        let effect = if depth == 0 {
            Effect::Camera
        } else {
            Effect::Indirect
        };
        T::lap(counters, effect, t0);
        let Some(hit) = found else {
            if ctx.plan.environment {
                let c = beta * scene.environment.unwrap_or(Vec3::ZERO);
                l += c;
                let path = aov::found(event, depth, Pass::Background);
                rec.light(c, path, Source::Environment);
            }
            break;
        };
        let object = &scene.objects[hit.geom as usize];
        let si = ctx.interaction(&ray, &hit);
        let wo = -ray.d;
        if R::ON && depth == 0 {
            rec.camera_hit(hit.geom, si.p);
        }

        // Le, MIS-weighted against next-event estimation.
        if let (Some(le), true) = (object.emission, si.front) {
            let c = beta * le * emission_weight(ctx, &si, wo, prev);
            l += c;
            let path = aov::found(event, depth, Pass::Emission);
            rec.light(c, path, Source::Object(hit.geom));
        }
        if depth == max_depth {
            break;
        }

        // The object a ray the material continues with leaves, where known.
        let mut continue_from = None;
        let scatter = match &scene.materials[object.material] {
            Material::Diffuse { albedo } => {
                let frame = si.shading_frame_facing(wo);
                rec.surface(*albedo, frame.n);
                let front = wo.dot(si.ng) >= 0.0;
                let ng = if front { si.ng } else { -si.ng };
                Scatter::Vertex(Vertex {
                    p: si.p,
                    ng,
                    wo_local: frame.to_local(wo),
                    frame,
                    lobe: Lobe::Diffuse(*albedo),
                    outside_of: ctx.leaving(si.geom, front),
                })
            }
            Material::Dielectric { eta } => {
                let (next, e) = dielectric_bounce(ctx, *eta, &si, wo, &mut beta, rng);
                continue_from = ctx.leaving_towards(&si, next.d);
                Scatter::Continue(next, e)
            }
            #[cfg(feature = "subsurface")]
            Material::Subsurface(ss) => {
                if R::ON {
                    rec.surface(ss.albedo(), si.shading_frame_facing(wo).n);
                }
                subsurface(
                    ss,
                    &si,
                    wo,
                    &mut beta,
                    rng,
                    counters,
                    depth,
                    cone.width_at(hit.t),
                )
            }
        };
        // The footprint after this vertex: specular continuations keep the
        // cone's spread, lobes widen it.
        let (cone_specular, cone_rough) = (cone.specular(hit.t), cone.rough(hit.t));
        // Light sampled at the vertex counts this much (½ at an entry
        // point of an antithetic pair, whose twin is sampled too).
        #[cfg_attr(not(feature = "subsurface"), allow(unused_mut))]
        let mut nee_scale = 1.0;
        // The light sample drawn ahead for the vertex, if any ([`Ahead`]).
        #[cfg(feature = "subsurface")]
        let mut nee_ahead: Option<Option<LightSample>> = None;
        // Borrowed, not moved out: the vertex stays where it was built.
        // At the first hit the path's class becomes that of what scattered;
        // the coat's reflections are specular.
        let first = R::ON && depth == 0;
        #[cfg(feature = "subsurface")]
        let coat_event = if first { Event::Specular } else { event };
        let vertex = match &scatter {
            Scatter::Vertex(v) => {
                if first {
                    event = v.lobe.event();
                }
                v
            }
            Scatter::Continue(next, e) => {
                if first {
                    event = *e;
                }
                prev = None;
                ray = *next;
                from = continue_from;
                cone = cone_specular;
                if !roulette(depth, &mut beta, rng) {
                    break;
                }
                continue;
            }
            #[cfg(feature = "subsurface")]
            Scatter::Absorbed => break,
            #[cfg(feature = "subsurface")]
            Scatter::Coated(c) => {
                if let (Some((v, b)), true) = (&c.coat, ctx.plan.area_lights) {
                    let t0 = T::now();
                    let (d, light) = direct_lighting(ctx, v, rng, counters);
                    T::lap(counters, Effect::Direct, t0);
                    let c = *b * d;
                    l += c;
                    rec.light(c, aov::sampled(coat_event, depth), Source::Light(light));
                }
                let (next, follow_reflected) = match (&c.entry, c.reflected) {
                    (Some(v), Some((r, mut b, p))) => {
                        // Both: this path enters the medium, the reflection
                        // waits on the stack (one branch per split depth).
                        if roulette(depth, &mut b, rng) {
                            stack.push(Branch {
                                ray: r,
                                from: ctx.leaving_towards(&si, r.d),
                                beta: b,
                                prev: p,
                                depth: depth + 1,
                                event: coat_event,
                                cone: cone_specular,
                            });
                        }
                        (Some(v), None)
                    }
                    (Some(v), None) => (Some(v), None),
                    (None, reflected) => (None, reflected),
                };
                // The control variate's terms, which count whether or not
                // the probes found an entry point.
                let lights = c.ahead.lights;
                if lights.is_some() {
                    let ev = if first { Event::Subsurface } else { event };
                    for (t, light) in c.ahead.terms {
                        if light != aov::NO_LIGHT {
                            l += t;
                            rec.light(t, aov::sampled(ev, depth), Source::Light(light));
                        }
                    }
                }
                match (next, follow_reflected) {
                    (Some(v), _) => {
                        if first {
                            event = v.lobe.event();
                        }
                        nee_ahead = lights.map(|ls| ls[0]);
                        if let Some((pv, b)) = &c.pair {
                            if ctx.plan.area_lights {
                                let t0 = T::now();
                                let ahead = lights.map(|ls| ls[1]);
                                let (d, light) =
                                    direct_lighting_ahead(ctx, pv, ahead, rng, counters);
                                T::lap(counters, Effect::Direct, t0);
                                let c = *b * d;
                                l += c;
                                rec.light(c, aov::sampled(event, depth), Source::Light(light));
                            }
                            nee_scale = 0.5;
                        }
                        v
                    }
                    (None, Some((r, b, p))) => {
                        (ray, beta, prev, event) = (r, b, p, coat_event);
                        from = ctx.leaving_towards(&si, r.d);
                        cone = cone_specular;
                        if !roulette(depth, &mut beta, rng) {
                            break;
                        }
                        continue;
                    }
                    (None, None) => break,
                }
            }
        };

        // Next-event estimation, then continue by sampling the lobe.
        if ctx.plan.area_lights {
            let t0 = T::now();
            #[cfg(feature = "subsurface")]
            let (d, light) = direct_lighting_ahead(ctx, vertex, nee_ahead, rng, counters);
            #[cfg(not(feature = "subsurface"))]
            let (d, light) = direct_lighting(ctx, vertex, rng, counters);
            T::lap(counters, Effect::Direct, t0);
            let c = (nee_scale * beta) * d;
            l += c;
            rec.light(c, aov::sampled(event, depth), Source::Light(light));
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
        from = vertex.outside_of;
        cone = cone_rough;
        if !roulette(depth, &mut beta, rng) {
            break;
        }
    }
    l
}

/// A specular bounce off or through a dielectric, and which it was.
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
) -> (Ray, Event) {
    let frame = Frame::from_normal(si.ng);
    let s = dielectric::sample(eta, frame.to_local(wo), rng.uniform());
    *beta *= s.weight;
    let e = if s.transmitted {
        Event::Transmission
    } else {
        Event::Specular
    };
    (si.spawn(frame.to_world(s.wi), ctx.ray_epsilon), e)
}

/// A subsurface hit at xo under the diffusion model: the coat at xo, then
/// one probe ray for the entry point xi, where the path continues with the
/// entry lobe.
///
/// The coat reflects Fr (smooth) or E(μo) (rough) and passes the rest into
/// the medium. For the smooth coat at `depth` < [`COAT_SPLIT_DEPTH`] both
/// are followed; otherwise the reflection is taken with probability Fr or
/// E (weight: the sample's own, divided by that probability) and the medium
/// otherwise (weight 1). The rough coat's lobe always gets next-event
/// estimation at xo. Without `specular` the reflection is dropped and the
/// medium weighted by 1 − Fr or 1 − E.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
#[cfg(feature = "subsurface")]
fn subsurface_probe<'s>(
    ctx: &Context,
    ss: &'s Subsurface,
    si: &Interaction,
    wo: Vec3,
    beta: &mut Vec3,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
    depth: u32,
    width: f32,
) -> Scatter<'s> {
    // Boundary at xo: the normal facing the camera is "outside"
    // (a mesh wound inside-out is read consistently the other way).
    let n_out = if si.front { si.ng } else { -si.ng };
    let beta_in = *beta;
    let Some(rc) = ss.rough_coat() else {
        let split = depth < COAT_SPLIT_DEPTH;
        // The smooth coat: a mirror reflecting Fr.
        let fr = fresnel::dielectric(wo.dot(n_out).max(0.0), ss.eta());
        if !ss.specular {
            *beta *= 1.0 - fr;
        } else if split {
            *beta *= 1.0 - fr;
            let reflected = Some((mirror(ctx, si, wo, n_out), beta_in * fr, None));
            let (entry, pair, ahead) =
                entries(ctx, ss, si, wo, beta, rng, scratch, counters, depth, width);
            return Scatter::Coated(Coated {
                coat: None,
                reflected,
                entry,
                pair,
                ahead,
            });
        } else if rng.uniform() < fr {
            // Specular reflection with probability Fr: weight 1.
            return Scatter::Continue(mirror(ctx, si, wo, n_out), Event::Specular);
        }
        return entry_scatter(entries(
            ctx, ss, si, wo, beta, rng, scratch, counters, depth, width,
        ));
    };
    // The rough coat. Where the shading normal faces away from ωo it
    // reflects nothing and everything enters.
    let frame = si.shading_frame_facing(wo);
    let wo_local = frame.to_local(wo);
    let e = if wo_local.z > 0.0 {
        rc.albedo(wo_local.z)
    } else {
        0.0
    };
    if !ss.specular || e <= 0.0 {
        *beta *= 1.0 - e;
        return entry_scatter(entries(
            ctx, ss, si, wo, beta, rng, scratch, counters, depth, width,
        ));
    }
    let v = Vertex {
        p: si.p,
        ng: n_out,
        frame,
        wo_local,
        lobe: Lobe::Coat {
            coat: rc,
            select: e,
        },
        outside_of: ctx.leaving(si.geom, si.front),
    };
    // Choose: the reflection with probability E (its weight divided by E
    // in the lobe's sample), else the medium (weight (1 − E)/(1 − E) = 1).
    if rng.uniform() < e {
        let reflected = coat_reflection(ctx, &v, beta_in, rng);
        return Scatter::Coated(Coated {
            coat: Some((v, beta_in)),
            reflected,
            entry: None,
            pair: None,
            ahead: Ahead::default(),
        });
    }
    let (entry, pair, ahead) = entries(ctx, ss, si, wo, beta, rng, scratch, counters, depth, width);
    Scatter::Coated(Coated {
        coat: Some((v, beta_in)),
        reflected: None,
        entry,
        pair,
        ahead,
    })
}

/// The smooth coat's reflection: the mirror direction about the shading
/// normal, which keeps highlights smooth on tessellated meshes; where it
/// would reflect below the surface the geometric normal is used instead.
#[cfg(feature = "subsurface")]
fn mirror(ctx: &Context, si: &Interaction, wo: Vec3, n_out: Vec3) -> Ray {
    si.spawn(mirror_direction(wo, si.ns, n_out), ctx.ray_epsilon)
}

/// `wo` reflected about the shading normal `ns` (either orientation),
/// or about the geometric normal `n_out` (the side `wo` is on) where the
/// former would go below the surface.
#[cfg(feature = "subsurface")]
fn mirror_direction(wo: Vec3, ns: Vec3, n_out: Vec3) -> Vec3 {
    let ns_out = if ns.dot(n_out) >= 0.0 { ns } else { -ns };
    let wi = reflect(wo, ns_out);
    if wi.dot(n_out) > 0.0 {
        wi
    } else {
        reflect(wo, n_out)
    }
}

/// A ray sampled from the rough coat's lobe at `v`, with its throughput
/// and (for the emission MIS weight) the vertex and the lobe's pdf; None
/// when the sample is lost (below the microsurface or the geometric
/// surface).
#[cfg(feature = "subsurface")]
fn coat_reflection(
    ctx: &Context,
    v: &Vertex,
    beta: Vec3,
    rng: &mut SampleRng,
) -> Option<Reflected> {
    let (wi_local, weight, pdf) = v.lobe.sample(v.wo_local, rng.uniform2_packed())?;
    let wi = v.frame.to_world(wi_local);
    if wi.dot(v.ng) <= 0.0 {
        return None;
    }
    let ray = Ray::new(offset_along(v.p, v.ng, ctx.ray_epsilon), wi);
    Some((ray, beta * weight, Some((v.p, pdf))))
}

/// The entry vertices the path goes on from at a subsurface hit at
/// `depth`, `beta` scaled by the chosen one's probe weight: one probe, or
/// below `ctx.pair_depth` where the material asks for it an antithetic
/// pair ([`PAIR_DEPTH`]), whose second vertex comes back with its own
/// throughput for light sampling; below `ctx.cv_depth` where the material
/// asks for it (the default) with the plane control variate's light
/// samples and terms ([`super::control_variate`]). Where the material's level-of-detail rule
/// applies to the footprint `width`, no probe: the entry lobe at xo itself,
/// weighted by the profile's plane integral ([`crate::materials::lod`]).
#[allow(clippy::too_many_arguments)]
#[cfg(feature = "subsurface")]
fn entries<'s>(
    ctx: &Context,
    ss: &'s Subsurface,
    si: &Interaction,
    wo: Vec3,
    beta: &mut Vec3,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
    depth: u32,
    width: f32,
) -> Entries<'s> {
    let frame_o = si.shading_frame_facing(wo);
    let TriangleCurvature {
        exit: kappa,
        mean: k_mean,
    } = ctx.curvatures(si.geom, si.prim);
    if ss.lod().applies(width, kappa) {
        return (
            Some(lod_entry(ctx, ss, si, frame_o, beta)),
            None,
            Ahead::default(),
        );
    }
    // The probe axes also see sharp edges near xo (`sharp_edges`); level
    // of detail above and the curvature correction read the triangle's.
    let kappa = ctx.axes_curvature(si.geom, si.prim, si.p);
    let cv =
        ss.control_variate && control_variate::applies(ctx.cv_depth, ctx.plan.area_lights, depth);
    // The control variate's light samples, drawn before the probe's randoms.
    let lights = cv.then(|| [draw_light(ctx, rng), None]);
    let u = ProbeRandoms::from_rng(rng);
    // The curvature correction's exit half, once for both probes of a pair.
    let exit = ss.curvature_correction().map(|cc| {
        (
            cc,
            cc.at_exit_with(k_mean, ctx.curvature_factor(si.geom, si.prim, cc)),
        )
    });
    let beta_in = *beta;
    if !(ss.probe_pair && depth < ctx.pair_depth) {
        let (seg, plane) = if cv {
            match ss.probe.sample_probe_and_plane(si.p, &frame_o, kappa, &u) {
                Some(sp) => sp,
                None => return (None, None, Ahead::default()),
            }
        } else {
            match ss.probe.sample_probe(si.p, &frame_o, kappa, &u) {
                Some(seg) => (seg, None),
                None => return (None, None, Ahead::default()),
            }
        };
        let mut ahead = Ahead::default();
        if let Some(lights) = lights {
            ahead.lights = Some(lights);
            if let (Some(ls), Some(pm)) = (&lights[0], &plane) {
                let model = CvModel::new(ss, si, &frame_o, k_mean, exit.map(|e| e.1));
                let c = model.one_probe(pm, ls);
                ahead.terms[0] = (-(beta_in * model.f_o) * c, ls.index);
            }
        }
        let e = probe_entry(ctx, ss, si, &seg, exit, &u, scratch, counters);
        return match e {
            Some((v, w)) => {
                *beta *= w;
                (Some(v), None, ahead)
            }
            None => (None, None, ahead),
        };
    }
    // The pair: with the control variate, a light sample for the twin too.
    let lights = lights.map(|[a, _]| [a, draw_light(ctx, rng)]);
    // The twin's randoms are u's with the angle at φ + π
    // (ProbeSampler::sample_probe_pair), which changes none of what
    // entry_on_segment reads.
    let ([seg_a, seg_b], plane) = if cv {
        match ss
            .probe
            .sample_probe_pair_and_plane(si.p, &frame_o, kappa, &u)
        {
            Some(sp) => sp,
            None => return (None, None, Ahead::default()),
        }
    } else {
        match ss.probe.sample_probe_pair(si.p, &frame_o, kappa, &u) {
            Some(segs) => (segs, None),
            None => return (None, None, Ahead::default()),
        }
    };
    let mut ahead = Ahead::default();
    if let Some(lights) = lights {
        ahead.lights = Some(lights);
        if let Some(pm) = &plane {
            let model = CvModel::new(ss, si, &frame_o, k_mean, exit.map(|e| e.1));
            let g0 = lights.map(|l| l.map_or(Vec3::ZERO, |ls| model.g(Vec3::ZERO, &ls)));
            // The term split by light sample (it is linear in the g_k), so
            // each part is recorded with the light it sampled.
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
    let a = probe_entry(ctx, ss, si, &seg_a, exit, &u, scratch, counters);
    let b = probe_entry(ctx, ss, si, &seg_b, exit, &u, scratch, counters);
    match (a, b) {
        (Some((va, wa)), Some((vb, wb))) => {
            // Go on from one, chosen with probability ½ (weight 2 × ½);
            // light is sampled at both, each weighted ½.
            let beta0 = *beta;
            let (go, (other, w_other), w_go) = if rng.uniform() < 0.5 {
                (va, (vb, wb), wa)
            } else {
                (vb, (va, wa), wb)
            };
            *beta = beta0 * w_go;
            (Some(go), Some((other, 0.5 * beta0 * w_other)), ahead)
        }
        (Some((v, w)), None) | (None, Some((v, w))) => {
            *beta *= 0.5 * w;
            (Some(v), None, ahead)
        }
        (None, None) => (None, None, ahead),
    }
}

/// The plane control variate's model at a subsurface exit point xo
/// ([`super::control_variate`]): g, the light a sample brings through the
/// entry lobe at a model point, unshadowed, and the constants of its term.
#[cfg(feature = "subsurface")]
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

#[cfg(feature = "subsurface")]
impl<'s> CvModel<'s> {
    /// The model at `si` (shading frame `frame_o`, mean curvature
    /// `k_mean`), with the curvature correction's exit half if any.
    fn new(
        ss: &'s Subsurface,
        si: &Interaction,
        frame_o: &Frame,
        k_mean: f32,
        exit: Option<ExitFactor>,
    ) -> Self {
        CvModel {
            ss,
            xo: si.p,
            n: frame_o.n,
            kappa: k_mean,
            a_plane: Vec3::from_array(ss.probe.planar_reflectance().map(|a| a as f32)),
            f_o: exit.map_or(Vec3::ONE, |e| e.at_exit_alone()),
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

/// The level-of-detail entry vertex: xo itself with the entry lobe, `beta`
/// scaled by the profile's plane integral A_plane and, on a convex surface
/// with the curvature correction on, f(κo) — the full estimator's mean on
/// a flat or spherical surface ([`crate::materials::lod`]).
#[cfg(feature = "subsurface")]
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
        lobe: Lobe::SubsurfaceEntry(ss),
        outside_of: ctx.leaving(si.geom, si.front),
    }
}

/// What [`entries`] found as a [`Scatter`]: the entry vertex (with its
/// pair's, if any, and the control variate's part), or the end of the
/// path.
#[cfg(feature = "subsurface")]
fn entry_scatter(e: Entries<'_>) -> Scatter<'_> {
    match e {
        (Some(v), None, ahead) if ahead.lights.is_none() => Scatter::Vertex(v),
        (None, _, ahead) if ahead.lights.is_none() => Scatter::Absorbed,
        (entry, pair, ahead) => Scatter::Coated(Coated {
            coat: None,
            reflected: None,
            entry,
            pair,
            ahead,
        }),
    }
}

/// The area integral at xo: one entry point xi from the probe segment
/// `seg` sampled with randoms `u`, and the probe's weight; None when the
/// probe finds nothing. `exit`: the material's curvature correction and
/// its exit half at xo, if it has one.
#[allow(clippy::too_many_arguments)]
#[cfg(feature = "subsurface")]
fn probe_entry<'s>(
    ctx: &Context,
    ss: &'s Subsurface,
    si: &Interaction,
    seg: &ProbeSegment,
    exit: Option<(&CurvatureCorrection, ExitFactor)>,
    u: &ProbeRandoms,
    scratch: &mut Scratch,
    counters: &mut Counters,
) -> Option<(Vertex<'s>, Vec3)> {
    counters.ray(Effect::Probe);
    let target = ProbeTarget {
        accel: ctx.accel,
        geom: si.geom,
        mesh: &ctx.scene.meshes[si.geom as usize],
    };
    let ps = entry_on_segment(&ss.probe, seg, u, &target, &mut scratch.probe_hits)?;
    // The curvature correction (bssrdf::curvature_correction): None, and
    // the weight untouched, on flat and concave surfaces.
    let mut weight = ps.weight;
    if let Some((cc, exit)) = &exit {
        let k_i = ctx.curvatures(si.geom, ps.hit.prim).mean;
        let f_i = ctx.curvature_factor(si.geom, ps.hit.prim, cc);
        if let Some(f) = cc.weight_from_factor(exit, k_i, f_i) {
            weight *= f;
        }
    }
    let n_in = if si.front { ps.normal } else { -ps.normal };
    Some((
        Vertex {
            p: ps.point,
            ng: n_in,
            frame: Frame::from_normal(n_in),
            wo_local: Vec3::Z,
            lobe: Lobe::SubsurfaceEntry(ss),
            // n_in faces the side xo was seen from, as ng does at xo.
            outside_of: ctx.leaving(si.geom, si.front),
        },
        weight,
    ))
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

/// One light sample for next-event estimation (three randoms); None
/// without lights or on a degenerate emitter.
#[inline(always)]
fn draw_light(ctx: &Context, rng: &mut SampleRng) -> Option<LightSample> {
    let [u_pick, u0, u1] = rng.uniform3();
    ctx.lights.sample(u_pick, [u0, u1])
}

/// Next-event estimation at a vertex: one light sample, weighted by the
/// power heuristic against lobe sampling of the same direction; and the
/// light triangle it sampled ([`aov::NO_LIGHT`] when none). (A plain index,
/// not a [`Source`]: the pair then still fits in two registers.)
fn direct_lighting(
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
fn direct_lighting_ahead(
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
fn unshadowed_at(
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

/// Without the `subsurface` feature there are no subsurface hits.
#[cfg(not(feature = "subsurface"))]
#[allow(clippy::too_many_arguments)]
fn subsurface_probe<'s>(
    _: &Context,
    ss: &'s Subsurface,
    _: &Interaction,
    _: Vec3,
    _: &mut Vec3,
    _: &mut SampleRng,
    _: &mut Scratch,
    _: &mut Counters,
    _: u32,
    _: f32,
) -> Scatter<'s> {
    match *ss {}
}

#[cfg(all(test, feature = "subsurface"))]
mod tests {
    use super::*;

    /// Angle of reflection equals angle of incidence, in the plane of `wo`
    /// and `n`: `wi + wo` is along `n` and `wi·n = wo·n`.
    fn assert_mirror(wi: Vec3, wo: Vec3, n: Vec3) {
        assert!((wi.length() - 1.0).abs() < 1e-5, "{wi}");
        assert!((wi.dot(n) - wo.dot(n)).abs() < 1e-5, "{wi} {wo} {n}");
        assert!((wi + wo).cross(n).length() < 1e-5, "{wi} {wo} {n}");
    }

    #[test]
    fn the_coat_mirrors_about_the_shading_normal_or_the_geometric_one_below_it() {
        let ng = Vec3::Z;
        // A shading normal tilted 40° towards +x, given either way round.
        let ns = Vec3::new(40f32.to_radians().sin(), 0.0, 40f32.to_radians().cos());
        for ns in [ns, -ns] {
            // Steep incidence: the shading mirror stays above the surface.
            let wo = Vec3::new(0.2, 0.1, 1.0).normalize();
            let wi = mirror_direction(wo, ns, ng);
            assert!(wi.dot(ng) > 0.0);
            assert_mirror(wi, wo, ns);
            // Grazing from −x: about ns the reflection would point below
            // the surface, so it is the mirror about ng.
            let wo = Vec3::new(-0.95, 0.1, 0.2).normalize();
            let ns_up = if ns.dot(ng) >= 0.0 { ns } else { -ns };
            let below = reflect(wo, ns_up);
            assert!(
                below.dot(ng) <= 0.0,
                "the case is not the fallback: {below}"
            );
            let wi = mirror_direction(wo, ns, ng);
            assert!(wi.dot(ng) > 0.0);
            assert_mirror(wi, wo, ng);
        }
        // Seen from below (n_out = −ng) the same holds on that side.
        let wo = Vec3::new(0.95, -0.1, -0.2).normalize();
        let wi = mirror_direction(wo, ns, -ng);
        assert!(wi.dot(-ng) > 0.0);
        assert_mirror(wi, wo, -ng);
    }
}
