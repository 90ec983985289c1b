//! Exact, order-free per-pixel sums of samples: each sample's f32 channels
//! are added as fixed-point integers, so a pixel's sum does not depend on
//! the order of its samples, and the sums of disjoint sample ranges, tiles
//! or machines add up to exactly the sum of one uninterrupted run.
//!
//! # Why fixed point
//!
//! Floating-point addition is not associative: summing a pixel's samples
//! in two halves and adding the halves rounds differently from summing them
//! in index order, so a frame merged from parts would differ from the
//! single-machine frame in the last bits. Integer addition is associative
//! and commutative. A sample `x` (an f32) becomes the integer
//! `round(x · 2^F)` ([`FixedPoint::to_fixed`]), sums are `i128`, and the
//! pixel's value is the mean `sum · 2^−F / n` rounded once to f32
//! ([`FixedPoint::mean`]). Every render — one machine or many, one pass or
//! many, resumed or not — goes through this one accumulation, so "merged
//! == uncut" holds by construction (docs/farm.md).
//!
//! # Range and resolution (radiance: F = 64, [`FixedPoint::RADIANCE`])
//!
//! An `i128` holds magnitudes below 2^127. A pixel sums at most
//! `u32::MAX` < 2^32 samples (the sample indices are `u32`), so each term is
//! held to |term| ≤ 2^95: then |sum| ≤ (2^32 − 1) · 2^95 < 2^127 and no sum
//! of any subset of a pixel's samples can overflow. With F = 64:
//!
//! - **resolution** 2^−64 ≈ 5.4·10^−20: every f32 with |x| ≥ 2^−41
//!   (≈ 4.5·10^−13) has its ulp ≥ 2^−64 and converts **exactly**; smaller
//!   magnitudes round to the nearest multiple of 2^−64 (an absolute error ≤
//!   2^−65 per sample, twelve orders of magnitude below anything an image
//!   shows);
//! - **range** |x| ≤ 2^31 ≈ 2.1·10^9 ([`FixedPoint::max_sample`]): a
//!   sample beyond it is clamped to ±2^31 (still per sample, so still
//!   order-free) and counted, and the render says how many were clamped.
//!   Radiance that large in one sample is a firefly many orders above any
//!   light in a scene.
//! - Non-finite samples never reach the sums: the renderer drops and counts
//!   them first, as before.
//!
//! Another channel set picks its own F: a layer of squared samples (for
//! variance) needs a range of x², e.g. F = 32 covers x² ≤ 2^63 at a
//! resolution of 2.3·10^−10. The bound on the term is always 2^95, so the
//! overflow argument above holds for every F.
//!
//! # Precision of the mean
//!
//! [`FixedPoint::mean`] converts the exact sum to f64 (one rounding, 2^−53
//! relative), scales by 2^−F (exact) and divides by n (one rounding), then
//! rounds to f32: within one f32 ulp of the exact mean of the (converted)
//! samples, and a function of the sum and n alone. The former f64 running
//! sum in index order carried up to n·2^−53 relative error before the same
//! final rounding, so the two agree to f32 rounding (measured in
//! docs/farm.md).
//!
//! # Cost
//!
//! Per sample and channel: one f32→f64 widening, a multiply, a clamp, a
//! round and an f64→i128 conversion, then a 128-bit add; beside a path
//! traced sample (microseconds) it does not show (docs/farm.md). Memory:
//! 16 bytes a channel a pixel.

/// The fixed-point format of a layer's sums: an integer `v` stands for
/// `v · 2^−frac_bits`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct FixedPoint {
    pub frac_bits: u32,
}

/// The largest magnitude of one term of a sum, as a power of two: with at
/// most `u32::MAX` terms, a sum stays below 2^127.
pub(crate) const TERM_BITS: u32 = 95;

impl FixedPoint {
    /// Radiance (beauty and light-path layers): Q63.64, exact for f32 in
    /// [2^−41, 2^31] in magnitude.
    pub const RADIANCE: FixedPoint = FixedPoint { frac_bits: 64 };

    /// A format with `frac_bits` fractional bits, if it leaves a range of
    /// at least 1 and is at most 126 (so 2^F is finite in f64 and the
    /// range/resolution arguments hold).
    pub fn new(frac_bits: u32) -> Option<FixedPoint> {
        (frac_bits <= TERM_BITS).then_some(FixedPoint { frac_bits })
    }

    /// The largest sample magnitude held as is: 2^(95 − F).
    pub fn max_sample(self) -> f64 {
        (2f64).powi(TERM_BITS as i32 - self.frac_bits as i32)
    }

    /// The smallest magnitude every f32 above which converts exactly:
    /// 2^(23 − F) (an f32's ulp is 2^−23 of its leading bit).
    pub fn exact_from(self) -> f64 {
        (2f64).powi(23 - self.frac_bits as i32)
    }

    /// `x` (finite) as a term: `round(x · 2^F)`, ties to even, clamped to
    /// ±2^95; and whether it was clamped.
    #[inline]
    pub fn to_fixed(self, x: f32) -> (i128, bool) {
        const LIMIT: f64 = (1u128 << TERM_BITS) as f64;
        // exact: f32 → f64 widens, a power of two scales exactly (no
        // overflow: |x| < 2^128, 2^128 · 2^95 is far inside f64)
        let v = x as f64 * (2f64).powi(self.frac_bits as i32);
        let clamped = v.abs() > LIMIT;
        // round half to even: below 2^52, adding and removing ±2^52 leaves
        // an ulp of 1, and the hardware's default rounding does the rest
        // (no call to the library's rint); from 2^52 on v is an integer
        const TWO52: f64 = 4503599627370496.0;
        let v = v.clamp(-LIMIT, LIMIT);
        let v = if v.abs() < TWO52 {
            let m = TWO52.copysign(v);
            (v + m) - m
        } else {
            v
        };
        // integer-valued and |v| ≤ 2^95, converted exactly without the
        // slow f64 → i128 library call: hi = v truncated to a multiple of
        // 2^48 (|hi| ≤ 2^47), lo = v − hi·2^48 (exact: the low bits of v,
        // |lo| < 2^48); both fit an i64. The cast truncates towards zero
        // (one cvttsd2si; f64::trunc is a library call on x86-64 without
        // SSE4.1, 19 instructions a channel: docs/performance.md, "Zero
        // cost for what is off").
        let hi = (v * (2f64).powi(-48)) as i64;
        let lo = v - hi as f64 * (2f64).powi(48);
        (((hi as i128) << 48) + lo as i64 as i128, clamped)
    }

    /// The mean of `n` samples whose terms sum to `sum`, as f32 (0 when n
    /// is 0). Depends on `sum` and `n` alone.
    #[inline]
    pub fn mean(self, sum: i128, n: u64) -> f32 {
        if n == 0 {
            return 0.0;
        }
        (sum as f64 * (2f64).powi(-(self.frac_bits as i32)) / n as f64) as f32
    }

    /// Adds one sample's channels to a pixel's sums; returns how many
    /// channels were clamped (see [`to_fixed`](Self::to_fixed)).
    #[inline]
    pub fn add(self, sums: &mut [i128], sample: &[f32]) -> u32 {
        debug_assert_eq!(sums.len(), sample.len());
        let mut clamped = 0;
        for (s, &x) in sums.iter_mut().zip(sample) {
            let (v, c) = self.to_fixed(x);
            *s += v;
            clamped += c as u32;
        }
        clamped
    }
}

/// A 128-bit sum as four 32-bit words, least significant first (how a
/// part file stores it: EXR's only integer sample type is u32).
pub fn to_words(v: i128) -> [u32; 4] {
    let u = v as u128;
    [
        u as u32,
        (u >> 32) as u32,
        (u >> 64) as u32,
        (u >> 96) as u32,
    ]
}

/// The inverse of [`to_words`].
pub(crate) fn from_words(w: [u32; 4]) -> i128 {
    (w[0] as u128 | (w[1] as u128) << 32 | (w[2] as u128) << 64 | (w[3] as u128) << 96) as i128
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: FixedPoint = FixedPoint::RADIANCE;

    /// A small deterministic generator (xorshift), for orders and values.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    /// Wide-ranging f32 samples: magnitudes from 1e-25 to 1e9, some zero,
    /// a few negative.
    fn samples(n: usize, seed: u64) -> Vec<f32> {
        let mut s = seed | 1;
        (0..n)
            .map(|_| {
                let r = xorshift(&mut s);
                let mag = 10f64.powf((r % 3400) as f64 / 100.0 - 25.0);
                let sign = if r.is_multiple_of(7) { -1.0 } else { 1.0 };
                if r.is_multiple_of(11) {
                    0.0
                } else {
                    (sign * mag) as f32
                }
            })
            .collect()
    }

    #[test]
    fn sums_do_not_depend_on_order_or_grouping() {
        let xs = samples(10_000, 7);
        let total: i128 = xs.iter().map(|&x| F.to_fixed(x).0).sum();
        let mut s = 99;
        for _ in 0..20 {
            // a random permutation, summed in random groups, groups summed
            let mut ys = xs.clone();
            for i in (1..ys.len()).rev() {
                ys.swap(i, xorshift(&mut s) as usize % (i + 1));
            }
            let mut groups = Vec::new();
            let mut rest = &ys[..];
            while !rest.is_empty() {
                let k = 1 + xorshift(&mut s) as usize % rest.len();
                let (a, b) = rest.split_at(k);
                let mut g = [0i128];
                for &x in a {
                    F.add(&mut g, &[x]);
                }
                groups.push(g[0]);
                rest = b;
            }
            groups.reverse();
            assert_eq!(groups.iter().sum::<i128>(), total);
        }
        // while f64 sums of the same permutations differ (the reason for
        // all this): the test above would be vacuous if they did not
        let fwd: f64 = xs.iter().map(|&x| x as f64).sum();
        let rev: f64 = xs.iter().rev().map(|&x| x as f64).sum();
        assert_ne!(fwd.to_bits(), rev.to_bits());
    }

    #[test]
    fn conversion_is_exact_in_range_and_rounds_below_it() {
        // exact: every f32 with 2^-41 <= |x| <= 2^31 round-trips
        for x in [
            2f32.powi(-41),
            1.0e-12,
            0.1,
            1.0,
            3.5e7,
            2f32.powi(31),
            -0.75,
        ] {
            let (v, c) = F.to_fixed(x);
            assert!(!c);
            assert_eq!(v as f64 * 2f64.powi(-64), x as f64, "{x}");
        }
        // the split conversion equals the direct one, for every format
        for f in [0, 32, 64, 80] {
            let fp = FixedPoint::new(f).unwrap();
            for x in samples(20_000, 11 + f as u64) {
                let direct = (x as f64 * 2f64.powi(f as i32))
                    .clamp(-(2f64.powi(95)), 2f64.powi(95))
                    .round_ties_even() as i128;
                assert_eq!(fp.to_fixed(x).0, direct, "{x} at F = {f}");
            }
        }
        assert_eq!(F.exact_from(), 2f64.powi(-41));
        assert_eq!(F.max_sample(), 2f64.powi(31));
        // below: the nearest multiple of 2^-64, ties to even
        assert_eq!(F.to_fixed(2f32.powi(-66)).0, 0);
        assert_eq!(F.to_fixed(3.0 * 2f32.powi(-65)).0, 2); // 1.5 -> 2
        assert_eq!(F.to_fixed(2f32.powi(-65)).0, 0); // 0.5 -> 0
        assert_eq!(F.to_fixed(1e-30).0, 0);
        // above: clamped to ±2^95 and reported
        assert_eq!(F.to_fixed(3e9), (1i128 << 95, true));
        assert_eq!(F.to_fixed(-f32::MAX), (-(1i128 << 95), true));
        assert!(!F.to_fixed(2f32.powi(31)).1);
    }

    #[test]
    fn the_largest_sums_do_not_overflow() {
        // u32::MAX terms of ±2^95 fit in an i128, for every format
        let worst = (1i128 << 95).checked_mul(u32::MAX as i128).unwrap();
        assert!(worst.checked_neg().is_some());
        // and one more term would not: the bound on the term is tight
        assert!((1i128 << 95).checked_mul(1 << 32).is_none());
        for f in [0, 32, 64, 95] {
            let fp = FixedPoint::new(f).unwrap();
            assert_eq!(fp.to_fixed(f32::MAX).0, 1i128 << 95);
        }
        assert_eq!(FixedPoint::new(96), None);
    }

    #[test]
    fn the_mean_is_the_f32_rounding_of_the_exact_mean() {
        // n samples of one value: the mean is the value
        for x in [0.1f32, 1.0, 7.25e-5, 123456.78, 2f32.powi(31)] {
            let (v, _) = F.to_fixed(x);
            for n in [1u64, 3, 1000, 1 << 20] {
                assert_eq!(F.mean(v * n as i128, n), x, "{x} x {n}");
            }
        }
        // against the f64 mean of exactly representable samples
        let xs = samples(4096, 3);
        let xs: Vec<f32> = xs.iter().map(|x| x.clamp(-1e6, 1e6)).collect();
        let sum: i128 = xs.iter().map(|&x| F.to_fixed(x).0).sum();
        let exact: f64 = xs.iter().map(|&x| x as f64).sum::<f64>() / xs.len() as f64;
        let m = F.mean(sum, xs.len() as u64);
        assert!(((m as f64 - exact) / exact).abs() < 1.2e-7, "{m} {exact}");
        assert_eq!(F.mean(12345, 0), 0.0);
    }

    #[test]
    fn words_round_trip() {
        for v in [0i128, 1, -1, i128::MAX, i128::MIN, 1 << 95, -(3 << 70) + 5] {
            assert_eq!(from_words(to_words(v)), v);
        }
        assert_eq!(to_words(1 << 64), [0, 0, 1, 0]);
        assert_eq!(to_words(-1), [u32::MAX; 4]);
    }
}
