//! The per-shape placement of the scene format: scale, then rotations in
//! the order listed, then translation, applied to a mesh's positions and
//! (by the inverse transpose) its shading normals.

use glam::Mat3;

use crate::geometry::{Mesh, Vec3};

/// An affine map `p ↦ linear · p + translate`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub linear: Mat3,
    pub translate: Vec3,
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        linear: Mat3::IDENTITY,
        translate: Vec3::ZERO,
    };

    /// `translate · R_n ⋯ R_1 · diag(scale)`, where `rotations` are
    /// (angle in degrees, axis) pairs, counter-clockwise about the axis
    /// (right-hand rule), applied first to last. Axes need not be unit
    /// length but must be non-zero; the caller validates that.
    pub(crate) fn from_srt(scale: Vec3, rotations: &[(f32, Vec3)], translate: Vec3) -> Self {
        let mut linear = Mat3::from_diagonal(scale);
        for &(deg, axis) in rotations {
            linear = Mat3::from_axis_angle(axis.normalize(), deg.to_radians()) * linear;
        }
        Transform { linear, translate }
    }

    pub fn point(&self, p: Vec3) -> Vec3 {
        self.linear * p + self.translate
    }

    /// The matrix that maps normals: the inverse transpose of the linear
    /// part, so transformed normals stay perpendicular to transformed
    /// surfaces under non-uniform scale.
    pub(crate) fn normal_matrix(&self) -> Mat3 {
        self.linear.inverse().transpose()
    }

    pub(crate) fn determinant(&self) -> f32 {
        self.linear.determinant()
    }

    /// Transforms `mesh` in place. A mirroring transform (negative
    /// determinant) would turn counter-clockwise triangles clockwise, so the
    /// winding is flipped to keep the front face — and one-sided emission —
    /// on the side the transformed normals point to.
    pub fn apply(&self, mesh: &mut Mesh) {
        let n = self.normal_matrix();
        mesh.transform(|p| self.point(p), |v| n * v);
        if self.determinant() < 0.0 {
            mesh.flip_winding();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shapes;

    fn geometric_normal(m: &Mesh, i: u32) -> Vec3 {
        let [a, b, c] = m.triangle(i);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn order_is_scale_then_rotate_then_translate() {
        let t = Transform::from_srt(
            Vec3::new(2.0, 1.0, 1.0),
            &[(90.0, Vec3::Z), (90.0, Vec3::new(0.0, 3.0, 0.0))],
            Vec3::new(0.0, 0.0, 10.0),
        );
        // x → (2,0,0) → rot z 90° → (0,2,0) → rot y 90° stays → +10 z
        assert!(t
            .point(Vec3::X)
            .abs_diff_eq(Vec3::new(0.0, 2.0, 10.0), 1e-5));
        // z → rot z stays (0,0,1) → rot y 90° → (1,0,0)
        assert!(t
            .point(Vec3::Z)
            .abs_diff_eq(Vec3::new(1.0, 0.0, 10.0), 1e-5));
    }

    #[test]
    fn normals_use_inverse_transpose() {
        // A plane x + y = 0 with normal (1,1,0)/√2, stretched 4× along x:
        // its points (1,-1,0) map to (4,-1,0); the true normal is ∝ (1,4,0).
        let t = Transform::from_srt(Vec3::new(4.0, 1.0, 1.0), &[], Vec3::ZERO);
        let n = (t.normal_matrix() * Vec3::new(1.0, 1.0, 0.0)).normalize();
        assert!(n.dot(t.point(Vec3::new(1.0, -1.0, 0.0))).abs() < 1e-5);
        assert!(n.abs_diff_eq(Vec3::new(1.0, 4.0, 0.0).normalize(), 1e-5));
    }

    #[test]
    fn mirroring_flips_winding_so_front_faces_agree_with_normals() {
        for scale in [Vec3::new(-1.0, 1.0, 1.0), Vec3::new(1.0, 1.0, -2.0)] {
            let mut q = shapes::quad();
            let t = Transform::from_srt(scale, &[], Vec3::ZERO);
            assert!(t.determinant() < 0.0);
            t.apply(&mut q);
            // The quad faced +z; the geometric (winding) normal must agree
            // with the transformed shading normal.
            let ns = q.normals.as_ref().unwrap()[0];
            for i in 0..2 {
                assert!(geometric_normal(&q, i).dot(ns) > 0.99, "{scale}");
            }
        }
        // z-mirror: the quad now faces −z.
        let mut q = shapes::quad();
        Transform::from_srt(Vec3::new(1.0, 1.0, -1.0), &[], Vec3::ZERO).apply(&mut q);
        assert!(geometric_normal(&q, 0).abs_diff_eq(-Vec3::Z, 1e-6));
        // Without mirroring the winding is untouched.
        let mut q = shapes::quad();
        Transform::from_srt(Vec3::splat(3.0), &[(180.0, Vec3::X)], Vec3::ZERO).apply(&mut q);
        assert_eq!(q.indices, shapes::quad().indices);
        assert!(geometric_normal(&q, 0).abs_diff_eq(-Vec3::Z, 1e-5));
    }

    #[test]
    fn mirrored_closed_mesh_stays_outward() {
        let mut c = shapes::cuboid();
        Transform::from_srt(Vec3::new(-1.0, 2.0, 1.0), &[], Vec3::ONE).apply(&mut c);
        let centre = Vec3::ONE;
        for i in 0..c.triangle_count() as u32 {
            let [a, b, cc] = c.triangle(i);
            let mid = (a + b + cc) / 3.0;
            assert!(geometric_normal(&c, i).dot(mid - centre) > 0.0);
        }
    }
}
