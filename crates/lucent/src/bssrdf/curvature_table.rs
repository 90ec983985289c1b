//! What a convex body absorbs against the half-space of the same medium
//! (`docs/bssrdf.md` §10): a table of
//!
//! ```text
//! h(ρ, x, η) = (1 − A_sphere) / (1 − A_slab),    x = √(1 − α'),
//! ```
//!
//! the ratio of the fractions of entering diffuse light that a sphere of
//! radius ρ diffusion lengths and the half-space absorb, behind a smooth
//! dielectric of index η, computed by the random walk's own physics
//! (generator `tools::sphere_albedo`, run by `examples/curvature_table.rs`;
//! the data file's header states its seed, walk counts and largest
//! errors). Interpolated linearly in η, x and ln ρ; why h, and the rules
//! outside the grid: `docs/bssrdf.md` §12.10.

use std::sync::OnceLock;

use super::albedo_table::{read_rows, TableError};

/// The data file, embedded.
pub(crate) const DATA: &str = include_str!("curvature_table.csv");

/// Where the data file is, for messages.
pub(crate) const DATA_PATH: &str = "crates/lucent/src/bssrdf/curvature_table.csv";

/// The data file's columns, in order.
pub const COLUMNS: [&str; 7] = ["eta", "x", "rho", "h", "se_h", "a_sphere", "a_slab"];

/// h on a regular grid in (η, x, ln ρ).
#[derive(Clone, Debug, PartialEq)]
pub struct CurvatureTable {
    pub etas: Vec<f64>,
    pub xs: Vec<f64>,
    pub rhos: Vec<f64>,
    /// h, indexed `[i_eta][i_x][i_rho]`.
    pub h: Vec<Vec<Vec<f64>>>,
    /// The largest standard error of 1 − h·(1 − A_slab) = A_sphere.
    pub max_se_sphere: f64,
}

/// The index i of the cell [v[i], v[i+1]] holding `t` (clamped to the
/// grid) and the weight of v[i+1].
pub(crate) fn cell(v: &[f64], t: f64) -> (usize, f64) {
    let n = v.len();
    if t <= v[0] {
        return (0, 0.0);
    }
    if t >= v[n - 1] {
        return (n - 2, 1.0);
    }
    // v[0] < t < v[n − 1] here, so the partition point lies in 1..n − 1; a
    // NaN t matches no node (point 0) and lands in the first cell, NaN
    // weight.
    let i = v.partition_point(|&x| x <= t).max(1) - 1;
    (i, (t - v[i]) / (v[i + 1] - v[i]))
}

impl CurvatureTable {
    /// The embedded table, parsed once.
    pub fn get() -> Result<&'static CurvatureTable, &'static TableError> {
        static TABLE: OnceLock<Result<CurvatureTable, TableError>> = OnceLock::new();
        TABLE
            .get_or_init(|| CurvatureTable::parse(DATA, DATA_PATH))
            .as_ref()
    }

    /// Parses the CSV text: `#` comment lines, a header naming
    /// [`COLUMNS`], then rows sorted by η, then x, then ρ, on a full grid
    /// (each increasing, at least two nodes each).
    pub fn parse(text: &str, file: &'static str) -> Result<CurvatureTable, TableError> {
        let err = |line: usize, field: &str, problem: String| TableError {
            file,
            line,
            field: field.to_string(),
            problem,
        };
        let mut rows: Vec<(usize, [f64; 7])> = Vec::new();
        let (hl, read) = read_rows(text, file, &COLUMNS)?;
        for (ln, v) in read {
            let ok = [
                v[0] >= 1.0,
                v[1] > 0.0 && v[1] <= 1.0,
                v[2] > 0.0,
                v[3] >= 0.0,
                v[4] >= 0.0,
                (0.0..=1.0).contains(&v[5]),
                (0.0..=1.0).contains(&v[6]),
            ];
            if let Some(k) = ok.iter().position(|&o| !o) {
                return Err(err(ln, COLUMNS[k], format!("{} out of range", v[k])));
            }
            rows.push((ln, v));
        }
        let distinct = |k: usize| {
            let mut out: Vec<f64> = Vec::new();
            for (_, v) in &rows {
                if !out.contains(&v[k]) {
                    out.push(v[k]);
                }
            }
            out
        };
        let (etas, xs, rhos) = (distinct(0), distinct(1), distinct(2));
        let (ne, nx, nr) = (etas.len(), xs.len(), rhos.len());
        let last = rows.last().map_or(hl, |r| r.0);
        if ne < 2 || nx < 2 || nr < 2 || ne * nx * nr != rows.len() {
            return Err(err(
                last,
                "row",
                format!(
                    "{} rows do not form a grid over {ne} eta, {nx} x, {nr} rho",
                    rows.len()
                ),
            ));
        }
        for (name, v) in [("eta", &etas), ("x", &xs), ("rho", &rhos)] {
            if v.windows(2).any(|w| w[1] <= w[0]) {
                return Err(err(last, name, "not increasing".into()));
            }
        }
        let mut h = vec![vec![vec![0.0; nr]; nx]; ne];
        let mut max_se_sphere = 0.0f64;
        for (n, (ln, v)) in rows.iter().enumerate() {
            let (ie, ix, ir) = (n / (nx * nr), (n / nr) % nx, n % nr);
            for (k, want) in [(0, etas[ie]), (1, xs[ix]), (2, rhos[ir])] {
                if v[k] != want {
                    return Err(err(
                        *ln,
                        COLUMNS[k],
                        format!("expected {want} (rows sorted by eta, x, rho)"),
                    ));
                }
            }
            h[ie][ix][ir] = v[3];
            max_se_sphere = max_se_sphere.max(v[4] * (1.0 - v[6]));
        }
        Ok(CurvatureTable {
            etas,
            xs,
            rhos,
            h,
            max_se_sphere,
        })
    }

    /// h at the table's ρ nodes for one medium (x, η interpolated,
    /// clamped to the grid): the row a material keeps.
    pub fn row(&self, x: f64, eta: f64) -> Vec<f64> {
        let (ie, se) = cell(&self.etas, eta);
        let (ix, sx) = cell(&self.xs, x);
        (0..self.rhos.len())
            .map(|ir| {
                let at = |e: usize, i: usize| self.h[e][i][ir];
                let lo = at(ie, ix) * (1.0 - sx) + at(ie, ix + 1) * sx;
                let hi = at(ie + 1, ix) * (1.0 - sx) + at(ie + 1, ix + 1) * sx;
                lo * (1.0 - se) + hi * se
            })
            .collect()
    }

    /// h(ρ) from a [`row`](Self::row): linear in ln ρ between nodes,
    /// clamped below the grid, 1 − (1 − h_N)·ρ_N/ρ beyond it (module docs).
    pub(crate) fn at_rho(&self, row: &[f64], rho: f64) -> f64 {
        let n = self.rhos.len();
        let last = self.rhos[n - 1];
        if rho >= last {
            return 1.0 - (1.0 - row[n - 1]) * last / rho;
        }
        if rho <= self.rhos[0] {
            return row[0];
        }
        let i = self.rhos.partition_point(|&r| r <= rho).clamp(1, n - 1) - 1;
        let t = (rho / self.rhos[i]).ln() / (self.rhos[i + 1] / self.rhos[i]).ln();
        row[i] * (1.0 - t) + row[i + 1] * t
    }

    /// h(ρ, x, η).
    pub fn h(&self, rho: f64, x: f64, eta: f64) -> f64 {
        self.at_rho(&self.row(x, eta), rho)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_hold_their_point_and_a_nan_lands_in_the_first() {
        let v = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(cell(&v, 0.5), (0, 0.0));
        assert_eq!(cell(&v, 9.0), (2, 1.0));
        assert_eq!(cell(&v, 1.5), (0, 0.5));
        assert_eq!(cell(&v, 2.0), (1, 0.0));
        assert_eq!(cell(&v, 7.0), (2, 0.75));
        let (i, w) = cell(&v, f64::NAN);
        assert_eq!(i, 0);
        assert!(w.is_nan());
    }

    #[test]
    fn embedded_table_parses_and_is_physical() {
        let t = CurvatureTable::get().expect("embedded table");
        assert!(t.etas.len() >= 2 && t.xs.len() >= 2 && t.rhos.len() >= 2);
        // A convex body absorbs less than the half-space, and the less the
        // larger it is: h < 1 at the smallest sphere, rising with ρ.
        for (ie, row_e) in t.h.iter().enumerate() {
            for (ix, row) in row_e.iter().enumerate() {
                assert!(row[0] < 0.5, "eta {} x {}: {row:?}", t.etas[ie], t.xs[ix]);
                let big = *row.last().unwrap();
                assert!(
                    big > 0.85 && big < 1.06,
                    "eta {} x {}: {big}",
                    t.etas[ie],
                    t.xs[ix]
                );
            }
        }
        assert!(t.max_se_sphere < 3e-3, "{}", t.max_se_sphere);
    }

    #[test]
    fn interpolation_hits_nodes_and_tends_to_one() {
        let t = CurvatureTable::get().unwrap();
        let (ie, ix, ir) = (1, 2, 5);
        let h = t.h(t.rhos[ir], t.xs[ix], t.etas[ie]);
        assert!((h - t.h[ie][ix][ir]).abs() < 1e-12);
        let row = t.row(t.xs[ix], t.etas[ie]);
        // continuous at the last node, → 1 as ρ → ∞
        let n = t.rhos.len() - 1;
        assert!((t.at_rho(&row, t.rhos[n]) - row[n]).abs() < 1e-12);
        assert!((t.at_rho(&row, 1e12) - 1.0).abs() < 1e-9);
        // between two nodes: between their values
        let mid = t.at_rho(&row, (t.rhos[3] * t.rhos[4]).sqrt());
        assert!(mid >= row[3].min(row[4]) && mid <= row[3].max(row[4]));
    }

    #[test]
    fn row_interpolates_bilinearly_between_x_and_eta_nodes() {
        // Halfway between two x nodes (η at a node, then halfway between
        // two η nodes too): the mean of the neighbouring nodes' h, at every
        // ρ node, for both η rows the bilinear form reads.
        let t = CurvatureTable::get().unwrap();
        for ie in 0..t.etas.len() - 1 {
            for ix in 0..t.xs.len() - 1 {
                let x = 0.5 * (t.xs[ix] + t.xs[ix + 1]);
                let at_node = t.row(x, t.etas[ie]);
                let eta = 0.5 * (t.etas[ie] + t.etas[ie + 1]);
                let between = t.row(x, eta);
                for ir in 0..t.rhos.len() {
                    let lo = 0.5 * (t.h[ie][ix][ir] + t.h[ie][ix + 1][ir]);
                    let hi = 0.5 * (t.h[ie + 1][ix][ir] + t.h[ie + 1][ix + 1][ir]);
                    assert!((at_node[ir] - lo).abs() < 1e-12, "η{ie} x{ix} ρ{ir}");
                    assert!(
                        (between[ir] - 0.5 * (lo + hi)).abs() < 1e-12,
                        "η{ie} x{ix} ρ{ir}"
                    );
                }
            }
        }
    }

    #[test]
    fn bad_files_name_line_and_field() {
        let head = "eta,x,rho,h,se_h,a_sphere,a_slab\n";
        let e = CurvatureTable::parse("eta,x\n", "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (1, "header"));
        let e = CurvatureTable::parse(&format!("{head}1.0,0.5,1.0,nan,0,0.5,0.4\n"), "f.csv")
            .unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (2, "h"));
        let e = CurvatureTable::parse(&format!("{head}1.0,0.5,1.0,0.5,0,1.5,0.4\n"), "f.csv")
            .unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (2, "a_sphere"));
        // three rows cannot fill a 2×2×2 grid
        let rows = "1.0,0.5,1,0.5,0,0.5,0.4\n1.0,0.5,2,0.6,0,0.5,0.4\n2.0,0.5,1,0.5,0,0.5,0.4\n";
        let e = CurvatureTable::parse(&format!("{head}{rows}"), "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (4, "row"));
        assert!(e.to_string().starts_with("f.csv:4: row:"));
    }

    /// The rows of a full grid over the given axis values, sorted by η,
    /// x, ρ as the generator writes them.
    fn grid(etas: &[f64], xs: &[f64], rhos: &[f64]) -> String {
        let mut t = String::from("eta,x,rho,h,se_h,a_sphere,a_slab\n");
        for e in etas {
            for x in xs {
                for r in rhos {
                    t += &format!("{e},{x},{r},0.5,0,0.5,0.4\n");
                }
            }
        }
        t
    }

    /// The smallest table interpolation can use, two values on each axis,
    /// parses; a table with one value on any axis (nothing to interpolate
    /// between: its cells would have zero width) or with rows missing from
    /// or added to its grid is refused on its last line, even when every
    /// other check would pass.
    #[test]
    fn only_a_full_grid_of_two_or_more_values_per_axis_parses() {
        let t =
            CurvatureTable::parse(&grid(&[1.0, 1.5], &[0.5, 1.0], &[1.0, 2.0]), "f.csv").unwrap();
        assert_eq!((t.etas.len(), t.xs.len(), t.rhos.len()), (2, 2, 2));
        for (etas, xs, rhos) in [
            (&[1.0][..], &[0.5, 1.0][..], &[1.0, 2.0][..]),
            (&[1.0, 1.5], &[0.5], &[1.0, 2.0]),
            (&[1.0, 1.5], &[0.5, 1.0], &[1.0]),
        ] {
            let text = grid(etas, xs, rhos);
            let e = CurvatureTable::parse(&text, "f.csv").unwrap_err();
            let rows = text.lines().count() - 1;
            assert_eq!((e.line, e.field.as_str()), (rows + 1, "row"), "{e}");
        }
        // a 2×2×2 grid with a ninth row repeating an axis value
        let text = grid(&[1.0, 1.5], &[0.5, 1.0], &[1.0, 2.0]) + "1.5,1.0,2.0,0.5,0,0.5,0.4\n";
        let e = CurvatureTable::parse(&text, "f.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (10, "row"), "{e}");
    }
}
