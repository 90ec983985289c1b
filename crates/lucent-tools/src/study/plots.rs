//! The study's plots, as PNG files drawn with plotters into a memory buffer
//! and encoded with `image` (no system graphics libraries):
//!
//! - `error-vs-time.png`: RMSE against time (render, plus denoise for the
//!   denoised configuration), log-log, one line per configuration
//!   (lower-left is better: less error for less time);
//! - `relmse-spp.png`: relMSE × spp against spp, log-log, for the sampler
//!   × estimator and denoised configurations (flat for independent
//!   samples);
//! - `bias-vs-rmax.png`: mean bias at the largest sample count against the
//!   Rmax quantile, as "nines" −log10(1 − q), with ±2σ bars;
//! - `bias-vs-table.png`: the same against the table size of the tabulated
//!   radius sampler, one series per node spacing, with the exact sampler's
//!   bias as a horizontal line.
//!
//! The canvas, font and palette are [`crate::plot`]'s, shared with
//! `lucent bench`.

use std::path::{Path, PathBuf};

use lucent::bssrdf::RadiusSampler;
use plotters::prelude::*;

use super::config::{Axis, Config};
use super::results::Row;
use crate::plot::{color, ensure_font, log_range, png, PlotError, FONT};

/// (x, bias %, 2σ %) points of one labelled series.
type BiasSeries = (String, Vec<(f64, f64, f64)>);

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

/// A log-log chart of one line per configuration through its rungs.
struct LineChart {
    caption: &'static str,
    x_desc: &'static str,
    y_desc: &'static str,
    x: fn(&Row) -> f64,
    y: fn(&Row) -> f64,
}

/// RMSE against time (render, and denoise where a configuration
/// denoises).
const ERROR_VS_TIME: LineChart = LineChart {
    caption: "RMSE vs time (log-log; lower left is better)",
    x_desc: "render (+ denoise) time [s]",
    y_desc: "RMSE",
    x: |r| r.seconds,
    y: |r| r.rmse,
};

/// relMSE × spp against spp: flat for independent samples.
const RELMSE_SPP: LineChart = LineChart {
    caption: "relMSE × spp vs spp (flat: error ∝ 1/spp)",
    x_desc: "samples per pixel",
    y_desc: "relMSE × spp",
    x: |r| r.spp as f64,
    y: |r| r.rel_mse * r.spp as f64,
};

fn line_chart(
    path: &Path,
    spec: &LineChart,
    rows: &[Row],
    configs: &[&Config],
) -> Result<bool, PlotError> {
    let mine: Vec<&Row> = rows
        .iter()
        .filter(|r| configs.iter().any(|c| c.name == r.config))
        .collect();
    let Some(xr) = log_range(mine.iter().map(|r| (spec.x)(r))) else {
        return Ok(false);
    };
    let Some(yr) = log_range(mine.iter().map(|r| (spec.y)(r))) else {
        return Ok(false);
    };
    png(path, |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption(spec.caption, (FONT, 24))
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(xr.log_scale(), yr.log_scale())?;
        chart
            .configure_mesh()
            .x_desc(spec.x_desc)
            .y_desc(spec.y_desc)
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .draw()?;
        for (i, c) in configs.iter().enumerate() {
            let pts: Vec<(f64, f64)> = rows_of(rows, &c.name)
                .iter()
                .map(|r| ((spec.x)(r), (spec.y)(r)))
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
) -> Result<bool, PlotError> {
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
pub(crate) fn write_all(
    dir: &Path,
    rows: &[Row],
    configs: &[Config],
) -> Result<Vec<PathBuf>, PlotError> {
    ensure_font()?;
    let mut out = Vec::new();
    let all: Vec<&Config> = configs.iter().collect();
    let p = dir.join("error-vs-time.png");
    if line_chart(&p, &ERROR_VS_TIME, rows, &all)? {
        out.push(p);
    }
    let compared: Vec<&Config> = super::convergence::compared(configs).collect();
    let p = dir.join("relmse-spp.png");
    if compared.len() >= 2 && line_chart(&p, &RELMSE_SPP, rows, &compared)? {
        out.push(p);
    }

    let baseline = configs.iter().find(|c| c.axis == Axis::Baseline);
    let rmax_cfgs: Vec<&Config> = configs
        .iter()
        .filter(|c| c.axis == Axis::RmaxQuantile)
        .chain(baseline)
        .collect();
    let nines = |c: &Config| {
        let q: f64 = c.overrides.value("rmax_quantile")?.parse().ok()?;
        Some(-(1.0 - q).log10())
    };
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

    let table_size = |spacing: lucent::bssrdf::TableSpacing| {
        move |c: &Config| match c.overrides.value("radius").map(RadiusSampler::parse) {
            Some(Ok(RadiusSampler::Table { size, spacing: s })) if s == spacing => {
                Some((size as f64).log2())
            }
            _ => None,
        }
    };
    let radius_cfgs: Vec<&Config> = configs.iter().filter(|c| c.axis == Axis::Radius).collect();
    let uni = bias_points(
        rows,
        &radius_cfgs,
        table_size(lucent::bssrdf::TableSpacing::Uniform),
    );
    let tail = bias_points(
        rows,
        &radius_cfgs,
        table_size(lucent::bssrdf::TableSpacing::Tail),
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
