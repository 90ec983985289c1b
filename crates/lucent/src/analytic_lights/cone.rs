//! Uniform sampling of a cone of directions (pbrt-v4 §A.5.4), the
//! solid angle both the sphere light and the distant light are sampled by.

use crate::geometry::{Frame, Vec3};
use crate::sampling::sin_cos_turns;

/// A cone of directions about a unit `axis`, of half-angle θmax given as
/// 1 − cos θmax (exact for the tiny angles of a far sphere or the sun,
/// where cos θmax rounds to 1 in f32).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub axis: Vec3,
    pub one_minus_cos: f32,
}

impl Cone {
    /// The cone whose half-angle has sine² `sin2` (in [0, 1]).
    pub fn from_sin2(axis: Vec3, sin2: f32) -> Cone {
        // 1 − √(1 − s) loses everything to rounding for small s: its
        // series s/2 + s²/8 + s³/16 is exact to f32 below 1e-3.
        let one_minus_cos = if sin2 < 1e-3 {
            sin2 * (0.5 + sin2 * (0.125 + sin2 * 0.0625))
        } else {
            1.0 - (1.0 - sin2).max(0.0).sqrt()
        };
        Cone {
            axis,
            one_minus_cos,
        }
    }

    /// The solid angle 2π (1 − cos θmax).
    pub fn solid_angle(&self) -> f32 {
        2.0 * std::f32::consts::PI * self.one_minus_cos
    }

    /// The density of each direction inside, per unit solid angle.
    pub fn pdf(&self) -> f32 {
        1.0 / self.solid_angle()
    }

    /// A direction uniform in the cone from two randoms, and its
    /// 1 − cos θ and sin² θ from the axis.
    pub fn sample(&self, u: [f32; 2]) -> (Vec3, f32, f32) {
        let omc = u[0] * self.one_minus_cos;
        let sin2 = omc * (2.0 - omc);
        let sin = sin2.max(0.0).sqrt();
        let (s, c) = sin_cos_turns(u[1]);
        let local = Vec3::new(sin * c, sin * s, 1.0 - omc);
        (Frame::from_normal(self.axis).to_world(local), omc, sin2)
    }

    /// Whether unit direction `d` lies inside (for half-angles up to
    /// 90°): by sin², which keeps its precision at tiny angles where the
    /// cosine does not.
    pub fn contains(&self, d: Vec3) -> bool {
        if d.dot(self.axis) <= 0.0 {
            return false;
        }
        let sin2 = d.cross(self.axis).length_squared();
        // sin² θ = (1 − cos θ)(1 + cos θ) ≤ the cone's, for θ < π/2.
        let omc = self.one_minus_cos;
        sin2 <= omc * (2.0 - omc)
    }
}
