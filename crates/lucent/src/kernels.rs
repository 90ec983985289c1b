//! Speed kernels: the places where lucent computes something less directly
//! than the equation it implements, because a measurement showed it pays.
//! Each is written beside the plain form it replaces and why the result is
//! the same (or how close); the rest of the renderer is written as its
//! equations, and a trick that cannot show a gain here goes.
//!
//! - [`exp4`]: e^x on four f32 lanes, for the probe density
//!   ([`crate::bssrdf::density`]);
//! - code placement (`#[inline(never)]`, `#[inline(always)]`) in the bounce
//!   loop of [`crate::integrator::path`];
//! - the antithetic probe pair's shared sampling and exit half.
//!
//! Measured gains, and the tricks measured and removed or not taken:
//! docs/performance.md, "Speed kernels".

use glam::Vec4;

/// e^x per lane, relative error ≤ 2 ulp for x ∈ [−87, 88]; 0 below −87.
///
/// Cody–Waite reduction x = n ln 2 + r with |r| ≤ ln 2 / 2, then Cephes'
/// degree-7 minimax polynomial for e^r (Moshier 1989, "Methods and Programs
/// for Mathematical Functions", `expf.c`) and 2^n built in the exponent bits.
/// Branch-free on 4 lanes (SSE2 on x86-64 through glam's `Vec4`).
#[inline(always)]
pub fn exp4(x: Vec4) -> Vec4 {
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let lo = Vec4::splat(-87.0);
    let xc = x.clamp(lo, Vec4::splat(88.0));
    // Adding 1.5·2²³ rounds to an integer held in the low mantissa bits.
    let t = xc * std::f32::consts::LOG2_E + MAGIC;
    let n = t - MAGIC;
    let r = (xc - n * LN2_HI) - n * LN2_LO;
    let mut p = Vec4::splat(1.987_569_2e-4);
    p = p * r + 1.398_2e-3;
    p = p * r + 8.333_452e-3;
    p = p * r + 4.166_579_6e-2;
    p = p * r + 1.666_666_5e-1;
    p = p * r + 0.5;
    let er = p * (r * r) + r + 1.0;
    Vec4::select(x.cmplt(lo), Vec4::ZERO, er * pow2_of_magic(t))
}

/// 1.5·2²³ (bits 0x4B40_0000), whose ulp is 1.
const MAGIC: f32 = 12_582_912.0;

/// 2^n for t = MAGIC + n (|n| ≤ 127): t's bits are MAGIC's plus n, so n + 127
/// shifted into the exponent field is 2^n.
#[inline(always)]
fn pow2_of_magic(t: Vec4) -> Vec4 {
    // MAGIC's bits (0x4B40_0000) less the exponent bias.
    const BIAS: i32 = 0x4B40_0000 - 127;
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is enabled (cfg above); these are pure lane operations.
        unsafe {
            let i = _mm_sub_epi32(_mm_castps_si128(t.into()), _mm_set1_epi32(BIAS));
            Vec4::from(_mm_castsi128_ps(_mm_slli_epi32::<23>(i)))
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        Vec4::from_array(
            t.to_array()
                .map(|t| f32::from_bits(((t.to_bits() as i32 - BIAS) as u32) << 23)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        if a == b {
            0.0
        } else {
            (a - b).abs() / b.abs()
        }
    }

    #[test]
    fn exp4_is_within_two_ulp_of_f64_exp() {
        // Dense over the whole normal range, and every reduction boundary
        // (n ln 2 ± ½ ln 2) where a wrong Cody–Waite split would show.
        let mut worst = 0.0f64;
        let mut xs: Vec<f32> = (0..=2_000_000)
            .map(|k| -87.0 + 175.0 * k as f32 / 2_000_000.0)
            .collect();
        for n in -125..=126 {
            for off in [-0.5f64, 0.5] {
                let b = (n as f64 + off) * std::f64::consts::LN_2;
                for db in [-1e-6, 0.0, 1e-6] {
                    xs.push((b + db) as f32);
                }
            }
        }
        for chunk in xs.chunks(4) {
            let mut x = [0.0f32; 4];
            x[..chunk.len()].copy_from_slice(chunk);
            let y = exp4(Vec4::from_array(x)).to_array();
            for i in 0..chunk.len() {
                if !(-87.0..=88.0).contains(&x[i]) {
                    continue;
                }
                let e = rel(y[i] as f64, (x[i] as f64).exp());
                worst = worst.max(e);
            }
        }
        // 2 ulp of f32 at the bottom of a binade is 2·2⁻²³ = 2.4e-7.
        assert!(worst < 2.4e-7, "worst relative error {worst:e}");
        assert_eq!(exp4(Vec4::ZERO), Vec4::ONE);
        assert_eq!(
            exp4(Vec4::new(-87.5, -1e30, f32::NEG_INFINITY, -88.0)),
            Vec4::ZERO
        );
        let tiny = exp4(Vec4::splat(-87.0)).x as f64;
        assert!(rel(tiny, (-87.0f64).exp()) < 2.4e-7);
    }
}
