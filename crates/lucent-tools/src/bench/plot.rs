//! The bench's plots: per query, time per ray against triangle count on the
//! displaced spheres, log-log, one line per (backend, threads); and build
//! time against triangle count per backend. Canvas, PNG writing, palette,
//! axis ranges and font are the shared ones of [`crate::plot`].

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{QueryKind, Row};
use crate::plot::{color, ensure_font, log_range, png, PlotError, FONT};

type Series = (String, Vec<(f64, f64)>);

/// Draws a log-log line plot of `series` into `path`.
fn line_plot(path: &Path, title: &str, ylabel: &str, series: &[Series]) -> Result<(), PlotError> {
    let xr =
        log_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.0))).ok_or(PlotError::NoData)?;
    let yr =
        log_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.1))).ok_or(PlotError::NoData)?;
    png(path, |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption(title, (FONT, 22))
            .margin(15)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(xr.log_scale(), yr.log_scale())?;
        chart
            .configure_mesh()
            .x_desc("triangles")
            .y_desc(ylabel)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .x_label_formatter(&|x| super::short_count(x.round() as usize))
            .draw()?;
        for (i, (name, pts)) in series.iter().enumerate() {
            let c = color(i);
            let style = ShapeStyle::from(&c).stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), style))?
                .label(name.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
        Ok(())
    })
}

/// Writes `bench-<query>.png` (ns per ray vs triangles) for every query and
/// `bench-build.png` (build seconds vs triangles) into `dir`, from the
/// displaced-sphere rows; returns the paths written (none without such
/// rows).
pub(crate) fn write_plots(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>, PlotError> {
    let spheres: Vec<&Row> = rows.iter().filter(|r| r.mesh == "sphere").collect();
    if spheres.is_empty() {
        return Ok(Vec::new());
    }
    ensure_font()?;
    let mut keys: Vec<(String, usize)> = Vec::new();
    for r in &spheres {
        if !keys.iter().any(|k| k.0 == r.backend && k.1 == r.threads) {
            keys.push((r.backend.clone(), r.threads));
        }
    }
    let mut written = Vec::new();
    for q in QueryKind::ALL {
        let series: Vec<Series> = keys
            .iter()
            .map(|(b, t)| {
                let mut pts: Vec<(f64, f64)> = spheres
                    .iter()
                    .filter(|r| r.query == q && &r.backend == b && r.threads == *t)
                    .map(|r| (r.triangles as f64, r.ns_per_ray()))
                    .collect();
                pts.sort_by(|a, b| a.0.total_cmp(&b.0));
                (
                    format!("{b}, {t} thread{}", if *t == 1 { "" } else { "s" }),
                    pts,
                )
            })
            .filter(|s| !s.1.is_empty())
            .collect();
        let path = dir.join(format!("bench-{}.png", q.name()));
        line_plot(
            &path,
            &format!("{} rays: time per ray, displaced spheres", q.name()),
            "ns per ray (wall time / rays)",
            &series,
        )?;
        written.push(path);
    }
    let mut backends: Vec<&str> = keys.iter().map(|k| k.0.as_str()).collect();
    backends.dedup();
    let series: Vec<Series> = backends
        .iter()
        .map(|b| {
            let mut pts: Vec<(f64, f64)> = Vec::new();
            for r in spheres.iter().filter(|r| r.backend == *b) {
                if !pts.iter().any(|p| p.0 == r.triangles as f64) {
                    pts.push((r.triangles as f64, r.build_seconds));
                }
            }
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            (b.to_string(), pts)
        })
        .collect();
    let path = dir.join("bench-build.png");
    line_plot(&path, "build time, displaced spheres", "seconds", &series)?;
    written.push(path);
    Ok(written)
}
