//! Physical units of the lights: the radiance L that a given power (W) or
//! irradiance (W/m²) stands for, as `docs/scene-format.md`, "Light units",
//! states them. Each is the inverse of an integral of L cos θ.

use super::spot::Spot;
use crate::geometry::Vec3;

use std::f64::consts::PI;

/// A one-sided emitter of total area A radiating L into its front
/// hemisphere emits Φ = π A L.
pub fn mesh_radiance(power: Vec3, area: f64) -> Vec3 {
    power / (PI * area) as f32
}

/// A sphere of radius r radiating L outwards (its projected area π r² in
/// every direction) emits Φ = π r² L · Ω, with Ω = 4π, or a spot's
/// [`Spot::solid_angle`].
pub fn sphere_radiance(power: Vec3, radius: f64, spot: Option<&Spot>) -> Vec3 {
    let omega = spot.map_or(4.0 * PI, |s| s.solid_angle());
    let r = radius;
    power / (PI * r * r * omega) as f32
}

/// A cone of half-angle θmax of radiance L gives a surface facing its axis
/// the irradiance E = ∫ L cos θ dω = π sin² θmax L.
pub fn distant_radiance(irradiance: Vec3, sin2_half_angle: f64) -> Vec3 {
    irradiance / (PI * sin2_half_angle) as f32
}
