//! The study's plots, as PNG files drawn with plotters into a memory buffer
//! and encoded with `image` (no system graphics libraries):
//!
//! - `error-vs-time.png`: RMSE against render time, log-log, one line per
//!   configuration (lower-left is better: less error for less time);
//! - `bias-vs-rmax.png`: mean bias at the largest sample count against the
//!   Rmax quantile, as "nines" −log10(1 − q), with ±2σ bars;
//! - `bias-vs-table.png`: the same against the table size of the tabulated
//!   radius sampler, one series per node spacing, with the exact sampler's
//!   bias as a horizontal line.
//!
//! Text needs a TrueType font; plotters' `ab_glyph` backend takes the bytes
//! of one, read from `$LUCENT_FONT` or the first of [`FONT_PATHS`] found
//! (`scripts/install-deps.sh` installs Debian's `fonts-dejavu-core`).

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use super::config::{Axis, Config};
use super::results::Row;
use crate::film::atomic_write;

pub const FONT_PATHS: [&str; 3] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
];

pub(crate) const FONT: &str = "sans-serif";
const W: u32 = 1200;
const H: u32 = 800;

/// Registers the plot font once per process.
pub fn ensure_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        let candidates: Vec<PathBuf> = std::env::var_os("LUCENT_FONT")
            .map(PathBuf::from)
            .into_iter()
            .chain(FONT_PATHS.iter().map(PathBuf::from))
            .collect();
        let path = candidates.iter().find(|p| p.is_file()).ok_or_else(|| {
            format!(
                "no TrueType font for the plots: looked for {}; run scripts/install-deps.sh \
                 (installs fonts-dejavu-core) or set LUCENT_FONT to a .ttf file",
                FONT_PATHS.join(", ")
            )
        })?;
        let bytes =
            std::fs::read(path).map_err(|e| format!("cannot read font {}: {e}", path.display()))?;
        // plotters keeps fonts for the process's lifetime; this is read once.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        register_font(FONT, FontStyle::Normal, bytes)
            .map_err(|_| format!("{}: not a TrueType font plotters can read", path.display()))
    })
    .clone()
}

pub(crate) type Res = Result<(), Box<dyn Error>>;

/// (x, bias %, 2σ %) points of one labelled series.
type BiasSeries = (String, Vec<(f64, f64, f64)>);

/// Draws with `draw` into a W×H RGB buffer and writes it to `path` as PNG.
pub(crate) fn png(
    path: &Path,
    draw: impl FnOnce(DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Res,
) -> Result<(), String> {
    let mut buf = vec![0u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        draw(root).map_err(|e| format!("plot {}: {e}", path.display()))?;
    }
    let img = image::RgbImage::from_raw(W, H, buf).ok_or("bad plot buffer")?;
    atomic_write(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| e.to_string())
    })
}

pub(crate) fn color(i: usize) -> RGBColor {
    // Tableau-like, then darker variants: distinct for ~20 lines.
    const C: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    let (r, g, b) = C[i % C.len()];
    if (i / C.len()) % 2 == 1 {
        RGBColor(r / 2, g / 2, b / 2)
    } else {
        RGBColor(r, g, b)
    }
}

/// A log axis range covering `v` (positive values) with some margin.
pub(crate) fn log_range(v: impl Iterator<Item = f64>) -> Option<std::ops::Range<f64>> {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    (hi > 0.0).then(|| lo / 1.3..if hi > lo { hi * 1.3 } else { lo * 2.0 })
}

fn lin_range(v: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    if lo > hi {
        return -1.0..1.0;
    }
    let pad = ((hi - lo) * 0.1).max(1e-6);
    lo - pad..hi + pad
}

fn rows_of<'a>(rows: &'a [Row], config: &str) -> Vec<&'a Row> {
    let mut v: Vec<&Row> = rows.iter().filter(|r| r.config == config).collect();
    v.sort_by_key(|r| r.spp);
    v
}

fn last_row<'a>(rows: &'a [Row], config: &str) -> Option<&'a Row> {
    rows_of(rows, config).last().copied()
}

fn error_vs_time(path: &Path, rows: &[Row], configs: &[Config]) -> Result<bool, String> {
    let Some(xr) = log_range(rows.iter().map(|r| r.seconds)) else {
        return Ok(false);
    };
    let Some(yr) = log_range(rows.iter().map(|r| r.rmse)) else {
        return Ok(false);
    };
    png(path, |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "RMSE vs render time (log-log; lower left is better)",
                (FONT, 24),
            )
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(xr.log_scale(), yr.log_scale())?;
        chart
            .configure_mesh()
            .x_desc("render time [s]")
            .y_desc("RMSE")
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .draw()?;
        for (i, c) in configs.iter().enumerate() {
            let pts: Vec<(f64, f64)> = rows_of(rows, &c.name)
                .iter()
                .map(|r| (r.seconds, r.rmse))
                .filter(|&(t, e)| t > 0.0 && e > 0.0)
                .collect();
            if pts.is_empty() {
                continue;
            }
            let (col, width) = if c.axis == Axis::Baseline {
                (BLACK, 3)
            } else {
                (color(i), 2)
            };
            chart
                .draw_series(LineSeries::new(pts.clone(), col.stroke_width(width)))?
                .label(c.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], col.stroke_width(width))
                });
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 13))
            .draw()?;
        root.present()?;
        Ok(())
    })?;
    Ok(true)
}

/// (x, bias %, 2σ %) points.
fn bias_points(
    rows: &[Row],
    configs: &[&Config],
    x: impl Fn(&Config) -> Option<f64>,
) -> Vec<(f64, f64, f64)> {
    let mut pts: Vec<(f64, f64, f64)> = configs
        .iter()
        .filter_map(|c| {
            let r = last_row(rows, &c.name)?;
            Some((x(c)?, 100.0 * r.bias, 200.0 * r.bias_stderr))
        })
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts
}

fn bias_chart(
    path: &Path,
    title: &str,
    x_desc: &str,
    series: &[BiasSeries],
    hline: Option<(String, f64)>,
) -> Result<bool, String> {
    if series.iter().all(|(_, p)| p.is_empty()) {
        return Ok(false);
    }
    let all = || series.iter().flat_map(|(_, p)| p.iter());
    let xr = lin_range(all().map(|p| p.0));
    let yr = lin_range(
        all()
            .flat_map(|p| [p.1 - p.2, p.1 + p.2])
            .chain(hline.iter().map(|h| h.1))
            .chain([0.0]),
    );
    png(path, |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, 24))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(xr.clone(), yr)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc("mean bias vs reference [%] (bars: ±2σ)")
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .draw()?;
        chart.draw_series(LineSeries::new(
            vec![(xr.start, 0.0), (xr.end, 0.0)],
            BLACK.mix(0.4),
        ))?;
        if let Some((label, y)) = &hline {
            let col = RGBColor(120, 120, 120);
            chart
                .draw_series(LineSeries::new(
                    vec![(xr.start, *y), (xr.end, *y)],
                    col.stroke_width(2),
                ))?
                .label(label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], col.stroke_width(2))
                });
        }
        for (i, (name, pts)) in series.iter().enumerate() {
            let col = color(i);
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.0, p.1)),
                    col.stroke_width(2),
                ))?
                .label(name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], col.stroke_width(2))
                });
            chart.draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 4, col.filled())))?;
            chart.draw_series(pts.iter().map(|p| {
                PathElement::new(
                    vec![(p.0, p.1 - p.2), (p.0, p.1 + p.2)],
                    col.stroke_width(2),
                )
            }))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 15))
            .draw()?;
        root.present()?;
        Ok(())
    })?;
    Ok(true)
}

/// Writes every plot the rows support; returns their paths.
pub fn write_all(dir: &Path, rows: &[Row], configs: &[Config]) -> Result<Vec<PathBuf>, String> {
    ensure_font()?;
    let mut out = Vec::new();
    let p = dir.join("error-vs-time.png");
    if error_vs_time(&p, rows, configs)? {
        out.push(p);
    }

    let baseline = configs.iter().find(|c| c.axis == Axis::Baseline);
    let rmax_cfgs: Vec<&Config> = configs
        .iter()
        .filter(|c| c.axis == Axis::RmaxQuantile)
        .chain(baseline)
        .collect();
    let nines = |c: &Config| c.overrides.rmax_quantile.map(|q| -(1.0 - q).log10());
    let pts = bias_points(rows, &rmax_cfgs, nines);
    if pts.len() >= 2 {
        let p = dir.join("bias-vs-rmax.png");
        let series = [("analytic sampler, Rmax at quantile q".to_string(), pts)];
        if bias_chart(
            &p,
            "Bias vs Rmax quantile (largest sample count)",
            "-log10(1 - q)   (2 = 0.99, 3 = 0.999)",
            &series,
            None,
        )? {
            out.push(p);
        }
    }

    let table_size = |spacing: crate::bssrdf::TableSpacing| {
        move |c: &Config| match c.overrides.radius {
            Some(crate::bssrdf::RadiusSampler::Table { size, spacing: s }) if s == spacing => {
                Some((size as f64).log2())
            }
            _ => None,
        }
    };
    let radius_cfgs: Vec<&Config> = configs.iter().filter(|c| c.axis == Axis::Radius).collect();
    let uni = bias_points(
        rows,
        &radius_cfgs,
        table_size(crate::bssrdf::TableSpacing::Uniform),
    );
    let tail = bias_points(
        rows,
        &radius_cfgs,
        table_size(crate::bssrdf::TableSpacing::Tail),
    );
    if uni.len() + tail.len() >= 2 {
        let p = dir.join("bias-vs-table.png");
        let hline = baseline
            .and_then(|b| last_row(rows, &b.name))
            .map(|r| ("analytic (baseline)".to_string(), 100.0 * r.bias));
        let series = [
            ("table, uniform spacing".to_string(), uni),
            ("table, tail spacing".to_string(), tail),
        ];
        if bias_chart(
            &p,
            "Bias vs table size (largest sample count)",
            "log2(table size)",
            &series,
            hline,
        )? {
            out.push(p);
        }
    }
    Ok(out)
}
