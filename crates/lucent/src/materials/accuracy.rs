//! The accuracy budget's value (`accuracy = 0.01` on a subsurface
//! material, `--accuracy 1%` on the command line): the largest relative
//! error of an object's image the estimator chosen for it may be
//! predicted to make. The choice itself is the render plan's
//! (`crate::integrator::plan::budget`), the model it reads
//! `crate::bssrdf::error_model` (`docs/bssrdf.md` §14).

use super::estimator_options::OptionError;

/// What a budget is written as, for messages.
const EXPECTED: &str = "a fraction in (0, 1) such as 0.01, a percentage such as 1%, or \"off\"";

/// `s` as a budget: "off" (None), a fraction ("0.01") or a percentage
/// ("1%", "1 %"), in (0, 1).
pub fn parse(s: &str) -> Result<Option<f32>, OptionError> {
    let t = s.trim();
    if t.eq_ignore_ascii_case("off") {
        return Ok(None);
    }
    let (number, scale) = match t.strip_suffix('%') {
        Some(n) => (n.trim_end(), 0.01),
        None => (t, 1.0),
    };
    let v = number.parse::<f64>().map(|v| v * scale);
    match v {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(Some(v as f32)),
        _ => Err(OptionError::Expected {
            expected: EXPECTED.into(),
            found: s.into(),
        }),
    }
}

/// The budget as [`parse`] reads it back: "off" or the fraction.
pub fn name(a: Option<f32>) -> String {
    match a {
        None => "off".into(),
        Some(v) => v.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mistake: a percentage read as a fraction (1% as a budget of 1,
    /// which every estimator meets), or a budget that cannot be met or
    /// means nothing accepted.
    #[test]
    fn percent_and_fraction_agree_and_out_of_range_is_refused() {
        assert_eq!(parse("1%").unwrap(), Some(0.01));
        assert_eq!(parse("0.01").unwrap(), Some(0.01));
        assert_eq!(parse(" 2.5 % ").unwrap(), Some(0.025));
        assert_eq!(parse("OFF").unwrap(), None);
        for bad in ["0", "1", "100%", "-1%", "nan", "inf", "", "%", "1%%", "one"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
        assert_eq!(parse(&name(Some(0.05))).unwrap(), Some(0.05));
        assert_eq!(parse(&name(None)).unwrap(), None);
    }
}
