//! The command line's own value parsers (crop, tile, samples, checkpoint,
//! passes) and the error a value that does not parse gives.

use lucent::farm::part;
use lucent::film::passes::PassSet;
use lucent::film::region::Region;

/// A flag's value that does not parse.
#[derive(Debug)]
pub(crate) enum ValueError {
    /// Not of the form `expected`.
    Expected {
        expected: &'static str,
        found: String,
    },
    /// A problem the parser named.
    Problem(String),
}

impl std::fmt::Display for ValueError {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            ValueError::Expected { expected, found } => {
                write!(f, "expected {expected}, found \"{found}\"")
            }
            ValueError::Problem(p) => f.write_str(p),
        }
    }
}

impl std::error::Error for ValueError {}

/// [`ValueError::Expected`] for the value `s`.
pub(crate) fn expected(expected: &'static str, s: &str) -> ValueError {
    ValueError::Expected {
        expected,
        found: s.into(),
    }
}

pub(crate) fn parse_crop(s: &str) -> Result<Region, ValueError> {
    Region::parse(s)
        .filter(|r| !r.is_empty())
        .ok_or_else(|| expected("X0,Y0,X1,Y1 with X0 < X1 and Y0 < Y1", s))
}

pub(crate) fn parse_tile(s: &str) -> Result<(u32, u32), ValueError> {
    s.split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)))
        .filter(|&(i, n)| i < n)
        .ok_or_else(|| expected("I/N with 0 ≤ I < N", s))
}

pub(crate) fn parse_samples(s: &str) -> Result<std::ops::Range<u32>, ValueError> {
    part::parse_samples(s).ok_or_else(|| expected("A..B with A < B", s))
}

pub(crate) fn parse_checkpoint(s: &str) -> Result<f64, ValueError> {
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| expected("a positive number of seconds", s))
}

pub(crate) fn parse_aov(s: &str) -> Result<PassSet, ValueError> {
    PassSet::parse_list(s).map_err(|e| ValueError::Problem(e.problem()))
}
