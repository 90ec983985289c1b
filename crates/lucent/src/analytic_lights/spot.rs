//! The spot cone of a sphere light: the radiance leaving in direction ω is
//! scaled by a smoothstep of cos(ω, axis) from 0 at the cone's edge to 1
//! inside its falloff (pbrt-v4 §12.1.2). `docs/scene-format.md`, "`[[lights]]`".

use crate::geometry::Vec3;

/// A spot cone: the unit `axis` the light is aimed along, and the cosines
/// of the full-intensity angle (`cos_inner`) and of the edge (`cos_outer`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    pub axis: Vec3,
    pub cos_inner: f32,
    pub cos_outer: f32,
}

impl Spot {
    /// The factor on radiance leaving in unit direction `travel`.
    pub fn factor(&self, travel: Vec3) -> f32 {
        let c = travel.dot(self.axis);
        if c >= self.cos_inner {
            return 1.0;
        }
        if c <= self.cos_outer {
            return 0.0;
        }
        let t = (c - self.cos_outer) / (self.cos_inner - self.cos_outer);
        t * t * (3.0 - 2.0 * t)
    }

    /// ∫ factor dω over the sphere of directions:
    /// 2π ((1 − cos_inner) + (cos_inner − cos_outer)/2), the smoothstep in
    /// cos θ averaging ½ over its interval.
    pub fn solid_angle(&self) -> f64 {
        let (ci, co) = (self.cos_inner as f64, self.cos_outer as f64);
        2.0 * std::f64::consts::PI * ((1.0 - ci) + 0.5 * (ci - co))
    }
}
