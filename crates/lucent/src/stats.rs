//! The render's tallies: ray queries (in total and by [`Effect`]), samples
//! dropped or clamped, random walks cut short, and the clock ticks of
//! `--stats` (`crate::integrator::effects`). Kept apart from the
//! integrator that counts them so that what stores them (parts,
//! `crate::farm`) need not depend on it.

use serde::{Deserialize, Serialize};

/// The effects ray queries and time are counted by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect {
    /// Nearest-hit queries of camera rays (one a sample).
    Camera,
    /// Nearest-hit queries of paths continued after a bounce (lobe,
    /// dielectric, coat reflection, a medium's exit).
    Indirect,
    /// Light samples at vertices and their shadow rays.
    Direct,
    /// Subsurface hits under diffusion: the coat and the probe rays.
    Probe,
    /// Subsurface hits under the random walk: the walk's flights.
    Walk,
}

/// How many [`Effect`]s there are.
pub const EFFECTS: usize = 5;

impl Effect {
    pub const ALL: [Effect; EFFECTS] = [
        Effect::Camera,
        Effect::Indirect,
        Effect::Direct,
        Effect::Probe,
        Effect::Walk,
    ];

    /// The name the summary and the docs use.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Camera => "camera rays",
            Effect::Indirect => "indirect continuation",
            Effect::Direct => "direct light (shadow rays)",
            Effect::Probe => "subsurface probes (and coat)",
            Effect::Walk => "random walk",
        }
    }
}

/// Per-thread tallies, summed after rendering (no shared atomics in the
/// hot loop). Serialized (in parts): the totals of the samples, not the
/// ray-query breakdown and ticks of one render's `--stats`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Counters {
    /// Ray queries issued: nearest, shadow and probe.
    pub rays: u64,
    /// Samples whose radiance was not finite and was discarded.
    pub nonfinite: u64,
    /// Sample channels beyond the accumulator's range, clamped to it
    /// (`crate::film::accumulate`).
    pub clamped: u64,
    /// Random walks stopped at the cap on events inside a medium.
    pub walks_capped: u64,
    /// Random walks that left an open mesh through a hole (no boundary hit).
    pub walks_escaped: u64,
    /// Of `rays`, those answered without the accelerator: proven to meet
    /// nothing (`crate::integrator::culling`).
    #[serde(skip)]
    pub culled: u64,
    /// Ray queries by [`Effect`]: they sum to `rays`.
    #[serde(skip)]
    pub effect_rays: [u64; EFFECTS],
    /// Clock ticks by [`Effect`] (0 unless timed,
    /// `crate::integrator::effects`).
    #[serde(skip)]
    pub effect_ticks: [u64; EFFECTS],
    /// Clock ticks of whole samples (0 unless timed).
    #[serde(skip)]
    pub sample_ticks: u64,
}

impl Counters {
    /// Probe queries made (subsurface probes; none under level of detail).
    pub fn probes(&self) -> u64 {
        self.effect_rays[Effect::Probe as usize]
    }

    /// One ray query made for `effect`.
    #[inline(always)]
    pub fn ray(&mut self, effect: Effect) {
        self.rays += 1;
        self.effect_rays[effect as usize] += 1;
    }

    /// `samples` samples traced their camera ray. The bounce loop counts
    /// every nearest-hit query as [`Effect::Indirect`] (so it does not test
    /// which is the camera's: one add a ray, as before the counts); every
    /// sample makes exactly one camera query, so the tile loop moves one a
    /// sample to [`Effect::Camera`].
    pub fn camera_rays(&mut self, samples: u64) {
        self.effect_rays[Effect::Camera as usize] += samples;
        self.effect_rays[Effect::Indirect as usize] -= samples;
    }
}

impl std::ops::AddAssign for Counters {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.nonfinite += o.nonfinite;
        self.clamped += o.clamped;
        self.walks_capped += o.walks_capped;
        self.walks_escaped += o.walks_escaped;
        self.culled += o.culled;
        for e in 0..EFFECTS {
            self.effect_rays[e] += o.effect_rays[e];
            self.effect_ticks[e] += o.effect_ticks[e];
        }
        self.sample_ticks += o.sample_ticks;
    }
}
