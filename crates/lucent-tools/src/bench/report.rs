//! The text report of `lucent bench` (`report.txt`, also printed):
//! throughput per mesh, query and thread count with each Embree's ratio to
//! the BVH (and Embree 4's to Embree 3 when both ran),
//! the builds, how time per ray grows with the triangle count (a
//! least-squares fit of t = a + b·log2(n) and of the log-log exponent k,
//! t ∝ n^k, over the displaced spheres), and thread scaling.

use std::fmt::Write as _;

use super::csv::Row;
use super::measure::QueryKind;
use super::settings::Settings;

/// 1280 → "1.3k", 5242880 → "5.2M".
pub fn short_count(n: usize) -> String {
    if n >= 1_000_000 {
        format!("{:.1}M", n as f64 / 1e6)
    } else if n >= 1000 {
        format!("{:.1}k", n as f64 / 1e3)
    } else {
        n.to_string()
    }
}

/// Least-squares fit y = a + b x; returns (a, b).
pub fn fit_line(pts: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| (my - sxy / sxx * mx, sxy / sxx))
}

/// The row of (mesh, triangles, backend, query, threads), if measured.
fn find<'a>(
    rows: &'a [Row],
    mesh: &str,
    tris: usize,
    backend: &str,
    q: QueryKind,
    t: usize,
) -> Option<&'a Row> {
    rows.iter().find(|r| {
        r.mesh == mesh
            && r.triangles == tris
            && r.backend == backend
            && r.query == q
            && r.threads == t
    })
}

/// The text report: throughput table with Embree/BVH ratios, builds,
/// growth with triangle count, and thread scaling.
pub fn report(rows: &[Row], threads: &[usize], s: &Settings, seconds: f64) -> String {
    let mut o = String::new();
    let backends: Vec<String> = s.backends.iter().map(|b| b.name().to_string()).collect();
    let mut meshes: Vec<(String, usize)> = Vec::new();
    for r in rows {
        if !meshes.iter().any(|m| m.0 == r.mesh && m.1 == r.triangles) {
            meshes.push((r.mesh.clone(), r.triangles));
        }
    }
    let _ = writeln!(
        o,
        "lucent bench: {} rays per set, threads {:?}, {:.0} s",
        s.rays, threads, seconds
    );
    throughput_table(&mut o, rows, &meshes, &backends, threads);
    builds_table(&mut o, rows, &meshes, &backends, threads);
    growth_table(&mut o, rows, &meshes, &backends, threads);
    scaling_table(&mut o, rows, &meshes, &backends, threads);
    o
}

/// The throughput ratios shown, as (numerator, denominator) indices into
/// `backends`: every other backend over the first (the BVH), and
/// embree4/embree3 when both are there.
fn ratio_pairs(backends: &[String]) -> Vec<(usize, usize)> {
    let mut v: Vec<(usize, usize)> = (1..backends.len()).map(|i| (i, 0)).collect();
    let at = |n: &str| backends.iter().position(|b| b == n);
    if let (Some(e3), Some(e4)) = (at("embree3"), at("embree4")) {
        v.push((e4, e3));
    }
    v
}

/// Mrays/s per (mesh, query, threads), one column per backend.
fn throughput_table(
    o: &mut String,
    rows: &[Row],
    meshes: &[(String, usize)],
    backends: &[String],
    threads: &[usize],
) {
    let _ = writeln!(o, "\nThroughput, Mrays/s (fastest pass)");
    let mut head = format!("{:<14} {:<11} {:>3}", "mesh", "query", "thr");
    for b in backends {
        let _ = write!(head, " {:>9}", b);
    }
    let pairs = ratio_pairs(backends);
    for &(num, den) in &pairs {
        let _ = write!(
            head,
            " {:>13}",
            format!("{}/{}", backends[num], backends[den])
        );
    }
    let _ = write!(head, " {:>12}", "hits");
    let _ = writeln!(o, "{head}");
    for (mesh, tris) in meshes {
        for q in QueryKind::ALL {
            for &t in threads {
                let rs: Vec<Option<&Row>> = backends
                    .iter()
                    .map(|b| find(rows, mesh, *tris, b, q, t))
                    .collect();
                let _ = write!(
                    o,
                    "{:<14} {:<11} {:>3}",
                    format!("{mesh} {}", short_count(*tris)),
                    q.name(),
                    t
                );
                for r in &rs {
                    let _ = write!(
                        o,
                        " {:>9}",
                        r.map_or("-".into(), |r| format!("{:.2}", r.mrays()))
                    );
                }
                for &(num, den) in &pairs {
                    match (rs[num], rs[den]) {
                        (Some(n), Some(d)) => {
                            let _ = write!(o, " {:>13.2}", n.mrays() / d.mrays());
                        }
                        _ => {
                            let _ = write!(o, " {:>13}", "-");
                        }
                    }
                }
                let hits: Vec<u64> = rs.iter().flatten().map(|r| r.hits).collect();
                let same = hits.windows(2).all(|w| w[0] == w[1]);
                let _ = write!(
                    o,
                    " {:>12}",
                    match (hits.first(), same) {
                        (Some(h), true) => h.to_string(),
                        (Some(_), false) => hits
                            .iter()
                            .map(|h| h.to_string())
                            .collect::<Vec<_>>()
                            .join("/"),
                        _ => "-".into(),
                    }
                );
                let _ = writeln!(o);
            }
        }
    }
}

/// Build wall time and memory per (mesh, backend).
fn builds_table(
    o: &mut String,
    rows: &[Row],
    meshes: &[(String, usize)],
    backends: &[String],
    threads: &[usize],
) {
    let _ = writeln!(
        o,
        "\nBuilds (wall time in a {}-thread pool; memory = RSS growth over the build)",
        threads.last().unwrap()
    );
    let _ = writeln!(
        o,
        "{:<14} {:<7} {:>9} {:>9}",
        "mesh", "backend", "seconds", "MiB"
    );
    for (mesh, tris) in meshes {
        for b in backends {
            if let Some(r) = rows
                .iter()
                .find(|r| &r.mesh == mesh && r.triangles == *tris && &r.backend == b)
            {
                let _ = writeln!(
                    o,
                    "{:<14} {:<7} {:>9.3} {:>9}",
                    format!("{mesh} {}", short_count(*tris)),
                    b,
                    r.build_seconds,
                    r.build_mib.map_or("-".into(), |m| format!("{m:.1}"))
                );
            }
        }
    }
}

/// Time per ray against triangle count over the displaced spheres (at
/// least two sizes): the fits' slope per doubling and exponent.
fn growth_table(
    o: &mut String,
    rows: &[Row],
    meshes: &[(String, usize)],
    backends: &[String],
    threads: &[usize],
) {
    let sphere_sizes: Vec<usize> = meshes
        .iter()
        .filter(|m| m.0 == "sphere")
        .map(|m| m.1)
        .collect();
    if sphere_sizes.len() >= 2 {
        let _ = writeln!(
            o,
            "\nGrowth with triangle count (displaced spheres {}–{}): fit of time per ray\n\
             t = a + b·log2(n): b in ns per doubling of n; and the log-log exponent k, t ∝ n^k",
            short_count(sphere_sizes[0]),
            short_count(*sphere_sizes.last().unwrap())
        );
        let _ = writeln!(
            o,
            "{:<7} {:<11} {:>3} {:>10} {:>10} {:>7}",
            "backend", "query", "thr", "ns@min", "ns/doubl", "k"
        );
        for b in backends {
            for q in QueryKind::ALL {
                for &t in threads {
                    let pts: Vec<&Row> = sphere_sizes
                        .iter()
                        .filter_map(|&n| find(rows, "sphere", n, b, q, t))
                        .collect();
                    let lin: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|r| ((r.triangles as f64).log2(), r.ns_per_ray()))
                        .collect();
                    let ll: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|r| ((r.triangles as f64).ln(), r.ns_per_ray().ln()))
                        .collect();
                    if let (Some((_, slope)), Some((_, k)), Some(first)) =
                        (fit_line(&lin), fit_line(&ll), pts.first())
                    {
                        let _ = writeln!(
                            o,
                            "{:<7} {:<11} {:>3} {:>10.1} {:>10.2} {:>7.3}",
                            b,
                            q.name(),
                            t,
                            first.ns_per_ray(),
                            slope,
                            k
                        );
                    }
                }
            }
        }
    }
}

/// Efficiency of the most threads over one thread (at least two counts).
fn scaling_table(
    o: &mut String,
    rows: &[Row],
    meshes: &[(String, usize)],
    backends: &[String],
    threads: &[usize],
) {
    if threads.len() >= 2 {
        let (t1, tn) = (threads[0], *threads.last().unwrap());
        let _ = writeln!(
            o,
            "\nThread scaling: efficiency = throughput({tn}t) / ({tn}/{t1} · throughput({t1}t)); \
             in brackets the CPU the process got at {tn}t (CPU time / wall time: {tn} = \
             {tn} whole cores, less on a machine busy with other work)"
        );
        let mut head = format!("{:<14} {:<7}", "mesh", "backend");
        for q in QueryKind::ALL {
            let _ = write!(head, " {:>16}", q.name());
        }
        let _ = writeln!(o, "{head}");
        for (mesh, tris) in meshes {
            for b in backends {
                let _ = write!(
                    o,
                    "{:<14} {:<7}",
                    format!("{mesh} {}", short_count(*tris)),
                    b
                );
                for q in QueryKind::ALL {
                    let cell = find(rows, mesh, *tris, b, q, t1)
                        .zip(find(rows, mesh, *tris, b, q, tn))
                        .map(|(a, c)| {
                            let e = c.mrays() / a.mrays() * t1 as f64 / tn as f64;
                            match c.cpu_per_wall {
                                Some(cpu) => format!("{:.0} % ({cpu:.1})", e * 100.0),
                                None => format!("{:.0} %", e * 100.0),
                            }
                        });
                    let _ = write!(o, " {:>16}", cell.unwrap_or_else(|| "-".into()));
                }
                let _ = writeln!(o);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_fit_recovers_slope() {
        let pts: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 3.0 + 2.0 * i as f64)).collect();
        let (a, b) = fit_line(&pts).unwrap();
        assert!((a - 3.0).abs() < 1e-9 && (b - 2.0).abs() < 1e-9);
        assert!(fit_line(&pts[..1]).is_none());
    }
}
