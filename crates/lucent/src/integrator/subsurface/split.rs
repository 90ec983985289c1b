//! How the bounce loop reads a subsurface hit with more than one vertex
//! ([`Coated`]): light sampled at the rough coat, the coat's reflection
//! kept on the stack or followed, light sampled at the pair's twin, and the entry vertex the path goes on from
//! (`docs/bssrdf.md` §5, §6 "The coat").

use crate::geometry::Vec3;
use crate::integrator::analytic_nee::record_analytic;
use crate::integrator::aov::{Event, Recorder};
use crate::integrator::branch::{roulette, At, Branch, Branches, Next, MAX_BRANCHES};
use crate::integrator::coated::Coated;
use crate::integrator::env_nee::record_environment;
use crate::integrator::lobe::{Bounce, Vertex};
use crate::integrator::nee::{direct_lighting, direct_lighting_ahead, record_direct, NeeAt};
use crate::integrator::path::COAT_SPLIT_DEPTH;
use crate::integrator::state::PathState;
use crate::integrator::{Clock, Context};
use crate::sampling::Draw;

/// Reads the coated hit `c` at `at` into `path`, adding the light it
/// sampled to `l`; a reflection that waits is pushed on `stack`.
#[inline(always)]
pub(crate) fn resolve<'v, 's, R: Recorder, T: Clock>(
    ctx: &Context,
    c: &'v Coated<'s>,
    at: &At,
    path: &mut Branch,
    l: &mut Vec3,
    st: &mut PathState<R>,
    stack: &mut Branches,
) -> Next<'v, 's> {
    // The coat's reflections are specular.
    let coat_event = if at.first {
        Event::Specular
    } else {
        path.event
    };
    if let (Some(w), true) = (&c.coat, ctx.plan.area_lights) {
        *l += record_direct::<R, T>(st, w.beta, coat_event, at.depth, |rng, counters| {
            direct_lighting(ctx, &w.vertex, rng, counters)
        });
    }
    if let (Some(w), true) = (&c.coat, ctx.plan.environment_map) {
        *l += record_environment::<R, T>(ctx, &w.vertex, st, w.beta, coat_event, at.depth);
    }
    if let (Some(w), true) = (&c.coat, ctx.plan.analytic_lights) {
        *l += record_analytic::<R, T>(ctx, &w.vertex, st, w.beta, coat_event, at.depth);
    }
    let (next, follow_reflected) = match (&c.entry, c.reflected) {
        // Both: this path enters the medium, the reflection waits on the
        // stack (one branch per split depth).
        (Some(v), Some(r)) => {
            push_reflection(ctx, r, at, path, coat_event, st, stack);
            (Some(v), None)
        }
        (Some(v), None) => (Some(v), None),
        (None, reflected) => (None, reflected),
    };
    match (next, follow_reflected) {
        (Some(v), _) => Next::Vertex(v, entry::<R, T>(ctx, c, v, at, path, l, st, stack)),
        (None, Some(r)) => {
            path.event = coat_event;
            path.go_on(r, ctx.leaving_towards(at.si, r.ray.d), at.cone_specular);
            Next::Bounce
        }
        (None, None) => Next::End,
    }
}

/// The coat's reflection `r` off `path`, pushed on the stack if it
/// survives roulette.
#[inline(always)]
fn push_reflection<R: Recorder>(
    ctx: &Context,
    r: Bounce,
    at: &At,
    path: &Branch,
    event: Event,
    st: &mut PathState<R>,
    stack: &mut Branches,
) {
    let mut b = r.beta;
    if roulette(at.depth, &mut b, st.rng) {
        stack.push(Branch {
            ray: r.ray,
            from: ctx.leaving_towards(at.si, r.ray.d),
            beta: b,
            prev: r.prev,
            scattered: path.scattered || r.prev.is_some(),
            depth: at.depth + 1,
            event,
            cone: at.cone_specular,
        });
    }
}

/// The path goes on from the entry vertex `v`: light is sampled at the
/// pair's twin now, and at `v` as the returned `NeeAt` asks (½ each with
/// a twin; with the light sample drawn ahead, if any). Where the pair's
/// paths go on from both entry points, the twin's and `v`'s other paths
/// wait on the stack ([`split_paths`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn entry<R: Recorder, T: Clock>(
    ctx: &Context,
    c: &Coated,
    v: &Vertex,
    at: &At,
    path: &mut Branch,
    l: &mut Vec3,
    st: &mut PathState<R>,
    stack: &mut Branches,
) -> NeeAt {
    if at.first {
        path.event = v.lobe.event();
    }
    let lights = c.ahead.lights;
    let mut nee = NeeAt {
        scale: 1.0,
        ahead: lights.map(|ls| ls[0]),
    };
    if let Some(twin) = &c.pair {
        if ctx.plan.area_lights {
            let ahead = lights.map(|ls| ls[1]);
            *l += record_direct::<R, T>(st, twin.beta, path.event, at.depth, |rng, counters| {
                direct_lighting_ahead(ctx, &twin.vertex, ahead, rng, counters)
            });
        }
        if ctx.plan.environment_map {
            *l +=
                record_environment::<R, T>(ctx, &twin.vertex, st, twin.beta, path.event, at.depth);
        }
        if ctx.plan.analytic_lights {
            *l += record_analytic::<R, T>(ctx, &twin.vertex, st, twin.beta, path.event, at.depth);
        }
        nee.scale = 0.5;
        if c.paths_each > 0 {
            let k = c.paths_each;
            let from = LobeStart {
                at,
                event: path.event,
            };
            split_paths(ctx, &twin.vertex, twin.beta, k, k, &from, st, stack);
            // `path.beta` holds v's ½ share: its light sample takes all of
            // it, each of its k paths 1/k of it, this one among them.
            path.beta /= k as f32;
            nee.scale = k as f32;
            split_paths(ctx, v, path.beta * k as f32, k, k - 1, &from, st, stack);
        }
    }
    nee
}

/// The most paths that go on from each of the pair's entry points: with
/// the coat's reflection, all wait on the stack at once.
const MAX_PATHS_EACH: u32 = 2;
const _: () = assert!(COAT_SPLIT_DEPTH as usize + 2 * MAX_PATHS_EACH as usize - 1 <= MAX_BRANCHES);

/// Where the paths split off an entry vertex start: the hit and the class
/// of the camera path's first event.
struct LobeStart<'a, 'b> {
    at: &'a At<'b>,
    event: Event,
}

/// `n` of `k` paths going on from the entry vertex `v` with throughput
/// `beta / k` each, pushed on the stack: their lobe directions from one
/// 2D point u, the j-th at (u₀ + j/k mod 1, u₁), so the k directions of a
/// vertex are stratified in the first coordinate. With `n < k` the path
/// itself is the first of the k (its direction its own draw) and these
/// are j = k − n … k − 1.
#[allow(clippy::too_many_arguments)]
fn split_paths<R: Recorder>(
    ctx: &Context,
    v: &Vertex,
    beta: Vec3,
    k: u32,
    n: u32,
    from: &LobeStart,
    st: &mut PathState<R>,
    stack: &mut Branches,
) {
    if n == 0 {
        return;
    }
    let u = st.rng.uniform2_packed();
    let each = beta / k as f32;
    for j in (k - n)..k {
        let uj = [(u[0] + j as f32 / k as f32).fract(), u[1]];
        if let Some(b) = v.bounce(ctx.ray_epsilon, each, uj) {
            stack.push(Branch {
                ray: b.ray,
                from: v.outside_of,
                beta: b.beta,
                prev: b.prev,
                scattered: true,
                depth: from.at.depth + 1,
                event: from.event,
                cone: from.at.cone_rough,
            });
        }
    }
}
