//! Replaying recorded queries on the bare backend, through `&dyn Accel`
//! (the dispatch the integrator uses): once digesting every answer, to
//! check it is the answer the render got ([`check_replay`]), and as timed
//! passes that only count hits ([`replay_pass`]), log i on worker i of a
//! pool of as many workers as the render had.

use std::time::Instant;

use super::digest::{add_answer, sum_digests, Answer, Digests};
use super::record::{Kind, Record};
use crate::bench::measure::process_cpu_seconds;
use lucent::accel::{Accel, ProbeHits};
use lucent::Error;

/// Replays `log` through `accel` and digests every answer (the check, not
/// timed).
pub fn replay_digest(accel: &dyn Accel, log: &[Record]) -> Digests {
    let mut d = Digests::default();
    let mut out = ProbeHits::new();
    for (position, r) in log.iter().enumerate() {
        let answer = match r.kind {
            Kind::Camera | Kind::Nearest => {
                Answer::Nearest(accel.intersect(&r.ray, r.tmin, r.tmax))
            }
            Kind::Occluded => Answer::Occluded(accel.occluded(&r.ray, r.tmin, r.tmax)),
            Kind::Probe => {
                accel.hits_on_segment(&r.ray, r.tmax, r.geom, r.seed, &mut out);
                Answer::Probe(&out)
            }
        };
        add_answer(&mut d, r.kind, position, &answer);
    }
    d
}

/// Replays `log` through `accel` as cheaply as possible (the timed loop):
/// returns the hit count (as [`Digest::hits`](super::Digest::hits), summed over kinds) so the
/// answers are used and can be checked.
pub fn replay_hits(accel: &dyn Accel, log: &[Record], out: &mut ProbeHits) -> u64 {
    let mut hits = 0u64;
    for r in log {
        hits += match r.kind {
            Kind::Camera | Kind::Nearest => {
                accel.intersect(&r.ray, r.tmin, r.tmax).is_some() as u64
            }
            Kind::Occluded => accel.occluded(&r.ray, r.tmin, r.tmax) as u64,
            Kind::Probe => {
                accel.hits_on_segment(&r.ray, r.tmax, r.geom, r.seed, out);
                out.total() as u64
            }
        };
    }
    hits
}

/// One timed replay pass of the logs.
pub(super) struct Pass {
    pub(super) hits: u64,
    pub(super) seconds: f64,
    /// Process CPU time over the pass.
    pub(super) cpu: Option<f64>,
    /// The busiest worker's time over the mean worker's time.
    pub(super) imbalance: f64,
}

/// Replays log i on worker i of `pool`, timed.
pub(super) fn replay_pass(
    pool: &rayon::ThreadPool,
    accel: &dyn Accel,
    logs: &[Vec<Record>],
) -> Pass {
    let c0 = process_cpu_seconds();
    let t0 = Instant::now();
    let per_thread: Vec<(u64, f64)> = pool.broadcast(|ctx| {
        let t = Instant::now();
        let mut out = ProbeHits::new();
        let h = logs
            .get(ctx.index())
            .map_or(0, |log| replay_hits(accel, log, &mut out));
        (h, t.elapsed().as_secs_f64())
    });
    let seconds = t0.elapsed().as_secs_f64().max(1e-9);
    let cpu = c0.zip(process_cpu_seconds()).map(|(a, b)| b - a);
    let max = per_thread.iter().map(|p| p.1).fold(0.0, f64::max);
    let mean = per_thread.iter().map(|p| p.1).sum::<f64>() / per_thread.len().max(1) as f64;
    Pass {
        hits: per_thread.iter().map(|p| p.0).sum(),
        seconds,
        cpu,
        imbalance: if mean > 0.0 { max / mean } else { 1.0 },
    }
}

/// Replays every log on its own worker of `pool`, digesting the answers,
/// and fails, naming the query kind and both digests, where the replay's
/// answers differ from `recorded`, the answers the render got.
pub(super) fn check_replay(
    pool: &rayon::ThreadPool,
    accel: &dyn Accel,
    logs: &[Vec<Record>],
    recorded: &Digests,
    label: &str,
) -> Result<(), Error> {
    let replayed = pool
        .broadcast(|ctx| logs.get(ctx.index()).map(|l| replay_digest(accel, l)))
        .into_iter()
        .flatten()
        .fold(Digests::default(), |mut a, d| {
            sum_digests(&mut a, &d);
            a
        });
    for k in Kind::ALL {
        let (a, b) = (recorded[k.index()], replayed[k.index()]);
        if a != b {
            return Err(Error::Runtime(format!(
                "{label}: replaying the {} queries gave other answers than the render got \
                 (render: {} queries, {} hits, digest {:016x}; replay: {} queries, {} hits, \
                 digest {:016x})",
                k.name(),
                a.queries,
                a.hits,
                a.hash,
                b.queries,
                b.hits,
                b.hash
            )));
        }
    }
    Ok(())
}

/// Fails unless the pass found `expect` hits (the render's count for the
/// same records): a replay must see the answers the render got.
pub(super) fn check_hits(p: &Pass, expect: u64, what: &str) -> Result<(), Error> {
    if p.hits == expect {
        return Ok(());
    }
    Err(Error::Runtime(format!(
        "{what}: a replay found {} hits, the render {expect}",
        p.hits
    )))
}
