//! Which triangles of a mesh share an edge: the random walk's connection
//! through the smooth boundary looks for a second refraction point on the
//! neighbours of the facet it solved on (`docs/bssrdf.md` §7, "Light
//! through the smooth boundary").
//!
//! Vertices are welded by position (as in [`super::sharp_edges`]), so a
//! mesh whose triangles repeat their corners still has neighbours. An edge
//! shared by exactly two triangles joins them; a border edge, a degenerate
//! one and an edge of three or more triangles give none.

use super::sharp_edges::weld;
use super::Mesh;

/// No triangle across this edge.
pub const NONE: u32 = u32::MAX;

/// Per triangle, the triangle across each of its three edges (module docs).
#[derive(Clone, Debug)]
pub struct EdgeNeighbours {
    across: Vec<[u32; 3]>,
}

impl EdgeNeighbours {
    /// The neighbours of every triangle of `mesh`: a sort of its triangles'
    /// sides by welded edge, so the two sides of an edge lie together.
    pub fn new(mesh: &Mesh) -> Self {
        let id = weld(mesh.positions());
        // (edge as lower id, higher id; triangle; which of its sides)
        let mut sides: Vec<(u64, u32, u8)> = Vec::with_capacity(3 * mesh.triangle_count());
        for (prim, idx) in mesh.indices.iter().enumerate() {
            for side in 0..3u8 {
                let a = id[idx[side as usize] as usize];
                let b = id[idx[(side as usize + 1) % 3] as usize];
                if a != b {
                    let (lo, hi) = (a.min(b) as u64, a.max(b) as u64);
                    sides.push((lo << 32 | hi, prim as u32, side));
                }
            }
        }
        sides.sort_unstable();
        let mut across = vec![[NONE; 3]; mesh.triangle_count()];
        for group in sides.chunk_by(|s, t| s.0 == t.0) {
            if let [(_, p, i), (_, q, j)] = group {
                if p != q {
                    across[*p as usize][*i as usize] = *q;
                    across[*q as usize][*j as usize] = *p;
                }
            }
        }
        EdgeNeighbours { across }
    }

    /// The triangles across the three edges of `prim` ([`NONE`] where there
    /// is none).
    pub fn of(&self, prim: u32) -> [u32; 3] {
        self.across[prim as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    /// Two triangles of a square share its diagonal even when each repeats
    /// its corners (welded by position); the other edges are borders. A
    /// pairing by vertex index instead of position finds nothing here.
    #[test]
    fn welded_square_pairs_its_diagonal_only() {
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
        ];
        let mesh = Mesh::new(p.to_vec(), vec![[0, 1, 2], [3, 4, 5]], None);
        let n = EdgeNeighbours::new(&mesh);
        assert_eq!(n.of(0), [NONE, NONE, 1]);
        assert_eq!(n.of(1), [0, NONE, NONE]);
    }

    /// On a closed sphere every triangle has three distinct neighbours and
    /// the relation is symmetric.
    #[test]
    fn closed_sphere_has_three_symmetric_neighbours() {
        let mesh = crate::scene::shapes::sphere(2);
        let n = EdgeNeighbours::new(&mesh);
        for prim in 0..mesh.triangle_count() as u32 {
            let a = n.of(prim);
            assert!(a.iter().all(|&q| q != NONE && q != prim), "{prim}: {a:?}");
            assert!(a[0] != a[1] && a[1] != a[2] && a[0] != a[2]);
            for q in a {
                assert!(n.of(q).contains(&prim));
            }
        }
    }
}
