//! The watertight ray/triangle test of Woop, Benthin and Wald 2013,
//! "Watertight Ray/Triangle Intersection" (JCGT 2(1)), without backface
//! culling and with inclusive edges.
//!
//! The ray is sheared into a space where it runs along +z from the origin,
//! so the test reduces to 2D edge functions of the sheared vertices. Every
//! vertex is transformed by the same operations whichever triangle it
//! belongs to, and an edge shared by two triangles yields edge functions of
//! exactly opposite sign, so a ray through a shared edge or vertex hits at
//! least one of the triangles around it. Edges are inclusive (an edge
//! function of zero counts as inside, as in Embree's robust mode), so such a
//! ray in fact hits every triangle touching that point. Edge functions that
//! come out exactly zero in `f32` are recomputed in `f64`, as the paper
//! prescribes, so a zero caused by rounding is not mistaken for an edge.
//!
//! The query backends and the brute-force reference in the tests share this
//! one function, so they agree bit for bit.

use crate::geometry::{Ray, Vec3};

/// A ray prepared for the watertight test: the axis permutation and shear
/// that map its direction to +z.
#[derive(Clone, Copy, Debug)]
pub struct RayTri {
    o: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl RayTri {
    pub fn new(ray: &Ray) -> Self {
        let d = ray.d;
        let a = d.abs();
        // The dominant axis becomes z, so the shear divides by the largest
        // component. (A zero or NaN direction makes the shear NaN, and every
        // test below then fails: such a ray hits nothing.)
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swapping x and y for a negative z keeps the winding (the sign of
        // the edge functions) consistent; it does not matter without culling
        // but keeps U, V, W's signs meaningful for debugging.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        RayTri {
            o: ray.o,
            kx,
            ky,
            kz,
            sx: d[kx] / d[kz],
            sy: d[ky] / d[kz],
            sz: 1.0 / d[kz],
        }
    }

    /// Intersects triangle (p0, p1, p2). Returns (t, u, v) with t in
    /// [tmin, tmax] (in units of |d|) and (u, v) the barycentrics of p1 and
    /// p2, or None. Degenerate triangles (zero projected area, including any
    /// with a repeated vertex) and triangles with NaN coordinates never hit.
    #[inline(always)]
    pub fn intersect(
        &self,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32, f32)> {
        // Masking with 3 lets the compiler drop the bounds checks on the
        // padded arrays (glam's `Vec3[i]` is a branchy match): 7% of the
        // whole nearest-hit query on a cache-resident mesh.
        let (kx, ky, kz) = (self.kx & 3, self.ky & 3, self.kz & 3);
        let pad = |v: Vec3| [v.x, v.y, v.z, 0.0];
        let a = pad(p0 - self.o);
        let b = pad(p1 - self.o);
        let c = pad(p2 - self.o);
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];

        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            u = edge_f64(cx, by, cy, bx);
            v = edge_f64(ax, cy, ay, cx);
            w = edge_f64(bx, ay, by, ax);
        }
        // Inside iff all three have one sign (zeros count as either).
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = self.sz * a[kz];
        let bz = self.sz * b[kz];
        let cz = self.sz * c[kz];
        let tt = u * az + v * bz + w * cz;
        let rcp = 1.0 / det;
        let t = tt * rcp;
        // Written so that NaN fails.
        if t >= tmin && t <= tmax {
            Some((t, v * rcp, w * rcp))
        } else {
            None
        }
    }
}

/// `a·b − c·d` with exact products (two f32 products are exact in f64).
#[inline(never)]
#[cold]
fn edge_f64(a: f32, b: f32, c: f32, d: f32) -> f32 {
    (a as f64 * b as f64 - c as f64 * d as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3::from(o), Vec3::from(d))
    }

    const P: [Vec3; 3] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];

    #[test]
    fn interior_hit_reports_t_and_barycentrics() {
        let r = ray([0.25, 0.5, 2.0], [0.0, 0.0, -2.0]);
        let (t, u, v) = RayTri::new(&r)
            .intersect(P[0], P[1], P[2], 0.0, f32::INFINITY)
            .unwrap();
        // t in units of |d| = 2
        assert!((t - 1.0).abs() < 1e-6, "t {t}");
        assert!((u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6, "{u} {v}");
        // both faces hit (no culling)
        let back = ray([0.25, 0.5, -2.0], [0.0, 0.0, 1.0]);
        assert!(RayTri::new(&back)
            .intersect(P[0], P[1], P[2], 0.0, 10.0)
            .is_some());
    }

    #[test]
    fn interval_is_inclusive() {
        let r = ray([0.25, 0.25, 1.0], [0.0, 0.0, -1.0]);
        let rt = RayTri::new(&r);
        assert!(rt.intersect(P[0], P[1], P[2], 1.0, 1.0).is_some());
        assert!(rt.intersect(P[0], P[1], P[2], 0.0, 0.999_999).is_none());
        assert!(rt.intersect(P[0], P[1], P[2], 1.000_001, 5.0).is_none());
    }

    #[test]
    fn edges_and_vertices_are_inclusive() {
        // a vertex, an edge midpoint and the hypotenuse, from both sides
        for o in [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [0.5, 0.5], [1.0, 0.0]] {
            for dz in [-1.0, 1.0] {
                let r = ray([o[0], o[1], -dz], [0.0, 0.0, dz]);
                let h = RayTri::new(&r).intersect(P[0], P[1], P[2], 0.0, 10.0);
                assert!(h.is_some(), "missed at {o:?} dz {dz}");
            }
        }
        let outside = ray([0.5, 0.500_001, 1.0], [0.0, 0.0, -1.0]);
        assert!(RayTri::new(&outside)
            .intersect(P[0], P[1], P[2], 0.0, 10.0)
            .is_none());
    }

    #[test]
    fn degenerate_and_nan_triangles_never_hit() {
        let rays = [
            ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
            ray([0.3, 0.3, 1.0], [0.1, -0.2, -1.0]),
            ray([-1.0, 0.5, 0.5], [1.0, 0.0, -0.5]),
        ];
        let a = Vec3::new(0.0, 0.0, 0.0);
        let b = Vec3::new(1.0, 1.0, 0.0);
        let nan = Vec3::new(f32::NAN, 0.0, 0.0);
        for r in &rays {
            let rt = RayTri::new(r);
            assert!(rt.intersect(a, a, b, -10.0, 10.0).is_none());
            assert!(rt.intersect(a, b, b, -10.0, 10.0).is_none());
            assert!(rt.intersect(a, a, a, -10.0, 10.0).is_none());
            assert!(rt.intersect(nan, P[1], P[2], -10.0, 10.0).is_none());
        }
    }

    #[test]
    fn shared_edge_of_random_triangle_pairs_is_watertight() {
        // Two triangles sharing edge (p, q); rays aimed at random points of
        // the edge must hit at least one (with inclusive edges: both if the
        // point is exactly on it, which rounding rarely allows).
        let mut rng = crate::sampling::Rng::from_key(11);
        let mut r3 = |s: f32| {
            Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            ) * s
        };
        for _ in 0..20_000 {
            let (p, q) = (r3(2.0), r3(2.0));
            let (a, b) = (r3(2.0), r3(2.0));
            let o = r3(10.0);
            let s = (r3(1.0).x + 0.5).clamp(0.0, 1.0);
            let target = p + (q - p) * s;
            let rt = RayTri::new(&Ray::new(o, target - o));
            let h1 = rt.intersect(p, q, a, 0.0, f32::INFINITY);
            let h2 = rt.intersect(q, p, b, 0.0, f32::INFINITY);
            // Only meaningful if a and b lie on opposite sides of the edge
            // as seen from o; otherwise the ray may pass outside both.
            let n = (q - p).cross(target - o);
            if n.dot(a - p) * n.dot(b - p) < 0.0 {
                assert!(h1.is_some() || h2.is_some(), "leak at {target:?}");
            }
        }
    }
}
