//! How error falls with samples, in the report: relMSE × spp at every rung
//! for the sampler × estimator configurations and the denoised one (flat
//! for independent samples, falling where a sequence sampler pays, rising
//! where a denoiser's error stops falling like 1/spp), and headlines
//! saying so (docs/accuracy.md, "Low-discrepancy sampling" and
//! "Denoising").

use std::fmt::Write as _;

use super::compare::{ladder_of, time_sentence};
use super::config::{self, Axis, Config};
use super::results::Row;

/// The configurations whose convergence the report tabulates: the
/// baseline, the random walk, the other sampler and the denoised baseline.
pub(super) fn compared(configs: &[Config]) -> impl Iterator<Item = &Config> {
    configs.iter().filter(|c| {
        matches!(
            c.axis,
            Axis::Baseline | Axis::Integrator | Axis::Sampler | Axis::Denoise
        )
    })
}

/// The "relMSE × spp" section: one row per compared configuration, one
/// column per rung.
pub(super) fn table(r: &mut String, configs: &[Config], rows: &[Row]) {
    let cs: Vec<&Config> = compared(configs).collect();
    let Some(spps) = cs.first().map(|c| {
        ladder_of(rows, &c.name)
            .iter()
            .map(|x| x.spp)
            .collect::<Vec<u32>>()
    }) else {
        return;
    };
    if cs.len() < 2 || spps.is_empty() {
        return;
    }
    writeln!(r, "## relMSE × spp by sample count\n").unwrap();
    writeln!(
        r,
        "Flat for independent samples (error ∝ 1/spp); falling where the sampler's points are \
         better than independent; rising where the error stops falling like 1/spp (a denoiser's \
         bias and its smoothing).\n"
    )
    .unwrap();
    let head: Vec<String> = spps.iter().map(|n| n.to_string()).collect();
    writeln!(
        r,
        "| configuration | sampler | integrator | denoised | {} |",
        head.join(" | ")
    )
    .unwrap();
    writeln!(r, "|---|---|---|---|{}", "---|".repeat(spps.len())).unwrap();
    for c in cs {
        let ladder = ladder_of(rows, &c.name);
        let cells: Vec<String> = spps
            .iter()
            .map(|&n| match ladder.iter().find(|x| x.spp == n) {
                Some(x) => format!("{:.4}", x.rel_mse * n as f64),
                None => "—".into(),
            })
            .collect();
        writeln!(
            r,
            "| {} | {} | {} | {} | {} |",
            c.name,
            c.sampler.name(),
            config::integrator_name(c.integrator),
            if c.denoise { "yes" } else { "no" },
            cells.join(" | ")
        )
        .unwrap();
    }
    writeln!(r).unwrap();
}

/// The rung the falls are measured from: an eighth of the largest count
/// (16 of 128), or the first rung.
fn from_rung<'a>(ladder: &[&'a Row]) -> Option<(&'a Row, &'a Row)> {
    let last = *ladder.last()?;
    let first = ladder
        .iter()
        .find(|x| x.spp >= (last.spp / 8).max(1))
        .copied()?;
    (first.spp < last.spp).then_some((first, last))
}

/// Sentences on convergence: each compared configuration's relMSE × spp
/// from an eighth of the ladder to its top, and the denoised curve's time
/// to the baseline's error.
pub(super) fn headlines(configs: &[Config], rows: &[Row]) -> Vec<String> {
    let mut out = Vec::new();
    for c in compared(configs) {
        let Some((a, b)) = from_rung(&ladder_of(rows, &c.name)) else {
            continue;
        };
        let (pa, pb) = (a.rel_mse * a.spp as f64, b.rel_mse * b.spp as f64);
        out.push(format!(
            "`{}` ({} sampler, {}{}): relMSE × spp {:.4} at {} spp, {:.4} at {} spp: {:.2}× \
             (relMSE falls {:.1}×; 1/spp would be {}×).",
            c.name,
            c.sampler.name(),
            config::integrator_name(c.integrator),
            if c.denoise { ", denoised" } else { "" },
            pa,
            a.spp,
            pb,
            b.spp,
            pb / pa,
            a.rel_mse / b.rel_mse,
            b.spp / a.spp
        ));
    }
    let base = configs.iter().find(|c| c.axis == Axis::Baseline);
    for (d, base) in configs
        .iter()
        .filter(|c| c.denoise)
        .zip(std::iter::repeat(base).flatten())
    {
        let (dl, bl) = (format!("`{}`", d.name), "the baseline".to_string());
        out.extend(time_sentence(rows, &d.name, &dl, &base.name, &bl));
        if let Some(last) = ladder_of(rows, &d.name).last() {
            let share = last.denoise_seconds / last.seconds;
            out.push(format!(
                "Denoising the {}-spp image took {:.3} s of its {:.3} s ({:.0} %); its bias {:+.3} % ± {:.3} % (2σ).",
                last.spp,
                last.denoise_seconds,
                last.seconds,
                100.0 * share,
                100.0 * last.bias,
                200.0 * last.bias_stderr
            ));
        }
    }
    out
}
