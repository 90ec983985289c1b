//! Where light entering a preset's sphere at one point leaves it, by
//! chord distance r, against what the diffusion estimator assigns
//! (`lucent_tools::sphere_transfer`, `docs/bssrdf.md` §10, "Where the
//! light leaves"):
//!
//!     cargo run --release --example sphere_transfer -- [PRESET [RADIUS_MM [WALKS [RMAX_QUANTILE [ANGLE]]]]]
//!
//! Defaults: marble, 10 mm, 200 000 walks per channel and body, the
//! renderer's Rmax quantile, diffuse entry; ANGLE (degrees from the
//! normal) makes the light enter from one side instead, and the table's
//! last column is the share of each bin's exits ahead of the entry point
//! (on the side the refracted light heads to). Per
//! channel and bin of r (mm): the walk's T(r) per mm² on the sphere and on
//! the half-space, the model's A·R(r)·f(1/R) (0 beyond Rmax; on the
//! half-space A·R(r)), and their ratios; then the share of the returned
//! light that leaves beyond chord √2·R (the far hemisphere) for the walk
//! and for the model. Deterministic for any thread count.

use lucent::bssrdf::curvature_correction::CurvatureCorrection;
use lucent::bssrdf::{profile, Fit, ProbeOptions, ProbeSampler, SubsurfaceParams};
use lucent_tools::halfspace::Entry;
use lucent_tools::sphere_albedo::Body;
use lucent_tools::sphere_transfer::{transfer, Walks};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let preset = args.first().map(String::as_str).unwrap_or("marble");
    let num = |i: usize, default: f64| -> f64 {
        args.get(i).map_or(default, |s| {
            s.parse().unwrap_or_else(|_| {
                eprintln!("error: not a number: {s}");
                std::process::exit(2)
            })
        })
    };
    let radius_mm = num(1, 10.0);
    let walks = num(2, 200_000.0) as u64;
    let p = SubsurfaceParams::from_preset(preset, 1.0, Fit::Searchlight).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let opts = ProbeOptions {
        rmax_quantile: num(3, ProbeOptions::default().rmax_quantile),
        ..ProbeOptions::default()
    };
    let sampler = ProbeSampler::new(&p, &opts).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let cc = CurvatureCorrection::new(&p, &sampler).unwrap().unwrap();
    let f = cc.exact_factor(1.0 / radius_mm);
    let bins = 20;
    let mut edges_mm: Vec<f64> = (0..=bins)
        .map(|i| 2.0 * radius_mm * i as f64 / bins as f64)
        .collect();
    // the last edge a hair beyond the diameter, so antipodal exits count
    edges_mm[bins] *= 1.0 + 1e-9;
    let setup = Setup {
        p,
        rmax: sampler.rmax(),
        far_bin: edges_mm.partition_point(|&e| e < 2f64.sqrt() * radius_mm),
        edges_mm,
        radius_mm,
        walks,
        entry: match args.get(4) {
            None => Entry::Diffuse,
            Some(_) => Entry::Oblique(num(4, 0.0).to_radians().cos() as f32),
        },
    };
    println!(
        "{preset}, sphere of radius {radius_mm} mm, Rmax {:.2} mm, {walks} walks",
        setup.rmax
    );
    for (c, &fc) in f.iter().enumerate() {
        channel(&setup, c, fc);
    }
}

/// What every channel's comparison shares.
struct Setup {
    p: SubsurfaceParams,
    rmax: f64,
    /// The first bin beyond chord √2·R (the far hemisphere).
    far_bin: usize,
    edges_mm: Vec<f64>,
    radius_mm: f64,
    walks: u64,
    entry: Entry,
}

/// Channel `c`'s table (module docs); `fc` is its f(1/R).
fn channel(s: &Setup, c: usize, fc: f64) {
    let (p, m) = (&s.p, s.p.medium.unwrap());
    let ss = m.sigma_s[c] * (1.0 - m.g);
    let st = ss + m.sigma_a[c];
    let edges: Vec<f64> = s.edges_mm.iter().map(|e| e * st).collect();
    let (alpha, stream) = (ss / st, 16 * c as u64);
    let body = Body::Sphere(s.radius_mm * st);
    let run = |body, stream| {
        let w = Walks {
            body,
            entry: s.entry,
            alpha,
            eta: p.eta,
            walks: s.walks,
            seed: 1,
            stream,
        };
        transfer(&w, &edges)
    };
    let (sphere, slab) = (run(body, stream), run(Body::HalfSpace, stream + 1));
    let (a, d) = (p.albedo[c], p.d[c]);
    let ld = lucent::bssrdf::params::diffuse_mfp(ss, m.sigma_a[c]);
    println!("channel {c}: A {a:.4}, d {d:.3} mm, ld {ld:.2} mm, f(1/R) {fc:.3}");
    println!("  r [mm]   T_sphere    model       ratio   T_slab      A·R(r)      ratio   ahead");
    let bins = s.edges_mm.len() - 1;
    let (mut model_far, mut model_all) = (0.0, 0.0);
    for i in 0..bins {
        let (r0, r1) = (s.edges_mm[i], s.edges_mm[i + 1]);
        let area = std::f64::consts::PI * (r1 * r1 - r0 * r0);
        // the profile's mean over the bin: its integral / area
        let int = a * (profile::cdf(r1.min(s.rmax), d) - profile::cdf(r0.min(s.rmax), d));
        let model = fc * int / area;
        model_all += fc * int;
        if i >= s.far_bin {
            model_far += fc * int;
        }
        let (ts, tp) = (sphere.density(i) * st * st, slab.density(i) * st * st);
        let ahead = sphere.ahead[i] as f64 / sphere.counts[i].max(1) as f64;
        println!(
            "  {:5.1}   {ts:.3e}   {model:.3e}   {:6.3}  {tp:.3e}   {:.3e}   {:6.3}  {:5.1} %",
            0.5 * (r0 + r1),
            ts / model,
            int / area,
            tp / (int / area),
            100.0 * ahead
        );
    }
    let walk_all = sphere.fraction(0..bins);
    let walk_far = sphere.fraction(s.far_bin..bins);
    println!(
        "  returned: walk {walk_all:.4}, model {model_all:.4}; beyond √2·R: walk {:.2} %, model {:.2} % of it",
        100.0 * walk_far / walk_all,
        100.0 * model_far / model_all
    );
}
