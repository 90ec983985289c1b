//! Generates `crates/lucent/src/bssrdf/profile_table.csv`: per (η, x =
//! √(1 − α')) the share of the light escaping the half-space that leaves
//! in each bin of u = r/ℓd from where it entered, by the random walk's
//! physics (`lucent_tools::profile_table`; `docs/bssrdf.md` §10, "Where
//! the light leaves").
//!
//!     cargo run --release --example profile_table [-- OUT.csv [--quick]]
//!
//! `scripts/profile-table.sh` runs it. Deterministic for any thread count.

use lucent_tools::profile_table::{edges, generate, Settings, BINS_PER_OCTAVE};
use std::fmt::Write as _;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .cloned()
        .unwrap_or_else(|| "crates/lucent/src/bssrdf/profile_table.csv".into());
    let mut s = Settings::default();
    if args.iter().any(|a| a == "--quick") {
        s.walks /= 20;
    }
    let start = std::time::Instant::now();
    let nodes = generate(&s, |m| {
        eprintln!("{m} ({:.0} s)", start.elapsed().as_secs_f64())
    });
    let secs = start.elapsed().as_secs_f64();
    let mut csv = String::new();
    for line in [
        "lucent profile table: where diffuse light entering the half-space of a medium",
        "behind a smooth dielectric boundary leaves it, by distance from the entry point",
        "(docs/bssrdf.md section 10). Made by `cargo run --release --example",
        "profile_table` (lucent_tools::profile_table): the random walk's free flights,",
        "isotropic scattering and dielectric boundary, analog absorption.",
        &format!(
            "seed {}, {} walks per node, {BINS_PER_OCTAVE} bins per octave; {secs:.0} s.",
            s.seed, s.walks
        ),
        "Columns: eta = inside/outside index; x = sqrt(1 - alpha'); u0, u1 = the bin",
        "in diffusion lengths 1/sigma_tr; share = the fraction of the escaping light",
        "that leaves in the bin, se its standard error.",
    ] {
        writeln!(csv, "# {line}").unwrap();
    }
    writeln!(csv, "eta,x,u0,u1,share,se").unwrap();
    let e = edges();
    for n in &nodes {
        for (k, w) in e.windows(2).enumerate() {
            writeln!(
                csv,
                "{},{},{:.7},{:.7},{:.4e},{:.2e}",
                n.eta, n.x, w[0], w[1], n.share[k], n.se[k]
            )
            .unwrap();
        }
    }
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, csv).expect("write table");
    std::fs::rename(&tmp, &out).expect("rename table");
    eprintln!("wrote {out}");
}
