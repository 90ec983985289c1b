//! The surface albedo A that a homogeneous medium behind a smooth
//! dielectric boundary actually reflects (`docs/bssrdf.md` §9): a table of
//! the total diffuse reflectance R(α', η) of a semi-infinite medium of
//! reduced albedo α', for light entering from uniform radiance outside,
//! computed by the random walk's own physics (generator `tools::halfspace`,
//! run by `examples/albedo_table.rs`; the data file's header states its
//! seed, walk counts and errors).
//!
//! Rows are η ∈ [1, 2], columns x = √(1 − α'); what is interpolated is the
//! ratio to the classical dipole. Why this R is the A the diffusion model
//! needs, and the parameterization: `docs/bssrdf.md` §12.5. η outside
//! [1, 2] is outside the table: [`AlbedoTable::reflectance`] returns None
//! and the caller falls back to `dipole::dipole_reflectance`.

use std::sync::OnceLock;

use super::dipole::dipole_reflectance;

/// ρ = R / R_dipole at the equally spaced x nodes of one row (η fixed);
/// at x = 1, where both vanish, ρ of the node before.
pub(crate) fn ratio_row(r: &[f64], eta: f64) -> Vec<f64> {
    let n = r.len() - 1;
    let mut rho: Vec<f64> = (0..=n)
        .map(|j| {
            let x = j as f64 / n as f64;
            let d = dipole_reflectance(1.0 - x * x, eta);
            if d > 0.0 {
                r[j] / d
            } else {
                f64::NAN
            }
        })
        .collect();
    rho[n] = rho[n - 1];
    rho
}

/// ρ linearly interpolated at x ∈ [0, 1] on equally spaced nodes.
pub(crate) fn lerp_nodes(ys: &[f64], x: f64) -> f64 {
    let n = ys.len() - 1;
    let f = (x * n as f64).clamp(0.0, n as f64);
    let j = (f.floor() as usize).min(n - 1);
    let t = f - j as f64;
    ys[j] * (1.0 - t) + ys[j + 1] * t
}

/// R at x from one row of R at equally spaced x nodes (η fixed), by the
/// ratio to the dipole (module docs).
pub fn interpolate_row(r: &[f64], x: f64, eta: f64) -> f64 {
    lerp_nodes(&ratio_row(r, eta), x) * dipole_reflectance(1.0 - x * x, eta)
}

/// The data file, embedded.
pub(crate) const DATA: &str = include_str!("albedo_table.csv");

/// Where the data file is, for messages.
pub(crate) const DATA_PATH: &str = "crates/lucent/src/bssrdf/albedo_table.csv";

/// A line of the data file that does not parse: the line (1-based), the
/// field and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}: {field}: {problem}")]
pub struct TableError {
    pub file: &'static str,
    pub line: usize,
    pub field: String,
    pub problem: String,
}

/// R(α', η) on a regular grid in (η, x = √(1 − α')).
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoTable {
    pub etas: Vec<f64>,
    pub xs: Vec<f64>,
    /// `r_diffuse`, indexed `[i_eta][i_x]`.
    pub diffuse: Vec<Vec<f64>>,
    /// Light entering along the normal instead (what a camera straight
    /// above a slab sees).
    pub normal: Vec<Vec<f64>>,
    /// ρ = R / R_dipole per row, what is interpolated.
    rho_diffuse: Vec<Vec<f64>>,
    rho_normal: Vec<Vec<f64>>,
    /// Largest standard error in the file.
    pub max_se: f64,
}

/// The data file's columns, in order.
pub const COLUMNS: [&str; 6] = [
    "eta",
    "x",
    "r_diffuse",
    "se_diffuse",
    "r_normal",
    "se_normal",
];

/// A table row: its line number and its numbers.
pub(crate) type Row<const N: usize> = (usize, [f64; N]);

/// The numeric rows of an embedded CSV table: blank and `#` comment lines
/// skipped, a header naming `columns` exactly, then rows of `N` finite
/// numbers, each with its line number (from 1) for messages; and the
/// header's line number.
pub(crate) fn read_rows<const N: usize>(
    text: &str,
    file: &'static str,
    columns: &[&str; N],
) -> Result<(usize, Vec<Row<N>>), TableError> {
    let err = |line: usize, field: &str, problem: String| TableError {
        file,
        line,
        field: field.to_string(),
        problem,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hl, header) = lines
        .next()
        .ok_or_else(|| err(0, "header", "no header line".into()))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    if names != columns {
        return Err(err(hl, "header", format!("expected {}", columns.join(","))));
    }
    let mut rows = Vec::new();
    for (ln, l) in lines {
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        if f.len() != N {
            return Err(err(ln, "row", format!("{} fields, expected {N}", f.len())));
        }
        let mut v = [0.0; N];
        for (k, s) in f.iter().enumerate() {
            v[k] = s
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| err(ln, columns[k], format!("not a finite number: \"{s}\"")))?;
        }
        rows.push((ln, v));
    }
    Ok((hl, rows))
}

impl AlbedoTable {
    /// The embedded table, parsed once.
    pub fn get() -> Result<&'static AlbedoTable, &'static TableError> {
        static TABLE: OnceLock<Result<AlbedoTable, TableError>> = OnceLock::new();
        TABLE
            .get_or_init(|| AlbedoTable::parse(DATA, DATA_PATH))
            .as_ref()
    }

    /// Parses the CSV text: `#` comment lines, a header naming
    /// [`COLUMNS`], then rows sorted by η then x, on a regular grid.
    pub fn parse(text: &str, file: &'static str) -> Result<AlbedoTable, TableError> {
        let err = |line: usize, field: &str, problem: String| TableError {
            file,
            line,
            field: field.to_string(),
            problem,
        };
        let mut rows: Vec<(usize, [f64; 6])> = Vec::new();
        let (hl, read) = read_rows(text, file, &COLUMNS)?;
        for (ln, v) in read {
            for (k, name) in COLUMNS.iter().enumerate().skip(2) {
                let ok = if k % 2 == 0 {
                    (0.0..=1.0).contains(&v[k])
                } else {
                    v[k] >= 0.0
                };
                if !ok {
                    return Err(err(ln, name, format!("{} out of range", v[k])));
                }
            }
            rows.push((ln, v));
        }
        let mut etas: Vec<f64> = Vec::new();
        for (_, v) in &rows {
            if etas.last() != Some(&v[0]) {
                etas.push(v[0]);
            }
        }
        let nx = rows.len() / etas.len().max(1);
        if etas.len() < 2 || nx < 2 || nx * etas.len() != rows.len() {
            return Err(err(
                rows.last().map_or(hl, |r| r.0),
                "row",
                format!(
                    "{} rows do not form a grid over {} eta",
                    rows.len(),
                    etas.len()
                ),
            ));
        }
        let xs: Vec<f64> = rows[..nx].iter().map(|r| r.1[1]).collect();
        let mut t = AlbedoTable {
            etas: etas.clone(),
            xs: xs.clone(),
            diffuse: Vec::new(),
            normal: Vec::new(),
            rho_diffuse: Vec::new(),
            rho_normal: Vec::new(),
            max_se: 0.0,
        };
        for (i, &eta) in etas.iter().enumerate() {
            if i > 0 && eta <= etas[i - 1] {
                return Err(err(rows[i * nx].0, "eta", "not increasing".into()));
            }
            let block = &rows[i * nx..(i + 1) * nx];
            for (j, (ln, v)) in block.iter().enumerate() {
                if v[0] != eta {
                    return Err(err(
                        *ln,
                        "eta",
                        format!("expected {eta} ({nx} rows per eta)"),
                    ));
                }
                let want = j as f64 / (nx - 1) as f64;
                if (v[1] - xs[j]).abs() > 1e-9 || (v[1] - want).abs() > 1e-3 {
                    return Err(err(
                        *ln,
                        "x",
                        format!("expected {want:.4} (a regular grid on [0, 1])"),
                    ));
                }
                t.max_se = t.max_se.max(v[3]).max(v[5]);
            }
            let (d, n): (Vec<f64>, Vec<f64>) = block.iter().map(|r| (r.1[2], r.1[4])).unzip();
            t.rho_diffuse.push(ratio_row(&d, eta));
            t.rho_normal.push(ratio_row(&n, eta));
            t.diffuse.push(d);
            t.normal.push(n);
        }
        Ok(t)
    }

    /// The tabulated η range.
    pub(crate) fn eta_range(&self) -> (f64, f64) {
        (self.etas[0], *self.etas.last().unwrap())
    }

    /// ρ bilinearly in (x, η), times the dipole.
    fn lerp(&self, rho: &[Vec<f64>], alpha_reduced: f64, eta: f64) -> Option<f64> {
        let (lo, hi) = self.eta_range();
        if !(lo..=hi).contains(&eta) || !alpha_reduced.is_finite() {
            return None;
        }
        let a = alpha_reduced.clamp(0.0, 1.0);
        let x = (1.0 - a).sqrt();
        let (i, s) = cell(&self.etas, eta);
        let r = lerp_nodes(&rho[i], x) * (1.0 - s) + lerp_nodes(&rho[i + 1], x) * s;
        Some((r * dipole_reflectance(a, eta)).clamp(0.0, 1.0))
    }

    /// R(α', η) for diffuse light; None outside the η range.
    pub fn reflectance(&self, alpha_reduced: f64, eta: f64) -> Option<f64> {
        self.lerp(&self.rho_diffuse, alpha_reduced, eta)
    }

    /// R(α', η) for light entering along the normal; None outside the η range.
    pub fn normal_reflectance(&self, alpha_reduced: f64, eta: f64) -> Option<f64> {
        self.lerp(&self.rho_normal, alpha_reduced, eta)
    }

    /// The α' with `reflectance(α', η) = a` (bisection; R is increasing in
    /// α', checked by a test), None outside the η range.
    pub(crate) fn invert(&self, a: f64, eta: f64) -> Option<f64> {
        self.reflectance(0.5, eta)?;
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if self.reflectance(mid, eta)? < a {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(0.5 * (lo + hi))
    }
}

/// The cell of the increasing `nodes` holding v, and the fraction within it.
fn cell(nodes: &[f64], v: f64) -> (usize, f64) {
    let i = nodes
        .windows(2)
        .position(|w| v <= w[1])
        .unwrap_or(nodes.len() - 2);
    (i, (v - nodes[i]) / (nodes[i + 1] - nodes[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_table_parses_and_is_monotone() {
        let t = AlbedoTable::get().unwrap();
        assert_eq!(t.eta_range(), (1.0, 2.0));
        assert_eq!((t.etas.len(), t.xs.len()), (11, 41));
        assert!(t.max_se < 2e-3, "{}", t.max_se);
        for (i, eta) in t.etas.iter().enumerate() {
            for grid in [&t.diffuse, &t.normal] {
                let r = &grid[i];
                // x = 0 is α' = 1 (R = 1), x = 1 is α' = 0 (R = 0)
                assert_eq!((r[0], *r.last().unwrap()), (1.0, 0.0), "eta {eta}");
                // decreasing in x = √(1 − α'), i.e. increasing in α'
                for w in r.windows(2) {
                    assert!(w[1] < w[0], "eta {eta}: {w:?}");
                }
            }
            // normal entry goes deeper, so less comes back
            for j in 1..t.xs.len() - 1 {
                assert!(
                    t.normal[i][j] < t.diffuse[i][j] + 3.0 * t.max_se,
                    "eta {eta} x {}",
                    t.xs[j]
                );
            }
        }
    }

    /// Spot checks: the dipole's total reflectance (which the Jensen table's
    /// measured Rd follows) is an approximation of this table, close for
    /// high albedos and index-matched boundaries; the table's own values at
    /// marble's red channel, and the round trip of the inversion.
    #[test]
    fn spot_checks_and_inversion() {
        let t = AlbedoTable::get().unwrap();
        // marble red: α' = 2.19 / 2.1921
        let a = 2.19 / (2.19 + 0.0021);
        for eta in [1.0, 1.3, 1.5] {
            let r = t.reflectance(a, eta).unwrap();
            let dip = dipole_reflectance(a, eta);
            println!("marble red η {eta}: table {r:.4}, dipole {dip:.4}");
            assert!((r - dip).abs() < 0.03, "η {eta}: {r} vs dipole {dip}");
        }
        // more light is trapped by a denser boundary, so less leaves
        let r = |eta| t.reflectance(0.99, eta).unwrap();
        assert!(r(1.0) > r(1.3) && r(1.3) > r(1.5) && r(1.5) > r(2.0));
        assert_eq!(t.reflectance(0.5, 2.5), None);
        assert_eq!(t.reflectance(0.5, 0.9), None);
        for eta in [1.0, 1.25, 1.5, 2.0] {
            for a in [0.0, 0.05, 0.3, 0.7, 0.95, 0.999] {
                let ap = t.invert(a, eta).unwrap();
                let back = t.reflectance(ap, eta).unwrap();
                assert!(
                    (back - a).abs() < 1e-9,
                    "η {eta} A {a}: α' {ap} gives {back}"
                );
            }
        }
    }

    #[test]
    fn bad_files_name_line_and_field() {
        let head = "# c\neta,x,r_diffuse,se_diffuse,r_normal,se_normal\n";
        let e = AlbedoTable::parse("eta,x\n", "t.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (1, "header"));
        let e = AlbedoTable::parse(&format!("{head}1.0,0,1,0,1,zz\n"), "t.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (3, "se_normal"));
        assert!(e.to_string().starts_with("t.csv:3: se_normal:"), "{e}");
        let e = AlbedoTable::parse(&format!("{head}1.0,0,1.5,0,1,0\n"), "t.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (3, "r_diffuse"));
        let rows = "1.0,0,1,0,1,0\n1.0,1,0,0,0,0\n2.0,0,1,0,1,0\n2.0,1,0,0,0,0\n";
        let ok = AlbedoTable::parse(&format!("{head}{rows}"), "t.csv").unwrap();
        // two x nodes: ρ = 1/R_dipole(1) = 1 at x = 0 and its copy at x = 1
        let want = dipole_reflectance(0.75, 1.5);
        assert!((ok.reflectance(0.75, 1.5).unwrap() - want).abs() < 1e-12);
        let e = AlbedoTable::parse(&format!("{head}{rows}2.0,1,0,0,0,0\n"), "t.csv").unwrap_err();
        assert_eq!(e.field, "row");
        // one η (nothing to interpolate between), one x per η: refused on
        // the last row, although each is a full grid of its rows
        for rows in [
            "1.0,0,1,0,1,0\n1.0,1,0,0,0,0\n",
            "1.0,0,1,0,1,0\n2.0,0,1,0,1,0\n",
        ] {
            let e = AlbedoTable::parse(&format!("{head}{rows}"), "t.csv").unwrap_err();
            assert_eq!((e.line, e.field.as_str()), (4, "row"), "{e}");
        }
        // η out of order: the error names the first line of the η block
        // that does not increase (line 5, the third row)
        let rows = "2.0,0,1,0,1,0\n2.0,1,0,0,0,0\n1.0,0,1,0,1,0\n1.0,1,0,0,0,0\n";
        let e = AlbedoTable::parse(&format!("{head}{rows}"), "t.csv").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (5, "eta"), "{e}");
    }
}
