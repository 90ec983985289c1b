//! Where diffuse light entering the half-space of a medium leaves it, by
//! distance: a table of the share of the escaping light that leaves in
//! each bin of u = r/ℓd from the entry point,
//!
//! ```text
//! share_k(x, η),    x = √(1 − α'),
//! ```
//!
//! behind a smooth dielectric of index η, computed by the random walk's own
//! physics (generator `tools::profile_table`, run by
//! `examples/profile_table.rs`; the data file's header states its seed and
//! walk counts). The tabulated profile ([`super::tabulated`]) is built from
//! one row, interpolated linearly in η and x and clamped to the grid; why
//! a table and not the normalized-diffusion fit: `docs/bssrdf.md` §10,
//! "Where the light leaves".

use std::sync::OnceLock;

use super::albedo_table::{read_rows, TableError};
use super::curvature_table::cell;

/// The data file, embedded.
pub(crate) const DATA: &str = include_str!("profile_table.csv");

/// Where the data file is, for messages.
pub(crate) const DATA_PATH: &str = "crates/lucent/src/bssrdf/profile_table.csv";

/// The data file's columns, in order.
pub const COLUMNS: [&str; 6] = ["eta", "x", "u0", "u1", "share", "se"];

/// The shares on a regular grid in (η, x) over common bins of u.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileTable {
    pub etas: Vec<f64>,
    pub xs: Vec<f64>,
    /// The bin edges in u = r/ℓd, from 0, increasing.
    pub edges: Vec<f64>,
    /// The shares, indexed `[i_eta][i_x][bin]`; each row sums to 1.
    pub share: Vec<Vec<Vec<f64>>>,
}

impl ProfileTable {
    /// The embedded table, parsed once.
    pub fn get() -> Result<&'static ProfileTable, &'static TableError> {
        static TABLE: OnceLock<Result<ProfileTable, TableError>> = OnceLock::new();
        TABLE
            .get_or_init(|| ProfileTable::parse(DATA, DATA_PATH))
            .as_ref()
    }

    /// Parses the CSV text: `#` comment lines, a header naming
    /// [`COLUMNS`], then rows sorted by η, then x, then u0, every (η, x)
    /// with the same bins (from 0, contiguous), shares ≥ 0 summing to 1
    /// within 10⁻³ per (η, x).
    pub fn parse(text: &str, file: &'static str) -> Result<ProfileTable, TableError> {
        let err = |line: usize, field: &str, problem: String| TableError {
            file,
            line,
            field: field.to_string(),
            problem,
        };
        let (hl, rows) = read_rows(text, file, &COLUMNS)?;
        let mut t = ProfileTable {
            etas: Vec::new(),
            xs: Vec::new(),
            edges: vec![0.0],
            share: Vec::new(),
        };
        let mut row: Vec<f64> = Vec::new();
        let mut key: Option<(f64, f64)> = None;
        let mut last = hl;
        let mut done: Vec<((f64, f64), Vec<f64>, usize)> = Vec::new();
        for (ln, v) in rows {
            let ok = [
                v[0] >= 1.0,
                v[1] > 0.0 && v[1] <= 1.0,
                v[2] >= 0.0,
                v[3] > v[2],
                v[4] >= 0.0 && v[4] <= 1.0,
                v[5] >= 0.0,
            ];
            if let Some(k) = ok.iter().position(|&o| !o) {
                return Err(err(ln, COLUMNS[k], format!("{} out of range", v[k])));
            }
            if key != Some((v[0], v[1])) {
                if let Some(k) = key {
                    done.push((k, std::mem::take(&mut row), last));
                }
                key = Some((v[0], v[1]));
            }
            let bin = row.len();
            if done.is_empty() {
                if v[2] != t.edges[bin] {
                    return Err(err(ln, "u0", format!("expected {}", t.edges[bin])));
                }
                t.edges.push(v[3]);
            } else if t.edges.get(bin..bin + 2) != Some(&[v[2], v[3]][..]) {
                return Err(err(ln, "u0", "bins differ from the first node's".into()));
            }
            row.push(v[4]);
            last = ln;
        }
        if let Some(k) = key {
            done.push((k, row, last));
        }
        for ((eta, x), _, _) in &done {
            if !t.etas.contains(eta) {
                t.etas.push(*eta);
            }
            if !t.xs.contains(x) {
                t.xs.push(*x);
            }
        }
        let (ne, nx, nb) = (t.etas.len(), t.xs.len(), t.edges.len() - 1);
        if ne < 2 || nx < 2 || ne * nx != done.len() {
            return Err(err(
                last,
                "row",
                format!(
                    "{} nodes do not form a grid over {ne} eta, {nx} x",
                    done.len()
                ),
            ));
        }
        t.share = vec![vec![Vec::new(); nx]; ne];
        for (n, ((eta, x), shares, ln)) in done.into_iter().enumerate() {
            let (ie, ix) = (n / nx, n % nx);
            if eta != t.etas[ie] || x != t.xs[ix] {
                return Err(err(ln, "x", "rows not sorted by eta, then x".into()));
            }
            if shares.len() != nb {
                return Err(err(
                    ln,
                    "u1",
                    format!("{} bins, expected {nb}", shares.len()),
                ));
            }
            let sum: f64 = shares.iter().sum();
            if (sum - 1.0).abs() > 1e-3 {
                return Err(err(ln, "share", format!("shares sum to {sum}")));
            }
            t.share[ie][ix] = shares;
        }
        for (name, v) in [("eta", &t.etas), ("x", &t.xs)] {
            if v.windows(2).any(|w| w[1] <= w[0]) {
                return Err(err(last, name, "not increasing".into()));
            }
        }
        Ok(t)
    }

    /// The shares for one medium, interpolated bilinearly in (η, x)
    /// (clamped to the grid) and normalized to sum to 1.
    pub fn row(&self, x: f64, eta: f64) -> Vec<f64> {
        let (ie, se) = cell(&self.etas, eta);
        let (ix, sx) = cell(&self.xs, x);
        let mut out: Vec<f64> = (0..self.edges.len() - 1)
            .map(|k| {
                let at = |e: usize, i: usize| self.share[e][i][k];
                let lo = at(ie, ix) * (1.0 - sx) + at(ie, ix + 1) * sx;
                let hi = at(ie + 1, ix) * (1.0 - sx) + at(ie + 1, ix + 1) * sx;
                lo * (1.0 - se) + hi * se
            })
            .collect();
        let sum: f64 = out.iter().sum();
        out.iter_mut().for_each(|s| *s /= sum);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded table parses; every row sends most of its light out
    /// within one diffusion length and next to none beyond eight.
    #[test]
    fn embedded_table_parses_and_is_physical() {
        let t = ProfileTable::get().expect("embedded table");
        assert!(t.etas.len() >= 2 && t.xs.len() >= 2 && t.edges.len() > 40);
        let share = |row: &[f64], keep: &dyn Fn(&[f64]) -> bool| -> f64 {
            row.iter()
                .zip(t.edges.windows(2))
                .filter(|(_, e)| keep(e))
                .map(|(s, _)| s)
                .sum()
        };
        for (ie, rows) in t.share.iter().enumerate() {
            for (ix, row) in rows.iter().enumerate() {
                let near = share(row, &|e| e[1] <= 1.0);
                let far = share(row, &|e| e[0] >= 8.0);
                let at = format!("eta {} x {}", t.etas[ie], t.xs[ix]);
                assert!(near > 0.5 && near < 0.999, "{at}: {near}");
                assert!(far < 2e-3, "{at}: {far}");
            }
        }
    }

    /// Halfway between two x nodes and two η nodes, a row is the mean of
    /// the four nodes' shares (before normalizing, which the nodes' own
    /// sums of 1 make a no-op up to rounding).
    #[test]
    fn rows_interpolate_bilinearly_and_sum_to_one() {
        let t = ProfileTable::get().unwrap();
        let (ie, ix) = (1, 3);
        let x = 0.5 * (t.xs[ix] + t.xs[ix + 1]);
        let eta = 0.5 * (t.etas[ie] + t.etas[ie + 1]);
        let row = t.row(x, eta);
        let sum = |ie: usize, ix: usize| t.share[ie][ix].iter().sum::<f64>();
        let norm = 0.25 * (sum(ie, ix) + sum(ie, ix + 1) + sum(ie + 1, ix) + sum(ie + 1, ix + 1));
        for (k, v) in row.iter().enumerate() {
            let want = 0.25
                * (t.share[ie][ix][k]
                    + t.share[ie][ix + 1][k]
                    + t.share[ie + 1][ix][k]
                    + t.share[ie + 1][ix + 1][k])
                / norm;
            assert!((v - want).abs() < 1e-12, "bin {k}: {v} vs {want}");
        }
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert_eq!(t.row(t.xs[ix], t.etas[ie]).len(), t.edges.len() - 1);
    }

    #[test]
    fn bad_files_name_line_and_field() {
        let head = "eta,x,u0,u1,share,se\n";
        let node = |e: f64, x: f64| format!("{e},{x},0,1,0.6,0\n{e},{x},1,2,0.4,0\n");
        let good = [(1.0, 0.1), (1.0, 0.2), (1.5, 0.1), (1.5, 0.2)]
            .map(|(e, x)| node(e, x))
            .concat();
        let t = ProfileTable::parse(&format!("{head}{good}"), "f.csv").unwrap();
        assert_eq!((t.etas.len(), t.xs.len(), t.edges.len()), (2, 2, 3));
        let e = ProfileTable::parse("eta,x\n", "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (1, "header"));
        let e = ProfileTable::parse(&format!("{head}1.0,0.1,0,1,1.5,0\n"), "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (2, "share"));
        // the second node's bins differ from the first's
        let text = format!("{head}{}1.0,0.2,0,1.5,0.6,0\n", node(1.0, 0.1));
        let e = ProfileTable::parse(&text, "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (4, "u0"));
        // shares that do not sum to 1
        let text = format!("{head}{}", good.replacen("0.4", "0.3", 1));
        let e = ProfileTable::parse(&text, "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (3, "share"));
        // three nodes cannot fill a 2×2 grid
        let three = [(1.0, 0.1), (1.0, 0.2), (1.5, 0.1)]
            .map(|(e, x)| node(e, x))
            .concat();
        let e = ProfileTable::parse(&format!("{head}{three}"), "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (7, "row"));
    }
}
