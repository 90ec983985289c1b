//! The random numbers one probe consumes (`docs/bssrdf.md` §5 step 1).

use crate::sampling::{Draw, SampleRng};

/// The random numbers one probe consumes, each uniform in [0, 1) (and a
/// seed for the probe-hit subset when a segment has more than
/// `MAX_PROBE_HITS` hits).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeRandoms {
    pub axis: f64,
    pub channel: f64,
    pub radius: f64,
    pub angle: f64,
    pub hit: f64,
    pub seed: u32,
}

impl ProbeRandoms {
    /// Four draws instead of six: only the radius needs 53 bits (its
    /// inverse CDF resolves the tails); the discrete choices and the angle
    /// share draws at 32 bits each.
    pub fn from_rng(rng: &mut impl Draw) -> Self {
        let radius = rng.uniform_f64();
        let [axis, channel] = rng.uniform2_f64_32();
        let [angle, hit] = rng.uniform2_f64_32();
        ProbeRandoms {
            axis,
            channel,
            radius,
            angle,
            hit,
            seed: rng.next_u32(),
        }
    }

    /// A path's probe: [`from_rng`](Self::from_rng) with the `random`
    /// sampler; with a sequence, the radius, angle, channel and axis from
    /// one 4D point (the disk's point stratified within each channel's
    /// share), the hit choice from another slot.
    pub fn from_sample(rng: &mut SampleRng) -> Self {
        if !rng.stratifies() {
            return Self::from_rng(rng);
        }
        let [radius, angle, channel, axis] = rng.point4_f64();
        let hit = rng.uniform2_f64_32()[0];
        ProbeRandoms {
            axis,
            channel,
            radius,
            angle,
            hit,
            seed: rng.next_u32(),
        }
    }
}
