//! Dielectric Fresnel reflectance (pbrt-v4 §9.3.6): the optics both the
//! surface materials and the BSSRDF's directional terms build on, so it sits
//! below [`crate::materials`] and [`crate::bssrdf`] and imports neither.

/// Unpolarized Fresnel reflectance for light arriving with cosine `cos_i`
/// (measured on the side it comes from, positive when it arrives from the
/// outside) at an interface of relative index `eta` = inside / outside.
pub fn dielectric(cos_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_and_total_internal_reflection() {
        let f0 = ((1.5f32 - 1.0) / (1.5 + 1.0)).powi(2);
        assert!((dielectric(1.0, 1.5) - f0).abs() < 1e-6);
        assert!((dielectric(-1.0, 1.5) - f0).abs() < 1e-6);
        assert_eq!(dielectric(-0.1, 1.5), 1.0); // inside, past critical angle
        assert!((dielectric(1e-4, 1.5) - 1.0).abs() < 1e-2); // grazing
        assert_eq!(dielectric(0.5, 1.0), 0.0);
    }
}
