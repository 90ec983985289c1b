//! What one render thread carries through the bounce loop: its random
//! numbers, reusable buffers, tallies and the recorder of light-path parts.

use super::aov::Recorder;
use super::Counters;
use crate::accel::ProbeHits;
use crate::sampling::SampleRng;

/// Per-thread buffers the integrator reuses so the hot path never allocates.
#[derive(Default)]
pub struct Scratch {
    pub probe_hits: ProbeHits,
}

/// The per-thread state every hot function of the bounce loop reads and
/// writes, passed as one value.
pub(crate) struct PathState<'a, R: Recorder> {
    pub(crate) rng: &'a mut SampleRng,
    #[cfg_attr(not(feature = "subsurface"), allow(dead_code))]
    pub(crate) scratch: &'a mut Scratch,
    pub(crate) counters: &'a mut Counters,
    pub(crate) rec: &'a mut R,
}
