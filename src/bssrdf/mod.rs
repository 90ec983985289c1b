//! Christensen–Burley normalized diffusion BSSRDF ("Approximate Reflectance
//! Profiles for Efficient Subsurface Scattering", Pixar TR 15-04, 2015),
//! sampled with probe rays (King et al. 2013, "BSSRDF Importance Sampling";
//! pbrt-v3 §15.4). The math is restated, with the seed's errors corrected,
//! in `docs/bssrdf.md`.
//!
//! - [`profile`]: R(r), its CDF and closed-form inverse, the s(A) fits;
//! - [`params`]: presets, measured and artist parameters → per-channel (A, d);
//! - [`radius`]: the four radius samplers with their disk pdfs;
//! - [`probe`]: the probe-ray estimator the integrator calls;
//! - [`fresnel_moment`]: Ft and the normalized exit lobe Sw.
//!
//! The separable BSSRDF is S = C·Ft(xi, wi)·Rd(|xo − xi|)·Ft(xo, wo) with
//! Rd = A·R; the integrator applies the directional factors.

pub mod fresnel_moment;
pub mod params;
pub mod probe;
pub mod profile;
pub mod radius;

pub use fresnel_moment::{sw, sw_normalization, transmittance};
pub use params::{Measured, Preset, SubsurfaceParams, PRESETS};
pub use probe::{
    ChannelStrategy, ProbeAxes, ProbeOptions, ProbeRandoms, ProbeSample, ProbeSampler,
};
pub use profile::Fit;
pub use radius::{RadialDist, RadiusSampler, TableSpacing};
