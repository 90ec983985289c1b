//! Do the backends agree? The same rays must find the same hits on every
//! backend and thread count, up to rays that graze an edge.

use std::collections::BTreeMap;

use super::csv::Row;
use super::measure::QueryKind;

/// Hit counts of two backends on the same rays agree if they differ by at
/// most this many: a ray through a shared edge or vertex may count one
/// triangle, two or none depending on the intersection test.
pub fn hit_tolerance(rays: usize) -> u64 {
    2 + rays as u64 / 5_000
}

/// Compares hit counts between backends (and thread counts) for one mesh.
pub(super) fn check_hits(
    rows: &[Row],
    label: &str,
    warnings: &mut Vec<String>,
    failures: &mut Vec<String>,
) {
    let mut by: BTreeMap<QueryKind, Vec<&Row>> = BTreeMap::new();
    for r in rows {
        by.entry(r.query).or_default().push(r);
    }
    for (q, rs) in by {
        let lo = rs.iter().min_by_key(|r| r.hits).unwrap();
        let hi = rs.iter().max_by_key(|r| r.hits).unwrap();
        if lo.hits == hi.hits {
            continue;
        }
        let msg = format!(
            "{label} {}: {} {}t found {} hits, {} {}t {} ({} rays)",
            q.name(),
            lo.backend,
            lo.threads,
            lo.hits,
            hi.backend,
            hi.threads,
            hi.hits,
            lo.rays
        );
        if hi.hits - lo.hits > hit_tolerance(lo.rays) {
            failures.push(msg.clone());
        }
        warnings.push(msg);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_check_flags_only_real_disagreements() {
        let row = |b: &str, hits| Row {
            mesh: "sphere".into(),
            triangles: 1280,
            backend: b.into(),
            query: QueryKind::Camera,
            threads: 1,
            rays: 10_000,
            hits,
            seconds: 0.01,
            build_seconds: 0.0,
            build_mib: None,
            cpu_per_wall: None,
        };
        let (mut w, mut f) = (Vec::new(), Vec::new());
        check_hits(
            &[row("bvh", 5000), row("embree", 5000)],
            "x",
            &mut w,
            &mut f,
        );
        assert!(w.is_empty() && f.is_empty());
        check_hits(
            &[row("bvh", 5000), row("embree", 5001)],
            "x",
            &mut w,
            &mut f,
        );
        assert_eq!((w.len(), f.len()), (1, 0));
        check_hits(
            &[row("bvh", 5000), row("embree", 5100)],
            "x",
            &mut w,
            &mut f,
        );
        assert_eq!((w.len(), f.len()), (2, 1));
    }
}
