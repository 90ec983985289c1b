//! The variance pass from exact integer sums: per channel, the unbiased
//! estimate s²/n of the variance of the beauty mean, s² = Σ(x − x̄)²/(n − 1),
//! from Σq (the beauty's own sum, q = round(x·2^64) the integer each sample
//! added) and Σq², both exact:
//!
//!   s²/n = (n·Σq² − (Σq)²) · 2^−128 / (n²(n − 1)),
//!
//! the numerator computed exactly in 256-bit integers (≥ 0 by
//! Cauchy–Schwarz, exactly 0 when all samples are equal), so the only
//! roundings are its conversion to f64 and one division. q² < 2^190 is
//! carried as three i128 sums of its 64-bit words, which merge by addition
//! like every other channel (docs/farm.md, "Passes in parts").

/// The fixed-point format of Σq² words (each an integer: q² is in units
/// of 2^−128; the words are the fraction bits' 64-bit pieces).
pub(crate) const SQUARE_BITS: u32 = 128;

/// i128 sums a channel of the variance pass keeps: Σq²'s 64-bit words.
pub(crate) const SQUARE_WORDS: usize = 3;

/// q² of a term q (|q| ≤ 2^95) as its three 64-bit words, least
/// significant first (q² < 2^190).
#[inline]
pub(crate) fn square_words(q: i128) -> [i128; SQUARE_WORDS] {
    let w = mul_u128(q.unsigned_abs(), q.unsigned_abs());
    [
        w[0] as i128,
        w[1] as i128,
        (w[2] as i128) | (w[3] as i128) << 64,
    ]
}

/// The 256-bit product of two u128, as four u64 limbs, least significant
/// first.
fn mul_u128(a: u128, b: u128) -> [u64; 4] {
    let (a0, a1) = (a as u64 as u128, a >> 64);
    let (b0, b1) = (b as u64 as u128, b >> 64);
    let mut r = [0u64; 4];
    add_at(&mut r, 0, a0 * b0);
    add_at(&mut r, 1, a0 * b1);
    add_at(&mut r, 1, a1 * b0);
    add_at(&mut r, 2, a1 * b1);
    r
}

/// Adds `v` at limb `at` of `r` (a 256-bit unsigned integer), carrying.
fn add_at(r: &mut [u64; 4], at: usize, v: u128) {
    let mut carry = v;
    for limb in r.iter_mut().skip(at) {
        if carry == 0 {
            break;
        }
        let s = *limb as u128 + (carry as u64) as u128;
        *limb = s as u64;
        carry = (carry >> 64) + (s >> 64);
    }
}

/// The variance of the mean of `n` samples whose beauty terms sum to `s1`
/// and whose squared terms' words sum to `sq` (module docs), f32.
pub fn variance(s1: i128, sq: &[i128], n: u64) -> f32 {
    if n < 2 {
        return f32::INFINITY;
    }
    // Σq² (each word sum is non-negative and < 2^96)
    let mut sum_sq = [0u64; 4];
    for (k, &w) in sq.iter().enumerate() {
        add_at(&mut sum_sq, k, w as u128);
    }
    // n·Σq² (< 2^254)
    let mut lhs = [0u64; 4];
    for (k, &limb) in sum_sq.iter().enumerate() {
        add_at(&mut lhs, k, limb as u128 * n as u128);
    }
    // − (Σq)², never below 0 (Cauchy–Schwarz); saturate a forged part
    let rhs = mul_u128(s1.unsigned_abs(), s1.unsigned_abs());
    let mut num = [0u64; 4];
    let mut borrow = false;
    for k in 0..4 {
        let (d, b1) = lhs[k].overflowing_sub(rhs[k]);
        let (d, b2) = d.overflowing_sub(borrow as u64);
        num[k] = d;
        borrow = b1 || b2;
    }
    if borrow {
        return 0.0;
    }
    let num: f64 = num
        .iter()
        .enumerate()
        .map(|(k, &l)| l as f64 * (2f64).powi(64 * k as i32 - SQUARE_BITS as i32))
        .sum();
    let n = n as f64;
    (num / (n * n * (n - 1.0))) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::accumulate::FixedPoint;

    #[test]
    fn squares_and_the_variance_numerator_are_exact() {
        let m = u64::MAX as i128;
        for (q, w) in [
            (0i128, [0, 0, 0]),
            (-3, [9, 0, 0]),
            (1 << 95, [0, 0, 1 << 62]),
            ((1 << 64) + 1, [1, 2, 1]),
            (-((1 << 64) - 1), [1, m - 1, 0]),
        ] {
            assert_eq!(square_words(q), w, "{q}");
        }
        // equal samples: exactly zero variance, at any magnitude
        for x in [1.0f32, 0.1, 3.0e9, 1e-30] {
            let q = FixedPoint::RADIANCE.to_fixed(x).0;
            let n = 37u64;
            let sq: Vec<i128> = square_words(q).iter().map(|w| w * n as i128).collect();
            assert_eq!(variance(q * n as i128, &sq, n), 0.0, "{x}");
        }
        // 0 and 1, n = 2: mean 1/2, s² = 1/2, s²/n = 1/4
        let q = FixedPoint::RADIANCE.to_fixed(1.0).0;
        assert_eq!(variance(q, &square_words(q), 2), 0.25);
        // against f64 on small integers: 1, 2, 3, 4 → s² = 5/3, /4
        let mut s1 = 0;
        let mut sq = [0i128; 3];
        for x in [1.0f32, 2.0, 3.0, 4.0] {
            let q = FixedPoint::RADIANCE.to_fixed(x).0;
            s1 += q;
            for (a, b) in sq.iter_mut().zip(square_words(q)) {
                *a += b;
            }
        }
        assert_eq!(variance(s1, &sq, 4), (5.0f64 / 3.0 / 4.0) as f32);
        assert_eq!(variance(s1, &sq, 1), f32::INFINITY);
        // against f64 on fractional samples, whose squares fill every limb,
        // so n·Σq² − (Σq)² borrows across limbs: a borrow dropped between
        // the second and third limb is an error of 1/(n²(n − 1)) in the
        // result, far above f32 rounding
        let mut rng = crate::sampling::Rng::from_key(7);
        for n in [2u64, 3, 5, 16] {
            for _ in 0..20 {
                let xs: Vec<f32> = (0..n).map(|_| rng.uniform_f64() as f32).collect();
                let (mut s1, mut sq) = (0i128, [0i128; 3]);
                for &x in &xs {
                    let q = FixedPoint::RADIANCE.to_fixed(x).0;
                    s1 += q;
                    for (a, b) in sq.iter_mut().zip(square_words(q)) {
                        *a += b;
                    }
                }
                let nf = n as f64;
                let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / nf;
                let s2 = xs.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / (nf - 1.0);
                let want = s2 / nf;
                let got = variance(s1, &sq, n) as f64;
                assert!(
                    (got - want).abs() <= 1e-6 * want + 1e-12,
                    "n = {n}, {xs:?}: {got} against {want}"
                );
            }
        }
    }
}
