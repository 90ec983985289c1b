//! Mean radiance per channel over a disk of pixels of an EXR, with its
//! standard error (pixels treated as independent), for the accuracy report
//! of `scripts/albedo-report.py`:
//!
//!     cargo run --release --example image_mean -- IMAGE.exr [CX CY R [left|right]]
//!
//! Prints `mean_r mean_g mean_b se_r se_g se_b pixels`. Without a disk
//! (pixel coordinates of its centre and its radius) every pixel counts.
//! A pixel counts if its whole square lies inside the disk; with `left`
//! or `right`, only the half of the disk left (x < CX) or right of its
//! centre (the lit and dark sides of a sphere lit from one side).

use lucent::film::Film;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: image_mean IMAGE.exr [CX CY R]");
        std::process::exit(2)
    };
    let film = Film::read_exr(Path::new(path)).unwrap_or_else(|e| {
        eprintln!("error: {path}: {e}");
        std::process::exit(2)
    });
    let disk: Option<[f64; 3]> = if args.len() >= 4 {
        let v: Vec<f64> = args[1..4]
            .iter()
            .map(|s| {
                s.parse().unwrap_or_else(|_| {
                    eprintln!("error: not a number: {s}");
                    std::process::exit(2)
                })
            })
            .collect();
        Some([v[0], v[1], v[2]])
    } else {
        None
    };
    let half = args.get(4).map(String::as_str);
    if !matches!(half, None | Some("left") | Some("right")) {
        eprintln!("error: expected left or right, found {}", args[4]);
        std::process::exit(2)
    }
    let (w, h) = (film.width as usize, film.height as usize);
    let mut vals: Vec<[f64; 3]> = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if let Some([cx, cy, r]) = disk {
                // farthest corner of the pixel square from the centre
                let dx = (x as f64 - cx).abs().max((x as f64 + 1.0 - cx).abs());
                let dy = (y as f64 - cy).abs().max((y as f64 + 1.0 - cy).abs());
                if dx * dx + dy * dy > r * r {
                    continue;
                }
                let left = (x as f64 + 1.0) <= cx;
                let right = x as f64 >= cx;
                if (half == Some("left") && !left) || (half == Some("right") && !right) {
                    continue;
                }
            }
            let p = film.pixels[y * w + x];
            vals.push([p[0] as f64, p[1] as f64, p[2] as f64]);
        }
    }
    let n = vals.len() as f64;
    if vals.len() < 2 {
        eprintln!("error: fewer than 2 pixels in the disk");
        std::process::exit(2)
    }
    let mut out = Vec::new();
    let mut ses = Vec::new();
    for c in 0..3 {
        let m = vals.iter().map(|v| v[c]).sum::<f64>() / n;
        let var = vals.iter().map(|v| (v[c] - m).powi(2)).sum::<f64>() / (n - 1.0);
        out.push(format!("{m:.6}"));
        ses.push(format!("{:.6}", (var / n).sqrt()));
    }
    println!("{} {} {}", out.join(" "), ses.join(" "), vals.len());
}
