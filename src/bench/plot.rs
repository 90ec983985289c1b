//! The bench's plots: per query, time per ray against triangle count on the
//! displaced spheres, log-log, one line per (backend, threads); and build
//! time against triangle count per backend. PNGs drawn by plotters into a
//! buffer and encoded with `image`; text through plotters' `ab_glyph` from
//! a TrueType file (`$LUCENT_FONT` or Debian's `fonts-dejavu-core`), so no
//! fontconfig is needed. The font is `lucent study`'s
//! ([`crate::study::plots::ensure_font`]).

use std::error::Error;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::{QueryKind, Row};
use crate::study::plots::ensure_font;

/// The family `study::plots::ensure_font` registers the font under.
const FONT: &str = "sans-serif";
const W: u32 = 1000;
const H: u32 = 700;

type Series = (String, Vec<(f64, f64)>);

fn color(i: usize) -> RGBColor {
    const C: [(u8, u8, u8); 8] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
    ];
    let (r, g, b) = C[i % C.len()];
    RGBColor(r, g, b)
}

fn log_range(v: impl Iterator<Item = f64>) -> Option<std::ops::Range<f64>> {
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    (hi > 0.0).then(|| lo / 1.5..if hi > lo { hi * 1.5 } else { lo * 2.0 })
}

/// Draws a log-log line plot of `series` into `path`.
fn line_plot(path: &Path, title: &str, ylabel: &str, series: &[Series]) -> Result<(), String> {
    let xr =
        log_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.0))).ok_or("no data to plot")?;
    let yr =
        log_range(series.iter().flat_map(|s| s.1.iter().map(|p| p.1))).ok_or("no data to plot")?;
    let mut buf = vec![0u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        let draw = || -> Result<(), Box<dyn Error>> {
            root.fill(&WHITE)?;
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
        };
        draw().map_err(|e| format!("plot {}: {e}", path.display()))?;
    }
    let img = image::RgbImage::from_raw(W, H, buf).ok_or("bad plot buffer")?;
    crate::film::atomic_write(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| e.to_string())
    })
}

/// Writes `bench-<query>.png` (ns per ray vs triangles) for every query and
/// `bench-build.png` (build seconds vs triangles) into `dir`, from the
/// displaced-sphere rows; returns the paths written (none without such
/// rows).
pub fn write_plots(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>, String> {
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
