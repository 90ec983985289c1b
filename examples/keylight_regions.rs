//! Diffusion against the random walk per region of a body lit from the
//! left (`scenes/keylight-sphere.toml`, `scripts/keylight-report.sh`):
//!
//!     cargo run --release --example keylight_regions -- CX CY R DIFF.exr… -- WALK.exr…
//!
//! With R > 0 the body is the disk of radius R pixels centred at (CX, CY)
//! (a sphere); a pixel counts if its whole square lies inside. Regions:
//! `lit` (left of CX), `far` (right of CX), `rim` (the far half beyond
//! 0.6 R from CX, where only light that crossed the body arrives), `whole`.
//! With R = 0 the body is every pixel where the walk's renders have light
//! (a mesh against a black background), and `rim` is replaced by `top`,
//! the pixels above CY (e.g. a bunny's ears).
//!
//! Each side is one or more renders with independent seeds; a region's
//! value is the mean over them and its standard error their spread / √k
//! (with one render, the pixels' spread, which overstates it where the
//! region has a gradient). Prints per region and channel both means and
//! diffusion/walk − 1 in per cent with its standard error, then the same
//! ratio in eight vertical bands across the body, from the lit side to
//! the far one.

use lucent::film::Film;
use lucent_tools::image_sets::two_sets;
use std::fmt::Write as _;
use std::io::Write as _;

/// Which pixels belong to the body, and where it is.
struct Body {
    inside: Vec<bool>,
    width: usize,
    cx: f64,
    cy: f64,
    /// The disk's radius, 0 for a mask.
    r: f64,
    /// The body's horizontal extent in pixels, [x0, x1).
    x0: f64,
    x1: f64,
}

impl Body {
    fn new(walk: &[Film], cx: f64, cy: f64, r: f64) -> Body {
        let (w, h) = (walk[0].width as usize, walk[0].height as usize);
        let inside: Vec<bool> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                if r > 0.0 {
                    // farthest corner of the pixel square from the centre
                    let dx = (x - cx).abs().max((x + 1.0 - cx).abs());
                    let dy = (y - cy).abs().max((y + 1.0 - cy).abs());
                    dx * dx + dy * dy <= r * r
                } else {
                    walk.iter().any(|f| f.pixels[i].max_element() > 0.0)
                }
            })
            .collect();
        let xs = || (0..w * h).filter(|&i| inside[i]).map(|i| (i % w) as f64);
        let (x0, x1) = if r > 0.0 {
            (cx - r, cx + r)
        } else {
            (
                xs().fold(f64::INFINITY, f64::min),
                xs().fold(0.0, f64::max) + 1.0,
            )
        };
        Body {
            inside,
            width: w,
            cx,
            cy,
            r,
            x0,
            x1,
        }
    }

    /// The pixels of the named region.
    fn region(&self, name: &str) -> Vec<bool> {
        self.select(|x, y| match name {
            "lit" => x + 1.0 <= self.cx,
            "far" => x >= self.cx,
            "rim" => x >= self.cx + 0.6 * self.r,
            "top" => y + 1.0 <= self.cy,
            _ => true,
        })
    }

    /// The pixels of band `i` of eight across the body's extent (by the
    /// pixel's centre).
    fn band(&self, i: usize) -> Vec<bool> {
        let w = (self.x1 - self.x0) / 8.0;
        let lo = self.x0 + w * i as f64;
        self.select(|x, _| (lo..lo + w).contains(&(x + 0.5)))
    }

    fn select(&self, keep: impl Fn(f64, f64) -> bool) -> Vec<bool> {
        (0..self.inside.len())
            .map(|i| {
                let (x, y) = ((i % self.width) as f64, (i / self.width) as f64);
                self.inside[i] && keep(x, y)
            })
            .collect()
    }
}

/// Mean and standard error (pixels as independent) per channel of the
/// pixels of `film` in `mask`.
fn pixel_stats(film: &Film, mask: &[bool]) -> [(f64, f64); 3] {
    let vals: Vec<[f64; 3]> = (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| {
            let p = film.pixels[i];
            [p[0] as f64, p[1] as f64, p[2] as f64]
        })
        .collect();
    let n = vals.len() as f64;
    if vals.len() < 2 {
        eprintln!("error: fewer than 2 pixels in a region");
        std::process::exit(2)
    }
    std::array::from_fn(|c| {
        let m = vals.iter().map(|v| v[c]).sum::<f64>() / n;
        let var = vals.iter().map(|v| (v[c] - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, (var / n).sqrt())
    })
}

/// A region's mean per channel over independent renders and its standard
/// error.
fn stats(films: &[Film], mask: &[bool]) -> [(f64, f64); 3] {
    let each: Vec<[(f64, f64); 3]> = films.iter().map(|f| pixel_stats(f, mask)).collect();
    if each.len() == 1 {
        return each[0];
    }
    let k = each.len() as f64;
    std::array::from_fn(|c| {
        let m = each.iter().map(|s| s[c].0).sum::<f64>() / k;
        let var = each.iter().map(|s| (s[c].0 - m).powi(2)).sum::<f64>() / (k - 1.0);
        (m, (var / k).sqrt())
    })
}

/// One region's lines: both means and the relative difference per channel.
fn print_region(out: &mut String, name: &str, d: [(f64, f64); 3], w: [(f64, f64); 3]) {
    for c in 0..3 {
        let ((md, sd), (mw, sw)) = (d[c], w[c]);
        let rel = md / mw - 1.0;
        let se = (md / mw) * ((sd / md).powi(2) + (sw / mw).powi(2)).sqrt();
        writeln!(
            out,
            "{name:<6}  {}   {md:.6}   {mw:.6}   {:+6.2} ± {:.2}",
            ["r", "g", "b"][c],
            100.0 * rel,
            100.0 * se
        )
        .unwrap();
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let split = args.iter().position(|a| a == "--");
    let (Some(split), true) = (split, args.len() >= 6) else {
        eprintln!("usage: keylight_regions CX CY R DIFF.exr... -- WALK.exr...");
        std::process::exit(2)
    };
    let v: Vec<f64> = args[0..3]
        .iter()
        .map(|s| match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => v,
            _ => {
                eprintln!("error: not a number ≥ 0: {s}");
                std::process::exit(2)
            }
        })
        .collect();
    let (diff, walk) = two_sets(&args[3..split], &args[split + 1..], ["diffusion", "walk"])
        .unwrap_or_else(|e| {
            eprintln!("error: {e}");
            std::process::exit(2)
        });
    let body = Body::new(&walk, v[0], v[1], v[2]);
    let fourth = if body.r > 0.0 { "rim" } else { "top" };
    // the table is written at once, and a reader that stops early (a
    // closed pipe) ends the program quietly
    let mut out = String::new();
    writeln!(
        out,
        "region  ch  diffusion    walk        diffusion/walk-1 [%]"
    )
    .unwrap();
    for name in ["lit", "far", fourth, "whole"] {
        let mask = body.region(name);
        print_region(&mut out, name, stats(&diff, &mask), stats(&walk, &mask));
    }
    writeln!(
        out,
        "band (x)          r        g        b   [diffusion/walk-1 %]"
    )
    .unwrap();
    for i in 0..8 {
        let mask = body.band(i);
        if mask.iter().filter(|&&m| m).count() < 2 {
            continue;
        }
        let (d, w) = (stats(&diff, &mask), stats(&walk, &mask));
        let rel: Vec<String> = (0..3)
            .map(|c| format!("{:+7.1}", 100.0 * (d[c].0 / w[c].0 - 1.0)))
            .collect();
        let lo = body.x0 + (body.x1 - body.x0) * i as f64 / 8.0;
        let hi = lo + (body.x1 - body.x0) / 8.0;
        writeln!(out, "[{lo:5.1}, {hi:5.1})  {}", rel.join("  ")).unwrap();
    }
    let _ = std::io::stdout().write_all(out.as_bytes());
}
