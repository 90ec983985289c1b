//! What besides the scene decides the render plan.

use crate::film::passes::PassSet;
use crate::integrator::path::PAIR_DEPTH;
use crate::integrator::IntegratorKind;
use crate::sampling::SamplerKind;

/// What besides the scene decides the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanOptions {
    pub integrator: IntegratorKind,
    /// The passes asked for (`--aov`, else the scene's `[output] aovs`).
    pub passes: PassSet,
    /// Subsurface hits below this depth, on materials with `probe_pair`,
    /// sample an antithetic probe pair
    /// (`crate::integrator::Context::pair_depth`).
    pub pair_depth: u32,
    /// Subsurface hits below this depth, on materials with
    /// `control_variate`, add the plane control variate
    /// (`crate::integrator::Context::cv_depth`).
    pub cv_depth: u32,
    /// The sampler the render uses (`--sampler`); None: the scene's.
    pub sampler: Option<SamplerKind>,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            integrator: IntegratorKind::Path,
            passes: PassSet::default(),
            pair_depth: PAIR_DEPTH,
            #[cfg(feature = "subsurface")]
            cv_depth: crate::integrator::control_variate::CV_DEPTH,
            #[cfg(not(feature = "subsurface"))]
            cv_depth: 0,
            sampler: None,
        }
    }
}
