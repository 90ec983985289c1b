//! Which side of a mesh is the outside of a convex body: what
//! `crate::integrator::culling` needs to know that a ray leaving the mesh
//! cannot meet it again. A side is convex-outside when every vertex lies on
//! or behind the plane of every triangle (seen from that side) within a
//! tolerance τ; tested exactly, in f64, over a tree of the vertices' boxes.
//! The property, why it suffices and the test: `docs/performance.md`,
//! "Convex-outside sides".

use crate::geometry::Mesh;
use glam::DVec3;

/// Vertices in a leaf of the test's tree.
const LEAF: usize = 8;

/// Meshes with more triangles than this are not tested (reported convex
/// on neither side): this bounds the test's time
/// (`docs/performance.md`, "Convex-outside sides").
pub(crate) const MAX_TRIANGLES: usize = 100_000;

/// Which sides of a mesh are convex-outside (module docs), with tolerance
/// `tol` (scene units, ≥ 0): `[front, back]`. An empty mesh has neither.
pub(crate) fn outside_sides(mesh: &Mesh, tol: f64) -> [bool; 2] {
    let verts: Vec<DVec3> = mesh.positions().iter().map(|p| p.as_dvec3()).collect();
    if verts.is_empty() || mesh.triangle_count() == 0 || mesh.triangle_count() > MAX_TRIANGLES {
        return [false, false];
    }
    let tree = Tree::new(verts);
    let mut sides = [true, true];
    for &[a, b, c] in &mesh.indices {
        let [a, b, c] = mesh.vertices([a, b, c]).map(|p| p.as_dvec3());
        let Some(n) = (b - a).cross(c - a).try_normalize() else {
            continue;
        };
        for (k, s) in [1.0, -1.0].into_iter().enumerate() {
            if sides[k] {
                let dir = n * s;
                sides[k] = !tree.any_above(dir, dir.dot(a) + tol);
            }
        }
        if sides == [false, false] {
            break;
        }
    }
    sides
}

/// A bounding-box tree over points, for "is any point above this plane".
struct Tree {
    points: Vec<DVec3>,
    nodes: Vec<Node>,
}

struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: the points `start..end`; inner: children `left` and `left + 1`.
    start: usize,
    end: usize,
    left: Option<usize>,
}

impl Tree {
    fn new(mut points: Vec<DVec3>) -> Self {
        let mut nodes = Vec::with_capacity(2 * points.len() / LEAF + 1);
        let n = points.len();
        nodes.push(Node::leaf(&points, 0, n));
        // Split nodes breadth-first at the median of their longest axis;
        // children are pushed in pairs, so `left + 1` is the right one.
        let mut i = 0;
        while i < nodes.len() {
            let (start, end) = (nodes[i].start, nodes[i].end);
            if end - start > LEAF {
                let axis = (nodes[i].hi - nodes[i].lo).max_position();
                let mid = (start + end) / 2;
                points[start..end]
                    .select_nth_unstable_by(mid - start, |a, b| a[axis].total_cmp(&b[axis]));
                nodes[i].left = Some(nodes.len());
                nodes.push(Node::leaf(&points, start, mid));
                nodes.push(Node::leaf(&points, mid, end));
            }
            i += 1;
        }
        Tree { points, nodes }
    }

    /// Whether some point p has dir·p > bound.
    fn any_above(&self, dir: DVec3, bound: f64) -> bool {
        let mut stack = [0usize; 64];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let node = &self.nodes[stack[len]];
            // The box's largest dir·x is at the corner dir points to.
            let corner = DVec3::select(dir.cmpge(DVec3::ZERO), node.hi, node.lo);
            if dir.dot(corner) <= bound {
                continue;
            }
            match node.left {
                Some(l) => {
                    stack[len] = l;
                    stack[len + 1] = l + 1;
                    len += 2;
                }
                None => {
                    if self.points[node.start..node.end]
                        .iter()
                        .any(|p| dir.dot(*p) > bound)
                    {
                        return true;
                    }
                }
            }
        }
        false
    }
}

impl Node {
    fn leaf(points: &[DVec3], start: usize, end: usize) -> Node {
        let (lo, hi) = points[start..end].iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        Node {
            lo,
            hi,
            start,
            end,
            left: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use crate::scene::shapes;

    #[test]
    fn spheres_and_boxes_are_convex_outside_on_their_front_only() {
        for mesh in [shapes::sphere(0), shapes::sphere(3), shapes::sphere(5)] {
            assert_eq!(outside_sides(&mesh, 1e-6), [true, false]);
        }
        assert_eq!(outside_sides(&shapes::cuboid(), 1e-6), [true, false]);
    }

    #[test]
    fn a_mesh_wound_inwards_is_convex_outside_on_its_back() {
        let mut mesh = shapes::sphere(3);
        mesh.flip_winding();
        assert_eq!(outside_sides(&mesh, 1e-6), [false, true]);
    }

    #[test]
    fn a_planar_mesh_is_convex_outside_on_both_sides() {
        assert_eq!(outside_sides(&shapes::quad(), 1e-6), [true, true]);
    }

    #[test]
    fn one_dent_or_a_second_body_makes_a_mesh_not_convex() {
        // One vertex of the sphere pushed in by 1 % of the radius.
        let mut dented = shapes::sphere(3);
        dented.transform(
            |p| {
                if (p - Vec3::Z).length() < 1e-4 {
                    p * 0.99
                } else {
                    p
                }
            },
            |n| n,
        );
        assert_eq!(outside_sides(&dented, 1e-6), [false, false]);
        // Two disjoint spheres in one mesh: each convex, together not.
        let a = shapes::sphere(2);
        let mut positions = a.positions().to_vec();
        let offset = positions.len() as u32;
        positions.extend(a.positions().iter().map(|p| *p + Vec3::new(3.0, 0.0, 0.0)));
        let mut indices = a.indices.clone();
        indices.extend(a.indices.iter().map(|t| t.map(|i| i + offset)));
        let two = Mesh::new(positions, indices, None);
        assert_eq!(outside_sides(&two, 1e-6), [false, false]);
    }

    #[test]
    fn the_tolerance_decides_nearly_coplanar_faces() {
        // A quad folded by 1e-5 along its diagonal: convex on one side
        // only, unless the tolerance covers the fold.
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 1e-5),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let folded = Mesh::new(positions, vec![[0, 1, 3], [1, 2, 3]], None);
        let strict = outside_sides(&folded, 1e-9);
        assert_eq!(strict.iter().filter(|s| **s).count(), 1, "{strict:?}");
        assert_eq!(outside_sides(&folded, 1e-4), [true, true]);
    }

    #[test]
    fn the_tree_finds_the_one_point_above_a_plane() {
        let mut rng = crate::sampling::Rng::new(5, 0, 0);
        let mut points: Vec<DVec3> = (0..1000)
            .map(|_| DVec3::new(rng.uniform_f64(), rng.uniform_f64(), rng.uniform_f64()))
            .collect();
        points.push(DVec3::new(0.5, 0.5, 2.0));
        let tree = Tree::new(points.clone());
        assert!(tree.any_above(DVec3::Z, 1.5));
        assert!(!tree.any_above(DVec3::Z, 2.0));
        for dir in [DVec3::X, -DVec3::Y, DVec3::new(1.0, 1.0, 1.0).normalize()] {
            let max = points.iter().map(|p| dir.dot(*p)).fold(f64::MIN, f64::max);
            assert!(tree.any_above(dir, max - 1e-9));
            assert!(!tree.any_above(dir, max));
        }
    }
}
