//! The pick of one hit among a probe segment's several, in proportion to
//! their scores (`docs/bssrdf.md` §5 step 4).

use super::randoms::ProbeRandoms;

/// The index of the hit one probe keeps among several, in proportion to
/// `scores` (each kept hit's Rd/p summed over channels, from
/// [`ProbeSampler::weigh`](super::ProbeSampler::weigh) with a count of 1), from the probe's `hit`
/// random number, and the factor that makes the pick unbiased:
///
/// ```text
/// P(k) = s_k / Σ_j s_j,   weight = Rd/p(x_k) × (total / kept) × Σ_j s_j / s_k,
/// ```
///
/// so E[weight·L] = (total/kept) Σ_{kept} Rd/p·L, the uniform pick's mean
/// (the kept hits are a uniform subset of the `total`). A segment that
/// crosses the body twice — a thin tile's top and bottom, both walls of a
/// sphere's far side — keeps the near, heavy hit nearly always instead of
/// half the time (docs/accuracy.md, "Sharp edges and thin bodies"). Hits of score 0 are
/// never picked; None when every score is 0 (nothing to scatter from).
pub fn pick_by_score(u: &ProbeRandoms, scores: &[f32], total: usize) -> Option<(usize, f32)> {
    let sum: f32 = scores.iter().sum();
    if !sum.is_finite() {
        return None;
    }
    let goal = u.hit as f32 * sum;
    let mut acc = 0.0;
    // the last hit with a score > 0 absorbs rounding in the running sum;
    // none (every score 0): nothing to pick
    let mut pick = scores.iter().rposition(|&s| s > 0.0)?;
    // goal ≥ 0, so a hit of score 0 never ends the scan: the running sum
    // it leaves unchanged was not above goal before it either
    for (k, &s) in scores.iter().enumerate() {
        acc += s;
        if goal < acc {
            pick = k;
            break;
        }
    }
    let factor = (total as f32 / scores.len() as f32) * (sum / scores[pick]);
    Some((pick, factor))
}
