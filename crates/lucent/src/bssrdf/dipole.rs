//! The classical dipole's total diffuse reflectance of a semi-infinite
//! medium (Jensen et al. 2001, "A Practical Model for Subsurface Light
//! Transport", eq. 5 integrated over the surface; Jensen & Buhler 2002,
//! eq. 2), with the Egan & Hilgeman fit of the diffuse Fresnel reflectance
//! in its boundary condition. The Jensen table's Rd column follows it
//! (`docs/bssrdf.md` §3); the albedo table (`albedo_table`) interpolates its
//! ratio to it, and the artist form inverts it
//! (`params::invert_dipole_reflectance`) with `albedo_source = "given"`.

/// Diffuse Fresnel reflectance Fdr(η), the Egan & Hilgeman polynomial fit
/// the dipole's boundary condition uses (Jensen et al. 2001, §2.4).
fn fdr(eta: f64) -> f64 {
    if eta >= 1.0 {
        -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
    } else {
        -0.4399 + 0.7099 / eta - 0.3319 / (eta * eta) + 0.0636 / (eta * eta * eta)
    }
}

/// Total diffuse reflectance of the classical dipole for reduced albedo α'
/// at relative index η (Jensen et al. 2001, eq. 5 integrated; Jensen &
/// Buhler 2002 eq. 2): Rd = α'/2 (1 + e^{−4/3 A √(3(1−α'))}) e^{−√(3(1−α'))},
/// A = (1 + Fdr)/(1 − Fdr). Increasing in α' from 0 to Rd(1) = 1.
pub fn dipole_reflectance(alpha: f64, eta: f64) -> f64 {
    let fd = fdr(eta);
    let big_a = (1.0 + fd) / (1.0 - fd);
    let s = (3.0 * (1.0 - alpha).max(0.0)).sqrt();
    0.5 * alpha * (1.0 + (-4.0 / 3.0 * big_a * s).exp()) * (-s).exp()
}
