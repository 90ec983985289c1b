//! Unidirectional path tracing (Kajiya 1986) of the rendering equation
//!
//!   L(x, ωo) = Le(x, ωo) + ∫ f(x, ωo, ωi) L(x, ωi) |cos θi| dωi,
//!
//! extended at subsurface objects by the BSSRDF's area integral
//! (`docs/bssrdf.md` §1), which a `SubsurfaceScatter` estimates. Each
//! non-specular vertex gets next-event estimation combined with lobe
//! sampling by the power heuristic (`nee`); paths end at
//! `max_depth` bounces or by Russian roulette. The coat's splitting, the
//! antithetic probe pair and level of detail: `docs/bssrdf.md` §5, §6
//! "The coat", §11.

use super::analytic_nee::{self, record_analytic};
use super::aov::{self, Event, Recorder, Source};
use super::branch::{roulette, At, Branch, Branches, Next};
use super::env_nee::{escaped, record_environment};
use super::footprint::Cone;
use super::hit_material::{self, HitMaterial, PointMaterial};
use super::lobe::Vertex;
use super::nee::{emission_weight, record_direct, NeeAt};
use super::scatter::{Scatter, SubsurfaceScatter, Through};
use super::state::PathState;
use super::{Clock, Context, Counters, Effect, Interaction};
use crate::accel::Hit;
use crate::film::passes::Pass;
use crate::geometry::{Frame, Ray, Vec3};
use crate::materials::{dielectric, Material};
use crate::sampling::{Draw, SampleRng};

pub(crate) use super::branch::RR_START;
pub use super::state::Scratch;
#[cfg(feature = "subsurface")]
pub(crate) use super::subsurface::COAT_SPLIT_DEPTH;
#[cfg(feature = "subsurface")]
use super::{scatter::SubsurfaceHit, subsurface::resolve};

pub use super::context::PAIR_DEPTH;

/// The diffusion BSSRDF's estimator of subsurface hits.
#[cfg(feature = "subsurface")]
type Diffusion = super::subsurface::Diffusion;
#[cfg(not(feature = "subsurface"))]
type Diffusion = super::scatter::NoSubsurface;

/// The radiance arriving along `camera_ray`: one sample of L, with the
/// BSSRDF estimated by probe rays; its parts go to `rec` ([`aov`]), its
/// effects' time to `T` ([`super::effects`]).
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
        &mut Diffusion {},
    )
}

/// One sample of L along `camera_ray` through the bounce loop, subsurface
/// hits estimated by `subsurface`: what each integrator's `radiance` is.
pub(crate) fn sample<R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &Context,
    camera_ray: Ray,
    rng: &mut SampleRng,
    scratch: &mut Scratch,
    counters: &mut Counters,
    rec: &mut R,
    subsurface: &mut S,
) -> Vec3 {
    let mut st = PathState {
        rng,
        scratch,
        counters,
        rec,
    };
    trace::<R, T, S>(ctx, camera_ray, &mut st, subsurface)
}

/// The bounce loop both integrators share; `subsurface` handles hits on
/// subsurface objects.
pub(crate) fn trace<R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &Context,
    camera_ray: Ray,
    st: &mut PathState<R>,
    subsurface: &mut S,
) -> Vec3 {
    // The paths a coat split off wait here; L sums over all of them.
    let mut stack = Branches::default();
    let mut first = Some(Branch {
        ray: camera_ray,
        from: None,
        beta: Vec3::ONE,
        prev: None,
        scattered: false,
        depth: 0,
        // Set at the first hit.
        event: Event::Diffuse,
        cone: Cone::camera(&ctx.camera_spread, camera_ray.d),
    });
    let mut l = Vec3::ZERO;
    // a path split off draws from the stream: its depths' slots are taken
    while let Some(start) = first.take().or_else(|| {
        st.rng.leave_sequence();
        stack.pop()
    }) {
        l += follow::<R, T, S>(ctx, start, st, subsurface, &mut stack);
    }
    l
}

/// One path from `start` until it ends, L = Σ β (Le + L_nee) over its
/// vertices; paths split off on the way are pushed on `stack`. (Without
/// the `subsurface` feature neither `subsurface` nor `stack` is used.)
#[inline(always)]
#[cfg_attr(not(feature = "subsurface"), allow(unused_variables))]
fn follow<R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &Context,
    start: Branch,
    st: &mut PathState<R>,
    subsurface: &mut S,
    stack: &mut Branches,
) -> Vec3 {
    let mut l = Vec3::ZERO;
    let mut path = start;
    let mut point = PointMaterial::default();
    let max_depth = ctx.scene.settings.max_depth;
    // A random walk's exit that the next hit's emission may be left to
    // the walk's connection for (`super::walk_nee`).
    let mut through: Option<Through> = None;
    for depth in start.depth..=max_depth {
        st.rng.start_bounce(depth);
        let nearest_hit = nearest::<R, T>(ctx, &path, depth, st);
        let exit = through.take();
        if ctx.plan.analytic_lights {
            l += analytic_nee::found(ctx, &path, nearest_hit.map(|h| h.t), depth, st.rec);
        }
        let Some(hit) = nearest_hit else {
            // a transparent film leaves the environment seen directly out
            if ctx.plan.environment && !(depth == 0 && ctx.plan.transparent) {
                l += environment(ctx, &path, depth, st.rec);
            }
            break;
        };
        let object = &ctx.scene.objects[hit.geom as usize];
        let si = ctx.interaction(&path.ray, &hit);
        let at = at::<R>(&si, &path, &hit, depth);
        if R::ON && depth == 0 {
            st.rec.camera_hit(hit.geom, si.p);
        }
        // Le, MIS-weighted against next-event estimation.
        if let (Some(le), true) = (object.emission, si.front) {
            if !connected(ctx, exit, &si, &hit, st.counters) {
                l += emitted(ctx, &path, le, &at, hit.geom, st.rec);
            }
        }
        if depth == max_depth {
            break;
        }
        let material = &ctx.scene.materials[object.material];
        let scatter =
            scatter_at::<R, T, S>(ctx, material, &at, &mut path, st, subsurface, &mut point);
        // Borrowed, not moved out: the vertex stays where it was built.
        let (vertex, nee) = match next::<R, T>(
            ctx,
            &scatter,
            &at,
            &mut path,
            &mut l,
            st,
            stack,
            &mut through,
        ) {
            Next::Vertex(v, nee) => (v, nee),
            Next::Bounce => {
                if !roulette(depth, &mut path.beta, st.rng) {
                    break;
                }
                continue;
            }
            Next::End => break,
        };
        // Next-event estimation, then continue by sampling the lobe.
        if ctx.plan.area_lights {
            let beta = nee.scale * path.beta;
            l += record_direct::<R, T>(st, beta, path.event, depth, |rng, counters| {
                nee.light(ctx, vertex, rng, counters)
            });
        }
        if ctx.plan.environment_map {
            let beta = nee.scale * path.beta;
            l += record_environment::<R, T>(ctx, vertex, st, beta, path.event, depth);
        }
        if ctx.plan.analytic_lights {
            let beta = nee.scale * path.beta;
            l += record_analytic::<R, T>(ctx, vertex, st, beta, path.event, depth);
        }
        let Some(b) = vertex.bounce(ctx.ray_epsilon, path.beta, st.rng.uniform2_packed()) else {
            break;
        };
        path.go_on(b, vertex.outside_of, at.cone_rough);
        if !roulette(depth, &mut path.beta, st.rng) {
            break;
        }
    }
    l
}

/// Where the path goes from what the hit scattered into: on from a
/// vertex, along a ray already set in `path`, or nowhere.
#[inline(always)]
#[cfg_attr(
    not(feature = "subsurface"),
    allow(unused_variables, clippy::extra_unused_type_parameters)
)]
#[allow(clippy::too_many_arguments)]
fn next<'v, 's, R: Recorder, T: Clock>(
    ctx: &Context,
    scatter: &'v Scatter<'s>,
    at: &At,
    path: &mut Branch,
    l: &mut Vec3,
    st: &mut PathState<R>,
    stack: &mut Branches,
    through: &mut Option<Through>,
) -> Next<'v, 's> {
    match scatter {
        Scatter::Vertex(v) => {
            if at.first {
                path.event = v.lobe.event();
            }
            Next::Vertex(v, NeeAt::PLAIN)
        }
        Scatter::Continue(ray, e) => {
            if at.first {
                path.event = *e;
            }
            path.straight_on(*ray, at.cone_specular);
            Next::Bounce
        }
        Scatter::Absorbed => Next::End,
        #[cfg(feature = "subsurface")]
        Scatter::Coated(c) => resolve::<R, T>(ctx, c, at, path, l, st, stack),
        #[cfg(feature = "subsurface")]
        Scatter::WalkLit {
            light,
            source,
            exit,
        } => {
            if at.first {
                path.event = Event::Subsurface;
            }
            *l += *light;
            let found = aov::sampled(path.event, at.depth);
            st.rec.light(*light, found, Source::Light(*source));
            let Some((ray, t)) = exit else {
                return Next::End;
            };
            path.straight_on(*ray, at.cone_specular);
            *through = *t;
            Next::Bounce
        }
    }
}

/// Whether the emission of the light triangle `hit` (at `si`), found
/// straight after the walk's exit `exit`, is counted by the walk's
/// connection through the boundary instead ([`super::walk_nee`]).
#[inline(always)]
#[cfg_attr(not(feature = "subsurface"), allow(unused_variables))]
fn connected(
    ctx: &Context,
    exit: Option<Through>,
    si: &Interaction,
    hit: &Hit,
    counters: &mut Counters,
) -> bool {
    #[cfg(feature = "subsurface")]
    if let Some(t) = exit {
        if ctx.lights.pdf_area(hit.geom, hit.prim) > 0.0 {
            return super::walk_nee::covers(ctx, &t, si.p, counters);
        }
    }
    false
}

/// Where `path` is at `hit`. The footprint after the vertex: specular
/// continuations keep the cone's spread, lobes widen it. At the first hit
/// of a recorded path its class becomes that of what scattered.
#[inline(always)]
fn at<'a, R: Recorder>(si: &'a Interaction, path: &Branch, hit: &Hit, depth: u32) -> At<'a> {
    At {
        si,
        wo: -path.ray.d,
        t: hit.t,
        depth,
        bary: [hit.u, hit.v],
        first: R::ON && depth == 0,
        cone_specular: path.cone.specular(hit.t),
        cone_rough: path.cone.rough(hit.t),
    }
}

/// The emission of the object `geom` hit at `at`, MIS-weighted, recorded.
#[inline(always)]
fn emitted<R: Recorder>(
    ctx: &Context,
    path: &Branch,
    le: Vec3,
    at: &At,
    geom: u32,
    rec: &mut R,
) -> Vec3 {
    let c = path.beta * le * emission_weight(ctx, at.si, at.wo, path.prev);
    let found = aov::found(path.event, at.depth, Pass::Emission);
    rec.light(c, found, Source::Object(geom));
    c
}

/// What the material at `at` scatters into (`path.beta` scaled by it);
/// `path.from` becomes the object a continuation leaves, where known
/// (through a dielectric; a medium's exit is not culled from). A textured
/// material's values at the hit are kept in `point`.
#[inline(always)]
fn scatter_at<'s, R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &'s Context,
    material: &'s Material,
    at: &At,
    path: &mut Branch,
    st: &mut PathState<R>,
    subsurface: &mut S,
    point: &'s mut PointMaterial,
) -> Scatter<'s> {
    let Material::Textured(t) = material else {
        let m = HitMaterial::untextured(material);
        return scatter_as::<R, T, S>(ctx, m, at, path, st, subsurface);
    };
    let width = path.cone.width_at(at.t);
    let hit = hit_material::textured(ctx, t, at.si, at.bary, at.wo, width, point);
    let at = At { si: &hit.si, ..*at };
    scatter_as::<R, T, S>(ctx, hit.material, &at, path, st, subsurface)
}

/// What the material `m`, its parameters fixed at `at`, turns into there.
#[inline(always)]
#[cfg_attr(
    not(feature = "subsurface"),
    allow(unused_variables, clippy::extra_unused_type_parameters)
)]
fn scatter_as<'s, R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &'s Context,
    m: HitMaterial<'s>,
    at: &At,
    path: &mut Branch,
    st: &mut PathState<R>,
    subsurface: &mut S,
) -> Scatter<'s> {
    match m {
        HitMaterial::Diffuse(albedo) => {
            Scatter::Vertex(diffuse_vertex(ctx, at.si, at.wo, albedo, st.rec))
        }
        HitMaterial::Dielectric(eta) => smooth_dielectric(ctx, eta, at, path, st.rng),
        HitMaterial::RoughDielectric(d) => {
            super::glossy::rough_dielectric(ctx, &d, at, path, st.rng)
        }
        HitMaterial::Conductor(c) => super::glossy::conductor(ctx, c, at, path, st.rec),
        HitMaterial::Plastic(p) => super::glossy::plastic(ctx, p, at, path, st.rng, st.rec),
        #[cfg(feature = "subsurface")]
        HitMaterial::Subsurface(ss) => subsurface_at::<R, T, S>(ctx, ss, at, path, st, subsurface),
    }
}

/// The subsurface material `ss` hit at `at`.
#[cfg(feature = "subsurface")]
#[inline(always)]
fn subsurface_at<'s, R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &'s Context,
    ss: &'s crate::materials::Subsurface,
    at: &At,
    path: &mut Branch,
    st: &mut PathState<R>,
    subsurface: &mut S,
) -> Scatter<'s> {
    path.from = None;
    let width = path.cone.width_at(at.t);
    let (si, wo, depth) = (at.si, at.wo, at.depth);
    let h = SubsurfaceHit {
        ss,
        si,
        wo,
        depth,
        width,
        scattered: path.scattered,
    };
    subsurface_hit::<R, T, S>(ctx, &h, &mut path.beta, st, subsurface)
}

/// A smooth dielectric of index `eta` hit at `at`: reflection or
/// refraction, continuing the path.
fn smooth_dielectric<'s>(
    ctx: &Context,
    eta: f32,
    at: &At,
    path: &mut Branch,
    rng: &mut crate::sampling::SampleRng,
) -> Scatter<'s> {
    let (next, e) = dielectric_bounce(ctx, eta, at.si, at.wo, &mut path.beta, rng);
    path.from = ctx.leaving_towards(at.si, next.d);
    Scatter::Continue(next, e)
}

/// The nearest hit along the path's ray, timed as the camera's (depth 0)
/// or the indirect rays' effect.
#[inline(always)]
fn nearest<R: Recorder, T: Clock>(
    ctx: &Context,
    path: &Branch,
    depth: u32,
    st: &mut PathState<R>,
) -> Option<Hit> {
    // camera rays too: the tile loop moves one a sample to Effect::Camera
    st.counters.ray(Effect::Indirect);
    let t0 = T::now();
    let found = ctx.intersect(&path.ray, path.from, st.counters);
    let effect = if depth == 0 {
        Effect::Camera
    } else {
        Effect::Indirect
    };
    T::lap(st.counters, effect, t0);
    found
}

/// The environment's light reaching a path that leaves the scene.
#[inline(always)]
fn environment<R: Recorder>(ctx: &Context, path: &Branch, depth: u32, rec: &mut R) -> Vec3 {
    let c = path.beta * escaped(ctx, path.ray.d, path.prev);
    let found = aov::found(path.event, depth, Pass::Background);
    rec.light(c, found, Source::Environment);
    c
}

/// The Lambertian vertex at `si`.
#[inline(always)]
fn diffuse_vertex<'s, R: Recorder>(
    ctx: &Context,
    si: &Interaction,
    wo: Vec3,
    albedo: Vec3,
    rec: &mut R,
) -> Vertex<'s> {
    let frame = si.shading_frame_facing(wo);
    rec.surface(albedo, frame.n);
    let front = wo.dot(si.ng) >= 0.0;
    let ng = if front { si.ng } else { -si.ng };
    Vertex {
        p: si.p,
        ng,
        wo_local: frame.to_local(wo),
        frame,
        lobe: super::lobe::Lobe::Diffuse(albedo),
        outside_of: ctx.leaving(si.geom, front),
    }
}

/// A subsurface hit handed to `subsurface`, timed as its effect.
#[cfg(feature = "subsurface")]
#[inline(always)]
fn subsurface_hit<'s, R: Recorder, T: Clock, S: SubsurfaceScatter>(
    ctx: &'s Context,
    h: &SubsurfaceHit<'_, 's>,
    beta: &mut Vec3,
    st: &mut PathState<R>,
    subsurface: &mut S,
) -> Scatter<'s> {
    if R::ON {
        st.rec
            .surface(h.ss.albedo(), h.si.shading_frame_facing(h.wo).n);
    }
    let t0 = T::now();
    let s = subsurface.scatter(ctx, h, beta, st);
    T::lap(st.counters, S::EFFECT, t0);
    s
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
