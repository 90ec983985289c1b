//! Diffusion against the random walk per region of a sphere lit from the
//! left (`scenes/keylight-sphere.toml`, `scripts/keylight-report.sh`):
//!
//!     cargo run --release --example keylight_regions -- CX CY R DIFF.exr… -- WALK.exr…
//!
//! The disk of radius R pixels centred at (CX, CY) is the sphere; a pixel
//! counts if its whole square lies inside. Regions: `lit` (left of CX),
//! `far` (right of CX), `rim` (the far half beyond 0.6 R from CX, where
//! only light that crossed the body arrives), `whole`. Each side is one or
//! more renders with independent seeds; a region's value is the mean over
//! them and its standard error their spread / √k (with one render, the
//! pixels' spread, which overstates it where the region has a gradient).
//! Prints per region and channel both means and diffusion/walk − 1 in per
//! cent with its standard error, then the same ratio in eight vertical
//! bands across the disk, from the lit limb to the far one.

use lucent::film::Film;
use std::path::Path;

/// One region's pixel test: (x offset of the pixel's near edge from CX,
/// of its far edge) → counts.
type Region = (&'static str, fn(f64, f64, f64) -> bool);

const REGIONS: [Region; 4] = [
    ("lit", |_x0, x1, _r| x1 <= 0.0),
    ("far", |x0, _x1, _r| x0 >= 0.0),
    ("rim", |x0, _x1, r| x0 >= 0.6 * r),
    ("whole", |_, _, _| true),
];

fn read(path: &str) -> Film {
    Film::read_exr(Path::new(path)).unwrap_or_else(|e| {
        eprintln!("error: {path}: {e}");
        std::process::exit(2)
    })
}

/// Mean and standard error (pixels as independent) per channel of the
/// pixels of `film` that lie in the disk and pass `keep`.
fn pixel_stats(film: &Film, disk: [f64; 3], keep: fn(f64, f64, f64) -> bool) -> [(f64, f64); 3] {
    let [cx, cy, r] = disk;
    let w = film.width as usize;
    let mut vals: Vec<[f64; 3]> = Vec::new();
    for y in 0..film.height as usize {
        for x in 0..w {
            let dx = (x as f64 - cx).abs().max((x as f64 + 1.0 - cx).abs());
            let dy = (y as f64 - cy).abs().max((y as f64 + 1.0 - cy).abs());
            if dx * dx + dy * dy > r * r || !keep(x as f64 - cx, x as f64 + 1.0 - cx, r) {
                continue;
            }
            let p = film.pixels[y * w + x];
            vals.push([p[0] as f64, p[1] as f64, p[2] as f64]);
        }
    }
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
fn stats(films: &[Film], disk: [f64; 3], keep: fn(f64, f64, f64) -> bool) -> [(f64, f64); 3] {
    let each: Vec<[(f64, f64); 3]> = films.iter().map(|f| pixel_stats(f, disk, keep)).collect();
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

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let split = args.iter().position(|a| a == "--");
    let (Some(split), true) = (split, args.len() >= 6) else {
        eprintln!("usage: keylight_regions CX CY R DIFF.exr... -- WALK.exr...");
        std::process::exit(2)
    };
    let v: Vec<f64> = args[0..3]
        .iter()
        .map(|s| {
            s.parse().unwrap_or_else(|_| {
                eprintln!("error: not a number: {s}");
                std::process::exit(2)
            })
        })
        .collect();
    let disk = [v[0], v[1], v[2]];
    let diff: Vec<Film> = args[3..split].iter().map(|p| read(p)).collect();
    let walk: Vec<Film> = args[split + 1..].iter().map(|p| read(p)).collect();
    if diff.is_empty() || walk.is_empty() {
        eprintln!("error: no diffusion or no walk image");
        std::process::exit(2)
    }
    println!("region  ch  diffusion    walk        diffusion/walk-1 [%]");
    for (name, keep) in REGIONS {
        print_region(name, stats(&diff, disk, keep), stats(&walk, disk, keep));
    }
    println!("band (x/R)       r        g        b   [diffusion/walk-1 %]");
    for (i, keep) in BANDS.iter().enumerate() {
        let (d, w) = (stats(&diff, disk, *keep), stats(&walk, disk, *keep));
        let rel: Vec<String> = (0..3)
            .map(|c| format!("{:+7.1}", 100.0 * (d[c].0 / w[c].0 - 1.0)))
            .collect();
        let x0 = -1.0 + 0.25 * i as f64;
        println!("[{x0:+.2}, {:+.2})  {}", x0 + 0.25, rel.join("  "));
    }
}

/// Eight bands of width R/4 in the pixel's x offset from CX (its centre).
const BANDS: [fn(f64, f64, f64) -> bool; 8] = [
    |x0, x1, r| band(x0, x1, r, 0),
    |x0, x1, r| band(x0, x1, r, 1),
    |x0, x1, r| band(x0, x1, r, 2),
    |x0, x1, r| band(x0, x1, r, 3),
    |x0, x1, r| band(x0, x1, r, 4),
    |x0, x1, r| band(x0, x1, r, 5),
    |x0, x1, r| band(x0, x1, r, 6),
    |x0, x1, r| band(x0, x1, r, 7),
];

fn band(x0: f64, x1: f64, r: f64, i: usize) -> bool {
    let t = 0.5 * (x0 + x1) / r;
    let lo = -1.0 + 0.25 * i as f64;
    t >= lo && t < lo + 0.25
}

/// One region's lines: both means and the relative difference per channel.
fn print_region(name: &str, d: [(f64, f64); 3], w: [(f64, f64); 3]) {
    for c in 0..3 {
        let ((md, sd), (mw, sw)) = (d[c], w[c]);
        let rel = md / mw - 1.0;
        let se = (md / mw) * ((sd / md).powi(2) + (sw / mw).powi(2)).sqrt();
        println!(
            "{name:<6}  {}   {md:.6}   {mw:.6}   {:+6.2} ± {:.2}",
            ["r", "g", "b"][c],
            100.0 * rel,
            100.0 * se
        );
    }
}
