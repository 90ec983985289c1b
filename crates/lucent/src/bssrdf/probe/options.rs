//! The probe estimator's options: the axis rule, the channel strategy, the
//! radius sampler, Rmax's quantile, renormalization and the profile's
//! shape (`docs/bssrdf.md` §10 and §12.1).

use super::axes::ProbeAxes;
use crate::bssrdf::radius::RadiusSampler;
use crate::error::{Constraint, Param, ParamError};

/// How the color channels share one probe sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ChannelStrategy {
    /// Estimate only the channel the radius was sampled for: one channel
    /// per sample (King et al. 2013), a research variant.
    Single,
    /// Estimate all channels with the balance heuristic over channels.
    #[default]
    Mis,
}

impl ChannelStrategy {
    /// The name the scene format and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            ChannelStrategy::Single => "single",
            ChannelStrategy::Mis => "mis",
        }
    }
}

/// The shape of the diffusion profile R(r).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ProfileShape {
    /// The normalized-diffusion fit (Christensen & Burley 2015).
    #[default]
    Burley,
    /// The half-space's transfer by the random walk, tabulated
    /// (`bssrdf::tabulated`); sampled by its own inverse CDF, so the
    /// radius sampler is not used. Materials that record no medium keep
    /// the fit.
    Tabulated,
}

impl ProfileShape {
    pub const ALL: [ProfileShape; 2] = [ProfileShape::Burley, ProfileShape::Tabulated];

    /// The name the scene format and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            ProfileShape::Burley => "burley",
            ProfileShape::Tabulated => "tabulated",
        }
    }
}

/// Options of the probe estimator; `Default` is the recommended setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeOptions {
    pub axes: ProbeAxes,
    pub channel: ChannelStrategy,
    pub radius: RadiusSampler,
    /// Rmax is this quantile of the widest active channel's profile.
    pub rmax_quantile: f64,
    /// Divide Rd by CDF(Rmax) so truncation loses no energy.
    pub renormalize: bool,
    /// The profile's shape.
    pub profile: ProfileShape,
}

impl Default for ProbeOptions {
    fn default() -> Self {
        ProbeOptions {
            axes: ProbeAxes::Curvature,
            channel: ChannelStrategy::Mis,
            radius: RadiusSampler::Analytic,
            rmax_quantile: 0.999,
            renormalize: false,
            profile: ProfileShape::Burley,
        }
    }
}

impl ProbeOptions {
    /// The configuration of the course report (README "The math") with a
    /// given radius sampler: normal axis, one channel per sample, no
    /// renormalization.
    pub fn seed_document(radius: RadiusSampler) -> Self {
        ProbeOptions {
            axes: ProbeAxes::Normal,
            channel: ChannelStrategy::Single,
            radius,
            rmax_quantile: 0.999,
            renormalize: false,
            profile: ProfileShape::Burley,
        }
    }

    pub fn validate(&self) -> Result<(), ParamError> {
        self.radius.validate()?;
        let q = self.rmax_quantile;
        if !(q > 0.0 && q < 1.0) {
            return Err(ParamError::new(
                Param::RmaxQuantile,
                q,
                Constraint::Open(0.0, 1.0),
            ));
        }
        Ok(())
    }
}
