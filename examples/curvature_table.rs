//! Generates `crates/lucent/src/bssrdf/curvature_table.csv`: per (η, x = √(1 − α'), ρ)
//! the ratio h = (1 − A_sphere) / (1 − A_slab) of what a sphere of radius
//! ρ diffusion lengths and the half-space of the same medium absorb under
//! uniform light, by the random walk's physics
//! (`lucent_tools::sphere_albedo`; `docs/bssrdf.md` §10).
//!
//!     cargo run --release --example curvature_table [-- OUT.csv [--quick]]
//!     cargo run --release --example curvature_table -- --check
//!
//! `--check` measures the embedded table's interpolation error instead: at
//! η = 1.3 and 1.5, new walks at points between the nodes (geometric
//! midpoints in ρ, midpoints in x), A_sphere = 1 − h (1 − A_slab)
//! interpolated against simulated.
//! `scripts/curvature-table.sh` runs it. Deterministic for any thread count.

use lucent::bssrdf::curvature_table::CurvatureTable;
use lucent_tools::sphere_albedo::{escape, generate, Body, Settings};
use lucent_tools::table_file::TableCommand;
use std::fmt::Write as _;

fn main() {
    let cmd = TableCommand::from_args("crates/lucent/src/bssrdf/curvature_table.csv");
    let mut s = Settings::default();
    if cmd.has("--check") {
        check(&s);
        return;
    }
    if cmd.has("--quick") {
        s.walks_sphere /= 20;
        s.walks_slab /= 20;
    }
    let t = generate(&s, |m| cmd.progress(m));
    let secs = cmd.seconds();
    let max_se = t.nodes.iter().map(|n| n.se_h).fold(0.0, f64::max);
    // The error that matters downstream: of A_sphere = 1 − h (1 − A_slab).
    let max_se_a = t
        .nodes
        .iter()
        .map(|n| n.se_h * (1.0 - n.a_slab))
        .fold(0.0, f64::max);
    let header = [
        "lucent curvature table: what a sphere absorbs against the half-space of the",
        "same medium, both behind a smooth dielectric boundary, under uniform light",
        "(docs/bssrdf.md section 10). Made by `cargo run --release --example",
        "curvature_table` (lucent_tools::sphere_albedo): the random walk's free",
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
    ]
    .map(String::from);
    let mut rows = String::new();
    for n in &t.nodes {
        writeln!(
            rows,
            "{},{},{:.6},{:.6},{:.6},{:.6},{:.6}",
            n.eta, n.x, n.rho, n.h, n.se_h, n.a_sphere, n.a_slab
        )
        .unwrap();
    }
    cmd.write(&header, "eta,x,rho,h,se_h,a_sphere,a_slab", &rows);
}

/// Interpolation check (module docs): prints each point and the largest
/// |interpolated − simulated| A_sphere with the simulation's standard error.
fn check(s: &Settings) {
    let t = CurvatureTable::get().expect("embedded table");
    let (mut worst, mut worst_se) = (0.0f64, 0.0f64);
    for eta in [1.3, 1.5] {
        // x midpoints at ρ nodes 1, 4, 16 ld; ρ midpoints at x nodes.
        let mut points = Vec::new();
        for w in t.xs.windows(2).step_by(2) {
            for rho in [1.0, 4.0] {
                points.push((0.5 * (w[0] + w[1]), rho));
            }
        }
        for &x in &[0.03, 0.2, 0.6] {
            for w in t.rhos.windows(2).step_by(3) {
                points.push((x, (w[0] * w[1]).sqrt()));
            }
        }
        for (k, &(x, rho)) in points.iter().enumerate() {
            let alpha = 1.0 - x * x;
            let stream = 1_000_000 + k as u64 * 2;
            let (slab, se_l, _) = escape(
                Body::HalfSpace,
                alpha,
                eta as f32,
                s.walks_slab,
                s.seed + 1,
                stream,
            );
            let radius = rho / (3f64.sqrt() * x);
            let (sph, se_s, _) = escape(
                Body::Sphere(radius),
                alpha,
                eta as f32,
                s.walks_sphere * 2,
                s.seed + 1,
                stream + 1,
            );
            let interp = 1.0 - t.h(rho, x, eta) * (1.0 - slab);
            let err = (interp - sph).abs();
            let se = (se_s * se_s + se_l * se_l).sqrt();
            println!("eta {eta} x {x:.3} rho {rho:.3}: A_sphere {sph:.4} ± {se_s:.4}, interpolated {interp:.4}, |diff| {err:.4} ({:.1} se)", err / se);
            if err > worst {
                worst = err;
                worst_se = se;
            }
        }
    }
    println!("largest |interpolated - simulated| A_sphere: {worst:.4} (standard error of that difference {worst_se:.4})");
}
