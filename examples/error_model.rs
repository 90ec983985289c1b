//! The accuracy budget's error measure (`docs/bssrdf.md` §14): how far an
//! estimator's image of one object is from the random walk's, as
//!
//!     E = Σ_b,c |D̄_bc − W̄_bc| / Σ_b,c W̄_bc,
//!
//! over four vertical bands b of the object (its pixels where the walk
//! has light, split by column from its left edge to its right one) and
//! the three channels c; D̄ and W̄ are band means over independent renders.
//! A light from one side makes the bands run from the lit limb to the far
//! one, so E counts where the light leaves as well as how much leaves.
//!
//!     cargo run --release --example error_model -- EST.exr… -- WALK.exr…
//!
//! Prints `E sigma`: sigma is E's standard error from the renders'
//! spread per band (each side's per-band standard error, added in
//! quadrature over bands and channels; with one render per side the
//! pixels' spread, which overstates it where a band has a gradient).
//! `scripts/error-model.sh` and `scripts/accuracy-check.sh` call it.

use lucent::film::Film;
use lucent_tools::image_sets::two_sets;

const BANDS: usize = 4;

/// Band index of every pixel of the object (None: not the object).
fn bands(walk: &[Film]) -> Vec<Option<usize>> {
    let w = walk[0].width as usize;
    let n = walk[0].pixels.len();
    let lit = |i: usize| walk.iter().any(|f| f.pixels[i].max_element() > 0.0);
    let cols: Vec<usize> = (0..n).filter(|&i| lit(i)).map(|i| i % w).collect();
    let (x0, x1) = match (cols.iter().min(), cols.iter().max()) {
        (Some(&a), Some(&b)) => (a as f64, b as f64 + 1.0),
        _ => {
            eprintln!("error: the walk's renders are black");
            std::process::exit(2)
        }
    };
    let width = (x1 - x0) / BANDS as f64;
    (0..n)
        .map(|i| {
            let x = (i % w) as f64 + 0.5;
            lit(i).then(|| (((x - x0) / width) as usize).min(BANDS - 1))
        })
        .collect()
}

/// Per band and channel: the mean over renders and its standard error.
fn band_means(films: &[Film], band: &[Option<usize>]) -> Vec<[(f64, f64); 3]> {
    let each: Vec<Vec<[f64; 3]>> = films.iter().map(|f| one(f, band)).collect();
    let k = each.len() as f64;
    (0..BANDS)
        .map(|b| {
            std::array::from_fn(|c| {
                let m = each.iter().map(|e| e[b][c]).sum::<f64>() / k;
                let var = if each.len() > 1 {
                    each.iter().map(|e| (e[b][c] - m).powi(2)).sum::<f64>() / (k - 1.0) / k
                } else {
                    pixel_variance(&films[0], band, b, c, m)
                };
                (m, var.sqrt())
            })
        })
        .collect()
}

/// One render's band means.
fn one(f: &Film, band: &[Option<usize>]) -> Vec<[f64; 3]> {
    let mut sum = [[0.0; 3]; BANDS];
    let mut count = [0usize; BANDS];
    for (i, b) in band.iter().enumerate() {
        if let Some(b) = *b {
            for (c, s) in sum[b].iter_mut().enumerate() {
                *s += f.pixels[i][c] as f64;
            }
            count[b] += 1;
        }
    }
    (0..BANDS)
        .map(|b| sum[b].map(|s| s / count[b].max(1) as f64))
        .collect()
}

/// The variance of band `b`'s mean in channel `c`, pixels as independent.
fn pixel_variance(f: &Film, band: &[Option<usize>], b: usize, c: usize, m: f64) -> f64 {
    let v: Vec<f64> = (0..band.len())
        .filter(|&i| band[i] == Some(b))
        .map(|i| f.pixels[i][c] as f64)
        .collect();
    let n = v.len().max(2) as f64;
    v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0) / n
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(split) = args.iter().position(|a| a == "--") else {
        eprintln!("usage: error_model EST.exr... -- WALK.exr...");
        std::process::exit(2)
    };
    let (est, walk) = two_sets(&args[..split], &args[split + 1..], ["estimator", "walk"])
        .unwrap_or_else(|e| {
            eprintln!("error: {e}");
            std::process::exit(2)
        });
    let band = bands(&walk);
    let (d, w) = (band_means(&est, &band), band_means(&walk, &band));
    let (mut num, mut den, mut var) = (0.0, 0.0, 0.0);
    for b in 0..BANDS {
        for c in 0..3 {
            num += (d[b][c].0 - w[b][c].0).abs();
            den += w[b][c].0;
            var += d[b][c].1.powi(2) + w[b][c].1.powi(2);
        }
    }
    println!("{:.5} {:.5}", num / den, var.sqrt() / den);
}
