//! The probe estimator's per-hit arithmetic in f32 with a polynomial exp:
//! the balance-heuristic density of an entry point over axes and channels,
//! and Rd at its distance (`docs/bssrdf.md` §5; pbrt-v3 `Pdf_Sp`), for the
//! exact radius samplers (analytic and mixture), whose disk pdf is
//! R(r)/CDF(Rmax) (Christensen & Burley 2015, eq. 2).
//!
//! The f64 evaluation in [`super::probe`] stays the reference and serves the
//! other samplers. This path exists because the reference spent about as
//! many instructions per probe hit as the probe query itself: 12 libm `exp`
//! calls (3 channels × 3 axes for the density, 3 for Rd) in f64. Here the
//! four radii of one hit — the disk radius for each axis and the 3D
//! distance — sit in the four lanes of one `[f32; 4]`, so each channel costs
//! one 4-wide [`exp4`] that the compiler vectorizes.
//!
//! Why f32 suffices: the weight leaves the sampler as f32 anyway, and every
//! quantity is scaled by the widest channel's d so that the range of each
//! does not depend on scene units; radii come from squared local coordinates
//! computed in f64 (no cancellation at small r). Where it would not suffice
//! — a channel whose profile underflows f32 within Rmax (ratio of the
//! channels' d beyond [`RHO_F32_MAX`]/quantile) — [`FastProbe::new`]
//! declines and the f64 reference is used. Tests bound both the exp's and
//! the weights' relative error against the f64 reference.

use glam::Vec4;

use super::profile::RHO_MIN;

/// The largest r/d at which the f32 path evaluates a channel: e^{−ρ/3} at
/// this ρ is 1.8e-35, still a normal f32 (and [`exp4`] is exact to 2 ulp down
/// to e^{−87}).
pub const RHO_F32_MAX: f64 = 240.0;

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

/// Per-material constants of the f32 path, all lengths in units of the
/// widest active channel's d (written L below).
#[derive(Clone, Debug)]
pub struct FastProbe {
    /// 1/L in scene units.
    inv_len: f64,
    /// Rmax / L in the three disk-radius lanes, ∞ in the distance lane
    /// (the clamp of the radii; the lanes are built once, not per hit).
    rmax: Vec4,
    /// Per channel, in every lane: −1/(3 d/L), the exponent's scale.
    neg_inv3d: [Vec4; 3],
    /// Per channel, in every lane: RHO_MIN·d/L, the radius clamp of
    /// `profile::profile`; 1 for an inactive channel so it never divides
    /// by 0.
    rmin: [Vec4; 3],
    /// Per channel: L²·pdf_disk(r)·r/(e^{−ρ} + e^{−ρ/3}) = L/(8π d CDF(Rmax)).
    k_pdf: [f32; 3],
    /// Per channel: L²·Rd(r)·r/(e^{−ρ} + e^{−ρ/3}) = scale·L/(8π d).
    k_rd: [f32; 3],
}

impl FastProbe {
    /// `d`, `scale` (A, or A/CDF(Rmax)) and `mass` (CDF(Rmax)) per channel,
    /// `active` the channels with A > 0 and d > 0. None when some active
    /// channel's r/d can exceed [`RHO_F32_MAX`] within Rmax.
    pub fn new(
        d: [f64; 3],
        scale: [f64; 3],
        mass: [f64; 3],
        active: [bool; 3],
        rmax: f64,
    ) -> Option<Self> {
        let len = (0..3)
            .filter(|&c| active[c])
            .map(|c| d[c])
            .fold(0.0, f64::max);
        let d_min = (0..3)
            .filter(|&c| active[c])
            .map(|c| d[c])
            .fold(f64::INFINITY, f64::min);
        if !(len > 0.0 && len.is_finite() && rmax / d_min <= RHO_F32_MAX) {
            return None;
        }
        let per = |f: &dyn Fn(usize) -> f64, off: f32| -> [f32; 3] {
            std::array::from_fn(|c| if active[c] { f(c) as f32 } else { off })
        };
        let pi8 = 8.0 * std::f64::consts::PI;
        Some(FastProbe {
            inv_len: 1.0 / len,
            rmax: {
                let r = (rmax / len) as f32;
                Vec4::new(r, r, r, f32::INFINITY)
            },
            neg_inv3d: per(&|c| len / (3.0 * d[c]), 0.0).map(|v| Vec4::splat(-v)),
            rmin: per(&|c| RHO_MIN * d[c] / len, 1.0).map(Vec4::splat),
            k_pdf: per(&|c| len / (pi8 * d[c] * mass[c]), 0.0),
            k_rd: per(&|c| scale[c] * len / (pi8 * d[c]), 0.0),
        })
    }

    /// The weights Rd(|xo − xi|)/p(xi) per channel, before the hit count, for
    /// an entry point at `local` = (xi − xo) in the shading frame (T, B, N),
    /// with `cos` = |V_a·N(xi)| and `probs` the axis probabilities (T, B, N).
    /// `single` is the sampled channel under [`ChannelStrategy::Single`]
    /// (p is then that channel's density alone), None for the balance
    /// heuristic over channels. None when p is 0 or not finite.
    ///
    /// [`ChannelStrategy::Single`]: super::ChannelStrategy::Single
    #[inline]
    pub fn weights(
        &self,
        local: [f64; 3],
        cos: [f32; 3],
        probs: [f32; 3],
        single: Option<usize>,
        n_active: usize,
    ) -> Option<[f32; 3]> {
        let [x, y, z] = local.map(|v| v * self.inv_len);
        let (x2, y2, z2) = (x * x, y * y, z * z);
        // Lanes: disk radius ⟂ T, ⟂ B, ⟂ N, then the 3D distance. Rounding
        // can put a hit just outside the sphere; the disk radii are kept on
        // the disk so the sampled axis never scores 0 (as the reference).
        let r2 = [y2 + z2, x2 + z2, x2 + y2, x2 + y2 + z2].map(|v| (v as f32).sqrt());
        let r = Vec4::from_array(r2).min(self.rmax);
        let w = Vec4::new(probs[0] * cos[0], probs[1] * cos[1], probs[2] * cos[2], 0.0);
        let mut pdf = [0.0f32; 3];
        let mut rd = [0.0f32; 3];
        for c in 0..3 {
            let rc = r.max(self.rmin[c]);
            let e = exp4(rc * self.neg_inv3d[c]);
            let v = (e * e * e + e) / rc;
            pdf[c] = self.k_pdf[c] * w.dot(v);
            rd[c] = self.k_rd[c] * v.w;
        }
        let p = match single {
            Some(ch) => pdf[ch],
            None => pdf[0] + pdf[1] + pdf[2],
        } / n_active as f32;
        if !(p > 0.0 && p.is_finite()) {
            return None;
        }
        let inv = 1.0 / p;
        Some(match single {
            Some(ch) => std::array::from_fn(|c| if c == ch { rd[c] * inv } else { 0.0 }),
            None => rd.map(|v| v * inv),
        })
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

    #[test]
    fn vanishing_ratio_of_d_declines_the_f32_path() {
        let a = [true; 3];
        let ok = FastProbe::new([1.0, 0.5, 0.1], [0.5; 3], [0.99; 3], a, 19.86);
        assert!(ok.is_some());
        // Rmax = 19.86 (d = 1) and d = 0.05 in blue: r/d reaches 397 > 240.
        let no = FastProbe::new([1.0, 0.5, 0.05], [0.5; 3], [0.99; 3], a, 19.86);
        assert!(no.is_none());
        // an inactive narrow channel does not count
        let off = FastProbe::new(
            [1.0, 0.5, 1e-9],
            [0.5; 3],
            [0.99; 3],
            [true, true, false],
            19.86,
        );
        assert!(off.is_some());
    }
}
