//! `report.md`: what was run, how the reference was made, one table row per
//! configuration at the largest sample count, and the plots.
//!
//! Two time comparisons with the baseline are given, both from the
//! measured ladders: "time to baseline RMSE" interpolates (log-log) when
//! the configuration first reaches the error the baseline has at its
//! largest sample count; "efficiency" is 1/(MSE · time) at the largest
//! sample count, relative to the baseline's (> 1: better).

use std::fmt::Write as _;
use std::path::PathBuf;

use super::compare::{ladder_of, time_sentence};
use super::config::{self, Axis, Config};
use super::convergence;
use super::metrics::time_to_reach;
use super::results::Row;
use super::{ReferenceInfo, Settings};
use lucent::film::atomic_write;
use lucent::scene::Scene;

/// The command line that reproduces the study.
pub(crate) fn command_line(s: &Settings) -> String {
    let mut c = format!(
        "lucent study {} -o {}",
        s.scene.display(),
        s.out_dir.display()
    );
    if s.quick {
        c.push_str(" --quick");
    }
    let d = Settings::new(&s.scene, &s.out_dir, s.quick);
    if s.reference != d.reference {
        write!(c, " --reference {}", config::integrator_name(s.reference)).unwrap();
    }
    if s.reference_spp != d.reference_spp {
        write!(c, " --reference-spp {}", s.reference_spp).unwrap();
    }
    if s.max_spp != d.max_spp {
        write!(c, " --max-spp {}", s.max_spp).unwrap();
    }
    if s.width != d.width {
        write!(c, " --width {}", s.width).unwrap();
    }
    if let Some(seed) = s.seed {
        write!(c, " --seed {seed}").unwrap();
    }
    if s.firefly_k != d.firefly_k {
        write!(c, " --firefly-k {}", s.firefly_k).unwrap();
    }
    if !s.only.is_empty() {
        let names: Vec<&str> = s.only.iter().map(|a| a.name()).collect();
        write!(c, " --only {}", names.join(",")).unwrap();
    }
    if let Some(t) = s.threads {
        write!(c, " --threads {t}").unwrap();
    }
    c
}

fn fmt_opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map(f).unwrap_or_else(|| "—".into())
}

/// What a run made besides the rows, for its report.
pub struct Made<'a> {
    pub reference: &'a ReferenceInfo,
    pub plots: &'a [PathBuf],
    /// Why there is no denoised curve, if there is none.
    pub no_denoise: Option<&'a str>,
    /// How long this run took.
    pub seconds: f64,
}

/// Writes `DIR/report.md`; returns its path, or why it could not be written
/// (`cannot write PATH: …`).
pub fn write(
    s: &Settings,
    scene: &Scene,
    configs: &[Config],
    rows: &[Row],
    made: &Made,
) -> Result<PathBuf, lucent::Error> {
    let Made {
        reference,
        plots,
        no_denoise,
        seconds: run_seconds,
    } = *made;
    let path = s.out_dir.join("report.md");
    let name = s
        .scene
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut r = String::new();
    writeln!(r, "# Accuracy vs time: {name}\n").unwrap();
    writeln!(r, "Reproduce with:\n\n    {}\n", command_line(s)).unwrap();
    setup_section(&mut r, s, scene, configs, reference, run_seconds);
    if let Some(why) = no_denoise {
        writeln!(
            r,
            "**No denoised curve:** Open Image Denoise is unavailable ({why}).\n"
        )
        .unwrap();
    }
    let pixels = (w as f64) * (h as f64);
    results_table(&mut r, configs, rows, pixels);
    convergence::table(&mut r, configs, rows);
    writeln!(r, "## Headlines\n").unwrap();
    for h in headlines(configs, rows, pixels)
        .into_iter()
        .chain(convergence::headlines(configs, rows))
    {
        writeln!(r, "- {h}").unwrap();
    }
    writeln!(r).unwrap();
    writeln!(r, "## Plots\n").unwrap();
    for p in plots {
        let f = p.file_name().unwrap_or_default().to_string_lossy();
        writeln!(r, "![{f}]({f})\n").unwrap();
    }
    writeln!(r, "Raw rows: `results.csv`; final images: `images/`.").unwrap();
    atomic_write(&path, |tmp| {
        std::io::Write::write_all(tmp, r.as_bytes()).map_err(|e| e.to_string())
    })?;
    Ok(path)
}

/// The "Setup" section: image, ladder, reference, baseline, metrics, and
/// how long this run took.
fn setup_section(
    r: &mut String,
    s: &Settings,
    scene: &Scene,
    configs: &[Config],
    reference: &ReferenceInfo,
    run_seconds: f64,
) {
    let (w, h) = (scene.camera.width, scene.camera.height);
    writeln!(r, "## Setup\n").unwrap();
    writeln!(
        r,
        "- Image {w}×{h}, path depth {}, {} threads{}.",
        scene.settings.max_depth,
        s.threads
            .map(|t| t.to_string())
            .unwrap_or_else(|| "all".into()),
        if s.quick { ", quick mode" } else { "" }
    )
    .unwrap();
    let spps: Vec<String> = super::ladder(s.max_spp)
        .iter()
        .map(|n| n.to_string())
        .collect();
    writeln!(
        r,
        "- Sample-count ladder {} (progressive: rung j adds the next range of samples of the one seed, as a farm's parts split them; \
         times are cumulative wall time, with the denoise of that rung's image for a denoising configuration).",
        spps.join(", ")
    )
    .unwrap();
    writeln!(
        r,
        "- Reference: **{}** integrator, **{} spp**, seed {}, probe options: {}; {} (`{}`{}).",
        config::integrator_name(reference.integrator),
        reference.spp,
        reference.seed,
        config::describe(&reference.overrides),
        if reference.seconds.is_finite() {
            format!("rendered in {:.1} s", reference.seconds)
        } else {
            "render time unknown".into()
        },
        reference
            .path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy(),
        if reference.cached {
            ", reused from the cache"
        } else {
            ""
        }
    )
    .unwrap();
    writeln!(
        r,
        "- Configurations vary **one axis at a time** from the baseline (not the cross product). Baseline: {}, backend {}, integrator {}.",
        configs.first().map(|c| config::describe(&c.overrides)).unwrap_or_default(),
        configs.first().map(|c| c.backend.name()).unwrap_or(""),
        configs.first().map(|c| config::integrator_name(c.integrator)).unwrap_or(""),
    )
    .unwrap();
    writeln!(
        r,
        "- Metrics (see `crates/lucent-tools/src/study/metrics.rs`): RMSE; relMSE with ε = 0.01; bias = Σ(I − R)/ΣR with its standard error; \
         fireflies = pixels above {}× the reference luminance.",
        s.firefly_k
    )
    .unwrap();
    writeln!(
        r,
        "- This run took {run_seconds:.0} s (rows already in results.csv were not re-rendered).\n"
    )
    .unwrap();
}

/// Every configuration at its largest sample count against the baseline:
/// the table of results and its note.
fn results_table(r: &mut String, configs: &[Config], rows: &[Row], pixels: f64) {
    let base_rows = configs
        .first()
        .map(|b| ladder_of(rows, &b.name))
        .unwrap_or_default();
    let base_last = base_rows.last().copied();
    writeln!(r, "## Results at the largest sample count\n").unwrap();
    writeln!(
        r,
        "| configuration | backend | integrator | spp | time [s] | ns/sample | RMSE | relMSE | bias [%] ± 2σ | fireflies (final / all rungs) | time to baseline RMSE [s] | efficiency vs baseline |"
    )
    .unwrap();
    writeln!(r, "|---|---|---|---|---|---|---|---|---|---|---|---|").unwrap();
    for c in configs {
        let ladder = ladder_of(rows, &c.name);
        let Some(last) = ladder.last() else { continue };
        let pts: Vec<(f64, f64)> = ladder.iter().map(|x| (x.seconds, x.rmse)).collect();
        let reach = base_last.and_then(|b| time_to_reach(&pts, b.rmse));
        let eff = base_last
            .map(|b| (b.rmse * b.rmse * b.seconds) / (last.rmse * last.rmse * last.seconds));
        writeln!(
            r,
            "| {} | {} | {} | {} | {:.3} | {:.0} | {:.4e} | {:.4e} | {:+.3} ± {:.3} | {} / {} | {} | {} |",
            c.name,
            c.backend.name(),
            config::integrator_name(c.integrator),
            last.spp,
            last.seconds,
            last.seconds * 1e9 / (pixels * last.spp as f64),
            last.rmse,
            last.rel_mse,
            100.0 * last.bias,
            200.0 * last.bias_stderr,
            last.fireflies,
            ladder.iter().map(|x| x.fireflies).sum::<u64>(),
            fmt_opt(reach, |t| format!("{t:.3}")),
            fmt_opt(eff, |e| format!("{e:.2}")),
        )
        .unwrap();
    }
    writeln!(
        r,
        "\n\"—\" in *time to baseline RMSE*: the ladder never got that low (noise or bias).\n"
    )
    .unwrap();
}

fn bias_text(r: &Row) -> String {
    format!(
        "{:+.3} % ± {:.3} % (2σ)",
        100.0 * r.bias,
        200.0 * r.bias_stderr
    )
}

/// Sentences with the study's headline numbers, each from measured rows.
fn headlines(configs: &[Config], rows: &[Row], pixels: f64) -> Vec<String> {
    let mut out = Vec::new();
    let Some(base) = configs.iter().find(|c| c.axis == Axis::Baseline) else {
        return out;
    };
    let last = |name: &str| ladder_of(rows, name).last().copied();
    let named = |axis: Axis| configs.iter().filter(move |c| c.axis == axis);
    let label = |c: &Config| {
        if c.axis == Axis::Baseline {
            format!("the baseline ({})", config::describe(&c.overrides))
        } else {
            format!("`{}`", c.name)
        }
    };
    // Probe axes, both ways round, and their fireflies.
    for c in named(Axis::Axes) {
        let (b, v) = (label(base), label(c));
        out.extend(time_sentence(rows, &base.name, &b, &c.name, &v));
        out.extend(time_sentence(rows, &c.name, &v, &base.name, &b));
        let total = |n: &str| ladder_of(rows, n).iter().map(|x| x.fireflies).sum::<u64>();
        out.push(format!(
            "Fireflies summed over the ladder: {} for the baseline, {} for `{}`.",
            total(&base.name),
            total(&c.name),
            c.name
        ));
    }
    // Analytic inverse against a 256-entry table.
    if let (Some(b), Some(t)) = (
        last(&base.name),
        named(Axis::Radius).find(|c| c.value == "table:256"),
    ) {
        if let Some(tr) = last(&t.name) {
            let ns = |r: &Row| r.seconds * 1e9 / (pixels * r.spp as f64);
            out.push(format!(
                "The analytic inverse costs {:+.0} ns per camera sample against `{}` ({:.0} vs {:.0} ns, wall time, \
                 whole-path cost); bias {} (analytic) vs {} (table).",
                ns(b) - ns(tr),
                t.name,
                ns(b),
                ns(tr),
                bias_text(b),
                bias_text(tr)
            ));
        }
    }
    for c in named(Axis::Radius)
        .chain(named(Axis::RmaxQuantile))
        .chain(named(Axis::Channel))
    {
        if let Some(r) = last(&c.name) {
            out.push(format!(
                "`{}`: bias {} at {} spp.",
                c.name,
                bias_text(r),
                r.spp
            ));
        }
    }
    if let Some(b) = last(&base.name) {
        out.push(format!("Baseline: bias {} at {} spp.", bias_text(b), b.spp));
    }
    for c in named(Axis::Integrator) {
        let (b, v) = (label(base), label(c));
        out.extend(time_sentence(rows, &base.name, &b, &c.name, &v));
        if let (Some(br), Some(cr)) = (last(&base.name), last(&c.name)) {
            out.push(format!(
                "Against the reference, the baseline keeps a bias of {} and `{}` {}.",
                bias_text(br),
                c.name,
                bias_text(cr)
            ));
        }
    }
    for c in named(Axis::Backend) {
        if let (Some(br), Some(cr)) = (last(&base.name), last(&c.name)) {
            out.push(format!(
                "`{}` takes {:.2}× the baseline's time ({:.3} s vs {:.3} s at {} spp) for RMSE {:.4e} vs {:.4e}.",
                c.name,
                cr.seconds / br.seconds,
                cr.seconds,
                br.seconds,
                br.spp,
                cr.rmse,
                br.rmse
            ));
        }
    }
    out
}
