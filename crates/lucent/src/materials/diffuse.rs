//! Lambertian reflection: f = ρ/π, sampled by cosine-weighted directions.
//! Directions are in the local shading frame (z = normal, on wo's side).

use crate::geometry::Vec3;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use std::f32::consts::FRAC_1_PI;

/// f(wo, wi): ρ/π when both lie on the same side, else 0.
pub(crate) fn eval(albedo: Vec3, wo: Vec3, wi: Vec3) -> Vec3 {
    if wo.z * wi.z > 0.0 {
        albedo * FRAC_1_PI
    } else {
        Vec3::ZERO
    }
}

pub fn pdf(wo: Vec3, wi: Vec3) -> f32 {
    if wo.z * wi.z > 0.0 {
        cosine_hemisphere_pdf(wi.z.abs())
    } else {
        0.0
    }
}

/// Samples wi on wo's side; returns (wi, f·|cos|/pdf = ρ, pdf).
pub fn sample(albedo: Vec3, wo: Vec3, u: [f32; 2]) -> Option<(Vec3, Vec3, f32)> {
    let mut wi = cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    let p = cosine_hemisphere_pdf(wi.z.abs());
    if p <= 0.0 {
        return None;
    }
    Some((wi, albedo, p))
}
