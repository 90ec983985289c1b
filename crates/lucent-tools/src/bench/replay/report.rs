//! `render-mix.txt`, also printed: per (backend, threads) the end-to-end
//! rate against the raw rate and what that leaves per ray outside the
//! queries, then each query kind's replay alone.

use std::fmt::Write as _;
use std::time::Duration;

use super::csv::opt;
use super::rows::{MixRow, TARGET_RATIO};
use super::settings::Settings;
use lucent::scene::Scene;

fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

/// The text report: end-to-end against raw per (backend, threads), then
/// the per-kind replays.
pub fn report(rows: &[MixRow], s: &Settings, scene: &Scene, elapsed: Duration) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "lucent bench --scene {}: {}x{}, {} spp, {} triangles, {:.0} s",
        s.scene.display(),
        scene.camera.width,
        scene.camera.height,
        s.spp,
        scene.triangle_count(),
        elapsed.as_secs_f64()
    );
    end_to_end_table(&mut o, rows, s);
    per_kind_table(&mut o, rows, s);
    o
}

/// End to end against raw, one line per (backend, threads).
fn end_to_end_table(o: &mut String, rows: &[MixRow], s: &Settings) {
    let _ = writeln!(
        o,
        "\nEnd to end (fastest of {} renders) against raw (the same queries replayed on the bare \
         backend, fastest of {} passes); cpu = process CPU time / wall time",
        s.renders.max(1),
        s.passes.max(1)
    );
    let _ = writeln!(
        o,
        "{:<7} {:>3} {:>10} {:>10} {:>8} {:>8} {:>5} {:>8} {:>8} {:>5} {:>6} {:>7} {:>7} {:>8} {:>8} {:>9}",
        "backend",
        "thr",
        "rays",
        "records",
        "render s",
        "Mrays/s",
        "cpu",
        "replay s",
        "raw Mr/s",
        "cpu",
        "ratio",
        "(cpu)",
        "queries",
        "query ns",
        "other ns",
        format!("other@{TARGET_RATIO}")
    );
    for r in rows {
        let _ = writeln!(
            o,
            "{:<7} {:>3} {:>10} {:>10} {:>8.3} {:>8.2} {:>5} {:>8.3} {:>8.2} {:>5} {:>6.2} {:>7} {:>7} {:>8.0} {:>8.0} {:>9.0}",
            r.backend,
            r.threads,
            r.render_rays,
            r.records,
            r.render_seconds,
            r.render_mrays(),
            opt(r.render_cpu_per_wall),
            r.replay_seconds,
            r.raw_mrays(),
            opt(r.replay_cpu_per_wall),
            r.ratio(),
            r.ratio_cpu().map_or("-".into(), |x| format!("{x:.2}")),
            pct(r.query_share()),
            r.query_ns_per_ray(),
            r.other_ns_per_ray(),
            r.other_ns_for_target(TARGET_RATIO)
        );
    }
    let _ = writeln!(
        o,
        "(ratio = render Mrays/s / raw Mrays/s; (cpu): the same from the smallest process CPU \
         times instead of wall times; queries = replay time / render time; ns are wall time per \
         ray: in queries, outside them, and outside them at ratio {TARGET_RATIO})"
    );
}

/// Each kind's records replayed alone, with a "sum" line per (backend,
/// threads).
fn per_kind_table(o: &mut String, rows: &[MixRow], s: &Settings) {
    let _ = writeln!(
        o,
        "\nPer query kind: each kind's records replayed alone (fastest of {} passes)",
        s.passes.max(1)
    );
    let _ = writeln!(
        o,
        "{:<7} {:>3} {:<8} {:>10} {:>8} {:>10} {:>8} {:>8} {:>8} {:>9} {:>9} {:>9}",
        "backend",
        "thr",
        "kind",
        "queries",
        "of all",
        "hits",
        "seconds",
        "Mrays/s",
        "ns/query",
        "of replay",
        "of render",
        "(cpu)"
    );
    for r in rows {
        let sum: f64 = r.kinds.iter().map(|k| k.seconds).sum();
        for k in &r.kinds {
            let _ = writeln!(
                o,
                "{:<7} {:>3} {:<8} {:>10} {:>8} {:>10} {:>8.3} {:>8.2} {:>8.0} {:>9} {:>9} {:>9}",
                r.backend,
                r.threads,
                k.kind.name(),
                k.queries,
                pct(k.queries as f64 / r.records.max(1) as f64),
                k.hits,
                k.seconds,
                k.mrays(),
                if k.queries > 0 {
                    k.seconds / k.queries as f64 * 1e9
                } else {
                    0.0
                },
                pct(if sum > 0.0 { k.seconds / sum } else { 0.0 }),
                pct(k.seconds / r.render_seconds),
                k.cpu_seconds
                    .zip(r.render_cpu_seconds)
                    .map_or("-".into(), |(a, b)| pct(a / b))
            );
        }
        let _ = writeln!(
            o,
            "{:<7} {:>3} {:<8} {:>10} {:>8} {:>10} {:>8.3} {:>8} {:>8} {:>9} {:>9}",
            r.backend,
            r.threads,
            "sum",
            r.records,
            "",
            "",
            sum,
            "",
            "",
            pct(if r.replay_seconds > 0.0 {
                sum / r.replay_seconds
            } else {
                0.0
            }),
            pct(sum / r.render_seconds)
        );
    }
    let _ = writeln!(
        o,
        "(of replay: share of the summed per-kind times; on the \"sum\" line, summed per-kind \
         times over the all-kinds replay; (cpu): the kind's smallest CPU time over the render's)"
    );
}
