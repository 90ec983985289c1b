//! Built-in and procedural meshes: the scene format's `sphere`, `quad` and
//! `box`, and the generated meshes tests and benchmarks use (random
//! triangle soups, displaced spheres), so nothing large is downloaded.

use std::collections::HashMap;

use crate::geometry::{Mesh, Vec3};
use crate::sampling::Rng;

/// A unit sphere at the origin: an icosahedron subdivided `level` times and
/// projected onto the sphere, 20·4^level triangles, counter-clockwise seen
/// from outside, with smooth (radial) normals. Level 8 has 1,310,720.
pub fn sphere(level: u32) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&v| Vec3::from(v).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 2);
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut midpoint = |a: u32, b: u32, verts: &mut Vec<Vec3>| -> u32 {
            let key = (a.min(b), a.max(b));
            *mid.entry(key).or_insert_with(|| {
                verts.push(((verts[a as usize] + verts[b as usize]) * 0.5).normalize());
                (verts.len() - 1) as u32
            })
        };
        for &[a, b, c] in &faces {
            let ab = midpoint(a, b, &mut verts);
            let bc = midpoint(b, c, &mut verts);
            let ca = midpoint(c, a, &mut verts);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let normals = verts.clone();
    Mesh::new(verts, faces, Some(normals))
}

/// A sphere whose radius is displaced by a sum of sines (amplitude `amp`),
/// so its BVH is not as easy as a perfect sphere's. Normals are left to the
/// geometric ones.
pub fn displaced_sphere(level: u32, amp: f32) -> Mesh {
    let s = sphere(level);
    let pos: Vec<Vec3> = s
        .positions()
        .iter()
        .map(|&p| {
            let k = 1.0 + amp * ((7.0 * p.x).sin() * (9.0 * p.y).sin() * (11.0 * p.z).sin());
            p * k
        })
        .collect();
    Mesh::new(pos, s.indices.clone(), None)
}

/// The square [-1, 1]² in the xy plane, facing +z (two triangles).
pub fn quad() -> Mesh {
    let p = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    Mesh::new(p, vec![[0, 1, 2], [0, 2, 3]], Some(vec![Vec3::Z; 4]))
}

/// The cube [-1, 1]³ with outward faces, 12 triangles, 24 vertices (flat
/// normals per face).
pub fn cuboid() -> Mesh {
    let mut pos = Vec::with_capacity(24);
    let mut nrm = Vec::with_capacity(24);
    let mut idx = Vec::with_capacity(12);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            // two tangent axes, ordered so (u × v) = n
            let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut u = Vec3::ZERO;
            u[ua] = 1.0;
            let mut v = Vec3::ZERO;
            v[va] = sign;
            let base = pos.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                pos.push(n + u * a + v * b);
                nrm.push(n);
            }
            idx.push([base, base + 1, base + 2]);
            idx.push([base, base + 2, base + 3]);
        }
    }
    Mesh::new(pos, idx, Some(nrm))
}

/// `n` random triangles in the cube [-1, 1]³ with edge lengths up to
/// `size`, for backend tests and benchmarks.
pub fn random_soup(n: usize, size: f32, seed: u64) -> Mesh {
    let mut rng = Rng::from_key(seed);
    let mut p = Vec::with_capacity(3 * n);
    let mut idx = Vec::with_capacity(n);
    let r3 =
        |rng: &mut Rng| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
    for i in 0..n {
        let c = r3(&mut rng);
        for _ in 0..3 {
            let v = c + r3(&mut rng) * (0.5 * size);
            p.push(v);
        }
        let b = 3 * i as u32;
        idx.push([b, b + 1, b + 2]);
    }
    Mesh::new(p, idx, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed_and_outward(m: &Mesh) -> (f32, f32) {
        // Divergence theorem: volume = Σ (a · (b × c)) / 6 > 0 for outward winding.
        let mut vol = 0.0;
        let mut area = 0.0;
        for i in 0..m.triangle_count() as u32 {
            let [a, b, c] = m.triangle(i);
            vol += a.dot(b.cross(c)) / 6.0;
            area += m.area(i);
        }
        (vol, area)
    }

    #[test]
    fn sphere_converges_to_the_unit_sphere() {
        let s = sphere(4);
        assert_eq!(s.triangle_count(), 20 * 256);
        let (vol, area) = closed_and_outward(&s);
        let pi = std::f32::consts::PI;
        assert!(
            (vol - 4.0 / 3.0 * pi).abs() / (4.0 / 3.0 * pi) < 0.01,
            "vol {vol}"
        );
        assert!((area - 4.0 * pi).abs() / (4.0 * pi) < 0.01, "area {area}");
        // shared vertices: Euler characteristic V − E + F = 2
        let f = s.triangle_count() as i64;
        assert_eq!(s.vertex_count() as i64 - 3 * f / 2 + f, 2);
    }

    #[test]
    fn cube_and_quad_are_oriented() {
        let (vol, area) = closed_and_outward(&cuboid());
        assert!((vol - 8.0).abs() < 1e-5 && (area - 24.0).abs() < 1e-4);
        let q = quad();
        let [a, b, c] = q.triangle(0);
        assert!((b - a).cross(c - a).normalize().abs_diff_eq(Vec3::Z, 1e-6));
    }
}
