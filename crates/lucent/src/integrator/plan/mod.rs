//! The render plan: what a scene needs simulated, decided once before
//! rendering, so a scene without lights, environment or subsurface
//! materials pays nothing for them.
//!
//! The plan has two faces. [`Plan`] is what the bounce loop reads: a few
//! booleans, tested once per vertex where the effect would be estimated
//! (a branch the predictor learns at once, since it never changes within
//! a render). [`Explanation`] ([`explain`]) is the same decision written
//! out for people and pipelines: every effect, the method chosen and the
//! reason, per material where materials differ. `lucent render --explain`
//! prints it ([`text`] for people, JSON for pipelines) and the EXR header
//! stores it (`lucent/plan`, `docs/output.md`). Both are derived from the
//! same scene and options by the functions of this module, and the tests
//! (`tests/cli/plan.rs`) check that the explanation says what the flags do
//! and that a render honours it (no probe ray where it says none).

#[cfg(feature = "subsurface")]
pub mod budget;
mod choice;
pub mod explain;
mod materials;
mod options;
pub mod text;

use crate::scene::Scene;

pub use explain::{Explanation, PlanOptions};

/// The flags the hot path reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Some object emits: do next-event estimation.
    pub area_lights: bool,
    /// Escaping rays see a non-zero environment.
    pub environment: bool,
    /// The environment is an image: light-sample it where lights are
    /// sampled, and weigh what escaping rays find by MIS.
    pub environment_map: bool,
    /// Some object has a subsurface material: probe rays will be cast.
    pub subsurface: bool,
    /// Some object's subsurface hits are estimated by the random walk (an
    /// accuracy budget chose it, [`budget`]): the path integrator then asks
    /// at each subsurface hit which estimator its object takes;
    /// without one every hit is diffusion's, chosen once per render
    /// ([`super::IntegratorKind::radiance`]).
    pub walks: bool,
    /// The scene has `[[lights]]`: light-sample them where lights are
    /// sampled, and weigh what rays find of them by MIS.
    pub analytic_lights: bool,
    /// A transparent film: camera rays that escape add nothing.
    pub transparent: bool,
}

impl Plan {
    pub fn new(scene: &Scene) -> Self {
        Plan {
            area_lights: scene.objects.iter().any(|o| emits(o.emission)),
            environment: scene.environment.as_ref().is_some_and(|e| !e.is_black()),
            environment_map: scene
                .environment
                .as_ref()
                .is_some_and(|e| e.map().is_some()),
            subsurface: scene
                .objects
                .iter()
                .any(|o| scene.materials[o.material].is_subsurface()),
            walks: scene.objects.iter().any(|o| o.walk),
            analytic_lights: !scene.lights.is_empty(),
            transparent: scene.output.file.transparent == Some(true),
        }
    }
}

/// Whether an object's emission makes it a light.
pub(crate) fn emits(e: Option<crate::geometry::Vec3>) -> bool {
    e.is_some_and(|e| e.max_element() > 0.0)
}
