//! The accuracy budget's value (`accuracy = 0.01` on a subsurface
//! material, `--accuracy 1%` on the command line): the largest relative
//! error of an object's image the estimator chosen for it may be
//! predicted to make. The choice itself is the render plan's
//! (`crate::integrator::plan::budget`), the model it reads
//! `crate::bssrdf::error_model` (`docs/bssrdf.md` §14).

/// What a budget is written as, for messages.
pub const EXPECTED: &str = "a fraction in (0, 1) such as 0.01, a percentage such as 1%, or \"off\"";

/// `s` as a budget: "off" (None), a fraction ("0.01") or a percentage
/// ("1%", "1 %"), in (0, 1); None for anything else ([`EXPECTED`]).
pub fn parse(s: &str) -> Option<Option<f32>> {
    let t = s.trim();
    if t.eq_ignore_ascii_case("off") {
        return Some(None);
    }
    let (number, scale) = match t.strip_suffix('%') {
        Some(n) => (n.trim_end(), 0.01),
        None => (t, 1.0),
    };
    let v = number.parse::<f64>().map(|v| v * scale);
    match v {
        Ok(v) if v > 0.0 && v < 1.0 => Some(Some(v as f32)),
        _ => None,
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
        assert_eq!(parse("1%"), Some(Some(0.01)));
        assert_eq!(parse("0.01"), Some(Some(0.01)));
        assert_eq!(parse(" 2.5 % "), Some(Some(0.025)));
        assert_eq!(parse("OFF"), Some(None));
        for bad in ["0", "1", "100%", "-1%", "nan", "inf", "", "%", "1%%", "one"] {
            assert_eq!(parse(bad), None, "{bad}");
        }
        assert_eq!(parse(&name(Some(0.05))), Some(Some(0.05)));
        assert_eq!(parse(&name(None)), Some(None));
    }
}
