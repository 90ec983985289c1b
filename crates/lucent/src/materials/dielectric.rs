//! A smooth dielectric boundary: specular reflection with probability Fr and
//! refraction with probability 1 − Fr (pbrt-v4 §9.3). Directions are local
//! (z = geometric normal pointing outside); η = inside / outside.

use crate::fresnel;
use crate::geometry::Vec3;

/// A sampled specular direction and its path-throughput weight.
pub struct SpecularSample {
    pub wi: Vec3,
    /// f·|cos|/pdf; 1 for reflection, 1/η'² for refraction (radiance is
    /// compressed into a smaller solid angle when entering a denser medium).
    pub weight: f32,
    pub transmitted: bool,
}

/// Refracts `wo` (pointing away from the surface) about +z with relative
/// index `eta`; None on total internal reflection.
pub fn refract(wo: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let (cos_i, etap, n) = if wo.z > 0.0 {
        (wo.z, eta, 1.0)
    } else {
        (-wo.z, 1.0 / eta, -1.0)
    };
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (etap * etap);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let wi = -wo / etap + Vec3::new(0.0, 0.0, n * (cos_i / etap - cos_t));
    Some((wi.normalize(), etap))
}

pub fn sample(eta: f32, wo: Vec3, u: f32) -> SpecularSample {
    let mirror = SpecularSample {
        wi: Vec3::new(-wo.x, -wo.y, wo.z),
        weight: 1.0,
        transmitted: false,
    };
    if u < fresnel::dielectric(wo.z, eta) {
        return mirror;
    }
    // Fr = 1 wherever refract finds total internal reflection (the same
    // sin²θt), so its None is a guard here, not a branch light takes.
    match refract(wo, eta) {
        Some((wi, etap)) => SpecularSample {
            wi,
            weight: 1.0 / (etap * etap),
            transmitted: true,
        },
        None => mirror,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refraction_obeys_snell_both_ways() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let (wi, etap) = refract(wo, 1.5).unwrap();
        assert_eq!(etap, 1.5);
        assert!(wi.z < 0.0);
        assert!((0.6 - 1.5 * wi.x.abs()).abs() < 1e-5); // sin θo = η sin θi
        let (back, _) = refract(wi, 1.5).unwrap();
        assert!((back - wo).length() < 1e-5);
        assert!(refract(Vec3::new(0.9, 0.0, -0.4359).normalize(), 1.5).is_none());
    }
}
