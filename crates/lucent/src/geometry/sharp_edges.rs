//! Sharp edges of a subsurface mesh, and how far an exit point is from the
//! nearest one: what the probe-axis rule reads where shading normals cannot
//! show the surface turning. The rule κ_axes(xo) = max(κ(triangle),
//! 1/s(xo)), s the distance to the nearest sharp edge within Rmax; which
//! edges are sharp, the bound of s and the query: `docs/bssrdf.md` §5,
//! "Sharp edges"; measurements: `docs/accuracy.md`, "Sharp edges and thin
//! bodies".

use crate::geometry::{Mesh, Vec3};

/// Shading normals meeting at a larger angle than this across an edge make
/// it sharp. A flat-shaded sphere of 20,480 triangles turns ~2.5° per
/// edge (not sharp: its 1/R floor and its size speak for it); a box turns
/// 90°, a regular icosahedron 41.8°.
pub(crate) const SHARP_ANGLE_DEG: f32 = 30.0;

/// Most segments in a leaf of the tree.
pub(crate) const LEAF: usize = 4;

/// One mesh's sharp edges, in a tree for nearest-distance queries.
#[derive(Clone, Debug)]
pub struct SharpEdges {
    segments: Vec<[Vec3; 2]>,
    nodes: Vec<Node>,
}

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: segments `first .. first + count`; inner (count = 0): children
    /// `first` and `first + 1`.
    first: u32,
    count: u32,
}

/// Positions as keys: bit patterns, with −0 read as +0.
fn key(p: Vec3) -> [u32; 3] {
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

/// Vertices welded by position: per vertex, the rank of its position's
/// key among the distinct keys (equal positions, equal ids).
pub(crate) fn weld(pos: &[Vec3]) -> Vec<u32> {
    let mut by_key: Vec<u32> = (0..pos.len() as u32).collect();
    by_key.sort_unstable_by_key(|&v| key(pos[v as usize]));
    let mut id = vec![0u32; pos.len()];
    let mut next = 0u32;
    for (r, &v) in by_key.iter().enumerate() {
        if r > 0 && key(pos[v as usize]) != key(pos[by_key[r - 1] as usize]) {
            next += 1;
        }
        id[v as usize] = next;
    }
    id
}

/// The sharp edges of `mesh` (module docs): each once, as its two end
/// points, lower position key first, in the order of their keys.
///
/// Vertices are first welded by position (a sort of the vertex keys), so an
/// edge is a pair of small ids; the triangles' edges, 16 bytes each, are
/// then sorted so that the triangles of one edge lie together. No map and
/// no allocation per edge: on a 1,310,720-triangle sphere this pass takes
/// a fraction of a second and a transient ~63 MB.
pub fn sharp_edges(mesh: &Mesh) -> Vec<[Vec3; 2]> {
    let cos_sharp = SHARP_ANGLE_DEG.to_radians().cos();
    let pos = mesh.positions();
    let id = weld(pos);
    /// One triangle's side: the edge (lower id, higher id) and the
    /// triangle's corners at those two ends.
    #[derive(Clone, Copy)]
    struct Side {
        edge: u64,
        prim: u32,
        ends: [u8; 2],
    }
    let mut sides = Vec::with_capacity(3 * mesh.triangle_count());
    for (prim, idx) in mesh.indices.iter().enumerate() {
        for (i, j) in [(0u8, 1u8), (1, 2), (2, 0)] {
            let (a, b) = (id[idx[i as usize] as usize], id[idx[j as usize] as usize]);
            if a == b {
                continue; // a degenerate edge
            }
            let (ends, lo, hi) = if a < b {
                ([i, j], a, b)
            } else {
                ([j, i], b, a)
            };
            sides.push(Side {
                edge: (lo as u64) << 32 | hi as u64,
                prim: prim as u32,
                ends,
            });
        }
    }
    sides.sort_unstable_by_key(|s| (s.edge, s.prim, s.ends));
    // the shading normal of triangle `prim` at its corner `c`
    let normal = |prim: u32, c: u8| match &mesh.normals {
        Some(ns) => ns[mesh.indices[prim as usize][c as usize] as usize].normalize_or_zero(),
        None => mesh.face_normal(prim),
    };
    sides
        .chunk_by(|a, b| a.edge == b.edge)
        .filter(|group| match group {
            [_] => false,
            [s, t] => {
                (0..2).any(|e| normal(s.prim, s.ends[e]).dot(normal(t.prim, t.ends[e])) < cos_sharp)
            }
            _ => true,
        })
        .map(|group| {
            let (s, idx) = (group[0], mesh.indices[group[0].prim as usize]);
            s.ends.map(|c| pos[idx[c as usize] as usize])
        })
        .collect()
}

/// Distance from `p` to the segment `[a, b]`.
fn point_segment_distance(p: Vec3, [a, b]: [Vec3; 2]) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + t * ab)).length()
}

/// Distance from `p` to the box `[lo, hi]` (0 inside).
fn point_box_distance(p: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length()
}

impl SharpEdges {
    /// The tree over `mesh`'s sharp edges; None when it has none.
    pub fn new(mesh: &Mesh) -> Option<Self> {
        Self::from_segments(sharp_edges(mesh))
    }

    /// The tree over `segments`; None when there are none.
    pub(crate) fn from_segments(mut segments: Vec<[Vec3; 2]>) -> Option<Self> {
        if segments.is_empty() {
            return None;
        }
        let mut nodes = vec![Node {
            lo: Vec3::ZERO,
            hi: Vec3::ZERO,
            first: 0,
            count: 0,
        }];
        let n = segments.len();
        build(&mut segments, 0, n, 0, &mut nodes);
        Some(SharpEdges { segments, nodes })
    }

    /// How many sharp edges the tree holds (at least 1: an empty set has
    /// no tree, [`SharpEdges::new`]).
    pub fn count(&self) -> usize {
        self.segments.len()
    }

    /// The distance from `p` to the nearest sharp edge, or `reach` if none
    /// is nearer.
    #[inline]
    pub fn distance(&self, p: Vec3, reach: f32) -> f32 {
        self.nearest(p, reach, 0.0).0
    }

    /// The distance from `p` to the nearest sharp edge, or `reach` if none
    /// is nearer — or, once an edge within `enough` is found, that edge's
    /// distance (≤ `enough`, not necessarily the nearest); and how many
    /// nodes the query opened (the tree's quality, which tests bound: a
    /// badly split tree answers the same, only slower). The nearer child
    /// is opened first, so the bound tightens early.
    pub fn nearest(&self, p: Vec3, reach: f32, enough: f32) -> (f32, usize) {
        let mut best = reach;
        // (node, its box's distance from p), the nearer child on top
        let mut stack = [(0u32, 0.0f32); 64];
        let mut top = 1;
        let mut opened = 0;
        while top > 0 && best > enough {
            top -= 1;
            let (at, near) = stack[top];
            if near >= best {
                continue;
            }
            opened += 1;
            let node = self.nodes[at as usize];
            if node.count > 0 {
                let (a, b) = (node.first as usize, (node.first + node.count) as usize);
                for s in &self.segments[a..b] {
                    best = best.min(point_segment_distance(p, *s));
                }
                continue;
            }
            let child = |i: u32| {
                let c = &self.nodes[i as usize];
                (i, point_box_distance(p, c.lo, c.hi))
            };
            let (l, r) = (child(node.first), child(node.first + 1));
            let (far, near) = if l.1 <= r.1 { (r, l) } else { (l, r) };
            // Median splits: depth ≤ log2(segments) + 1, far below 63.
            for c in [far, near] {
                if c.1 < best {
                    stack[top] = c;
                    top += 1;
                }
            }
        }
        (best, opened)
    }
}

/// Fills node `at` with segments `lo .. hi` (reordered in place), splitting
/// at the median of the centroids along the widest axis.
fn build(segs: &mut [[Vec3; 2]], lo: usize, hi: usize, at: usize, nodes: &mut Vec<Node>) {
    let (mut bmin, mut bmax) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut cmin, mut cmax) = (bmin, bmax);
    for s in &segs[lo..hi] {
        bmin = bmin.min(s[0]).min(s[1]);
        bmax = bmax.max(s[0]).max(s[1]);
        let c = 0.5 * (s[0] + s[1]);
        cmin = cmin.min(c);
        cmax = cmax.max(c);
    }
    nodes[at].lo = bmin;
    nodes[at].hi = bmax;
    if hi - lo <= LEAF {
        nodes[at].first = lo as u32;
        nodes[at].count = (hi - lo) as u32;
        return;
    }
    let ext = cmax - cmin;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = (lo + hi) / 2;
    segs[lo..hi].select_nth_unstable_by(mid - lo, |a, b| {
        let (ca, cb) = ((a[0] + a[1])[axis], (b[0] + b[1])[axis]);
        ca.total_cmp(&cb)
    });
    let left = nodes.len();
    let blank = nodes[at];
    nodes.push(blank);
    nodes.push(blank);
    nodes[at].first = left as u32;
    nodes[at].count = 0;
    build(segs, lo, mid, left, nodes);
    build(segs, mid, hi, left + 1, nodes);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::scene::shapes;

    fn without_normals(m: &Mesh) -> Mesh {
        Mesh::new(
            m.positions()[..m.vertex_count()].to_vec(),
            m.indices.clone(),
            None,
        )
    }

    #[test]
    fn a_cube_has_its_twelve_edges_and_not_its_face_diagonals() {
        // 24 vertices (no index shared between faces): edges meet by position.
        let edges = sharp_edges(&shapes::cuboid());
        assert_eq!(edges.len(), 12);
        for [a, b] in edges {
            // along one axis, length 2, between corners
            let d = (b - a).abs();
            assert_eq!(d.x + d.y + d.z, 2.0, "{a} {b}");
            assert_eq!(d.max_element(), 2.0);
            assert!(a.abs() == Vec3::ONE && b.abs() == Vec3::ONE);
        }
        // the same without vertex normals (face normals: the same jumps)
        assert_eq!(sharp_edges(&without_normals(&shapes::cuboid())).len(), 12);
        // a tile off the origin: corners that share two coordinates and
        // the sign of the third are still told apart
        let mut tile = shapes::cuboid();
        tile.transform(|p| p * Vec3::new(1.0, 0.2, 1.0) + Vec3::splat(5.0), |n| n);
        assert_eq!(sharp_edges(&tile).len(), 12);
    }

    #[test]
    fn minus_zero_and_zero_are_one_position() {
        // a fold at 90° along x = 0 whose two faces do not share vertices,
        // one written with −0.0: the faces still meet at one sharp edge
        // (and the same turned so that the −0.0 is each coordinate in turn)
        let p = [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-0.0, 0.0, 0.0),
            Vec3::new(-0.0, 0.0, 1.0),
            Vec3::new(-0.0, 1.0, 0.0),
        ];
        for turn in 0..3 {
            let q: Vec<Vec3> = p
                .iter()
                .map(|v| Vec3::from_array(std::array::from_fn(|i| v[(i + 3 - turn) % 3])))
                .collect();
            let m = Mesh::new(q, vec![[0, 1, 2], [3, 4, 5]], None);
            let e = sharp_edges(&m);
            assert_eq!(e.len(), 1, "turn {turn}: {e:?}");
            let mid = (e[0][0] + e[0][1]) / 2.0;
            assert_eq!(mid.to_array()[(1 + turn) % 3], 0.5);
        }
    }

    #[test]
    fn smooth_and_finely_faceted_surfaces_have_none() {
        // smooth normals: nothing jumps
        assert!(SharpEdges::new(&shapes::sphere(3)).is_none());
        // flat-shaded, 1,280 facets turning under 10° at each edge
        assert!(SharpEdges::new(&without_normals(&shapes::sphere(3))).is_none());
        // one open quad: its four edges are boundaries
        assert!(SharpEdges::new(&shapes::quad()).is_none());
        // a flat-shaded icosahedron turns 41.8° at each of its 30 edges
        let ico = without_normals(&shapes::sphere(0));
        assert_eq!(ico.triangle_count(), 20);
        assert_eq!(sharp_edges(&ico).len(), 30);
        // its smooth-shaded twin has none
        assert!(SharpEdges::new(&shapes::sphere(0)).is_none());
    }

    #[test]
    fn a_fold_is_sharp_beyond_the_threshold_only() {
        // two unit squares sharing the edge x = 0, the second turned by
        // `deg` about it; shared vertex indices, face normals only
        let fold = |deg: f32| {
            let (s, c) = deg.to_radians().sin_cos();
            let p = vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
                Vec3::new(c, 0.0, s),
                Vec3::new(c, 1.0, s),
            ];
            let idx = vec![[2, 0, 1], [2, 1, 3], [0, 4, 5], [0, 5, 1]];
            sharp_edges(&Mesh::new(p, idx, None))
        };
        assert_eq!(fold(SHARP_ANGLE_DEG - 1.0).len(), 0);
        let e = fold(SHARP_ANGLE_DEG + 1.0);
        assert_eq!(e, vec![[Vec3::ZERO, Vec3::Y]]);
        assert_eq!(fold(90.0).len(), 1);
        // three triangles on one edge (non-manifold): sharp whatever the angle
        let p = vec![
            Vec3::ZERO,
            Vec3::Y,
            Vec3::new(-1.0, 0.5, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(1.0, 0.5, 0.01),
        ];
        let m = Mesh::new(p, vec![[2, 0, 1], [0, 3, 1], [0, 4, 1]], None);
        assert_eq!(sharp_edges(&m), vec![[Vec3::ZERO, Vec3::Y]]);
    }

    #[test]
    fn the_tree_finds_the_nearest_edge_as_brute_force_does() {
        let mut rng = Rng::from_key(7);
        let mut v = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        for n in [1usize, 3, 4, 5, 17, 300] {
            let segs: Vec<[Vec3; 2]> = (0..n).map(|_| [v(), v()]).collect();
            let tree = SharpEdges::from_segments(segs.clone()).unwrap();
            assert_eq!(tree.count(), n);
            for _ in 0..500 {
                let p = v() * 1.5;
                let brute = segs
                    .iter()
                    .map(|s| point_segment_distance(p, *s))
                    .fold(f32::INFINITY, f32::min);
                for reach in [0.05f32, 0.3, 10.0] {
                    let want = brute.min(reach);
                    let got = tree.distance(p, reach);
                    assert_eq!(got, want, "n {n} p {p} reach {reach}");
                }
            }
        }
        assert!(SharpEdges::from_segments(Vec::new()).is_none());
    }

    #[test]
    fn the_tree_opens_few_nodes_for_a_short_reach() {
        // 2,000 short edges spread through a box, queries that look 0.02
        // around random points: a tree split by position opens a few dozen
        // of its ~1,000 nodes per query; a split that ignores position
        // (wrong axis, wrong centroid, wrong median) leaves boxes that
        // overlap everywhere and opens hundreds. Flat boxes of three
        // different extents, the widest along each axis in turn (a split
        // along the wrong axis is as bad as one that ignores position),
        // at the origin and far from it along their thinnest axis (where a
        // centroid that is not the endpoints' mean, e.g. their product,
        // ranks the axes by the offset instead of the extent).
        for (size, offset) in [
            (Vec3::new(1.0, 0.05, 0.3), Vec3::ZERO),
            (Vec3::new(0.3, 1.0, 0.05), Vec3::ZERO),
            (Vec3::new(0.05, 0.3, 1.0), Vec3::ZERO),
            (Vec3::new(0.3, 1.0, 0.05), Vec3::new(0.0, 0.0, 200.0)),
            (Vec3::new(1.0, 0.05, 0.3), Vec3::new(0.0, -200.0, 0.0)),
            // a rod's edges: long in y, the query's reach across in x,
            // flat in z
            (Vec3::new(0.02, 1.0, 0.002), Vec3::ZERO),
        ] {
            let mut rng = Rng::from_key(3);
            let mut v = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
            let segs: Vec<[Vec3; 2]> = (0..2000)
                .map(|_| {
                    let a = (v() * 2.0 - 1.0) * size + offset;
                    [a, a + (v() - 0.5) * 0.02]
                })
                .collect();
            let tree = SharpEdges::from_segments(segs).unwrap();
            let queries = 1000;
            let opened: usize = (0..queries)
                .map(|_| tree.nearest((v() * 2.0 - 1.0) * size + offset, 0.02, 0.0).1)
                .sum();
            let mean = opened as f64 / queries as f64;
            println!(
                "box {size} at {offset}: nodes opened per query {mean:.1} of {}",
                tree.nodes.len()
            );
            assert!(mean < 40.0, "box {size} at {offset}: {mean}");
        }
    }

    #[test]
    fn point_to_segment_distance_clamps_to_the_ends() {
        let s = [Vec3::ZERO, Vec3::X * 2.0];
        assert_eq!(point_segment_distance(Vec3::new(1.0, 3.0, 4.0), s), 5.0);
        assert_eq!(point_segment_distance(Vec3::new(-3.0, 4.0, 0.0), s), 5.0);
        assert_eq!(point_segment_distance(Vec3::new(5.0, 0.0, 4.0), s), 5.0);
        // a zero-length segment is its point
        assert_eq!(
            point_segment_distance(Vec3::new(0.0, 3.0, 4.0), [Vec3::ZERO; 2]),
            5.0
        );
        assert_eq!(point_box_distance(Vec3::ZERO, -Vec3::ONE, Vec3::ONE), 0.0);
        assert_eq!(
            point_box_distance(Vec3::new(4.0, 0.0, 5.0), -Vec3::ONE, Vec3::ONE),
            5.0
        );
    }
}
