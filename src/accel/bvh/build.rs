//! Binned SAH construction (Wald 2007, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies") into a flat array of 32-byte nodes.
//!
//! Primitives are binned by centroid into [`BINS`] bins per axis, the split
//! with the lowest surface area heuristic cost (Goldsmith & Salmon 1987;
//! MacDonald & Booth 1990) is taken, and a node becomes a leaf when that is
//! cheaper and it holds at most `max_leaf` primitives. Subtrees are built in
//! parallel with rayon, and the binning and bounds passes of big nodes are
//! split over threads too, since the top levels see every primitive.
//!
//! Layout: the two children of a node are stored side by side in one
//! 64-byte-aligned [`NodePair`] (one cache line), in depth-first order of
//! the pairs. Traversal tests both children's boxes of a node it enters,
//! which then costs one cache line rather than two.

use glam::Vec3;
use rayon::prelude::*;

/// Centroid bins per axis; 32 is the usual quality/speed point.
const BINS: usize = 32;
/// Cost of visiting a node relative to one triangle test (the pair of box
/// tests is cheaper than a watertight triangle test).
const TRAVERSAL_COST: f32 = 1.0;
/// Nodes with more primitives than this are built in parallel.
const PAR_SUBTREE: usize = 4096;
/// Nodes with more primitives than this also bin in parallel.
const PAR_BINNING: usize = 1 << 16;
/// Below this depth the SAH decides; deeper (only reached by pathological
/// inputs) nodes are halved by count, which bounds the depth by
/// `SAH_DEPTH + 32` and so the traversal stack.
const SAH_DEPTH: u32 = 64;
/// Traversal stack size: the deepest possible tree plus slack.
pub(super) const STACK: usize = 128;

/// A node: bounds, then either the index of its first child (`count == 0`;
/// the children are nodes `offset` and `offset + 1`) or the first of
/// `count` primitives in leaf order.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
pub(super) struct Node {
    pub b: [[f32; 3]; 2],
    pub offset: u32,
    pub count: u16,
    /// Split axis of an inner node, kept for debugging and statistics.
    pub axis: u16,
}

/// Two sibling nodes sharing a cache line.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(super) struct NodePair(pub [Node; 2]);

const _: () = assert!(std::mem::size_of::<Node>() == 32);
const _: () = assert!(std::mem::size_of::<NodePair>() == 64);

/// A built hierarchy: the root is node 0 (node 1 is padding so that sibling
/// pairs start at even indices); `order` maps leaf positions to the ids of
/// the primitives they reference.
#[derive(Clone, Debug, Default)]
pub(super) struct Tree {
    pub pairs: Vec<NodePair>,
    pub order: Vec<u32>,
}

impl Tree {
    #[inline(always)]
    pub fn node(&self, i: u32) -> &Node {
        &self.pairs[(i >> 1) as usize].0[(i & 1) as usize]
    }
    pub fn node_count(&self) -> usize {
        if self.pairs.is_empty() {
            0
        } else {
            2 * self.pairs.len() - 1
        }
    }
    /// Depth of the deepest leaf (the root has depth 0).
    pub fn depth(&self) -> usize {
        fn rec(t: &Tree, i: u32) -> usize {
            let n = t.node(i);
            if n.count > 0 {
                0
            } else {
                1 + rec(t, n.offset).max(rec(t, n.offset + 1))
            }
        }
        if self.pairs.is_empty() {
            0
        } else {
            rec(self, 0)
        }
    }
}

/// A primitive as the builder sees it: bounds, centroid, id.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrimRef {
    pub lo: Vec3,
    pub hi: Vec3,
    pub id: u32,
}

impl PrimRef {
    #[inline(always)]
    fn centroid(&self) -> Vec3 {
        (self.lo + self.hi) * 0.5
    }
}

#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: Vec3::splat(f32::INFINITY),
        hi: Vec3::splat(f32::NEG_INFINITY),
    };
    #[inline(always)]
    fn grow(&mut self, lo: Vec3, hi: Vec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }
    #[inline(always)]
    fn union(self, o: Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
    /// Half the surface area (the factor cancels in the SAH).
    #[inline(always)]
    fn half_area(&self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// Bounds of the primitives and of their centroids.
fn bounds(prims: &[PrimRef]) -> (Aabb, Aabb) {
    let serial = |ps: &[PrimRef]| {
        let mut b = Aabb::EMPTY;
        let mut c = Aabb::EMPTY;
        for p in ps {
            b.grow(p.lo, p.hi);
            let m = p.centroid();
            c.grow(m, m);
        }
        (b, c)
    };
    if prims.len() > PAR_BINNING {
        prims.par_chunks(PAR_BINNING / 4).map(serial).reduce(
            || (Aabb::EMPTY, Aabb::EMPTY),
            |a, b| (a.0.union(b.0), a.1.union(b.1)),
        )
    } else {
        serial(prims)
    }
}

/// Maps a centroid coordinate to its bin; shared by binning and
/// partitioning so that both agree exactly.
#[derive(Clone, Copy)]
struct Binner {
    lo: Vec3,
    scale: Vec3,
}

impl Binner {
    fn new(c: &Aabb) -> Self {
        let ext = c.hi - c.lo;
        // Slightly under BINS so the maximum lands in the last bin.
        let k = BINS as f32 * (1.0 - 1e-5);
        let scale = Vec3::select(ext.cmpgt(Vec3::ZERO), Vec3::splat(k) / ext, Vec3::ZERO);
        Binner { lo: c.lo, scale }
    }
    #[inline(always)]
    fn bin(&self, c: Vec3, axis: usize) -> usize {
        let b = ((c[axis] - self.lo[axis]) * self.scale[axis]) as usize;
        b.min(BINS - 1)
    }
}

#[derive(Clone, Copy)]
struct Bins {
    b: [[Aabb; BINS]; 3],
    n: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Self {
        Bins {
            b: [[Aabb::EMPTY; BINS]; 3],
            n: [[0; BINS]; 3],
        }
    }
    fn fill(binner: &Binner, prims: &[PrimRef]) -> Self {
        let mut s = Bins::new();
        for p in prims {
            let c = p.centroid();
            for a in 0..3 {
                let i = binner.bin(c, a);
                s.b[a][i].grow(p.lo, p.hi);
                s.n[a][i] += 1;
            }
        }
        s
    }
    fn merge(mut self, o: Bins) -> Bins {
        for a in 0..3 {
            for i in 0..BINS {
                self.b[a][i] = self.b[a][i].union(o.b[a][i]);
                self.n[a][i] += o.n[a][i];
            }
        }
        self
    }
}

/// Best SAH split: (cost, axis, number of bins on the left).
fn best_split(bins: &Bins, extent: Vec3) -> Option<(f32, usize, usize)> {
    let mut best: Option<(f32, usize, usize)> = None;
    for a in 0..3 {
        if extent[a] <= 0.0 {
            continue;
        }
        // right-to-left sweep: SAH term and count of bins [i, BINS)
        let mut right_cost = [0f32; BINS];
        let mut right_n = [0u32; BINS];
        let mut acc = Aabb::EMPTY;
        let mut n = 0u32;
        for i in (1..BINS).rev() {
            acc = acc.union(bins.b[a][i]);
            n += bins.n[a][i];
            right_cost[i] = acc.half_area() * n as f32;
            right_n[i] = n;
        }
        let mut acc = Aabb::EMPTY;
        let mut n = 0u32;
        for i in 1..BINS {
            acc = acc.union(bins.b[a][i - 1]);
            n += bins.n[a][i - 1];
            if n == 0 || right_n[i] == 0 {
                continue;
            }
            let cost = acc.half_area() * n as f32 + right_cost[i];
            if best.map_or(true, |b| cost < b.0) {
                best = Some((cost, a, i));
            }
        }
    }
    best
}

enum BuildNode {
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        axis: u32,
        kids: Box<[BuildNode; 2]>,
    },
}

fn build_rec(prims: &mut [PrimRef], first: usize, depth: u32, max_leaf: usize) -> BuildNode {
    let n = prims.len();
    let (bounds, cbounds) = bounds(prims);
    let leaf = BuildNode::Leaf {
        bounds,
        first: first as u32,
        count: n as u32,
    };
    if n <= 1 {
        return leaf;
    }
    let extent = cbounds.hi - cbounds.lo;
    let split = if depth < SAH_DEPTH && extent.max_element() > 0.0 {
        let binner = Binner::new(&cbounds);
        let bins = if n > PAR_BINNING {
            prims
                .par_chunks(PAR_BINNING / 4)
                .map(|c| Bins::fill(&binner, c))
                .reduce(Bins::new, Bins::merge)
        } else {
            Bins::fill(&binner, prims)
        };
        best_split(&bins, extent).map(|(cost, axis, nb)| (cost, axis, nb, binner))
    } else {
        None
    };
    let (mid, axis) = match split {
        Some((cost, axis, nb, binner)) => {
            let leaf_cost = n as f32 * bounds.half_area();
            let split_cost = TRAVERSAL_COST * bounds.half_area() + cost;
            if n <= max_leaf && leaf_cost <= split_cost {
                return leaf;
            }
            let mid = partition(prims, |p| binner.bin(p.centroid(), axis) < nb);
            debug_assert!(mid > 0 && mid < n);
            (mid, axis)
        }
        None => {
            if n <= max_leaf {
                return leaf;
            }
            // Coincident centroids or too deep: halve by count.
            (n / 2, extent.max_position())
        }
    };
    let (l, r) = prims.split_at_mut(mid);
    let (a, b) = if n > PAR_SUBTREE {
        rayon::join(
            || build_rec(l, first, depth + 1, max_leaf),
            || build_rec(r, first + mid, depth + 1, max_leaf),
        )
    } else {
        (
            build_rec(l, first, depth + 1, max_leaf),
            build_rec(r, first + mid, depth + 1, max_leaf),
        )
    };
    BuildNode::Inner {
        bounds,
        axis: axis as u32,
        kids: Box::new([a, b]),
    }
}

/// In-place partition; returns the number of elements satisfying `left`.
fn partition(prims: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    let mut i = 0;
    let mut j = prims.len();
    loop {
        while i < j && left(&prims[i]) {
            i += 1;
        }
        while i < j && !left(&prims[j - 1]) {
            j -= 1;
        }
        if i >= j {
            return i;
        }
        prims.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}

fn flat_node(b: &BuildNode) -> Node {
    match b {
        BuildNode::Leaf {
            bounds,
            first,
            count,
        } => Node {
            b: [bounds.lo.to_array(), bounds.hi.to_array()],
            offset: *first,
            count: *count as u16,
            axis: 0,
        },
        BuildNode::Inner { bounds, axis, .. } => Node {
            b: [bounds.lo.to_array(), bounds.hi.to_array()],
            offset: 0,
            count: 0,
            axis: *axis as u16,
        },
    }
}

/// Writes the children of the inner node at `at` (already placed) and,
/// depth first, their subtrees.
fn flatten(b: &BuildNode, at: u32, pairs: &mut Vec<NodePair>) {
    if let BuildNode::Inner { kids, .. } = b {
        let p = pairs.len() as u32;
        pairs.push(NodePair([flat_node(&kids[0]), flat_node(&kids[1])]));
        pairs[(at >> 1) as usize].0[(at & 1) as usize].offset = 2 * p;
        flatten(&kids[0], 2 * p, pairs);
        flatten(&kids[1], 2 * p + 1, pairs);
    }
}

/// Builds a hierarchy over `prims` (whose bounds must be finite) with
/// leaves of at most `max_leaf` primitives (at most `u16::MAX`).
pub(super) fn build(mut prims: Vec<PrimRef>, max_leaf: usize) -> Tree {
    assert!((1..=u16::MAX as usize).contains(&max_leaf));
    if prims.is_empty() {
        return Tree::default();
    }
    let root = build_rec(&mut prims, 0, 0, max_leaf);
    let mut pairs = Vec::with_capacity(prims.len() / 2 + 1);
    pairs.push(NodePair([flat_node(&root), Node::default()]));
    flatten(&root, 0, &mut pairs);
    Tree {
        pairs,
        order: prims.iter().map(|p| p.id).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn random_prims(n: usize, seed: u64) -> Vec<PrimRef> {
        let mut rng = Rng::from_key(seed);
        (0..n as u32)
            .map(|id| {
                let c = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                let e = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 0.05;
                PrimRef {
                    lo: c - e,
                    hi: c + e,
                    id,
                }
            })
            .collect()
    }

    /// Every node bounds its subtree, every leaf its primitives, and every
    /// primitive is referenced by exactly one leaf.
    fn check(tree: &Tree, prims: &[PrimRef], max_leaf: usize) {
        let mut seen = vec![0u32; prims.len()];
        let contains = |n: &Node, lo: Vec3, hi: Vec3| {
            Vec3::from(n.b[0]).cmple(lo).all() && Vec3::from(n.b[1]).cmpge(hi).all()
        };
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let n = tree.node(i);
            if n.count > 0 {
                assert!(n.count as usize <= max_leaf);
                for k in n.offset..n.offset + n.count as u32 {
                    let id = tree.order[k as usize];
                    seen[id as usize] += 1;
                    let p = &prims[id as usize];
                    assert!(contains(n, p.lo, p.hi));
                }
            } else {
                assert_eq!(n.offset % 2, 0);
                for c in [n.offset, n.offset + 1] {
                    let k = tree.node(c);
                    assert!(contains(n, Vec3::from(k.b[0]), Vec3::from(k.b[1])));
                    stack.push(c);
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn random_boxes_build_a_valid_tree() {
        for (n, seed) in [(1, 1), (2, 2), (7, 3), (1000, 4), (100_000, 5)] {
            let prims = random_prims(n, seed);
            let tree = build(prims.clone(), 8);
            check(&tree, &prims, 8);
            if n == 100_000 {
                // SAH trees on uniform data are near balanced.
                assert!(tree.depth() < 40, "depth {}", tree.depth());
            }
        }
    }

    #[test]
    fn coincident_boxes_are_halved_into_small_leaves() {
        let p = PrimRef {
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            id: 0,
        };
        let prims: Vec<PrimRef> = (0..1000).map(|id| PrimRef { id, ..p }).collect();
        let tree = build(prims.clone(), 4);
        check(&tree, &prims, 4);
        assert!(tree.depth() <= 10);
    }

    #[test]
    fn pathological_spacing_keeps_the_depth_bounded() {
        // Geometrically spaced centroids make every SAH split peel off one
        // primitive; the depth cap must kick in.
        let prims: Vec<PrimRef> = (0..3000u32)
            .map(|id| {
                let x = 1.01f32.powi(id as i32);
                PrimRef {
                    lo: Vec3::new(x, 0.0, 0.0),
                    hi: Vec3::new(x, 1.0, 1.0),
                    id,
                }
            })
            .collect();
        let tree = build(prims.clone(), 1);
        check(&tree, &prims, 1);
        assert!(tree.depth() < STACK - 1, "depth {}", tree.depth());
    }
}
