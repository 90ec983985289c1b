//! Binned SAH construction (Wald 2007, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies"), collapsed into an 8-wide tree.
//!
//! Primitives are binned by centroid into [`BINS`] bins per axis, the split
//! with the lowest surface area heuristic cost (Goldsmith & Salmon 1987;
//! MacDonald & Booth 1990) is taken, and a node becomes a leaf when that is
//! cheaper and it holds at most `max_leaf` primitives. Subtrees are built in
//! parallel with rayon, and the binning and bounds passes of big nodes are
//! split over threads too, since the top levels see every primitive.
//!
//! The binary tree is then collapsed into a [`WIDTH`]-wide one (each node
//! adopts the children of its largest inner children until it has
//! `WIDTH`, as in Wald et al. 2008, "Getting Rid of Packets"), stored as
//! 256-byte [`NodeW`]s (four cache lines, fetched together) holding their
//! children's boxes in structure-of-arrays form, tested four at a time with
//! SSE. Incoherent rays on a million triangles wait mostly on cache
//! misses, one per level, so a shallower tree is a faster one
//! (docs/performance.md, "The BVH's triangle test", for 4- against 8-wide).

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// Centroid bins per axis for big nodes; 32 is the usual quality/speed
/// point. Small nodes use one bin per primitive (at least [`MIN_BINS`]):
/// the sweep over the bins costs as much as binning 32 primitives, and
/// most nodes of a tree are small, so 32 bins everywhere spent a third of
/// the build sweeping mostly empty bins.
const BINS: usize = 32;
const MIN_BINS: usize = 8;
/// Cost of visiting a node relative to testing one block of primitives
/// (an 8-box SSE test against a 4-triangle SSE test: about the same).
const TRAVERSAL_COST: f32 = 1.0;
/// Nodes with more primitives than this are built in parallel.
const PAR_SUBTREE: usize = 4096;
/// Nodes with more primitives than this also bin in parallel.
const PAR_BINNING: usize = 1 << 16;
/// Below this depth the SAH decides; deeper (only reached by pathological
/// inputs) nodes are halved by count, which bounds the depth by
/// `SAH_DEPTH + 32` and so the traversal stack.
const SAH_DEPTH: u32 = 64;
/// The deepest a tree can be: SAH levels, then halvings of at most 2^28.
pub(super) const MAX_DEPTH: usize = SAH_DEPTH as usize + 28;

/// A reference to a child: an inner node's index, or (high bit set) a
/// leaf's first primitive in leaf order and its count.
pub(super) type NodeRef = u32;
const LEAF_BIT: u32 = 1 << 31;
const COUNT_SHIFT: u32 = 28;
/// Leaves reference at most this many primitives (3 bits of count).
pub(super) const MAX_LEAF_COUNT: usize = 8;
/// Primitives per tree are limited by the 28 bits of a leaf's offset.
pub(super) const MAX_PRIMS: usize = 1 << COUNT_SHIFT;

#[inline(always)]
pub(super) fn is_leaf(r: NodeRef) -> bool {
    r & LEAF_BIT != 0
}
/// (first, count) of a leaf reference.
#[inline(always)]
pub(super) fn leaf_range(r: NodeRef) -> (u32, u32) {
    (r & (MAX_PRIMS as u32 - 1), ((r >> COUNT_SHIFT) & 7) + 1)
}
fn leaf_ref(first: u32, count: u32) -> NodeRef {
    debug_assert!((1..=MAX_LEAF_COUNT as u32).contains(&count) && (first as usize) < MAX_PRIMS);
    LEAF_BIT | (count - 1) << COUNT_SHIFT | first
}

/// A wide node: the boxes of up to [`WIDTH`] children as rows
/// `[lo.x, hi.x, lo.y, hi.y, lo.z, hi.z]` of `WIDTH` lanes each, and their
/// references. Unused lanes hold an empty box (lo = +∞, hi = −∞), which
/// every ray misses, so traversal needs no child count.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct NodeW {
    pub b: [[f32; WIDTH]; 6],
    pub child: [NodeRef; WIDTH],
}

/// Children per node.
pub(super) const WIDTH: usize = 8;
const _: () = assert!(std::mem::size_of::<NodeW>().is_multiple_of(64));

impl NodeW {
    pub(super) const EMPTY: NodeW = NodeW {
        b: [
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        child: [0; WIDTH],
    };
}

/// A built hierarchy: `root` (whose box is `bounds`) references node 0 or
/// is a single leaf. Leaves reference blocks of slots; `order`
/// maps slots to primitive ids, with [`PAD`] in the slots that fill a
/// leaf's last block.
#[derive(Clone, Debug, Default)]
pub(super) struct Tree {
    pub nodes: Vec<NodeW>,
    pub root: NodeRef,
    pub bounds: [[f32; 3]; 2],
    pub order: Vec<u32>,
}

/// The primitive id of an unused slot.
pub(super) const PAD: u32 = u32::MAX;

impl Tree {
    /// No primitives. (Not `order.is_empty()`: a mesh's tree hands its
    /// order over to the triangle packets.)
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty() && !is_leaf(self.root)
    }
    /// Depth of the deepest leaf (a root leaf has depth 0).
    pub fn depth(&self) -> usize {
        fn rec(t: &Tree, r: NodeRef) -> usize {
            if is_leaf(r) {
                return 0;
            }
            let n = &t.nodes[r as usize];
            (0..WIDTH)
                .filter(|&k| n.b[0][k] <= n.b[1][k])
                .map(|k| 1 + rec(t, n.child[k]))
                .max()
                .unwrap_or(0)
        }
        if self.is_empty() {
            0
        } else {
            rec(self, self.root)
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
    fn centroid(&self) -> Vec3A {
        (Vec3A::from(self.lo) + Vec3A::from(self.hi)) * 0.5
    }
    #[inline(always)]
    fn bounds(&self) -> Aabb {
        Aabb {
            lo: self.lo.into(),
            hi: self.hi.into(),
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Aabb {
    // SIMD vectors: growing the bins' boxes is most of the build.
    lo: Vec3A,
    hi: Vec3A,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: Vec3A::splat(f32::INFINITY),
        hi: Vec3A::splat(f32::NEG_INFINITY),
    };
    #[inline(always)]
    fn grow(&mut self, b: Aabb) {
        self.lo = self.lo.min(b.lo);
        self.hi = self.hi.max(b.hi);
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
        let e = (self.hi - self.lo).max(Vec3A::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// Bounds of the primitives and of their centroids.
fn bounds(prims: &[PrimRef]) -> (Aabb, Aabb) {
    let serial = |ps: &[PrimRef]| {
        let mut b = Aabb::EMPTY;
        let mut c = Aabb::EMPTY;
        for p in ps {
            b.grow(p.bounds());
            let m = p.centroid();
            c.grow(Aabb { lo: m, hi: m });
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
    lo: Vec3A,
    scale: Vec3A,
    /// Bins in use, ≤ [`BINS`].
    count: usize,
}

impl Binner {
    fn new(c: &Aabb, prims: usize) -> Self {
        let count = prims.clamp(MIN_BINS, BINS);
        let ext = c.hi - c.lo;
        // Slightly under `count` so the maximum lands in the last bin.
        let k = count as f32 * (1.0 - 1e-5);
        let scale = Vec3A::select(ext.cmpgt(Vec3A::ZERO), Vec3A::splat(k) / ext, Vec3A::ZERO);
        Binner {
            lo: c.lo,
            scale,
            count,
        }
    }
    /// The bin of centroid `c` along each axis, computed for all three at
    /// once (the binning loop needs all three; a per-axis `Vec3A` index is
    /// a branchy match).
    #[inline(always)]
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        let f = (c - self.lo) * self.scale;
        // Truncation in one instruction; Rust's saturating `as` casts cost
        // more than the rest of the binning. Out-of-range lanes (not
        // expected: centroids lie in the bounds the scale came from) give
        // i32::MIN and are clamped like any other.
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of the x86_64 baseline; the conversion is a
        // plain register operation.
        let i: [i32; 4] = unsafe {
            use std::arch::x86_64::{__m128, _mm_cvttps_epi32};
            std::mem::transmute(_mm_cvttps_epi32(__m128::from(f)))
        };
        #[cfg(not(target_arch = "x86_64"))]
        let i = f.to_array().map(|x| x as i32);
        [0, 1, 2].map(|a| (i[a].max(0) as usize).min(self.count - 1))
    }
    #[inline(always)]
    fn bin(&self, c: Vec3A, axis: usize) -> usize {
        self.bins(c)[axis]
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
            let b = p.bounds();
            for (a, i) in binner.bins(p.centroid()).into_iter().enumerate() {
                s.b[a][i].grow(b);
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

/// Blocks needed for `n` primitives: the SAH counts leaf cost per block,
/// since a block is tested at once (Wald et al. 2008 do the same for
/// 4-triangle leaves), which favours leaves that fill their blocks.
#[inline(always)]
fn blocks(n: u32, block: u32) -> f32 {
    n.div_ceil(block) as f32
}

/// Best SAH split: (cost, axis, number of bins on the left).
fn best_split(bins: &Bins, count: usize, extent: Vec3A, block: u32) -> Option<(f32, usize, usize)> {
    let mut best: Option<(f32, usize, usize)> = None;
    for a in 0..3 {
        if extent[a] <= 0.0 {
            continue;
        }
        // right-to-left sweep: SAH term and count of bins [i, count)
        let mut right_cost = [0f32; BINS];
        let mut right_n = [0u32; BINS];
        let mut acc = Aabb::EMPTY;
        let mut n = 0u32;
        for i in (1..count).rev() {
            acc = acc.union(bins.b[a][i]);
            n += bins.n[a][i];
            right_cost[i] = acc.half_area() * blocks(n, block);
            right_n[i] = n;
        }
        let mut acc = Aabb::EMPTY;
        let mut n = 0u32;
        for i in 1..count {
            acc = acc.union(bins.b[a][i - 1]);
            n += bins.n[a][i - 1];
            if n == 0 || right_n[i] == 0 {
                continue;
            }
            let cost = acc.half_area() * blocks(n, block) + right_cost[i];
            if best.is_none_or(|b| cost < b.0) {
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
        /// First slot in the padded order (set after the build).
        slot: u32,
    },
    Inner {
        bounds: Aabb,
        kids: Box<[BuildNode; 2]>,
    },
}

/// What is fixed for a whole build.
#[derive(Clone, Copy)]
struct Params {
    max_leaf: usize,
    block: u32,
}

fn build_rec(prims: &mut [PrimRef], first: usize, depth: u32, par: Params) -> BuildNode {
    let n = prims.len();
    let (bounds, cbounds) = bounds(prims);
    let leaf = BuildNode::Leaf {
        bounds,
        first: first as u32,
        count: n as u32,
        slot: 0,
    };
    // One block is always a leaf: a split would cost a traversal step
    // plus at least as many block tests.
    if n <= 1 || n <= (par.block as usize).min(par.max_leaf) {
        return leaf;
    }
    let extent = cbounds.hi - cbounds.lo;
    let split = if depth < SAH_DEPTH && extent.max_element() > 0.0 {
        let binner = Binner::new(&cbounds, n);
        let bins = if n > PAR_BINNING {
            prims
                .par_chunks(PAR_BINNING / 4)
                .map(|c| Bins::fill(&binner, c))
                .reduce(Bins::new, Bins::merge)
        } else {
            Bins::fill(&binner, prims)
        };
        best_split(&bins, binner.count, extent, par.block)
            .map(|(cost, axis, nb)| (cost, axis, nb, binner))
    } else {
        None
    };
    let mid = match split {
        Some((cost, axis, nb, binner)) => {
            let leaf_cost = blocks(n as u32, par.block) * bounds.half_area();
            let split_cost = TRAVERSAL_COST * bounds.half_area() + cost;
            if n <= par.max_leaf && leaf_cost <= split_cost {
                return leaf;
            }
            let mid = partition(prims, |p| binner.bin(p.centroid(), axis) < nb);
            debug_assert!(mid > 0 && mid < n);
            mid
        }
        None => {
            if n <= par.max_leaf {
                return leaf;
            }
            // Coincident centroids or too deep: halve by count.
            n / 2
        }
    };
    let (l, r) = prims.split_at_mut(mid);
    let (a, b) = if n > PAR_SUBTREE {
        rayon::join(
            || build_rec(l, first, depth + 1, par),
            || build_rec(r, first + mid, depth + 1, par),
        )
    } else {
        (
            build_rec(l, first, depth + 1, par),
            build_rec(r, first + mid, depth + 1, par),
        )
    };
    BuildNode::Inner {
        bounds,
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

impl BuildNode {
    fn bounds(&self) -> &Aabb {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Inner { bounds, .. } => bounds,
        }
    }
}

/// Gives each leaf its first slot, in primitive order (left subtrees hold
/// the lower primitives), rounding each leaf up to whole blocks; returns
/// the slot after the last.
fn assign_slots(b: &mut BuildNode, next: u32, block: u32) -> u32 {
    match b {
        BuildNode::Leaf { count, slot, .. } => {
            *slot = next;
            next + count.div_ceil(block) * block
        }
        BuildNode::Inner { kids, .. } => {
            let [l, r] = &mut **kids;
            let next = assign_slots(l, next, block);
            assign_slots(r, next, block)
        }
    }
}

/// Collapses the binary subtree `b` into wide nodes appended to `nodes`
/// (parents before children) and returns its reference.
fn collapse(b: &BuildNode, block: u32, nodes: &mut Vec<NodeW>) -> NodeRef {
    let kids = match b {
        BuildNode::Leaf { count, slot, .. } => {
            return leaf_ref(slot / block, count.div_ceil(block));
        }
        BuildNode::Inner { kids, .. } => kids,
    };
    let mut adopt: Vec<&BuildNode> = vec![&kids[0], &kids[1]];
    // Open the inner child with the largest area until there are WIDTH:
    // big boxes are the ones most rays enter.
    while adopt.len() < WIDTH {
        let open = adopt
            .iter()
            .enumerate()
            .filter(|(_, k)| matches!(k, BuildNode::Inner { .. }))
            .max_by(|a, b| {
                a.1.bounds()
                    .half_area()
                    .total_cmp(&b.1.bounds().half_area())
            })
            .map(|(i, _)| i);
        let Some(i) = open else { break };
        let BuildNode::Inner { kids, .. } = adopt[i] else {
            unreachable!()
        };
        adopt[i] = &kids[0];
        adopt.push(&kids[1]);
    }
    let at = nodes.len();
    nodes.push(NodeW::EMPTY);
    let mut node = NodeW::EMPTY;
    for (k, kid) in adopt.iter().enumerate() {
        let bb = kid.bounds();
        for a in 0..3 {
            node.b[2 * a][k] = bb.lo[a];
            node.b[2 * a + 1][k] = bb.hi[a];
        }
        node.child[k] = collapse(kid, block, nodes);
    }
    nodes[at] = node;
    at as NodeRef
}

/// Builds a hierarchy over `prims` (whose bounds must be finite) with
/// leaves of at most `max_leaf` primitives in blocks of `block`; a leaf
/// reference counts blocks (at most [`MAX_LEAF_COUNT`]).
pub(super) fn build(mut prims: Vec<PrimRef>, max_leaf: usize, block: usize) -> Tree {
    assert!(block >= 1 && (1..=MAX_LEAF_COUNT * block).contains(&max_leaf));
    assert!(
        prims.len() <= MAX_PRIMS,
        "more than 2^28 triangles in one mesh"
    );
    if prims.is_empty() {
        return Tree::default();
    }
    let par = Params {
        max_leaf,
        block: block as u32,
    };
    let mut root = build_rec(&mut prims, 0, 0, par);
    let slots = assign_slots(&mut root, 0, par.block) as usize;
    assert!(slots <= MAX_PRIMS, "more than 2^28 slots in one tree");
    let mut order = vec![PAD; slots];
    let mut tmp = Vec::with_capacity(prims.len() / 4 + 1);
    let root_ref = collapse(&root, par.block, &mut tmp);
    fill_order(&root, &prims, &mut order);
    // Copied once more into an exactly sized, huge-page-backed array.
    let mut nodes = super::mem::with_huge_pages(tmp.len());
    nodes.extend_from_slice(&tmp);
    let bb = root.bounds();
    Tree {
        nodes,
        root: root_ref,
        bounds: [bb.lo.to_array(), bb.hi.to_array()],
        order,
    }
}

/// Writes each leaf's primitive ids into its slots.
fn fill_order(b: &BuildNode, prims: &[PrimRef], order: &mut [u32]) {
    match b {
        BuildNode::Leaf {
            first, count, slot, ..
        } => {
            let src = &prims[*first as usize..(*first + *count) as usize];
            for (dst, p) in order[*slot as usize..].iter_mut().zip(src) {
                *dst = p.id;
            }
        }
        BuildNode::Inner { kids, .. } => {
            fill_order(&kids[0], prims, order);
            fill_order(&kids[1], prims, order);
        }
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
    fn check(tree: &Tree, prims: &[PrimRef], max_leaf: usize, block: usize) {
        let mut seen = vec![0u32; prims.len()];
        let inside =
            |lo: Vec3, hi: Vec3, blo: Vec3, bhi: Vec3| blo.cmple(lo).all() && bhi.cmpge(hi).all();
        let root = (Vec3::from(tree.bounds[0]), Vec3::from(tree.bounds[1]));
        let mut stack = vec![(tree.root, root)];
        while let Some((r, (blo, bhi))) = stack.pop() {
            if is_leaf(r) {
                let (first, count) = leaf_range(r);
                let b = block as u32;
                let ids: Vec<u32> = (first * b..(first + count) * b)
                    .map(|k| tree.order[k as usize])
                    .collect();
                let used = ids.iter().take_while(|&&id| id != PAD).count();
                // Padding only fills the last block.
                assert!(ids[used..].iter().all(|&id| id == PAD));
                assert!(used > (count - 1) as usize * b as usize);
                assert!(used <= max_leaf);
                for &id in &ids[..used] {
                    seen[id as usize] += 1;
                    let p = &prims[id as usize];
                    assert!(inside(p.lo, p.hi, blo, bhi));
                }
            } else {
                let n = &tree.nodes[r as usize];
                let mut used = 0;
                for k in 0..WIDTH {
                    let lo = Vec3::new(n.b[0][k], n.b[2][k], n.b[4][k]);
                    let hi = Vec3::new(n.b[1][k], n.b[3][k], n.b[5][k]);
                    if lo.x > hi.x {
                        continue;
                    }
                    used += 1;
                    assert!(inside(lo, hi, blo, bhi));
                    stack.push((n.child[k], (lo, hi)));
                }
                assert!(used >= 2);
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn random_boxes_build_a_valid_tree() {
        for (n, seed) in [(1, 1), (2, 2), (7, 3), (1000, 4), (100_000, 5)] {
            let prims = random_prims(n, seed);
            let tree = build(prims.clone(), 8, 1);
            check(&tree, &prims, 8, 1);
            let tree = build(prims.clone(), 8, 4);
            check(&tree, &prims, 8, 4);
            if n == 100_000 {
                // SAH trees on uniform data are near balanced.
                assert!(tree.depth() < 40, "depth {}", tree.depth());
            }
        }
    }

    #[test]
    fn block_leaves_fill_their_blocks() {
        let prims = random_prims(50_000, 9);
        let tree = build(prims.clone(), 8, 4);
        check(&tree, &prims, 8, 4);
        // The block-counting SAH leaves little padding: most leaves hold 4
        // or 8 primitives.
        let pads = tree.order.iter().filter(|&&id| id == PAD).count();
        assert!(pads * 5 < prims.len(), "{pads} padding slots");
        assert_eq!(tree.order.len() % 4, 0);
    }

    #[test]
    fn coincident_boxes_are_halved_into_small_leaves() {
        let p = PrimRef {
            lo: Vec3::ZERO,
            hi: Vec3::ONE,
            id: 0,
        };
        let prims: Vec<PrimRef> = (0..1000).map(|id| PrimRef { id, ..p }).collect();
        let tree = build(prims.clone(), 4, 1);
        check(&tree, &prims, 4, 1);
        assert!(tree.depth() <= 10);
    }

    #[test]
    fn half_area_is_half_the_surface_area() {
        let b = Aabb {
            lo: Vec3A::new(-1.0, 2.0, 0.5),
            hi: Vec3A::new(0.0, 4.0, 3.5),
        };
        // sides 1, 2, 3: 1·2 + 2·3 + 3·1
        assert_eq!(b.half_area(), 11.0);
        assert_eq!(Aabb::EMPTY.half_area(), 0.0);
    }

    /// The SAH decides leaf against split for small sets: two boxes far
    /// apart are split (a leaf costs 2 · 203 in half areas, a split
    /// 1 · 203 + 3 + 3), four boxes nearly on top of each other stay one
    /// leaf (4 · 3.006 against 3.006 + 2 · 3.0 + 2 · 3.0).
    #[test]
    fn the_sah_splits_distant_boxes_and_keeps_overlapping_ones_together() {
        let unit = |x: f32, id: u32| PrimRef {
            lo: Vec3::new(x, 0.0, 0.0),
            hi: Vec3::new(x + 1.0, 1.0, 1.0),
            id,
        };
        let far = vec![unit(0.0, 0), unit(100.0, 1)];
        let tree = build(far.clone(), 8, 1);
        check(&tree, &far, 8, 1);
        assert!(!is_leaf(tree.root), "two distant boxes in one leaf");
        let near: Vec<PrimRef> = (0..4).map(|i| unit(0.001 * i as f32, i)).collect();
        let tree = build(near.clone(), 8, 1);
        check(&tree, &near, 8, 1);
        assert!(is_leaf(tree.root), "four overlapping boxes split");
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
        let tree = build(prims.clone(), 1, 1);
        check(&tree, &prims, 1, 1);
        assert!(tree.depth() <= MAX_DEPTH, "depth {}", tree.depth());
    }
}
