//! Error against a reference of frames raw and denoised, with the guides
//! prefiltered (`cleanAux`) and as they are, for docs/accuracy.md
//! ("Denoising") and the journal:
//!
//!     LUCENT_OIDN=… cargo run --profile quick --example denoise_compare -- \
//!         REF.exr THREADS FRAME.exr...
//!
//! Each FRAME needs the `albedo` and `N` passes. Prints, per frame, the
//! relMSE, bias and the bias's standard error (the study's metrics) of its beauty and of its two
//! denoised versions, and each denoise's time.

use std::path::Path;
use std::time::Instant;

use lucent::denoise::{denoise, DenoiseInput, DenoiseOptions};
use lucent::film::Film;
use lucent::geometry::Vec3;
use lucent_tools::study::metrics::compare;

#[path = "../tests/common/exr_file.rs"]
#[allow(dead_code)]
mod exr_file;

/// The channels `names` of the single-layer EXR at `path`, as pixels, and
/// its size.
fn read(path: &str, names: [&str; 3]) -> (Vec<Vec3>, u32, u32) {
    let image = exr_file::first_layer(Path::new(path));
    let list = &image.layer_data.channel_data.list;
    let plane = |n: &str| -> Vec<f32> {
        let c = list
            .iter()
            .find(|c| c.name == *n)
            .unwrap_or_else(|| panic!("{path}: no {n}"));
        exr_file::floats(&c.sample_data)
    };
    let [r, g, b] = names.map(plane);
    let px = (0..r.len()).map(|i| Vec3::new(r[i], g[i], b[i])).collect();
    let s = image.layer_data.size;
    (px, s.0 as u32, s.1 as u32)
}

fn film(pixels: Vec<Vec3>, width: u32, height: u32) -> Film {
    Film {
        width,
        height,
        pixels,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: denoise_compare REF.exr THREADS FRAME.exr...");
        std::process::exit(2);
    }
    let (r, w, h) = read(&args[0], ["R", "G", "B"]);
    let reference = film(r, w, h);
    let threads: usize = args[1].parse().expect("THREADS");
    println!("frame,version,relmse,bias,bias_stderr,denoise_seconds");
    for path in &args[2..] {
        let (color, w, h) = read(path, ["R", "G", "B"]);
        let (albedo, _, _) = read(path, ["albedo.R", "albedo.G", "albedo.B"]);
        let (normal, _, _) = read(path, ["N.X", "N.Y", "N.Z"]);
        let name = Path::new(path).file_name().unwrap().to_string_lossy();
        let show = |version: &str, px: Vec<Vec3>, secs: f64| {
            let m = compare(&film(px, w, h), &reference, 1.0).expect("same size");
            let (r, b, e) = (m.rel_mse, m.bias, m.bias_stderr);
            println!("{name},{version},{r:.6},{b:.5},{e:.5},{secs:.3}");
        };
        show("raw", color.clone(), 0.0);
        for (version, prefilter_guides) in [
            ("denoised-prefiltered", true),
            ("denoised-noisy-guides", false),
        ] {
            let input = DenoiseInput {
                width: w,
                height: h,
                color: &color,
                albedo: &albedo,
                normal: &normal,
            };
            let opts = DenoiseOptions {
                threads: Some(threads),
                prefilter_guides,
                layers: false,
                max_memory_mb: None,
            };
            let t = Instant::now();
            let out = denoise(&input, &opts).unwrap_or_else(|e| panic!("{path}: {e}"));
            show(version, out, t.elapsed().as_secs_f64());
        }
    }
}
