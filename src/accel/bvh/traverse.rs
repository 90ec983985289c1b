//! Stack-based, front-to-back traversal of a [`Tree`](super::build::Tree)
//! with a robust ray/box slab test.
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

use super::build::{Node, Tree, STACK};
use crate::geometry::Ray;

/// Relative slack on the box interval: covers the ≤ 3 ulp error of each
/// slab distance (Ize 2013 uses 2γ₃ ≈ 3.6e-7) plus the rounding of the
/// triangle test's own t, with a wide margin; it costs nothing measurable.
const SLACK: f32 = 1.0 / (1 << 18) as f32;

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(super) struct RayBox {
    o: [f32; 3],
    inv: [f32; 3],
    /// 1 where the direction is negative: the near plane is then `b[1]`.
    near: [usize; 3],
}

impl RayBox {
    pub fn new(ray: &Ray) -> Self {
        let d = ray.d.to_array();
        RayBox {
            o: ray.o.to_array(),
            inv: d.map(|x| 1.0 / x),
            near: d.map(|x| x.is_sign_negative() as usize),
        }
    }

    /// Entry distance if the ray meets the node's box within [tmin, tmax].
    #[inline(always)]
    pub fn hit(&self, n: &Node, tmin: f32, tmax: f32) -> Option<f32> {
        let mut lo = tmin;
        let mut hi = tmax;
        for a in 0..3 {
            let tn = (n.b[self.near[a]][a] - self.o[a]) * self.inv[a];
            let tf = (n.b[1 - self.near[a]][a] - self.o[a]) * self.inv[a];
            // Comparisons are false for NaN, so NaN leaves lo/hi as they are.
            lo = if tn > lo { tn } else { lo };
            hi = if tf < hi { tf } else { hi };
        }
        // An infinite lo or hi makes one side NaN (∞ − ∞), which fails the
        // comparison: exactly the cases where the slab was missed.
        if lo - lo.abs() * SLACK <= hi + hi.abs() * SLACK {
            Some(lo)
        } else {
            None
        }
    }
}

/// What a leaf visit asks of the traversal.
pub(super) enum Visit {
    Continue,
    Stop,
}

/// Visits, nearest box first, every leaf whose box the ray meets within
/// [tmin, *tmax]. `leaf(first, count, tmax)` may shrink `*tmax` (nearest
/// hit): boxes entered beyond it are then skipped, also when popped from
/// the stack. Returns true if a leaf asked to stop.
#[inline(always)]
pub(super) fn traverse(
    tree: &Tree,
    ray: &RayBox,
    tmin: f32,
    tmax: &mut f32,
    mut leaf: impl FnMut(u32, u32, &mut f32) -> Visit,
) -> bool {
    if tree.pairs.is_empty() {
        return false;
    }
    let root = tree.node(0);
    if ray.hit(root, tmin, *tmax).is_none() {
        return false;
    }
    let mut stack_node = [0u32; STACK];
    let mut stack_t = [0f32; STACK];
    let mut sp = 0usize;
    let mut node = root;
    loop {
        if node.count > 0 {
            if let Visit::Stop = leaf(node.offset, node.count as u32, tmax) {
                return true;
            }
        } else {
            let c = node.offset;
            let pair = &tree.pairs[(c >> 1) as usize].0;
            let h0 = ray.hit(&pair[0], tmin, *tmax);
            let h1 = ray.hit(&pair[1], tmin, *tmax);
            match (h0, h1) {
                (Some(t0), Some(t1)) => {
                    let (near, far, tfar) = if t1 < t0 { (1, 0, t0) } else { (0, 1, t1) };
                    stack_node[sp] = c + far;
                    stack_t[sp] = tfar;
                    sp += 1;
                    node = &pair[near];
                    continue;
                }
                (Some(_), None) => {
                    node = &pair[0];
                    continue;
                }
                (None, Some(_)) => {
                    node = &pair[1];
                    continue;
                }
                (None, None) => {}
            }
        }
        // Pop the next box that still starts within the interval.
        loop {
            if sp == 0 {
                return false;
            }
            sp -= 1;
            if stack_t[sp] - stack_t[sp].abs() * SLACK <= *tmax {
                node = tree.node(stack_node[sp]);
                break;
            }
        }
    }
}
