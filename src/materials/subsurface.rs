//! The subsurface material: a smooth dielectric boundary over a medium whose
//! multiple scattering is the Christensen–Burley normalized-diffusion
//! profile (see [`crate::bssrdf`] and `docs/bssrdf.md`).
//!
//! Following a camera path, light leaves the object at xo (where the path
//! arrives) after entering at xi (found by a probe ray). The separable
//! BSSRDF splits into
//!
//!   S(xi, ωi; xo, ωo) = Ft(xo, ωo) · Rd(|xo − xi|) · Sw(ωi)
//!
//! where Ft = 1 − Fr is always applied at xo, optionally as the complement
//! of a specular reflection layer, and the lobe at xi is either the
//! normalized Fresnel lobe Sw (pbrt-v3 §11.4) or, as in the seed, a plain
//! cosine lobe 1/π.

use crate::bssrdf::{sw_normalization, ProbeOptions, ProbeSampler, SubsurfaceParams};
use crate::geometry::Vec3;

#[derive(Clone, Debug)]
pub struct Subsurface {
    pub params: SubsurfaceParams,
    pub probe: ProbeSampler,
    /// Use the normalized Fresnel lobe Sw at the entry point xi (else 1/π).
    pub exit_sw: bool,
    /// Put a specular reflection layer (probability Fr) on top at xo; else
    /// the path is weighted by Ft = 1 − Fr and the reflected part is lost.
    pub specular: bool,
    /// c = 1 − 2 FM1(1/η), Sw's normalization.
    sw_c: f32,
}

impl PartialEq for Subsurface {
    fn eq(&self, o: &Self) -> bool {
        self.params == o.params
            && self.probe.options() == o.probe.options()
            && self.exit_sw == o.exit_sw
            && self.specular == o.specular
    }
}

impl Subsurface {
    pub fn new(params: SubsurfaceParams, opts: &ProbeOptions, exit_sw: bool, specular: bool) -> Result<Self, String> {
        let probe = ProbeSampler::new(&params, opts)?;
        Ok(Subsurface { sw_c: sw_normalization(params.eta), params, probe, exit_sw, specular })
    }

    pub fn eta(&self) -> f32 {
        self.params.eta
    }

    /// The entry-point lobe value per steradian for a direction with cosine
    /// `cos` to the outward normal: Sw(ω) or 1/π.
    pub fn lobe(&self, cos: f32) -> f32 {
        if cos <= 0.0 {
            return 0.0;
        }
        if self.exit_sw {
            crate::bssrdf::sw(cos, self.params.eta, self.sw_c)
        } else {
            std::f32::consts::FRAC_1_PI
        }
    }

    /// The albedo A per channel (for previews and tests).
    pub fn albedo(&self) -> Vec3 {
        let a = self.params.albedo;
        Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
    }
}
