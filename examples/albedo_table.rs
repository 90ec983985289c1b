//! Generates `crates/lucent/src/bssrdf/albedo_table.csv`, the total diffuse reflectance
//! of a semi-infinite medium behind a smooth dielectric boundary, by the
//! random walk's physics (`lucent_tools::halfspace`; `docs/bssrdf.md` §9).
//!
//!     cargo run --release --example albedo_table [-- OUT.csv [--quick]]
//!     cargo run --release --example albedo_table -- --similarity
//!
//! `--similarity` measures instead how well the g = 0 table serves an
//! anisotropic medium through its reduced albedo α' (g = 0.5 and 0.8 at
//! η = 1.3, against g = 0 walks with the same random numbers).
//!
//! `scripts/albedo-table.sh` runs it. Deterministic for any thread count.

use lucent_tools::halfspace::{albedo_from_reduced, generate, run, Batch, Entry, TableSettings};
use lucent_tools::table_file::TableCommand;
use std::fmt::Write as _;

fn main() {
    let cmd = TableCommand::from_args("crates/lucent/src/bssrdf/albedo_table.csv");
    let mut s = TableSettings::default();
    if cmd.has("--similarity") {
        similarity(&s);
        return;
    }
    if cmd.has("--quick") {
        s.walks_diffuse /= 20;
        s.walks_normal /= 20;
    }
    let t = generate(&s, |m| cmd.progress(m));
    let secs = cmd.seconds();
    let header = [
        "lucent albedo table: total diffuse reflectance of a semi-infinite medium",
        "behind a smooth dielectric boundary (docs/bssrdf.md section 9).",
        "Made by `cargo run --release --example albedo_table` (lucent_tools::halfspace):",
        "the random walk's free flights, Henyey-Greenstein sampling (g = 0) and",
        "dielectric boundary in the half-space z < 0, all albedos from one set of",
        "walks (R(alpha) = E[alpha^n], n = scattering events before escape).",
        &format!(
            "seed {}, {} walks per eta with diffuse entry, {} with normal entry, cap {} events;",
            s.seed, s.walks_diffuse, s.walks_normal, s.cap
        ),
        &format!(
            "{:.3e} scattering events in {secs:.0} s.",
            t.walk_events as f64
        ),
        "Columns: eta = inside/outside index; x = sqrt(1 - alpha'), alpha' the",
        "reduced albedo; r_diffuse = fraction of the light entering from uniform",
        "radiance outside that leaves again (the A of the diffusion model);",
        "r_normal = the same for light entering along the normal; se_* = standard",
        "errors. x = 0 is exact (R = 1).",
        &format!(
            "Measured errors: largest standard error {:.1e}; largest |linear interpolation",
            t.max_se
        ),
        &format!(
            "in x - simulated| at the x midpoints {:.1e} (x > 1/40), in eta at eta = {:?} {:.1e}",
            t.max_x_interp, s.eta_checks, t.max_eta_interp
        ),
        &format!(
            "(interpolating R/R_dipole, docs/bssrdf.md section 9); cap bias below {:.1e}.",
            t.max_cap_bound
        ),
    ]
    .map(String::from);
    let mut rows = String::new();
    for r in &t.rows {
        writeln!(
            rows,
            "{:.2},{:.4},{:.6},{:.6},{:.6},{:.6}",
            r.eta, r.x, r.r_diffuse, r.se_diffuse, r.r_normal, r.se_normal
        )
        .unwrap();
    }
    cmd.write(
        &header,
        "eta,x,r_diffuse,se_diffuse,r_normal,se_normal",
        &rows,
    );
}

/// R(α', η = 1.3) at g = 0.5 and 0.8 (single-scattering albedo from α')
/// against g = 0, printed as a markdown table.
fn similarity(s: &TableSettings) {
    let eta = 1.3;
    let reduced = [0.3, 0.6, 0.8, 0.9, 0.95, 0.99, 0.995, 0.999];
    let walks = 100_000;
    let base = run(eta, 0.0, Entry::Diffuse, &reduced, &s.batch(walks));
    println!("| α' | R, g = 0 | R, g = 0.5 | R, g = 0.8 |");
    println!("|---|---|---|---|");
    let mut rows: Vec<Vec<String>> = reduced
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let (r, se) = base.estimate(i);
            vec![format!("{a}"), format!("{r:.4} ± {se:.4}")]
        })
        .collect();
    for g in [0.5, 0.8] {
        let albedos: Vec<f64> = reduced.iter().map(|&a| albedo_from_reduced(a, g)).collect();
        let cap = (s.cap as f64 / (1.0 - g)) as u32;
        let t = run(
            eta,
            g,
            Entry::Diffuse,
            &albedos,
            &Batch {
                cap,
                ..s.batch(walks)
            },
        );
        for (i, row) in rows.iter_mut().enumerate() {
            let (r, se) = t.estimate(i);
            let (r0, _) = base.estimate(i);
            row.push(format!(
                "{r:.4} ± {se:.4} ({:+.2} %)",
                100.0 * (r / r0 - 1.0)
            ));
        }
    }
    for r in rows {
        println!("| {} |", r.join(" | "));
    }
}
