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
use lucent_tools::table_file::TableCommand;
use std::fmt::Write as _;

fn main() {
    let cmd = TableCommand::from_args("crates/lucent/src/bssrdf/profile_table.csv");
    let mut s = Settings::default();
    if cmd.has("--quick") {
        s.walks /= 20;
    }
    let nodes = generate(&s, |m| cmd.progress(m));
    let secs = cmd.seconds();
    let header = [
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
    ]
    .map(String::from);
    let mut rows = String::new();
    let e = edges();
    for n in &nodes {
        for (k, w) in e.windows(2).enumerate() {
            writeln!(
                rows,
                "{},{},{:.7},{:.7},{:.4e},{:.2e}",
                n.eta, n.x, w[0], w[1], n.share[k], n.se[k]
            )
            .unwrap();
        }
    }
    cmd.write(&header, "eta,x,u0,u1,share,se", &rows);
}
