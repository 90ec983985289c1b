//! The 64-bit mixer the samplers hash their keys with: the SplitMix64 /
//! Stafford "variant 13" finalizer (Steele et al. 2014), a bijection with
//! full avalanche.

#[inline]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The key of slot `slot` of a sample's sequence (`super::sampler`) under
/// `key`.
#[inline]
pub(crate) fn slot_key(key: u64, slot: u32) -> u64 {
    mix64(key ^ (slot as u64 + 1).wrapping_mul(0xa076_1d64_78bd_642f))
}
