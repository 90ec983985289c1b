//! Generates `src/bssrdf/curvature_table.csv`: per (η, x = √(1 − α'), ρ)
//! the ratio h = (1 − A_sphere) / (1 − A_slab) of what a sphere of radius
//! ρ diffusion lengths and the half-space of the same medium absorb under
//! uniform light, by the random walk's physics
//! (`lucent::tools::sphere_albedo`; `docs/bssrdf.md` §10).
//!
//!     cargo run --release --example curvature_table [-- OUT.csv [--quick]]
//!
//! `scripts/curvature-table.sh` runs it. Deterministic for any thread count.

use lucent::tools::sphere_albedo::{generate, Settings};
use std::fmt::Write as _;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .cloned()
        .unwrap_or_else(|| "src/bssrdf/curvature_table.csv".into());
    let mut s = Settings::default();
    if args.iter().any(|a| a == "--quick") {
        s.walks_sphere /= 20;
        s.walks_slab /= 20;
    }
    let start = std::time::Instant::now();
    let t = generate(&s, |m| {
        eprintln!("{m} ({:.0} s)", start.elapsed().as_secs_f64())
    });
    let secs = start.elapsed().as_secs_f64();
    let max_se = t.nodes.iter().map(|n| n.se_h).fold(0.0, f64::max);
    // The error that matters downstream: of A_sphere = 1 − h (1 − A_slab).
    let max_se_a = t
        .nodes
        .iter()
        .map(|n| n.se_h * (1.0 - n.a_slab))
        .fold(0.0, f64::max);
    let mut csv = String::new();
    for line in [
        "lucent curvature table: what a sphere absorbs against the half-space of the",
        "same medium, both behind a smooth dielectric boundary, under uniform light",
        "(docs/bssrdf.md section 10). Made by `cargo run --release --example",
        "curvature_table` (lucent::tools::sphere_albedo): the random walk's free",
        "flights, isotropic scattering and dielectric boundary, analog absorption.",
        &format!(
            "seed {}, {} walks per sphere node, {} per half-space; {:.3e} events in {secs:.0} s.",
            s.seed, s.walks_sphere, s.walks_slab, t.events as f64
        ),
        "Columns: eta = inside/outside index; x = sqrt(1 - alpha'); rho = sphere radius",
        "in diffusion lengths 1/sigma_tr; h = (1 - A_sphere)/(1 - A_slab) and its",
        "standard error; A_sphere, A_slab the escape fractions of entering diffuse light.",
        &format!(
            "Largest standard error: of h {max_se:.2e}, of A_sphere = 1 - h (1 - A_slab) {max_se_a:.2e}."
        ),
    ] {
        writeln!(csv, "# {line}").unwrap();
    }
    writeln!(csv, "eta,x,rho,h,se_h,a_sphere,a_slab").unwrap();
    for n in &t.nodes {
        writeln!(
            csv,
            "{},{},{:.6},{:.6},{:.6},{:.6},{:.6}",
            n.eta, n.x, n.rho, n.h, n.se_h, n.a_sphere, n.a_slab
        )
        .unwrap();
    }
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, csv).expect("write table");
    std::fs::rename(&tmp, &out).expect("rename table");
    eprintln!("wrote {out}");
}
