//! What every plot of lucent's shares: a PNG canvas drawn with plotters
//! into a memory buffer and encoded with `image` (no system graphics
//! libraries), written atomically; the font; the palette; log-axis ranges.
//! The charts themselves are drawn by their commands (`study::plots`,
//! `bench::plot`).
//!
//! Text needs a TrueType font; plotters' `ab_glyph` backend takes the bytes
//! of one, read from `$LUCENT_FONT` or the first of [`FONT_PATHS`] found
//! (`scripts/install-deps.sh` installs Debian's `fonts-dejavu-core`).

use std::error::Error;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use lucent::film::atomic_write;

pub const FONT_PATHS: [&str; 3] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
];

pub(crate) const FONT: &str = "sans-serif";
const W: u32 = 1200;
const H: u32 = 800;

/// Why the plot font cannot be used. Kept for the process (the font is
/// looked for once), hence `Clone` and the messages as text.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FontError {
    /// Neither `$LUCENT_FONT` nor any of [`FONT_PATHS`] is a file.
    #[error(
        "no TrueType font for the plots: looked for {}; run scripts/install-deps.sh \
         (installs fonts-dejavu-core) or set LUCENT_FONT to a .ttf file",
        FONT_PATHS.join(", ")
    )]
    Missing,
    /// The font file found cannot be read.
    #[error("cannot read font {}: {problem}", path.display())]
    Read { path: PathBuf, problem: String },
    /// The font file found is not a font plotters can use.
    #[error("{}: not a TrueType font plotters can read", path.display())]
    NotTrueType { path: PathBuf },
}

/// Why a plot was not written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The plot font cannot be used.
    #[error(transparent)]
    Font(#[from] FontError),
    /// The canvas could not be cleared.
    #[error("{0}")]
    Canvas(String),
    /// Drawing the chart into `path` failed.
    #[error("plot {}: {problem}", path.display())]
    Draw { path: PathBuf, problem: String },
    /// The drawn buffer does not make an image of the canvas's size.
    #[error("bad plot buffer")]
    Buffer,
    /// A chart was asked for with no positive values to draw.
    #[error("no data to plot")]
    NoData,
    /// The PNG file could not be written (`cannot write PATH: …`).
    #[error(transparent)]
    Write(#[from] lucent::Error),
}

/// Registers the plot font once per process.
pub(crate) fn ensure_font() -> Result<(), FontError> {
    static DONE: OnceLock<Result<(), FontError>> = OnceLock::new();
    DONE.get_or_init(|| {
        let candidates: Vec<PathBuf> = std::env::var_os("LUCENT_FONT")
            .map(PathBuf::from)
            .into_iter()
            .chain(FONT_PATHS.iter().map(PathBuf::from))
            .collect();
        let path = candidates
            .iter()
            .find(|p| p.is_file())
            .ok_or(FontError::Missing)?;
        let bytes = std::fs::read(path).map_err(|e| FontError::Read {
            path: path.clone(),
            problem: e.to_string(),
        })?;
        // plotters keeps fonts for the process's lifetime; this is read once.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        register_font(FONT, FontStyle::Normal, bytes)
            .map_err(|_| FontError::NotTrueType { path: path.clone() })
    })
    .clone()
}

pub(crate) type Res = Result<(), Box<dyn Error>>;

/// Draws with `draw` into a W×H RGB buffer and writes it to `path` as PNG.
pub fn png(
    path: &Path,
    draw: impl FnOnce(DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Res,
) -> Result<(), PlotError> {
    let mut buf = vec![0u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE)
            .map_err(|e| PlotError::Canvas(e.to_string()))?;
        draw(root).map_err(|e| PlotError::Draw {
            path: path.to_path_buf(),
            problem: e.to_string(),
        })?;
    }
    let img = image::RgbImage::from_raw(W, H, buf).ok_or(PlotError::Buffer)?;
    atomic_write(path, |tmp| lucent::film::write_png(&img, tmp))?;
    Ok(())
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
    // values a log axis can span with its margin (1e308 · 1.3 is inf)
    let (lo, hi) = v
        .filter(|x| x.is_finite() && *x > 0.0 && *x < 1e300)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    (hi > 0.0).then(|| lo / 1.3..if hi > lo { hi * 1.3 } else { lo * 2.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ranges_cover_the_positive_values_with_margin() {
        let r = log_range([0.0, -3.0, f64::NAN, 2.0, 50.0].into_iter()).unwrap();
        assert!((r.start - 2.0 / 1.3).abs() < 1e-12 && (r.end - 65.0).abs() < 1e-12);
        // One value still gives a range of positive width.
        let r = log_range([4.0].into_iter()).unwrap();
        assert!(r.start < 4.0 && r.end > 4.0);
        assert!(log_range([0.0, -1.0].into_iter()).is_none());
        // a value whose margin overflows (1e308 · 1.3) is left out, so
        // the axis stays finite and the plot ends
        let r = log_range([1e308, 2.0].into_iter()).unwrap();
        assert!(r.end.is_finite() && r.end < 10.0, "{r:?}");
    }

    #[test]
    fn palette_colours_are_distinct_for_twenty_lines() {
        let c: Vec<_> = (0..20).map(color).collect();
        for i in 0..20 {
            for j in 0..i {
                assert_ne!(c[i], c[j], "{i} {j}");
            }
        }
    }
}
