//! Comparing configurations by their ladders: a configuration's rows in
//! sample order, and how long one takes to reach another's final error
//! (docs/accuracy.md, "How a study works": time-to-error).

use super::metrics::time_to_reach;
use super::results::Row;

/// The rows of `config`, by sample count.
pub(super) fn ladder_of<'a>(rows: &'a [Row], config: &str) -> Vec<&'a Row> {
    let mut v: Vec<&Row> = rows.iter().filter(|r| r.config == config).collect();
    v.sort_by_key(|r| r.spp);
    v
}

/// How much less time `a` needs than `b` to reach `b`'s final RMSE.
pub(super) fn time_sentence(
    rows: &[Row],
    a: &str,
    a_label: &str,
    b: &str,
    b_label: &str,
) -> Option<String> {
    let (la, lb) = (ladder_of(rows, a), ladder_of(rows, b));
    let (a_last, b_last) = (la.last()?, lb.last()?);
    let pts: Vec<(f64, f64)> = la.iter().map(|x| (x.seconds, x.rmse)).collect();
    Some(match time_to_reach(&pts, b_last.rmse) {
        Some(t) if t > 0.0 => {
            let ratio = b_last.seconds / t;
            format!(
                "{a_label} reaches the RMSE of {b_label} at {} spp ({:.3e}, {:.3} s) in {:.3} s: {}.",
                b_last.spp,
                b_last.rmse,
                b_last.seconds,
                t,
                if ratio >= 1.0 {
                    format!("{ratio:.2}× less time")
                } else {
                    format!("{:.2}× more time", 1.0 / ratio)
                }
            )
        }
        _ => format!(
            "{a_label} never reaches the RMSE of {b_label} at {} spp ({:.3e}) within its ladder \
             (its own final RMSE: {:.3e} at {} spp, {:.3} s).",
            b_last.spp, b_last.rmse, a_last.rmse, a_last.spp, a_last.seconds
        ),
    })
}
