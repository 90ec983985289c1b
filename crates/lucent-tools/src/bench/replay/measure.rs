//! One (backend, threads) of `lucent bench --scene`: record the render's
//! queries, check their replay, then time renders against replays.
//!
//! The recording render comes first, so the timed renders can be checked
//! to count the same rays. Timed renders and replays of all the records
//! alternate, so that both see the same spells of load from other work on
//! the machine; then each kind's records are replayed alone. Every timed
//! replay must find the render's hit count.

use std::time::Instant;

use super::digest::Digests;
use super::playback::{check_hits, check_replay, replay_pass};
use super::record::{Kind, Record, RECORD_BYTES};
use super::recorder::Recorder;
use super::rows::{KindRow, MixRow};
use super::settings::Settings;
use super::timing::Best;
use super::{input, runtime, status};
use crate::bench::measure::process_cpu_seconds;
use lucent::accel::Accel;
use lucent::integrator::IntegratorKind;
use lucent::render::{self, RenderOptions};
use lucent::scene::Scene;
use lucent::Error;

/// What the recording render produced.
struct Recording {
    /// One log per worker.
    logs: Vec<Vec<Record>>,
    /// The digest of the answers the render got.
    recorded: Digests,
    /// The render's own ray counter.
    render_rays: u64,
    /// Queries logged, over all workers.
    records: u64,
    /// Wall time of the recording render.
    seconds: f64,
}

/// Renders, records and replays one (backend, threads).
pub(super) fn measure(
    s: &Settings,
    scene: &Scene,
    accel: &dyn Accel,
    threads: usize,
    notes: &mut Vec<String>,
) -> Result<MixRow, Error> {
    let label = format!("{} {threads}t", accel.name());
    let opts = RenderOptions {
        spp: Some(s.spp),
        seed: None,
        sampler: None,
        threads: Some(threads),
        progress: None,
        integrator: IntegratorKind::Path,
        stats: false,
    };
    let rec = record(s, scene, accel, &opts, &label, notes)?;

    // Every answer of the replay must be the one the render got.
    status(
        s,
        format!("{label}: checking the replay of {} queries", rec.records),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| runtime(format!("cannot start {threads} worker threads: {e}")))?;
    check_replay(&pool, accel, &rec.logs, &rec.recorded, &label)?;

    let (render_t, replay_t) =
        time_renders_and_replays(s, scene, accel, &opts, &pool, &rec, &label)?;
    let kinds = time_kinds(s, accel, &pool, &rec, &label)?;
    Ok(MixRow {
        backend: accel.name().to_string(),
        threads,
        render_rays: rec.render_rays,
        records: rec.records,
        render_seconds: render_t.wall,
        render_cpu_seconds: render_t.cpu(),
        render_cpu_per_wall: render_t.cpu_per_wall(),
        record_seconds: rec.seconds,
        replay_seconds: replay_t.wall,
        replay_cpu_seconds: replay_t.cpu(),
        replay_cpu_per_wall: replay_t.cpu_per_wall(),
        replay_imbalance: replay_t.imbalance,
        kinds,
    })
}

/// The recording render: fails if the log would pass the cap, and notes a
/// record count other than the render's ray count.
fn record(
    s: &Settings,
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
    label: &str,
    notes: &mut Vec<String>,
) -> Result<Recording, Error> {
    status(s, format!("{label}: recording render"));
    let threads = opts.threads.unwrap_or(1);
    let recorder = Recorder::new(accel, scene.camera.look_from, threads, s.max_records);
    let w0 = Instant::now();
    let (_, rec_stats) = render::render(scene, &recorder, opts).map_err(runtime)?;
    let seconds = w0.elapsed().as_secs_f64();
    let (logs, recorded, dropped) = recorder.finish();
    if dropped > 0 {
        return Err(input(format!(
            "{label}: the render issued more than {} ray queries ({} MB of log); \
             lower --spp or the scene's resolution",
            s.max_records,
            s.max_records * RECORD_BYTES / 1_000_000
        )));
    }
    // The queries that reached the accelerator: rays answered by bounds
    // (`integrator::culling`) are not asked of it and not recorded.
    let render_rays = rec_stats.counters.rays - rec_stats.counters.culled;
    let records: u64 = logs.iter().map(|l| l.len() as u64).sum();
    if records != render_rays {
        notes.push(format!(
            "{label}: the render counted {render_rays} rays, the recorder saw {records} \
             queries: the integrator counts a probe ray before the BSSRDF sampler decides \
             whether to trace it (it skips the query when the chosen channel has no profile)"
        ));
    }
    Ok(Recording {
        logs,
        recorded,
        render_rays,
        records,
        seconds,
    })
}

/// `s.renders` timed renders alternating with `s.passes` timed replays of
/// all the records: (renders, replays).
fn time_renders_and_replays(
    s: &Settings,
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
    pool: &rayon::ThreadPool,
    rec: &Recording,
    label: &str,
) -> Result<(Best, Best), Error> {
    let all_hits: u64 = rec.recorded.iter().map(|d| d.hits).sum();
    status(
        s,
        format!(
            "{label}: {} timed renders and {} replays",
            s.renders.max(1),
            s.passes.max(1)
        ),
    );
    let (mut render_t, mut replay_t) = (Best::new(), Best::new());
    for i in 0..s.renders.max(s.passes).max(1) {
        if i < s.renders.max(1) {
            let c0 = process_cpu_seconds();
            let (_, stats) = render::render(scene, accel, opts).map_err(runtime)?;
            let cpu = c0.zip(process_cpu_seconds()).map(|(a, b)| b - a);
            let queries = stats.counters.rays - stats.counters.culled;
            if queries != rec.render_rays {
                return Err(runtime(format!(
                    "{label}: two renders of the same scene made {} and {queries} queries",
                    rec.render_rays
                )));
            }
            render_t.add(stats.seconds.max(1e-9), cpu, 1.0);
        }
        if i < s.passes.max(1) {
            let p = replay_pass(pool, accel, &rec.logs);
            check_hits(&p, all_hits, label)?;
            replay_t.add(p.seconds, p.cpu, p.imbalance);
        }
    }
    Ok((render_t, replay_t))
}

/// Each kind's records replayed alone, `s.passes` times, in [`Kind::ALL`]
/// order (a kind without records gets a row of zeros).
fn time_kinds(
    s: &Settings,
    accel: &dyn Accel,
    pool: &rayon::ThreadPool,
    rec: &Recording,
    label: &str,
) -> Result<Vec<KindRow>, Error> {
    let mut kinds = Vec::new();
    for k in Kind::ALL {
        let d = rec.recorded[k.index()];
        let mut t = Best::new();
        if d.queries > 0 {
            let only: Vec<Vec<Record>> = rec
                .logs
                .iter()
                .map(|l| l.iter().filter(|r| r.kind == k).copied().collect())
                .collect();
            let what = format!("{label} {}", k.name());
            for _ in 0..s.passes.max(1) {
                let p = replay_pass(pool, accel, &only);
                check_hits(&p, d.hits, &what)?;
                t.add(p.seconds, p.cpu, p.imbalance);
            }
        }
        kinds.push(KindRow {
            kind: k,
            queries: d.queries,
            hits: d.hits,
            seconds: if d.queries > 0 { t.wall } else { 0.0 },
            cpu_seconds: if d.queries > 0 { t.cpu() } else { None },
        });
    }
    Ok(kinds)
}
