//! An orthonormal shading frame (t, b, n) around a unit normal.

use super::Vec3;

/// An orthonormal frame (t, b, n), right-handed.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// Builds a frame around a unit normal without branches on the sign of
    /// n.z (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"),
    /// so nearby normals get nearby tangents.
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { t, b: bt, n }
    }
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_for_all_octants() {
        for &n in &[
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.5, -0.81).normalize(),
            Vec3::new(1e-8, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!((f.b.length() - 1.0).abs() < 1e-5);
            assert!(
                f.t.dot(f.b).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5 && f.b.dot(n).abs() < 1e-5
            );
            assert!((f.t.cross(f.b) - n).length() < 1e-5);
            let v = Vec3::new(0.2, -0.7, 0.4);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
