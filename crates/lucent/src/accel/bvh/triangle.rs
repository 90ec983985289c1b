//! The watertight ray/triangle test of Woop, Benthin and Wald 2013,
//! "Watertight Ray/Triangle Intersection" (JCGT 2(1)), without backface
//! culling and with inclusive edges: a ray through a shared edge or vertex
//! hits every triangle touching that point, and edge functions that come
//! out exactly zero in `f32` are recomputed in `f64`, as the paper
//! prescribes.
//!
//! The BVH stores its triangles four to a [`Tri4`] packet and tests a
//! packet with [`RayTri::intersect4`]: every lane performs exactly the
//! scalar test's operations in the same order (no fused multiply-add), so
//! it returns bit-identical results to [`RayTri::intersect`], which the
//! brute-force reference in the tests uses. Why the test is watertight and
//! the packet exact: `docs/performance.md`, "The BVH's triangle test".

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
        // padded arrays (glam's `Vec3[i]` is a branchy match; the gain:
        // docs/performance.md, "The BVH's triangle test").
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

/// Four triangles in structure-of-arrays form, `p[vertex][axis][lane]`,
/// so that one SSE load fetches an axis of a vertex of all four, and their
/// ids. Unused lanes hold NaN coordinates, which no ray hits.
///
/// The ids sit beside the vertices (as in Embree's `Triangle4v`) rather
/// than in a separate slot-to-id table: on a 5M-triangle mesh that table
/// is 21 MB, and looking a hit's id up in it would be one more cache miss
/// per hit, paid by every probe segment.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Tri4 {
    pub p: [[[f32; 4]; 3]; 3],
    /// The mesh's triangle index of each lane (meaningless for unused
    /// lanes).
    pub id: [u32; 4],
}

impl Tri4 {
    pub const EMPTY: Tri4 = Tri4 {
        p: [[[f32::NAN; 4]; 3]; 3],
        id: [u32::MAX; 4],
    };

    /// Puts triangle `p`, the mesh's triangle `id`, in `lane`.
    pub fn set(&mut self, lane: usize, p: [Vec3; 3], id: u32) {
        for (v, q) in p.iter().enumerate() {
            for a in 0..3 {
                self.p[v][a][lane] = q[a];
            }
        }
        self.id[lane] = id;
    }

    /// The triangle in `lane`.
    #[inline(always)]
    pub fn get(&self, lane: usize) -> [Vec3; 3] {
        let l = lane & 3;
        self.p.map(|v| Vec3::new(v[0][l], v[1][l], v[2][l]))
    }
}

/// What [`RayTri::intersect4`] found: a bit per hit lane and each lane's
/// (t, u, v), meaningful only for the hit lanes.
#[derive(Clone, Copy, Debug)]
pub struct Hits4 {
    pub mask: u32,
    pub t: [f32; 4],
    pub u: [f32; 4],
    pub v: [f32; 4],
}

impl Hits4 {
    /// The hit lane with the smallest t, if any.
    #[inline(always)]
    pub fn nearest(&self) -> Option<usize> {
        let mut m = self.mask;
        let mut best: Option<usize> = None;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            if best.is_none_or(|b| self.t[k] < self.t[b]) {
                best = Some(k);
            }
        }
        best
    }
}

impl RayTri {
    /// [`intersect`](Self::intersect) on the four triangles of a packet.
    #[cfg(all(target_arch = "x86_64", not(feature = "bvh-portable")))]
    #[inline(always)]
    pub fn intersect4(&self, tri: &Tri4, tmin: f32, tmax: f32) -> Hits4 {
        use std::arch::x86_64::*;
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let o = self.o.to_array();
        let mut out = Hits4 {
            mask: 0,
            t: [0.0; 4],
            u: [0.0; 4],
            v: [0.0; 4],
        };
        // SAFETY: SSE2 is part of the x86_64 baseline; the loads read
        // 16-byte-aligned rows of an aligned `Tri4`, the stores write the
        // local arrays of `out`.
        let zero_edges = unsafe {
            let rel = |v: usize, k: usize| {
                _mm_sub_ps(_mm_load_ps(tri.p[v][k].as_ptr()), _mm_set1_ps(o[k]))
            };
            let (sx, sy, sz) = (
                _mm_set1_ps(self.sx),
                _mm_set1_ps(self.sy),
                _mm_set1_ps(self.sz),
            );
            let (a_z, b_z, c_z) = (rel(0, kz), rel(1, kz), rel(2, kz));
            let ax = _mm_sub_ps(rel(0, kx), _mm_mul_ps(sx, a_z));
            let ay = _mm_sub_ps(rel(0, ky), _mm_mul_ps(sy, a_z));
            let bx = _mm_sub_ps(rel(1, kx), _mm_mul_ps(sx, b_z));
            let by = _mm_sub_ps(rel(1, ky), _mm_mul_ps(sy, b_z));
            let cx = _mm_sub_ps(rel(2, kx), _mm_mul_ps(sx, c_z));
            let cy = _mm_sub_ps(rel(2, ky), _mm_mul_ps(sy, c_z));
            let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
            let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
            let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
            let zero = _mm_setzero_ps();
            let or3 = |a, b, c| _mm_or_ps(_mm_or_ps(a, b), c);
            let zero_edges = _mm_movemask_ps(or3(
                _mm_cmpeq_ps(u, zero),
                _mm_cmpeq_ps(v, zero),
                _mm_cmpeq_ps(w, zero),
            )) as u32;
            let neg = or3(
                _mm_cmplt_ps(u, zero),
                _mm_cmplt_ps(v, zero),
                _mm_cmplt_ps(w, zero),
            );
            let pos = or3(
                _mm_cmpgt_ps(u, zero),
                _mm_cmpgt_ps(v, zero),
                _mm_cmpgt_ps(w, zero),
            );
            let det = _mm_add_ps(_mm_add_ps(u, v), w);
            let tt = _mm_add_ps(
                _mm_add_ps(
                    _mm_mul_ps(u, _mm_mul_ps(sz, a_z)),
                    _mm_mul_ps(v, _mm_mul_ps(sz, b_z)),
                ),
                _mm_mul_ps(w, _mm_mul_ps(sz, c_z)),
            );
            let rcp = _mm_div_ps(_mm_set1_ps(1.0), det);
            let t = _mm_mul_ps(tt, rcp);
            // cmpneq is true for NaN, as `!(det == 0.0)` is; a NaN t then
            // fails both interval comparisons.
            let ok = _mm_andnot_ps(
                _mm_and_ps(neg, pos),
                _mm_and_ps(
                    _mm_cmpneq_ps(det, zero),
                    _mm_and_ps(
                        _mm_cmpge_ps(t, _mm_set1_ps(tmin)),
                        _mm_cmple_ps(t, _mm_set1_ps(tmax)),
                    ),
                ),
            );
            out.mask = _mm_movemask_ps(ok) as u32 & !zero_edges;
            if out.mask != 0 {
                _mm_storeu_ps(out.t.as_mut_ptr(), t);
                _mm_storeu_ps(out.u.as_mut_ptr(), _mm_mul_ps(v, rcp));
                _mm_storeu_ps(out.v.as_mut_ptr(), _mm_mul_ps(w, rcp));
            }
            zero_edges
        };
        if zero_edges != 0 {
            self.redo_lanes(tri, zero_edges, tmin, tmax, &mut out);
        }
        out
    }

    /// [`intersect`](Self::intersect) on the four triangles of a packet,
    /// one at a time.
    #[cfg(any(not(target_arch = "x86_64"), feature = "bvh-portable"))]
    #[inline(always)]
    pub fn intersect4(&self, tri: &Tri4, tmin: f32, tmax: f32) -> Hits4 {
        let mut out = Hits4 {
            mask: 0,
            t: [0.0; 4],
            u: [0.0; 4],
            v: [0.0; 4],
        };
        self.redo_lanes(tri, 0xf, tmin, tmax, &mut out);
        out
    }

    /// Runs the scalar test on the lanes in `lanes`: those whose edge
    /// functions need the `f64` fallback (rays through edges and vertices,
    /// rare), or all of them without SSE.
    #[inline(never)]
    fn redo_lanes(&self, tri: &Tri4, lanes: u32, tmin: f32, tmax: f32, out: &mut Hits4) {
        for k in 0..4 {
            if lanes & 1 << k == 0 {
                continue;
            }
            let [p0, p1, p2] = tri.get(k);
            if let Some((t, u, v)) = self.intersect(p0, p1, p2, tmin, tmax) {
                out.mask |= 1 << k;
                (out.t[k], out.u[k], out.v[k]) = (t, u, v);
            }
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

    /// Points uniform in the cube of side `s` centred on the origin.
    fn random_points(seed: u64) -> impl FnMut(f32) -> Vec3 {
        let mut rng = crate::sampling::Rng::from_key(seed);
        move |s| {
            Vec3::new(
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            ) * s
        }
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

    /// The packet test must be the scalar test, bit for bit, lane by lane:
    /// random triangles, triangles on an integer grid hit through their
    /// edges and vertices (the `f64` fallback), and NaN (empty) lanes.
    #[test]
    fn packet_test_is_the_scalar_test_on_each_lane() {
        let mut r3 = random_points(5);
        let (mut hits, mut grid_hits) = (0, 0);
        for i in 0..40_000 {
            let grid = i % 2 == 1;
            let snap = |v: Vec3| if grid { v.round() } else { v };
            let mut tri = Tri4::EMPTY;
            let mut lanes = Vec::new();
            for k in 0..4 {
                if i % 7 == 3 && k == 2 {
                    continue; // an empty lane
                }
                let p = [snap(r3(4.0)), snap(r3(4.0)), snap(r3(4.0))];
                tri.set(k, p, k as u32);
                lanes.push((k, p));
            }
            let o = snap(r3(20.0));
            let target = if grid {
                lanes[0].1[0] + snap(r3(2.0)) * 0.5
            } else {
                lanes[0].1[0] + r3(2.0)
            };
            let rt = RayTri::new(&Ray::new(o, target - o));
            let (tmin, tmax) = if i % 5 == 0 { (0.5, 1.5) } else { (0.0, 10.0) };
            let got = rt.intersect4(&tri, tmin, tmax);
            let mut want_mask = 0;
            for &(k, p) in &lanes {
                let want = rt.intersect(p[0], p[1], p[2], tmin, tmax);
                if let Some((t, u, v)) = want {
                    want_mask |= 1 << k;
                    assert_eq!(
                        (got.t[k].to_bits(), got.u[k].to_bits(), got.v[k].to_bits()),
                        (t.to_bits(), u.to_bits(), v.to_bits()),
                        "lane {k} of case {i}"
                    );
                    hits += 1;
                    grid_hits += grid as usize;
                }
            }
            assert_eq!(got.mask, want_mask, "case {i}");
        }
        assert!(hits > 5_000 && grid_hits > 1_000, "{hits} {grid_hits}");
    }

    #[test]
    fn nearest_lane_has_the_smallest_t() {
        let h = Hits4 {
            mask: 0b1011,
            t: [3.0, 1.0, 0.5, 2.0],
            u: [0.0; 4],
            v: [0.0; 4],
        };
        assert_eq!(h.nearest(), Some(1));
        assert_eq!(Hits4 { mask: 0, ..h }.nearest(), None);
    }

    #[test]
    fn shared_edge_of_random_triangle_pairs_is_watertight() {
        // Two triangles sharing edge (p, q); rays aimed at random points of
        // the edge must hit at least one (with inclusive edges: both if the
        // point is exactly on it, which rounding rarely allows).
        let mut r3 = random_points(11);
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
