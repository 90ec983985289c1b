//! Texture coordinates of the built-in shapes, generated (before the
//! shape's transform) only for a shape whose material reads a texture
//! (`docs/scene-format.md`, "Texture coordinates"):
//!
//! - `sphere`: latitude-longitude, u = ½ + atan2(x, z)/2π (u = ½ facing +z,
//!   the seam facing −z), v = ½ + asin(y)/π (v = 1 at the +y pole);
//! - `quad`: u = (x + 1)/2, v = (y + 1)/2;
//! - `box`: each face its own [0, 1]² in the face's two tangent axes
//!   (the quad's layout, turned onto the face).

use glam::Vec2;

use super::format::ShapeKind;
use crate::geometry::{Mesh, Vec3};

/// The corner texture coordinates of the built-in shape `kind`'s `mesh`
/// (as [`super::shapes`] builds it, untransformed); None for an OBJ.
pub(super) fn generated_uvs(kind: ShapeKind, mesh: &Mesh) -> Option<Vec<[Vec2; 3]>> {
    let corners = |f: &dyn Fn([Vec3; 3]) -> [Vec2; 3]| {
        mesh.indices
            .iter()
            .map(|&t| f(mesh.vertices(t)))
            .collect::<Vec<_>>()
    };
    match kind {
        ShapeKind::Obj => None,
        ShapeKind::Sphere => Some(corners(&sphere_corners)),
        ShapeKind::Quad => Some(corners(&|p| p.map(|p| (p.truncate() + Vec2::ONE) * 0.5))),
        ShapeKind::Box => Some(corners(&box_corners)),
    }
}

/// A sphere triangle's corners: a triangle across the seam gets u + 1 on
/// its corners left of it (so it interpolates across u = 1, which wraps),
/// a corner at a pole the mean u of the other two.
fn sphere_corners(p: [Vec3; 3]) -> [Vec2; 3] {
    let tau = std::f32::consts::TAU;
    let mut uv = p.map(|p| {
        Vec2::new(
            0.5 + p.x.atan2(p.z) / tau,
            0.5 + p.y.clamp(-1.0, 1.0).asin() / std::f32::consts::PI,
        )
    });
    let (lo, hi) = uv
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), t| {
            (lo.min(t.x), hi.max(t.x))
        });
    if hi - lo > 0.5 {
        for t in &mut uv {
            if t.x < 0.5 {
                t.x += 1.0;
            }
        }
    }
    for k in 0..3 {
        if p[k].x.hypot(p[k].z) < 1e-6 {
            uv[k].x = 0.5 * (uv[(k + 1) % 3].x + uv[(k + 2) % 3].x);
        }
    }
    uv
}

/// A box triangle's corners in its face's tangent axes (those
/// [`super::shapes::cuboid`] builds the face from).
fn box_corners(p: [Vec3; 3]) -> [Vec2; 3] {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let axis = n.abs().max_position();
    let sign = n[axis].signum();
    let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
    p.map(|p| (Vec2::new(p[ua], sign * p[va]) + Vec2::ONE) * 0.5)
}

#[cfg(test)]
mod tests {
    use super::super::shapes;
    use super::*;

    #[test]
    fn quad_corners_span_the_unit_square() {
        let q = shapes::quad();
        let uv = generated_uvs(ShapeKind::Quad, &q).unwrap();
        assert_eq!(uv[0], [Vec2::ZERO, Vec2::X, Vec2::ONE]);
    }

    #[test]
    fn sphere_uvs_are_continuous_within_each_triangle() {
        let s = shapes::sphere(3);
        let uv = generated_uvs(ShapeKind::Sphere, &s).unwrap();
        for t in &uv {
            let du = t.iter().map(|c| c.x).fold(f32::NEG_INFINITY, f32::max)
                - t.iter().map(|c| c.x).fold(f32::INFINITY, f32::min);
            assert!(du < 0.2, "{t:?}");
        }
        // +z is u = ½ on the equator, +y the top
        let front = sphere_corners([Vec3::Z; 3]);
        assert!((front[0] - Vec2::new(0.5, 0.5)).length() < 1e-6);
        assert!((sphere_corners([Vec3::X, Vec3::Z, Vec3::Y])[2].y - 1.0).abs() < 1e-6);
    }

    #[test]
    fn box_faces_each_span_the_unit_square() {
        let b = shapes::cuboid();
        let uv = generated_uvs(ShapeKind::Box, &b).unwrap();
        for t in &uv {
            for c in t {
                assert!(c.x.abs() < 1e-6 || (c.x - 1.0).abs() < 1e-6, "{c:?}");
                assert!(c.y.abs() < 1e-6 || (c.y - 1.0).abs() < 1e-6, "{c:?}");
            }
        }
    }
}
