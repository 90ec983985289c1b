//! The brute-force references the accelerator tests compare against: every
//! triangle of every mesh, no hierarchy. [`Brute`] runs the BVH's own f32
//! triangle test, so our BVH must agree with it exactly; [`reference`] is
//! an independent Möller–Trumbore in f64 with closed edges that marks the
//! knife edges where two correct backends may differ.

use lucent::accel::bvh::can_hit;
use lucent::accel::bvh::triangle::RayTri;
use lucent::accel::{Hit, ProbeHits};
use lucent::geometry::{Mesh, Ray, Vec3};

/// The reference: every triangle that can be hit, in order.
pub struct Brute<'a> {
    pub meshes: &'a [Mesh],
    tris: Vec<(u32, u32, [Vec3; 3])>,
}

impl<'a> Brute<'a> {
    pub fn new(meshes: &'a [Mesh]) -> Self {
        let tris = meshes
            .iter()
            .enumerate()
            .flat_map(|(g, m)| {
                (0..m.triangle_count() as u32).filter_map(move |i| {
                    let p = m.triangle(i);
                    can_hit(p).then_some((g as u32, i, p))
                })
            })
            .collect();
        Brute { meshes, tris }
    }
    pub fn test(&self, ray: &Ray, p: [Vec3; 3], tmin: f32, tmax: f32) -> Option<(f32, f32, f32)> {
        RayTri::new(ray).intersect(p[0], p[1], p[2], tmin, tmax)
    }
    pub fn all(&self, ray: &Ray, tmin: f32, tmax: f32) -> Vec<Hit> {
        let rt = RayTri::new(ray);
        let mut v: Vec<Hit> = self
            .tris
            .iter()
            .filter_map(|&(geom, prim, p)| {
                rt.intersect(p[0], p[1], p[2], tmin, tmax)
                    .map(|(t, u, v)| Hit {
                        t,
                        geom,
                        prim,
                        u,
                        v,
                    })
            })
            .collect();
        v.sort_by(|a, b| {
            a.t.total_cmp(&b.t)
                .then(a.geom.cmp(&b.geom))
                .then(a.prim.cmp(&b.prim))
        });
        v
    }
    pub fn nearest(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        self.all(ray, tmin, tmax).first().copied()
    }
    pub fn segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32) -> ProbeHits {
        probe(&self.all(ray, 0.0, tmax), geom, seed)
    }
}

/// What hits_on_segment should return, given every hit on the segment.
pub fn probe(all: &[Hit], geom: u32, seed: u32) -> ProbeHits {
    let mut out = ProbeHits::new();
    out.reset(seed);
    for h in all.iter().filter(|h| h.geom == geom) {
        out.record(*h);
    }
    out.finish();
    out
}

/// One triangle the reference says the ray may hit.
#[derive(Clone, Copy, Debug)]
pub struct RefHit {
    pub geom: u32,
    pub prim: u32,
    pub t: f64,
    pub u: f64,
    pub v: f64,
    /// Far from every knife edge: a backend must report it.
    pub sure: bool,
}

/// Every triangle hit with t in [tmin, tmax], closed edges, in f64.
/// With `eps == 0` only exact hits count and all are `sure` (for meshes
/// where f32 arithmetic is exact); otherwise hits within `eps` of an edge
/// or bound are included but not `sure`, and so are near misses.
pub fn reference(
    meshes: &[Mesh],
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    only_geom: Option<u32>,
    eps: f64,
) -> Vec<RefHit> {
    let v = |p: Vec3| [p.x as f64, p.y as f64, p.z as f64];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let norm = |a: [f64; 3]| dot(a, a).sqrt();
    let (o, d) = (v(ray.o), v(ray.d));
    let (tmin, tmax) = (tmin as f64, tmax as f64);
    let mut out = Vec::new();
    for (g, m) in meshes.iter().enumerate() {
        if only_geom.is_some_and(|w| w != g as u32) {
            continue;
        }
        for prim in 0..m.triangle_count() as u32 {
            let [a, b, c] = m.triangle(prim).map(v);
            let (e1, e2) = (sub(b, a), sub(c, a));
            let p = cross(d, e2);
            let det = dot(e1, p);
            let scale = norm(e1) * norm(e2) * norm(d);
            if det == 0.0 || scale == 0.0 {
                continue;
            }
            // How much f32 rounding in a backend is amplified in the
            // barycentrics and t: 1 for a ray hitting a well-shaped
            // triangle head-on, large at grazing angles.
            // An origin far away relative to the triangle's size
            // amplifies them too.
            let s = sub(o, a);
            let cond = scale / det.abs();
            let far = (norm(s) / (norm(e1) * norm(e2)).sqrt()).max(1.0);
            let eps = eps * cond * far;
            let grazing = cond > 1e4;
            let u = dot(s, p) / det;
            let q = cross(s, e1);
            let w = dot(d, q) / det;
            let t = dot(e2, q) / det;
            let margin = u.min(w).min(1.0 - u - w);
            let t_eps = eps * t.abs().max(1.0);
            let inside = margin >= 0.0 && t >= tmin && t <= tmax;
            let near = margin >= -eps && t >= tmin - t_eps && t <= tmax + t_eps;
            let sure = inside
                && (eps == 0.0
                    || (margin > eps && t > tmin + t_eps && t < tmax - t_eps && !grazing));
            if inside || near {
                out.push(RefHit {
                    geom: g as u32,
                    prim,
                    t,
                    u,
                    v: w,
                    sure,
                });
            }
        }
    }
    out
}
