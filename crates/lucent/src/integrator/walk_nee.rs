//! Next-event estimation through the random walk's smooth dielectric
//! boundary (`boundary = "dielectric-nee"`, `docs/bssrdf.md` §7, "Light
//! through the smooth boundary").
//!
//! At a scattering point x inside the medium a light point l is sampled
//! by area, and a refracted path x → y → l is found: on a triangle's plane
//! the refraction point is unique, the root of a monotone function of one
//! variable in the plane of incidence ([`refraction_point`]); the solve
//! starts on the triangle the straight line x → l meets first and moves
//! to the triangle the segment x → y meets until the point lies on the
//! triangle it was solved on (`facet`). A mesh's normal jumps at its
//! edges, so a light point may also be reached through a neighbour of
//! that facet; the neighbours across its three edges are tried too
//! (`refractions`), and each path found counts. Each path's
//! contribution is the phase function at x, the medium's transmittance
//! over |x − y|, Fresnel transmittance times η² (radiance entering the
//! denser medium), the light's emission and the generalized geometry term
//! |dω_x / dA_l| of the refracted connection ([`refracted_geometry`]).
//!
//! **Exact split.** The walk's own exits count emission found directly
//! after a refraction that follows a scattering point x, except when the
//! exit triangle is one of those the connection finds paths through for
//! x and l (`covers`): those paths are the connection's; every other path
//! (through a triangle it does not find, after internal reflections, from
//! the entry point without scattering) stays the walk's. Each path is
//! counted by one estimator, so the sum is unbiased with no solution
//! missed and no multiple-solution bias.

use super::aov;
use super::interaction::offset_along;
use super::nee::draw_light;
use super::scatter::Through;
use super::{Context, Counters, Effect};
use crate::accel::Hit;
use crate::bssrdf::params::Medium;
use crate::fresnel;
use crate::geometry::adjacency;
use crate::geometry::{Ray, Vec3};
use crate::lights::LightSample;
use crate::sampling::{Draw, SampleRng};

/// Newton steps (bracketed) of the refraction point's solve: it converges
/// quadratically from the straight line's guess; the bracket halves when a
/// step leaves it.
const SOLVE_STEPS: u32 = 60;

/// Triangles a connection's solve may move through (see [`facet`]).
const FACET_STEPS: u32 = 4;

/// The light reaching a walk through its boundary: the sum of its
/// connections' contributions and the last scattering point since the walk
/// last met the boundary.
pub(crate) struct WalkLight {
    eta: f32,
    /// Σ over connections, per channel, in units of the walk's throughput.
    pub(crate) light: [f64; 3],
    last: Option<Vec3>,
    /// Set when the walk leaves by refraction straight after scattering.
    pub(crate) exit: Option<Through>,
    /// The light triangle of the last connection that brought light
    /// ([`aov::NO_LIGHT`] before one does).
    pub(crate) source: u32,
}

impl WalkLight {
    pub(crate) fn new(eta: f32) -> Self {
        WalkLight {
            eta,
            light: [0.0; 3],
            last: None,
            exit: None,
            source: aov::NO_LIGHT,
        }
    }

    /// At the scattering point `x` (reached along `d_in`, the walk's
    /// throughput there `beta`): one connection, taken with the
    /// probability of [`connect_probability`] and weighted by its inverse.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn at_scatter(
        &mut self,
        ctx: &Context,
        m: &Medium,
        x: Vec3,
        d_in: Vec3,
        beta: &[f64; 3],
        rng: &mut SampleRng,
        counters: &mut Counters,
    ) {
        self.last = Some(x);
        let p = connect_probability(ctx, m, x);
        if rng.uniform_f64() >= p {
            return;
        }
        if let Some((c, source)) = connect(ctx, m, self.eta, x, d_in, rng, counters) {
            for k in 0..3 {
                self.light[k] += beta[k] * c[k] / p;
            }
            self.source = source;
        }
    }

    /// The walk met the boundary and reflected back in.
    pub(crate) fn reflected(&mut self) {
        self.last = None;
    }

    /// The walk left through the triangle of `hit`.
    pub(crate) fn left(&mut self, hit: &Hit) {
        self.exit = self.last.map(|x| Through {
            x,
            geom: hit.geom,
            prim: hit.prim,
            eta: self.eta,
        });
    }
}

/// The probability of a connection at `x`: e^{−σt,min d}, d the distance
/// bound to the nearest surface there. The transmittance to the boundary
/// is at most that, so the weighted contribution stays bounded while
/// points deep inside, which light barely reaches, rarely pay for one.
fn connect_probability(ctx: &Context, m: &Medium, x: Vec3) -> f64 {
    let Some(grid) = ctx.distance_grid() else {
        return 1.0;
    };
    let d = grid.bound(x) as f64;
    let sigma = m.sigma_t().into_iter().fold(f64::INFINITY, f64::min);
    if d.is_nan() || d <= 0.0 || sigma.is_nan() || sigma <= 0.0 {
        return 1.0;
    }
    (-sigma * d).exp()
}

/// A refracted path from a scattering point to a light point: through
/// triangle `prim` of mesh `geom` at `y`, whose unit normal `n` points to
/// the light's side.
#[derive(Clone, Copy, Debug)]
struct Refraction {
    geom: u32,
    prim: u32,
    y: Vec3,
    n: Vec3,
}

/// The refracted paths a connection from `x` to `l` counts (see
/// [`refractions`]): the facet's, then at most one per edge neighbour.
struct Refractions {
    found: [Option<Refraction>; 4],
}

impl Refractions {
    fn iter(&self) -> impl Iterator<Item = &Refraction> {
        self.found.iter().flatten()
    }

    /// Whether one of them passes through triangle `prim` of mesh `geom`.
    fn through(&self, geom: u32, prim: u32) -> bool {
        self.iter().any(|r| (r.geom, r.prim) == (geom, prim))
    }
}

/// The refracted paths from `x` to the light point `l` the connection
/// counts: the one on the facet [`facet`] finds, and where the facet's
/// edge neighbours hold a second refraction point of their own
/// ([`on_triangle`]), those too. A mesh's normal jumps at an edge, so the
/// refracted directions of two neighbours overlap there and one light
/// point can be reached through both. The same x and l give the same
/// paths, which is what [`covers`] relies on.
fn refractions(ctx: &Context, x: Vec3, l: Vec3, eta: f32, counters: &mut Counters) -> Refractions {
    let mut found = [None; 4];
    let Some(f) = facet(ctx, x, l, eta, counters) else {
        return Refractions { found };
    };
    found[0] = Some(f);
    if let Some(adj) = ctx.edge_neighbours(f.geom) {
        for (slot, q) in found[1..].iter_mut().zip(adj.of(f.prim)) {
            if q != adjacency::NONE {
                *slot = on_triangle(ctx, x, l, eta, f.geom, q, counters);
            }
        }
    }
    Refractions { found }
}

/// The facet of a connection from `x` to the light point `l` and the
/// refraction point on it: starting from the triangle the segment x → l
/// meets first, the refraction point is solved on the current triangle's
/// plane; when the segment from x to that point meets another triangle
/// first, the solve moves to that one, at most [`FACET_STEPS`] times.
fn facet(ctx: &Context, x: Vec3, l: Vec3, eta: f32, counters: &mut Counters) -> Option<Refraction> {
    let to_l = l - x;
    let dist = to_l.length();
    if dist.is_nan() || dist <= 0.0 {
        return None;
    }
    let w = to_l / dist;
    counters.ray(Effect::Walk);
    let mut tri = ctx.accel.intersect(&Ray::new(x, w), 0.0, dist)?;
    let mut p0 = x + w * tri.t;
    for _ in 0..FACET_STEPS {
        let ng = ctx.scene.meshes[tri.geom as usize].face_normals()[tri.prim as usize];
        let n = if ng.dot(to_l) > 0.0 { ng } else { -ng };
        let y = refraction_point(x, l, p0, n, eta)?;
        let w1 = (y - x).normalize();
        counters.ray(Effect::Walk);
        let seen = ctx.accel.intersect(&Ray::new(x, w1), 0.0, f32::INFINITY)?;
        if (seen.geom, seen.prim) == (tri.geom, tri.prim) {
            let (geom, prim) = (tri.geom, tri.prim);
            return Some(Refraction { geom, prim, y, n });
        }
        (tri, p0) = (seen, x + w1 * seen.t);
    }
    None
}

/// The refracted path from `x` to `l` through triangle `prim` of mesh
/// `geom`, when the refraction point on its plane lies on it and the
/// segment from `x` meets it first (one ray query, asked only for a point
/// on the triangle).
fn on_triangle(
    ctx: &Context,
    x: Vec3,
    l: Vec3,
    eta: f32,
    geom: u32,
    prim: u32,
    counters: &mut Counters,
) -> Option<Refraction> {
    let mesh = &ctx.scene.meshes[geom as usize];
    let ng = mesh.face_normals()[prim as usize];
    let n = if ng.dot(l - x) > 0.0 { ng } else { -ng };
    let corners = mesh.triangle(prim);
    let y = refraction_point(x, l, corners[0], n, eta)?;
    if !within(y, corners, ng) {
        return None;
    }
    counters.ray(Effect::Walk);
    let seen = ctx
        .accel
        .intersect(&Ray::new(x, (y - x).normalize()), 0.0, f32::INFINITY)?;
    ((seen.geom, seen.prim) == (geom, prim)).then_some(Refraction { geom, prim, y, n })
}

/// Whether `y`, on the plane of the triangle `[a, b, c]` with normal `ng`,
/// lies inside it: on the same side of its three edges (either winding).
fn within(y: Vec3, [a, b, c]: [Vec3; 3], ng: Vec3) -> bool {
    let s = [(a, b), (b, c), (c, a)].map(|(p, q)| (q - p).cross(y - p).dot(ng));
    s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0)
}

/// Whether the walk's exit `t`, whose refracted ray found the emitter at
/// `l` (a triangle the lights sample), is a path the connection counts:
/// its exit triangle is one of the [`refractions`] from its scattering
/// point to `l`.
pub(crate) fn covers(ctx: &Context, t: &Through, l: Vec3, counters: &mut Counters) -> bool {
    refractions(ctx, t.x, l, t.eta, counters).through(t.geom, t.prim)
}

/// The refracted paths from `x` to the light point `l` that a connection
/// through a boundary of index `eta` counts (`refractions`), as (mesh,
/// triangle, refraction point): to check them from outside.
pub fn counted_paths(ctx: &Context, x: Vec3, l: Vec3, eta: f32) -> Vec<(u32, u32, Vec3)> {
    let mut counters = Counters::default();
    let found = refractions(ctx, x, l, eta, &mut counters);
    found.iter().map(|r| (r.geom, r.prim, r.y)).collect()
}

/// Whether the walk leaves the emission its exit from `x` through
/// triangle `prim` of mesh `geom` finds at `l` to the connection
/// (`covers`).
pub fn left_to_connection(ctx: &Context, x: Vec3, geom: u32, prim: u32, l: Vec3, eta: f32) -> bool {
    let t = Through { x, geom, prim, eta };
    covers(ctx, &t, l, &mut Counters::default())
}

/// The in-scattered radiance at `x` (arriving along `d_in`) from one light
/// sample through the boundary, summed over its [`refractions`], per
/// channel, and the light triangle; None when it brings none.
fn connect(
    ctx: &Context,
    m: &Medium,
    eta: f32,
    x: Vec3,
    d_in: Vec3,
    rng: &mut SampleRng,
    counters: &mut Counters,
) -> Option<([f64; 3], u32)> {
    let ls = draw_light(ctx, rng)?;
    let mut sum = [0.0; 3];
    let mut any = false;
    for r in refractions(ctx, x, ls.point, eta, counters).iter() {
        if let Some(c) = through_one(ctx, m, eta, x, d_in, &ls, r, counters) {
            (0..3).for_each(|k| sum[k] += c[k]);
            any = true;
        }
    }
    any.then_some((sum, ls.index))
}

/// The in-scattered radiance at `x` from the light sample `ls` along the
/// refracted path `r`, per channel; None when it is occluded or brings
/// none.
#[allow(clippy::too_many_arguments)]
fn through_one(
    ctx: &Context,
    m: &Medium,
    eta: f32,
    x: Vec3,
    d_in: Vec3,
    ls: &LightSample,
    r: &Refraction,
    counters: &mut Counters,
) -> Option<[f64; 3]> {
    let (y, n) = (r.y, r.n);
    let g = refracted_geometry(x, y, ls.point, n, eta, ls.normal);
    if g.is_nan() || g <= 0.0 {
        return None;
    }
    let (w1, d1) = ((y - x).normalize(), (y - x).length());
    counters.ray(Effect::Direct);
    let origin = offset_along(y, n, ctx.ray_epsilon);
    let light = ctx.leaving(ctx.lights.geom_of(ls.index), true);
    if ctx.occluded(
        &Ray::new(origin, ls.point - origin),
        1.0 - 1e-4,
        [None, light],
        counters,
    ) {
        return None;
    }
    let cos_out = (ls.point - y).normalize().dot(n);
    let transmitted = 1.0 - fresnel::dielectric(cos_out, eta);
    let phase = henyey_greenstein(m.g, d_in.dot(w1) as f64);
    let common = phase * (transmitted * eta * eta * g / ls.pdf_area) as f64;
    let sigma_t = m.sigma_t();
    Some(std::array::from_fn(|k| {
        (-sigma_t[k] * d1 as f64).exp() * common * ls.radiance[k] as f64
    }))
}

/// The Henyey–Greenstein phase function at the cosine `cos` between the
/// propagation direction and the scattered one (per steradian).
pub fn henyey_greenstein(g: f64, cos: f64) -> f64 {
    let denom = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * denom * denom.sqrt())
}

/// The point y on the plane through `p0` with unit normal `n` (pointing to
/// the side of `l`) where light from `l` refracts towards `x` (below the
/// plane, in the medium of relative index `eta`): η sin θ1 = sin θ2, θ1
/// at x's side. None when x and l are not on opposite sides.
pub fn refraction_point(x: Vec3, l: Vec3, p0: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let dv = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let (xv, lv, pv, nv) = (dv(x), dv(l), dv(p0), dv(n));
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let h1 = dot(sub(pv, xv), nv);
    let h2 = dot(sub(lv, pv), nv);
    if !(h1 > 0.0 && h2 > 0.0) {
        return None;
    }
    let xl = sub(lv, xv);
    let along = dot(xl, nv);
    let a = [
        xl[0] - along * nv[0],
        xl[1] - along * nv[1],
        xl[2] - along * nv[2],
    ];
    let dist = dot(a, a).sqrt();
    let s = if dist > 0.0 {
        solve_offset(eta as f64, h1, h2, dist)
    } else {
        0.0
    };
    let e = if dist > 0.0 {
        a.map(|c| c / dist)
    } else {
        [0.0; 3]
    };
    let y: [f64; 3] = std::array::from_fn(|i| xv[i] + h1 * nv[i] + s * e[i]);
    Some(Vec3::new(y[0] as f32, y[1] as f32, y[2] as f32))
}

/// The root s ∈ [0, D] of η s / √(s² + h1²) = (D − s) / √((D − s)² + h2²):
/// the refraction point's distance from x's foot on the plane, towards
/// l's. The left side rises and the right side falls in s, so the root is
/// unique.
fn solve_offset(eta: f64, h1: f64, h2: f64, d: f64) -> f64 {
    // the function and its derivative, sharing their square roots
    // (q^{3/2} as q √q: powf costs several times a square root)
    let f_df = |s: f64| {
        let r = d - s;
        let (q1, q2) = (s * s + h1 * h1, r * r + h2 * h2);
        let (r1, r2) = (q1.sqrt(), q2.sqrt());
        let f = eta * s / r1 - r / r2;
        (f, eta * h1 * h1 / (q1 * r1) + h2 * h2 / (q2 * r2))
    };
    let (mut lo, mut hi) = (0.0, d);
    let mut s = d * h1 / (h1 + eta * h2);
    for _ in 0..SOLVE_STEPS {
        let (v, dv) = f_df(s);
        if v < 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        let next = s - v / dv;
        let next = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        // far below the f32 the point is returned in
        if (next - s).abs() <= 1e-10 * d {
            return next;
        }
        s = next;
    }
    s
}

/// The generalized geometry term |dω_x / dA_l| of the refracted
/// connection x → y → l through a plane with unit normal `n` (towards l)
/// at y, index `eta` on x's side, `n_l` the light's front normal:
///
///   G = cos θl / ((d1 + η d2) (d1 cos θ2 / cos θ1 + η d2 cos θ1 / cos θ2)),
///
/// d1 = |y − x|, d2 = |l − y|, θ1 and θ2 the angles to n on either side
/// (`docs/bssrdf.md` §7). With η = 1 it is the usual cos θl / |l − x|².
pub fn refracted_geometry(x: Vec3, y: Vec3, l: Vec3, n: Vec3, eta: f32, n_l: Vec3) -> f32 {
    let (v1, v2) = (y - x, l - y);
    let (d1, d2) = (v1.length(), v2.length());
    if !(d1 > 0.0 && d2 > 0.0) {
        return 0.0;
    }
    let c1 = v1.dot(n) / d1;
    let c2 = v2.dot(n) / d2;
    let cl = -v2.dot(n_l) / d2;
    if !(c1 > 0.0 && c2 > 0.0 && cl > 0.0) {
        return 0.0;
    }
    cl / ((d1 + eta * d2) * (d1 * c2 / c1 + eta * d2 * c1 / c2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Refracts the unit direction `w` (upwards through the plane z = 0,
    /// from index η below to 1 above) and returns where it meets the
    /// plane through `l` with normal `n_l`.
    fn trace(x: Vec3, w: Vec3, eta: f32, l: Vec3, n_l: Vec3) -> Vec3 {
        let y = x + w * (-x.z / w.z);
        let (sx, sy) = (eta * w.x, eta * w.y);
        let out = Vec3::new(sx, sy, (1.0 - sx * sx - sy * sy).sqrt());
        let t = (l - y).dot(n_l) / out.dot(n_l);
        y + out * t
    }

    /// Snell's law holds at the solved point, for directions from normal
    /// to near grazing: a wrong root (e.g. η on the other side) breaks it.
    #[test]
    fn refraction_point_obeys_snell() {
        let n = Vec3::Z;
        for (x, l) in [
            (Vec3::new(0.1, 0.2, -0.3), Vec3::new(2.0, -1.0, 1.5)),
            (Vec3::new(0.0, 0.0, -0.01), Vec3::new(5.0, 0.0, 0.2)),
            (Vec3::new(0.3, 0.3, -2.0), Vec3::new(0.3, 0.3, 1.0)),
        ] {
            let y = refraction_point(x, l, Vec3::ZERO, n, 1.5).unwrap();
            assert!(y.z.abs() < 1e-6);
            let (w1, w2) = ((y - x).normalize(), (l - y).normalize());
            let s1 = (w1.x * w1.x + w1.y * w1.y).sqrt();
            let s2 = (w2.x * w2.x + w2.y * w2.y).sqrt();
            assert!((1.5 * s1 - s2).abs() < 1e-5, "{s1} {s2}");
            // in the plane of incidence
            assert!(w1.cross(w2).dot(n).abs() < 1e-5);
        }
        assert!(refraction_point(Vec3::new(0.0, 0.0, 0.1), Vec3::Z, Vec3::ZERO, n, 1.5).is_none());
    }

    /// The generalized geometry term is the ratio of a small solid angle
    /// at x to the light area its refracted rays cover, measured here by
    /// tracing a cross of directions through the plane: a term missing η,
    /// a cosine or a distance misses by far more than the difference's
    /// error.
    #[test]
    fn refracted_geometry_matches_traced_jacobian() {
        let n = Vec3::Z;
        for (x, l, n_l, eta) in [
            (
                Vec3::new(0.1, 0.2, -0.3),
                Vec3::new(2.0, -1.0, 1.5),
                Vec3::new(-0.6, 0.3, -0.7).normalize(),
                1.5f32,
            ),
            (
                Vec3::new(0.0, 0.0, -0.05),
                Vec3::new(0.2, 0.1, 3.0),
                Vec3::new(0.0, 0.0, -1.0),
                1.33,
            ),
            (
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(-1.0, 0.0, -1.0).normalize(),
                1.0,
            ),
        ] {
            let y = refraction_point(x, l, Vec3::ZERO, n, eta).unwrap();
            let g = refracted_geometry(x, y, l, n, eta, n_l) as f64;
            let w = (y - x).normalize();
            let frame = crate::geometry::Frame::from_normal(w);
            let h = 1e-3f32;
            let wu = (w + frame.to_world(Vec3::X) * h).normalize();
            let wv = (w + frame.to_world(Vec3::Y) * h).normalize();
            let wu2 = (w - frame.to_world(Vec3::X) * h).normalize();
            let wv2 = (w - frame.to_world(Vec3::Y) * h).normalize();
            let du = trace(x, wu, eta, l, n_l) - trace(x, wu2, eta, l, n_l);
            let dv = trace(x, wv, eta, l, n_l) - trace(x, wv2, eta, l, n_l);
            let area = du.cross(dv).length() as f64;
            let solid = (wu - wu2).cross(wv - wv2).length() as f64;
            let brute = solid / area;
            assert!(
                (g - brute).abs() < 2e-3 * brute,
                "η {eta}: G {g} vs traced {brute}"
            );
            if eta == 1.0 {
                let plain = n_l.dot(-(l - x).normalize()) / (l - x).length_squared();
                assert!((g - plain as f64).abs() < 1e-5 * g, "{g} {plain}");
            }
        }
    }

    #[test]
    fn henyey_greenstein_is_normalized() {
        for g in [-0.6, 0.0, 0.4, 0.9] {
            let n = 200_000;
            let sum: f64 = (0..n)
                .map(|i| {
                    let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                    henyey_greenstein(g, c) * 2.0 * std::f64::consts::PI * 2.0 / n as f64
                })
                .sum();
            assert!((sum - 1.0).abs() < 1e-4, "g {g}: {sum}");
        }
    }
}
