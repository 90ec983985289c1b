//! The accuracy budget's error and cost model (`docs/bssrdf.md` §14): for
//! each candidate estimator of a subsurface object, the relative error of
//! its image against the random walk's (the band error of
//! `examples/error_model.rs`) and its cost per sample relative to
//! diffusion with the Burley profile, as measured on spheres of Jensen's
//! marble of radius R under a key light or uniform light
//! (`scripts/error-model.sh`, the data file's header). Read as a function
//! of the object's size in diffusion lengths of its widest channel,
//! R/ℓd, interpolated linearly in ln(R/ℓd); outside the measured sizes
//! the largest error measured at any size is predicted, and the
//! prediction says it is out of range.
//!
//! The random walk is the truth the table is measured against: its
//! predicted error is 0 (its noise is variance, which more samples
//! reduce), its table rows record the noise floor of the measurement.

use std::sync::OnceLock;

/// The data file, embedded.
pub(crate) const DATA: &str = include_str!("error_model.csv");

/// Where the data file is, for messages.
pub const DATA_PATH: &str = "crates/lucent/src/bssrdf/error_model.csv";

/// The data file's columns, in order.
pub const COLUMNS: [&str; 7] = [
    "light",
    "radius_mm",
    "size_ld",
    "estimator",
    "error",
    "sigma",
    "cost",
];

/// How directional the light reaching an object is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lighting {
    /// Only a constant environment: light from every direction alike.
    Uniform,
    /// Some light from a few directions (emitters, `[[lights]]`, an
    /// environment image).
    Key,
}

impl Lighting {
    pub fn name(self) -> &'static str {
        match self {
            Lighting::Uniform => "uniform",
            Lighting::Key => "key",
        }
    }
}

/// A candidate estimator of a subsurface object, cheapest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Candidate {
    /// Diffusion with the Burley profile (`profile = "burley"`).
    Burley,
    /// Diffusion with the tabulated half-space profile.
    Tabulated,
    /// The random walk.
    Walk,
}

impl Candidate {
    pub const ALL: [Candidate; 3] = [Candidate::Burley, Candidate::Tabulated, Candidate::Walk];

    /// The name in the data file and the plan.
    pub fn name(self) -> &'static str {
        match self {
            Candidate::Burley => "burley",
            Candidate::Tabulated => "tabulated",
            Candidate::Walk => "walk",
        }
    }
}

/// What the model predicts for one candidate on one object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction {
    /// Relative error of the object's image (a fraction).
    pub error: f64,
    /// Cost per sample relative to diffusion with the Burley profile.
    pub cost: f64,
    /// Whether the object's size lies within the measured sizes.
    pub in_range: bool,
}

/// One measured node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    pub lighting: Lighting,
    pub size_ld: f64,
    pub candidate: Candidate,
    pub error: f64,
    pub sigma: f64,
    pub cost: f64,
}

/// A line of the data file the model cannot read.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelError {
    pub line: usize,
    pub problem: String,
}

/// The measured nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorModel {
    pub nodes: Vec<Node>,
}

impl ErrorModel {
    /// The embedded model, read once.
    pub fn get() -> Result<&'static ErrorModel, &'static ModelError> {
        static MODEL: OnceLock<Result<ErrorModel, ModelError>> = OnceLock::new();
        MODEL.get_or_init(|| ErrorModel::parse(DATA)).as_ref()
    }

    /// The model in `text` (the data file's format).
    pub fn parse(text: &str) -> Result<ErrorModel, ModelError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        match lines.next() {
            Some((_, h)) if h.split(',').eq(COLUMNS) => {}
            other => {
                return Err(ModelError {
                    line: other.map_or(0, |(n, _)| n),
                    problem: format!("expected the header {}", COLUMNS.join(",")),
                })
            }
        }
        let nodes = lines
            .map(|(n, l)| node(l).ok_or_else(|| bad_line(n)))
            .collect::<Result<Vec<_>, _>>()?;
        let model = ErrorModel { nodes };
        for l in [Lighting::Uniform, Lighting::Key] {
            for c in Candidate::ALL {
                if model.curve(l, c).is_empty() {
                    return Err(ModelError {
                        line: 0,
                        problem: format!("no row for light {} and {}", l.name(), c.name()),
                    });
                }
            }
        }
        Ok(model)
    }

    /// The nodes of one lighting and candidate, by size.
    fn curve(&self, lighting: Lighting, c: Candidate) -> Vec<&Node> {
        let mut v: Vec<&Node> = self
            .nodes
            .iter()
            .filter(|n| n.lighting == lighting && n.candidate == c)
            .collect();
        v.sort_by(|a, b| a.size_ld.total_cmp(&b.size_ld));
        v
    }

    /// The prediction for candidate `c` on an object `size_ld` diffusion
    /// lengths in size (module docs).
    pub fn predict(&self, lighting: Lighting, size_ld: f64, c: Candidate) -> Prediction {
        let curve = self.curve(lighting, c);
        let (first, last) = (curve[0].size_ld, curve[curve.len() - 1].size_ld);
        let in_range = size_ld >= first && size_ld <= last;
        let worst = curve.iter().map(|n| n.error).fold(0.0, f64::max);
        let t = size_ld.clamp(first, last).ln();
        let i = curve
            .windows(2)
            .position(|w| t <= w[1].size_ld.ln())
            .unwrap_or(0);
        let (a, b) = (curve[i], curve[(i + 1).min(curve.len() - 1)]);
        let span = b.size_ld.ln() - a.size_ld.ln();
        let w = if span > 0.0 {
            (t - a.size_ld.ln()) / span
        } else {
            0.0
        };
        let lerp = |x: f64, y: f64| x + w * (y - x);
        let error = match (c, in_range) {
            (Candidate::Walk, _) => 0.0,
            (_, true) => lerp(a.error, b.error),
            (_, false) => worst,
        };
        Prediction {
            error,
            cost: lerp(a.cost, b.cost),
            in_range,
        }
    }
}

fn bad_line(line: usize) -> ModelError {
    ModelError {
        line,
        problem: format!(
            "expected {} with light key or uniform and estimator burley, tabulated or walk, \
             sizes > 0, errors and costs finite and ≥ 0",
            COLUMNS.join(",")
        ),
    }
}

/// One data line as a node, None if malformed.
fn node(line: &str) -> Option<Node> {
    let f: Vec<&str> = line.split(',').map(str::trim).collect();
    let [light, _, size, est, error, sigma, cost] = f[..] else {
        return None;
    };
    let lighting = [Lighting::Uniform, Lighting::Key]
        .into_iter()
        .find(|l| l.name() == light)?;
    let candidate = Candidate::ALL.into_iter().find(|c| c.name() == est)?;
    let num = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite() && *v >= 0.0);
    let size_ld = num(size).filter(|&s| s > 0.0)?;
    Some(Node {
        lighting,
        size_ld,
        candidate,
        error: num(error)?,
        sigma: num(sigma)?,
        cost: num(cost)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::params::{diffuse_mfp, preset};

    /// The mistake: the table out of step with its generator
    /// (`scripts/error-model.sh`): a size not radius / ℓd of marble's
    /// widest channel, a node missing, a cost not relative to Burley.
    #[test]
    fn the_table_is_its_generators_grid_on_marble() {
        let m = ErrorModel::get().unwrap();
        let p = preset("marble").unwrap();
        let ld = (0..3)
            .map(|c| diffuse_mfp(p.sigma_s_reduced[c], p.sigma_a[c]))
            .fold(0.0, f64::max);
        let radius = |line: &str| line.split(',').nth(1).unwrap().parse::<f64>().unwrap();
        let data = DATA
            .lines()
            .filter(|l| l.starts_with("key,") || l.starts_with("uniform,"));
        for (line, n) in data.zip(&m.nodes) {
            let want = radius(line) / ld;
            assert!((n.size_ld / want - 1.0).abs() < 1e-3, "{line}: ℓd {ld}");
            if n.candidate == Candidate::Burley {
                assert_eq!(n.cost, 1.0, "{line}");
            }
        }
        for l in [Lighting::Uniform, Lighting::Key] {
            let sizes = |c| m.curve(l, c).iter().map(|n| n.size_ld).collect::<Vec<_>>();
            assert_eq!(sizes(Candidate::Burley), sizes(Candidate::Tabulated));
            assert_eq!(sizes(Candidate::Burley), sizes(Candidate::Walk));
        }
    }

    /// The mistake: a size outside the table predicted from its nearest
    /// node (too small a thin body's error), or the walk given an error.
    #[test]
    fn outside_the_table_the_worst_error_is_predicted() {
        let m = ErrorModel::get().unwrap();
        for l in [Lighting::Uniform, Lighting::Key] {
            for c in [Candidate::Burley, Candidate::Tabulated] {
                let worst = m.curve(l, c).iter().map(|n| n.error).fold(0.0, f64::max);
                for size in [1e-3, 1e4] {
                    let p = m.predict(l, size, c);
                    assert_eq!((p.error, p.in_range), (worst, false));
                }
                let first = m.curve(l, c)[0];
                let p = m.predict(l, first.size_ld, c);
                assert_eq!((p.error, p.in_range), (first.error, true));
            }
            assert_eq!(m.predict(l, 1.0, Candidate::Walk).error, 0.0);
        }
    }

    /// The mistake: a malformed table read as some model.
    #[test]
    fn malformed_tables_are_refused_with_their_line() {
        let head = COLUMNS.join(",");
        assert_eq!(ErrorModel::parse("a,b\n").unwrap_err().line, 1);
        let bad = format!("{head}\nkey,1,1,diffusion,0.1,0,1\n");
        assert_eq!(ErrorModel::parse(&bad).unwrap_err().line, 2);
        let missing = format!("{head}\nkey,1,1,burley,0.1,0,1\n");
        assert!(ErrorModel::parse(&missing).is_err());
    }
}
