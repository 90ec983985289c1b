//! Stack-based, front-to-back traversal of a wide [`Tree`](super::build::Tree)
//! with a robust ray/box slab test, four boxes at a time.
//!
//! The slab test (Kay & Kajiya 1986) picks each axis's near and far plane by
//! the sign of the direction, as Williams et al. 2005 ("An Efficient and
//! Robust Ray-Box Intersection Algorithm") do, so no min/max of the two
//! plane distances is needed. A zero direction component gives an infinite
//! inverse; an origin exactly on that slab's plane then yields 0·∞ = NaN,
//! and the running max/min are written so that a NaN never narrows the
//! interval (a ray lying in a box face must still reach the triangles on
//! it). The accepted interval is widened by a few ulps, following Ize 2013
//! ("Robust BVH Ray Traversal", JCGT 2(2)), so that rounding in the slab
//! distances never culls a box the triangle test would hit.

use super::build::{is_leaf, leaf_range, NodeRef, NodeW, Tree, MAX_DEPTH, WIDTH};
use std::mem::MaybeUninit;

use crate::geometry::Ray;

/// Relative slack on the box interval: covers the ≤ 3 ulp error of each
/// slab distance (Ize 2013 uses 2γ₃ ≈ 3.6e-7) plus the rounding of the
/// triangle test's own t, with a wide margin; it costs nothing measurable.
const SLACK: f32 = 1.0 / (1 << 18) as f32;

/// Trees of fewer wide nodes than this (1 MiB of nodes, with their
/// triangles ~2 MiB) are assumed to live in the caches and are not
/// prefetched.
const PREFETCH_NODES: usize = 4096;

/// Each level pushes at most `WIDTH - 1` siblings.
const STACK: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(super) struct RayBox {
    o: [f32; 3],
    inv: [f32; 3],
    /// Row of [`NodeW::b`] holding each axis's near plane (`hi` when the
    /// direction is negative) and far plane.
    near: [usize; 3],
    far: [usize; 3],
}

impl RayBox {
    pub fn new(ray: &Ray) -> Self {
        let d = ray.d.to_array();
        let neg = d.map(|x| x.is_sign_negative() as usize);
        RayBox {
            o: ray.o.to_array(),
            inv: d.map(|x| 1.0 / x),
            near: [neg[0], 2 + neg[1], 4 + neg[2]],
            far: [1 - neg[0], 3 - neg[1], 5 - neg[2]],
        }
    }

    /// Whether the ray meets the box `b` (`[lo, hi]`) within [tmin, tmax].
    pub(crate) fn hit1(&self, b: &[[f32; 3]; 2], tmin: f32, tmax: f32) -> bool {
        let mut lo = tmin;
        let mut hi = tmax;
        for a in 0..3 {
            let tn = (b[self.near[a] & 1][a] - self.o[a]) * self.inv[a];
            let tf = (b[self.far[a] & 1][a] - self.o[a]) * self.inv[a];
            lo = if tn > lo { tn } else { lo };
            hi = if tf < hi { tf } else { hi };
        }
        accept(lo, hi)
    }

    /// Entry distances of the node's boxes, and a bit mask of those the
    /// ray meets within [tmin, tmax]: the SSE version on x86_64, the
    /// portable one elsewhere or with the `bvh-portable` feature.
    #[cfg(all(target_arch = "x86_64", not(feature = "bvh-portable")))]
    #[inline(always)]
    pub(crate) fn hit_w(&self, n: &NodeW, tmin: f32, tmax: f32) -> ([f32; WIDTH], u32) {
        self.hit_w_sse(n, tmin, tmax)
    }

    /// The same, on the portable box test (see above).
    #[cfg(any(not(target_arch = "x86_64"), feature = "bvh-portable"))]
    #[inline(always)]
    pub(crate) fn hit_w(&self, n: &NodeW, tmin: f32, tmax: f32) -> ([f32; WIDTH], u32) {
        self.hit_w_portable(n, tmin, tmax)
    }

    /// [`hit_w`](Self::hit_w) in plain Rust, one box after another: what
    /// other architectures run. Compiled on x86_64 too for the unit tests
    /// (which compare it with the SSE version bit for bit) and with the
    /// `bvh-portable` feature (which makes the whole BVH use it).
    #[cfg(any(test, not(target_arch = "x86_64"), feature = "bvh-portable"))]
    #[inline(always)]
    pub(crate) fn hit_w_portable(&self, n: &NodeW, tmin: f32, tmax: f32) -> ([f32; WIDTH], u32) {
        let mut lo = [tmin; WIDTH];
        let mut hi = [tmax; WIDTH];
        for a in 0..3 {
            let rn = &n.b[self.near[a]];
            let rf = &n.b[self.far[a]];
            for k in 0..WIDTH {
                let tn = (rn[k] - self.o[a]) * self.inv[a];
                let tf = (rf[k] - self.o[a]) * self.inv[a];
                // Comparisons are false for NaN, so NaN leaves lo/hi as they are.
                lo[k] = if tn > lo[k] { tn } else { lo[k] };
                hi[k] = if tf < hi[k] { tf } else { hi[k] };
            }
        }
        let mut mask = 0;
        for k in 0..WIDTH {
            mask |= (accept(lo[k], hi[k]) as u32) << k;
        }
        (lo, mask)
    }

    /// The same with SSE, four boxes at a time: the compiler does not
    /// vectorize the portable version (it keeps the NaN-ordered selects
    /// scalar). `maxps(a, b)` is `a > b ? a : b` and `minps(a, b)` is
    /// `a < b ? a : b`, exactly the selects of the portable code, so both
    /// give bit-identical results.
    #[cfg(all(target_arch = "x86_64", any(test, not(feature = "bvh-portable"))))]
    #[inline(always)]
    pub(crate) fn hit_w_sse(&self, n: &NodeW, tmin: f32, tmax: f32) -> ([f32; WIDTH], u32) {
        use std::arch::x86_64::*;
        const _: () = assert!(WIDTH.is_multiple_of(4));
        let mut out = [0f32; WIDTH];
        let mut mask = 0u32;
        for g in (0..WIDTH).step_by(4) {
            // SAFETY: SSE2 is part of the x86_64 baseline; the loads read
            // 16-byte-aligned quarters of rows of a 64-byte-aligned node,
            // the store writes four floats of a local array.
            let m = unsafe {
                let mut lo = _mm_set1_ps(tmin);
                let mut hi = _mm_set1_ps(tmax);
                for a in 0..3 {
                    let o = _mm_set1_ps(self.o[a]);
                    let inv = _mm_set1_ps(self.inv[a]);
                    let rn = _mm_load_ps(n.b[self.near[a]][g..].as_ptr());
                    let rf = _mm_load_ps(n.b[self.far[a]][g..].as_ptr());
                    let tn = _mm_mul_ps(_mm_sub_ps(rn, o), inv);
                    let tf = _mm_mul_ps(_mm_sub_ps(rf, o), inv);
                    lo = _mm_max_ps(tn, lo);
                    hi = _mm_min_ps(tf, hi);
                }
                let abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff));
                let slack = _mm_set1_ps(SLACK);
                let l = _mm_sub_ps(lo, _mm_mul_ps(_mm_and_ps(lo, abs), slack));
                let h = _mm_add_ps(hi, _mm_mul_ps(_mm_and_ps(hi, abs), slack));
                _mm_storeu_ps(out[g..].as_mut_ptr(), lo);
                _mm_movemask_ps(_mm_cmple_ps(l, h)) as u32
            };
            mask |= m << g;
        }
        (out, mask)
    }
}

/// The widened interval test. An infinite lo or hi makes one side NaN
/// (∞ − ∞), which fails the comparison: exactly the cases where a slab was
/// missed (or the box is an empty lane).
#[inline(always)]
fn accept(lo: f32, hi: f32) -> bool {
    lo - lo.abs() * SLACK <= hi + hi.abs() * SLACK
}

/// Asks the cache for the lines holding `bytes` bytes from `p` on.
///
/// Incoherent rays spend most of their time waiting for node and triangle
/// loads; fetching every hit child while the nearest is processed overlaps
/// those misses.
#[inline(always)]
fn prefetch<T>(p: &T, bytes: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = p as *const T as *const i8;
        let lines = ((p as usize & 63) + bytes).div_ceil(64);
        for k in 0..lines {
            // SAFETY: a prefetch is a hint that never faults, whatever the
            // address (`wrapping_add` keeps the pointer arithmetic defined).
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * k)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, bytes);
}

/// Per-thread traversal counts for the unit tests: wide nodes whose boxes
/// were tested, leaves visited, and the deepest the stack got. Mutations
/// that only slow the traversal down (a box test that accepts every box,
/// children visited farthest first) leave every answer right; these counts
/// make them visible. Compiled only into the unit tests: the renderer
/// pays nothing.
#[cfg(test)]
pub(super) mod stats {
    use std::cell::Cell;

    thread_local! {
        static NODES: Cell<u64> = const { Cell::new(0) };
        static LEAVES: Cell<u64> = const { Cell::new(0) };
        static MAX_STACK: Cell<usize> = const { Cell::new(0) };
    }

    pub(crate) fn node() {
        NODES.set(NODES.get() + 1);
    }
    pub(crate) fn leaf() {
        LEAVES.set(LEAVES.get() + 1);
    }
    pub(crate) fn stack(sp: usize) {
        MAX_STACK.set(MAX_STACK.get().max(sp));
    }
    /// (nodes, leaves, deepest stack) since the last call; resets them.
    pub(crate) fn take() -> (u64, u64, usize) {
        (NODES.replace(0), LEAVES.replace(0), MAX_STACK.replace(0))
    }
}

/// What a leaf visit asks of the traversal.
pub(super) enum Visit {
    Continue,
    Stop,
}

/// Visits every leaf whose box the ray meets within [tmin, *tmax], nearest
/// box first if `ORDERED`. `leaf(first, count, tmax)` may shrink `*tmax`
/// (nearest hit): boxes entered beyond it are then skipped, also when
/// popped from the stack. Returns true if a leaf asked to stop. `leaf_data`
/// is what leaves index (triangles), prefetched when a leaf's box is hit.
///
/// Queries that must visit every leaf on the segment anyway (all hits of a
/// probe ray) gain nothing from the order and skip sorting the children.
#[inline(always)]
pub(super) fn traverse<const ORDERED: bool, L>(
    tree: &Tree,
    leaf_data: &[L],
    ray: &RayBox,
    tmin: f32,
    tmax: &mut f32,
    mut leaf: impl FnMut(u32, u32, &mut f32) -> Visit,
) -> bool {
    if tree.is_empty() {
        return false;
    }
    if is_leaf(tree.root) {
        // A tree of one leaf: the top level of a one-mesh scene, or a
        // small mesh. (A root node needs no test of the whole box: its
        // children's boxes are tested next, and they make up that box.)
        if !ray.hit1(&tree.bounds, tmin, *tmax) {
            return false;
        }
        #[cfg(test)]
        stats::leaf();
        let (first, count) = leaf_range(tree.root);
        return matches!(leaf(first, count, tmax), Visit::Stop);
    }
    // Prefetching hides DRAM latency on trees too big for the caches; on
    // small ones it only costs its instructions (docs/performance.md, "The
    // BVH's triangle test", has the figure).
    let prefetching = tree.nodes.len() >= PREFETCH_NODES;
    // Left uninitialized: zeroing 2 KiB per traversal (two per query) costs
    // a measurable share of an incoherent ray (same section). Only entries
    // below `sp` are ever read.
    let mut stack: [MaybeUninit<(NodeRef, f32)>; STACK] = [const { MaybeUninit::uninit() }; STACK];
    let mut sp = 0usize;
    let mut r = tree.root;
    loop {
        // Descend from r to a leaf or a dead end.
        loop {
            if is_leaf(r) {
                #[cfg(test)]
                stats::leaf();
                let (first, count) = leaf_range(r);
                if let Visit::Stop = leaf(first, count, tmax) {
                    return true;
                }
                break;
            }
            let n = &tree.nodes[r as usize];
            #[cfg(test)]
            stats::node();
            let (t, mut hit) = ray.hit_w(n, tmin, *tmax);
            // Hit children, sorted nearest first (insertion sort) if ORDERED.
            let mut kids = [(0 as NodeRef, 0f32); WIDTH];
            let mut m = 0;
            while hit != 0 {
                let k = hit.trailing_zeros() as usize;
                hit &= hit - 1;
                let mut j = m;
                while ORDERED && j > 0 && kids[j - 1].1 > t[k] {
                    kids[j] = kids[j - 1];
                    j -= 1;
                }
                let c = n.child[k];
                kids[j] = (c, t[k]);
                m += 1;
                if prefetching {
                    if is_leaf(c) {
                        let (first, count) = leaf_range(c);
                        if let Some(d) = leaf_data.get(first as usize) {
                            prefetch(d, count as usize * std::mem::size_of::<L>());
                        }
                    } else {
                        prefetch(&tree.nodes[c as usize], std::mem::size_of::<NodeW>());
                    }
                }
            }
            if m == 0 {
                break;
            }
            // Push the far ones, farthest first, and go on with the nearest.
            for &(c, tc) in kids[1..m].iter().rev() {
                stack[sp] = MaybeUninit::new((c, tc));
                sp += 1;
            }
            #[cfg(test)]
            stats::stack(sp);
            r = kids[0].0;
        }
        // Pop the next box that still starts within the interval.
        loop {
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every entry below the old `sp` was written by a push.
            let (c, tc) = unsafe { stack[sp].assume_init() };
            if tc - tc.abs() * SLACK <= *tmax {
                r = c;
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use crate::sampling::Rng;

    /// The portable box test (what other architectures run) and the SSE
    /// one agree bit for bit — entry distances and masks — on random
    /// boxes, flat boxes, empty lanes, rays with zero direction components
    /// and origins lying exactly on box planes.
    #[test]
    fn portable_box_test_is_the_sse_test() {
        let mut rng = Rng::from_key(11);
        let mut u = |s: f32| (rng.uniform() * 2.0 - 1.0) * s;
        let mut accepted = 0;
        for case in 0..20_000 {
            let mut n = NodeW::EMPTY;
            for k in 0..WIDTH {
                if k == case % WIDTH {
                    continue; // one empty lane
                }
                for a in 0..3 {
                    let lo = u(1.0);
                    let hi = if case % 5 == 0 { lo } else { lo + u(1.0).abs() };
                    n.b[2 * a][k] = lo;
                    n.b[2 * a + 1][k] = hi;
                }
            }
            // aimed at a point of another lane's box (or its corner)
            let k = (case + 1 + case / WIDTH % (WIDTH - 1)) % WIDTH;
            let f = if case % 4 == 0 { 0.0 } else { 0.5 + u(0.5) };
            let target = Vec3::new(
                n.b[0][k] + f * (n.b[1][k] - n.b[0][k]),
                n.b[2][k] + f * (n.b[3][k] - n.b[2][k]),
                n.b[4][k] + f * (n.b[5][k] - n.b[4][k]),
            );
            let mut o = Vec3::new(u(2.0), u(2.0), u(2.0));
            let mut d = target - o;
            match case % 7 {
                0 => d.x = 0.0,
                1 => {
                    d.y = -0.0;
                    o.y = n.b[2][1]; // on a box's plane, parallel to it
                }
                2 => o.z = n.b[5][2],
                _ => {}
            }
            let ray = RayBox::new(&Ray::new(o, d));
            let (tmin, tmax) = if case % 3 == 0 {
                (0.0, f32::INFINITY)
            } else {
                (u(1.0).abs(), 1.0 + u(3.0).abs())
            };
            let (ts, ms) = ray.hit_w_sse(&n, tmin, tmax);
            let (tp, mp) = ray.hit_w_portable(&n, tmin, tmax);
            assert_eq!(ms, mp, "mask, case {case}");
            assert_eq!(ts.map(f32::to_bits), tp.map(f32::to_bits), "t, case {case}");
            assert_eq!(mp >> (case % WIDTH) & 1, 0, "empty lane hit");
            // each lane agrees with the scalar test of that box
            for k in 0..WIDTH {
                let b = [
                    [n.b[0][k], n.b[2][k], n.b[4][k]],
                    [n.b[1][k], n.b[3][k], n.b[5][k]],
                ];
                assert_eq!(
                    ray.hit1(&b, tmin, tmax),
                    mp >> k & 1 == 1,
                    "case {case} lane {k}"
                );
            }
            accepted += mp.count_ones();
        }
        // a comparison of all-miss masks would prove little
        assert!(accepted > 12_000, "{accepted} boxes hit");
    }
}
