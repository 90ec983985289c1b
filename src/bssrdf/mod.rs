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
//! - [`fast`]: its per-hit density and weight in f32, for the exact samplers;
//! - [`fresnel_moment`]: Ft and the normalized exit lobe Sw.
//!
//! The separable BSSRDF is S = C·Ft(xi, wi)·Rd(|xo − xi|)·Ft(xo, wo) with
//! Rd = A·R; the integrator applies the directional factors.
//!
//! Use from an integrator, per material once and per path vertex:
//!
//! ```text
//! let params = SubsurfaceParams::from_preset("marble", units_per_mm, Fit::Searchlight)?;
//! let sampler = ProbeSampler::new(&params, &ProbeOptions::default())?;   // once
//! let c = sw_normalization(params.eta);                                    // once
//! // at exit point xo with shading frame `frame` on mesh `geom`:
//! let u = ProbeRandoms::from_rng(rng);
//! if let Some(ps) = sampler.sample(xo, &frame, &u, accel, geom, &mesh, &mut probe_hits) {
//!     // ps.weight = Rd / pdf × hit count (RGB); light arriving at ps.point
//!     // (normal ps.normal) through the lobe sw(cos, eta, c) contributes
//!     // Ft(xo, wo) · ps.weight · ∫ Li sw cos dω.
//! }
//! ```

pub mod fast;
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
