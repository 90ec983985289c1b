//! `lucent bench --scene`: how fast the renderer runs against how fast its
//! backend answers the very queries the render issued.
//!
//! The synthetic ray sets of `lucent bench` only approximate a render's
//! queries. Here the render itself is the workload:
//!
//! 1. the scene is rendered normally (the code path of `lucent render`),
//!    timed: the end-to-end rate is the render's ray count over its wall
//!    time;
//! 2. it is rendered once more through a [`Recorder`], an [`Accel`] that
//!    forwards every query to the real backend and appends it (kind, ray,
//!    interval, geometry, seed) to the log of the rayon worker that issued
//!    it, in issue order, with a digest of every answer;
//! 3. each worker's log is replayed on its own thread of a pool of the same
//!    size, through the bare backend as `&dyn Accel` (the dispatch the
//!    integrator uses): the raw rate is the number of queries over the
//!    replay's wall time, and replaying one kind at a time gives per-kind
//!    rates. The first replay recomputes the digest; an answer that differs
//!    from what the render saw is an error.
//!
//! The ratio of the two rates is the share of the render's wall time spent
//! inside ray queries; the rest is shading, sampling and bookkeeping.
//! Memory: a record is [`RECORD_BYTES`] bytes, and a run stops with an
//! error beyond [`Settings::max_records`] queries per (backend, threads).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use super::measure::process_cpu_seconds;
use super::BenchError;
use crate::accel::{self, Accel, Backend, Hit, ProbeHits};
use crate::geometry::{Ray, Vec3};
use crate::integrator::IntegratorKind;
use crate::render::{self, RenderOptions};
use crate::scene::Scene;

/// What the renderer asked the backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// Nearest hit of a primary ray (its origin is the camera's eye).
    Camera,
    /// Nearest hit of any other ray: bounces, refraction, random-walk steps.
    Nearest,
    /// Any hit: shadow rays of next-event estimation.
    Occluded,
    /// Every hit on one object along a segment: BSSRDF probe rays.
    Probe,
}

impl Kind {
    pub const ALL: [Kind; 4] = [Kind::Camera, Kind::Nearest, Kind::Occluded, Kind::Probe];
    pub fn name(self) -> &'static str {
        match self {
            Kind::Camera => "camera",
            Kind::Nearest => "nearest",
            Kind::Occluded => "occluded",
            Kind::Probe => "probe",
        }
    }
    fn index(self) -> usize {
        self as usize
    }
}

/// One recorded query. `geom` and `seed` matter for probes only, `tmin`
/// for nearest and occluded only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    pub ray: Ray,
    pub tmin: f32,
    pub tmax: f32,
    pub geom: u32,
    pub seed: u32,
    pub kind: Kind,
}

/// Bytes per [`Record`] in a log.
pub const RECORD_BYTES: usize = std::mem::size_of::<Record>();
// The memory figures in the docs and the default cap assume this.
const _: () = assert!(RECORD_BYTES <= 48);

/// Answers of one kind of query, summarized so that a recording and a
/// replay can be compared without storing the answers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Digest {
    pub queries: u64,
    /// Rays with a hit (nearest), occluded rays, or the sum of
    /// [`ProbeHits::total`] (probe).
    pub hits: u64,
    /// Wrapping sum over queries of a hash of (position in its thread's
    /// log, every field of the answer): any differing answer, or one at
    /// another position, changes it.
    pub hash: u64,
}

/// One [`Digest`] per [`Kind`], in [`Kind::ALL`] order.
pub type Digests = [Digest; 4];

fn mix(mut x: u64) -> u64 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^ (x >> 33)
}

fn chain(h: u64, v: u64) -> u64 {
    mix(h ^ v.wrapping_add(0x9e37_79b9_7f4a_7c15))
}

fn hash_hit(h: u64, hit: &Hit) -> u64 {
    let h = chain(h, (hit.geom as u64) << 32 | hit.prim as u64);
    let h = chain(h, hit.t.to_bits() as u64);
    chain(h, (hit.u.to_bits() as u64) << 32 | hit.v.to_bits() as u64)
}

enum Answer<'a> {
    Nearest(Option<Hit>),
    Occluded(bool),
    Probe(&'a ProbeHits),
}

fn add_answer(d: &mut Digests, kind: Kind, position: usize, answer: &Answer) {
    let mut h = chain(position as u64, kind as u64);
    let hits = match answer {
        Answer::Nearest(hit) => {
            if let Some(hit) = hit {
                h = hash_hit(h, hit);
            }
            hit.is_some() as u64
        }
        Answer::Occluded(o) => {
            h = chain(h, *o as u64);
            *o as u64
        }
        Answer::Probe(p) => {
            h = chain(h, p.total() as u64);
            for hit in p.hits() {
                h = hash_hit(h, hit);
            }
            p.total() as u64
        }
    };
    let e = &mut d[kind.index()];
    e.queries += 1;
    e.hits += hits;
    e.hash = e.hash.wrapping_add(h);
}

fn sum_digests(a: &mut Digests, b: &Digests) {
    for (x, y) in a.iter_mut().zip(b) {
        x.queries += y.queries;
        x.hits += y.hits;
        x.hash = x.hash.wrapping_add(y.hash);
    }
}

#[derive(Default)]
struct Slot {
    log: Vec<Record>,
    digests: Digests,
    /// Queries not logged because the slot was full.
    dropped: u64,
}

/// An [`Accel`] that forwards to `inner` and logs every query per rayon
/// worker, in the order each worker issued them.
///
/// Workers are told apart by `rayon::current_thread_index()`, so the
/// recorder must be used from one pool of `threads` workers (as
/// [`render::render`] does); a query from outside any pool goes to slot 0.
/// Each slot is a mutex only its own worker locks, so the locks are
/// uncontended.
pub struct Recorder<'a> {
    inner: &'a dyn Accel,
    eye: Vec3,
    slots: Vec<Mutex<Slot>>,
    cap_per_slot: usize,
}

impl<'a> Recorder<'a> {
    /// `eye`: the camera position, which tells primary rays from others.
    /// At most `max_records` queries are logged in all (spread evenly
    /// over the workers); beyond that they are counted as dropped.
    pub fn new(inner: &'a dyn Accel, eye: Vec3, threads: usize, max_records: usize) -> Self {
        let threads = threads.max(1);
        Recorder {
            inner,
            eye,
            slots: (0..threads).map(|_| Mutex::default()).collect(),
            cap_per_slot: max_records / threads,
        }
    }

    fn log(&self, rec: Record, answer: Answer) {
        let i = rayon::current_thread_index().unwrap_or(0);
        let mut slot = self.slots[i.min(self.slots.len() - 1)]
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        if slot.log.len() >= self.cap_per_slot {
            slot.dropped += 1;
            return;
        }
        let position = slot.log.len();
        slot.log.push(rec);
        add_answer(&mut slot.digests, rec.kind, position, &answer);
    }

    /// The per-worker logs, the digest of the answers the recorded
    /// queries got, and how many queries were not logged (over the cap).
    pub fn finish(self) -> (Vec<Vec<Record>>, Digests, u64) {
        let mut digests = Digests::default();
        let mut dropped = 0;
        let logs = self
            .slots
            .into_iter()
            .map(|m| {
                let s = m.into_inner().unwrap_or_else(|e| e.into_inner());
                sum_digests(&mut digests, &s.digests);
                dropped += s.dropped;
                s.log
            })
            .collect();
        (logs, digests, dropped)
    }
}

impl Accel for Recorder<'_> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        let hit = self.inner.intersect(ray, tmin, tmax);
        let kind = if ray.o == self.eye {
            Kind::Camera
        } else {
            Kind::Nearest
        };
        let rec = Record {
            ray: *ray,
            tmin,
            tmax,
            geom: 0,
            seed: 0,
            kind,
        };
        self.log(rec, Answer::Nearest(hit));
        hit
    }

    fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        let o = self.inner.occluded(ray, tmin, tmax);
        let rec = Record {
            ray: *ray,
            tmin,
            tmax,
            geom: 0,
            seed: 0,
            kind: Kind::Occluded,
        };
        self.log(rec, Answer::Occluded(o));
        o
    }

    fn hits_on_segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32, out: &mut ProbeHits) {
        self.inner.hits_on_segment(ray, tmax, geom, seed, out);
        let rec = Record {
            ray: *ray,
            tmin: 0.0,
            tmax,
            geom,
            seed,
            kind: Kind::Probe,
        };
        self.log(rec, Answer::Probe(out));
    }
}

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
/// returns the hit count (as [`Digest::hits`], summed over kinds) so the
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

/// One timed replay pass of the logs, log i on worker i of `pool`.
struct Pass {
    hits: u64,
    seconds: f64,
    /// Process CPU time over the pass.
    cpu: Option<f64>,
    /// The busiest worker's time over the mean worker's time.
    imbalance: f64,
}

fn replay_pass(pool: &rayon::ThreadPool, accel: &dyn Accel, logs: &[Vec<Record>]) -> Pass {
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

/// Repeated timings of one thing: the fastest wall time (the run least
/// disturbed by other work), the smallest CPU time, and CPU time over wall
/// time summed over all runs.
#[derive(Clone, Copy, Debug)]
struct Best {
    wall: f64,
    cpu: f64,
    total_wall: f64,
    total_cpu: f64,
    /// False once a run had no CPU clock.
    has_cpu: bool,
    /// [`Pass::imbalance`] of the fastest run.
    imbalance: f64,
}

impl Best {
    fn new() -> Best {
        Best {
            wall: f64::INFINITY,
            cpu: f64::INFINITY,
            total_wall: 0.0,
            total_cpu: 0.0,
            has_cpu: true,
            imbalance: 1.0,
        }
    }
    fn add(&mut self, wall: f64, cpu: Option<f64>, imbalance: f64) {
        if wall < self.wall {
            self.wall = wall;
            self.imbalance = imbalance;
        }
        self.total_wall += wall;
        match cpu {
            Some(c) => {
                self.cpu = self.cpu.min(c.max(1e-9));
                self.total_cpu += c;
            }
            None => self.has_cpu = false,
        }
    }
    fn cpu(&self) -> Option<f64> {
        (self.has_cpu && self.cpu.is_finite()).then_some(self.cpu)
    }
    fn cpu_per_wall(&self) -> Option<f64> {
        self.has_cpu
            .then(|| self.total_cpu / self.total_wall.max(1e-9))
    }
}

fn check_hits(p: &Pass, expect: u64, what: &str) -> Result<(), BenchError> {
    if p.hits == expect {
        return Ok(());
    }
    Err(runtime(format!(
        "{what}: a replay found {} hits, the render {expect}",
        p.hits
    )))
}

/// What `lucent bench --scene` does.
#[derive(Clone, Debug)]
pub struct Settings {
    pub scene: PathBuf,
    pub out: PathBuf,
    /// Samples per pixel of every render.
    pub spp: u32,
    /// Thread counts; each gets its own renders, recording and replays.
    pub threads: Vec<usize>,
    pub backends: Vec<Backend>,
    /// Timed renders per (backend, threads); the fastest counts.
    pub renders: u32,
    /// Timed replay passes (all kinds, alternating with the renders, then
    /// each kind); the fastest counts.
    pub passes: u32,
    /// Most queries one recording may hold (× [`RECORD_BYTES`] of memory).
    pub max_records: usize,
    /// Status lines on stderr.
    pub progress: bool,
}

/// Default samples per pixel: the marble bunny at 640×480 and 2 spp is
/// 1.7M queries (73 MB of log), about 1 s per render on one core.
pub const DEFAULT_SPP: u32 = 2;
/// Default cap on one recording: 32M queries, 1.4 GB.
pub const DEFAULT_MAX_RECORDS: usize = 32_000_000;

impl Settings {
    pub fn new(scene: impl Into<PathBuf>, out: impl Into<PathBuf>) -> Settings {
        let threads = super::default_threads();
        Settings {
            scene: scene.into(),
            out: out.into(),
            spp: DEFAULT_SPP,
            threads,
            backends: super::available_backends(),
            renders: 3,
            passes: 5,
            max_records: DEFAULT_MAX_RECORDS,
            progress: true,
        }
    }
}

/// Per-kind replay of one (backend, threads).
#[derive(Clone, Debug, PartialEq)]
pub struct KindRow {
    pub kind: Kind,
    pub queries: u64,
    pub hits: u64,
    /// Fastest replay of this kind's records only (0 when there are none).
    pub seconds: f64,
    /// Smallest process CPU time of those replays.
    pub cpu_seconds: Option<f64>,
}

impl KindRow {
    pub fn mrays(&self) -> f64 {
        if self.seconds > 0.0 {
            self.queries as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}

/// One (backend, threads) measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct MixRow {
    pub backend: String,
    pub threads: usize,
    /// The render's own ray counter (`RenderStats::counters.rays`).
    pub render_rays: u64,
    /// Queries the recorder saw.
    pub records: u64,
    /// Fastest timed render, wall seconds of its tile loop.
    pub render_seconds: f64,
    /// Smallest process CPU time of a timed render.
    pub render_cpu_seconds: Option<f64>,
    /// CPU time over wall time of all timed renders.
    pub render_cpu_per_wall: Option<f64>,
    /// The recording render's wall time (slower: it logs every query).
    pub record_seconds: f64,
    /// Fastest replay of all the records.
    pub replay_seconds: f64,
    /// Smallest process CPU time of a replay of all the records.
    pub replay_cpu_seconds: Option<f64>,
    /// CPU time over wall time of all those replays.
    pub replay_cpu_per_wall: Option<f64>,
    /// Busiest worker's replay time over the mean worker's.
    pub replay_imbalance: f64,
    /// In [`Kind::ALL`] order.
    pub kinds: Vec<KindRow>,
}

impl MixRow {
    /// End-to-end rate: the render's rays over its wall time, Mrays/s.
    pub fn render_mrays(&self) -> f64 {
        self.render_rays as f64 / self.render_seconds / 1e6
    }
    /// Raw rate: the recorded queries over the replay's wall time.
    pub fn raw_mrays(&self) -> f64 {
        self.records as f64 / self.replay_seconds / 1e6
    }
    /// End-to-end over raw.
    pub fn ratio(&self) -> f64 {
        self.render_mrays() / self.raw_mrays()
    }
    /// Share of the render's wall time spent in queries: replay / render.
    pub fn query_share(&self) -> f64 {
        self.replay_seconds / self.render_seconds
    }
    /// The ratio from CPU times instead of wall times: what the ratio
    /// would be if the machine ran us undisturbed (time we spent waiting
    /// for a core does not count; cache pollution by others still does).
    /// At more than one thread it also counts idle workers' spinning.
    pub fn ratio_cpu(&self) -> Option<f64> {
        let (rc, qc) = (self.render_cpu_seconds?, self.replay_cpu_seconds?);
        Some(self.render_rays as f64 / rc / (self.records as f64 / qc))
    }
    /// Wall time per ray outside the queries, ns (render − replay, per ray).
    pub fn other_ns_per_ray(&self) -> f64 {
        (self.render_seconds - self.replay_seconds) / self.render_rays as f64 * 1e9
    }
    /// Query wall time per ray, ns.
    pub fn query_ns_per_ray(&self) -> f64 {
        self.replay_seconds / self.records as f64 * 1e9
    }
    /// The time per ray outside queries at which the ratio would be 0.7 at
    /// today's query cost: q · 0.3 / 0.7.
    pub fn other_ns_for_target(&self, target: f64) -> f64 {
        self.query_ns_per_ray() * (1.0 - target) / target
    }
}

/// What [`run`] produced.
pub struct Outcome {
    pub rows: Vec<MixRow>,
    pub csv: PathBuf,
    /// The text printed on stdout (also `render-mix.txt`).
    pub report: String,
    /// Differences between the render's ray counter and the record count,
    /// explained (also in the report).
    pub notes: Vec<String>,
}

/// The target for end-to-end over raw.
pub const TARGET_RATIO: f64 = 0.7;

fn input(m: impl Into<String>) -> BenchError {
    BenchError::Input(m.into())
}

fn runtime(m: impl Into<String>) -> BenchError {
    BenchError::Runtime(m.into())
}

/// Runs the measurement for every backend and thread count and writes
/// `render-mix.csv` and `render-mix.txt` into `s.out`.
pub fn run(s: &Settings) -> Result<Outcome, BenchError> {
    if s.spp == 0 {
        return Err(input("--spp must be at least 1"));
    }
    if s.threads.is_empty() || s.threads.contains(&0) {
        return Err(input("--threads: thread counts must be at least 1"));
    }
    if s.backends.is_empty() {
        return Err(input("no backend to measure"));
    }
    let available = super::available_backends();
    if let Some(b) = s.backends.iter().find(|b| !available.contains(b)) {
        // The same message `lucent render --accel` gives.
        let e = accel::build(&std::sync::Arc::new(Vec::new()), *b).err();
        return Err(input(e.unwrap_or_else(|| {
            format!("backend {} is not available", b.name())
        })));
    }
    let scene = crate::scene::load(&s.scene).map_err(|e| input(e.to_string()))?;
    std::fs::create_dir_all(&s.out).map_err(|e| input(format!("{}: {e}", s.out.display())))?;
    let mut threads = s.threads.clone();
    threads.sort_unstable();
    threads.dedup();
    let started = Instant::now();
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for &backend in &s.backends {
        let accel = accel::build(&scene.meshes, backend).map_err(input)?;
        for &t in &threads {
            let row = measure(s, &scene, accel.as_ref(), t, &mut notes)?;
            rows.push(row);
        }
    }
    let csv = s.out.join("render-mix.csv");
    let name = scene_name(&s.scene);
    let mut text = csv_header();
    text.push('\n');
    for r in &rows {
        text.push_str(&csv_line(r, &name, &scene, s.spp));
        text.push('\n');
    }
    crate::film::atomic_write(&csv, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })
    .map_err(runtime)?;
    let mut rep = report(&rows, s, &scene, started.elapsed());
    for n in &notes {
        let _ = writeln!(rep, "note: {n}");
    }
    let txt = s.out.join("render-mix.txt");
    std::fs::write(&txt, &rep).map_err(|e| runtime(format!("{}: {e}", txt.display())))?;
    Ok(Outcome {
        rows,
        csv,
        report: rep,
        notes,
    })
}

fn scene_name(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().replace([',', '"', '\n'], "_"))
        .unwrap_or_default()
}

fn status(s: &Settings, m: String) {
    if s.progress {
        eprintln!("{m}");
    }
}

/// Renders, records and replays one (backend, threads).
fn measure(
    s: &Settings,
    scene: &Scene,
    accel: &dyn Accel,
    threads: usize,
    notes: &mut Vec<String>,
) -> Result<MixRow, BenchError> {
    let label = format!("{} {threads}t", accel.name());
    let opts = RenderOptions {
        spp: Some(s.spp),
        seed: None,
        threads: Some(threads),
        progress: false,
        integrator: IntegratorKind::Path,
    };

    // Recording first: the timed renders below must count the same rays.
    status(s, format!("{label}: recording render"));
    let recorder = Recorder::new(accel, scene.camera.look_from, threads, s.max_records);
    let w0 = Instant::now();
    let (_, rec_stats) = render::render(scene, &recorder, &opts).map_err(runtime)?;
    let record_seconds = w0.elapsed().as_secs_f64();
    let (logs, recorded, dropped) = recorder.finish();
    if dropped > 0 {
        return Err(input(format!(
            "{label}: the render issued more than {} ray queries ({} MB of log); \
             lower --spp or the scene's resolution",
            s.max_records,
            s.max_records * RECORD_BYTES / 1_000_000
        )));
    }
    let render_rays = rec_stats.counters.rays;
    let records: u64 = logs.iter().map(|l| l.len() as u64).sum();
    if records != render_rays {
        notes.push(format!(
            "{label}: the render counted {render_rays} rays, the recorder saw {records} \
             queries: the integrator counts a probe ray before the BSSRDF sampler decides \
             whether to trace it (it skips the query when the chosen channel has no profile)"
        ));
    }

    // Every answer of the replay must be the one the render got.
    status(
        s,
        format!("{label}: checking the replay of {records} queries"),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| runtime(format!("cannot start {threads} worker threads: {e}")))?;
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
            return Err(runtime(format!(
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
    let all_hits: u64 = recorded.iter().map(|d| d.hits).sum();

    // Renders and replays alternate, so that both see the same spells of
    // load from other work on the machine.
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
            let (_, stats) = render::render(scene, accel, &opts).map_err(runtime)?;
            let cpu = c0.zip(process_cpu_seconds()).map(|(a, b)| b - a);
            if stats.counters.rays != render_rays {
                return Err(runtime(format!(
                    "{label}: two renders of the same scene counted {render_rays} and {} rays",
                    stats.counters.rays
                )));
            }
            render_t.add(stats.seconds.max(1e-9), cpu, 1.0);
        }
        if i < s.passes.max(1) {
            let p = replay_pass(&pool, accel, &logs);
            check_hits(&p, all_hits, &label)?;
            replay_t.add(p.seconds, p.cpu, p.imbalance);
        }
    }

    let mut kinds = Vec::new();
    for k in Kind::ALL {
        let d = recorded[k.index()];
        let mut t = Best::new();
        if d.queries > 0 {
            let only: Vec<Vec<Record>> = logs
                .iter()
                .map(|l| l.iter().filter(|r| r.kind == k).copied().collect())
                .collect();
            let what = format!("{label} {}", k.name());
            for _ in 0..s.passes.max(1) {
                let p = replay_pass(&pool, accel, &only);
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
    Ok(MixRow {
        backend: accel.name().to_string(),
        threads,
        render_rays,
        records,
        render_seconds: render_t.wall,
        render_cpu_seconds: render_t.cpu(),
        render_cpu_per_wall: render_t.cpu_per_wall(),
        record_seconds,
        replay_seconds: replay_t.wall,
        replay_cpu_seconds: replay_t.cpu(),
        replay_cpu_per_wall: replay_t.cpu_per_wall(),
        replay_imbalance: replay_t.imbalance,
        kinds,
    })
}

/// The CSV's header: one row per (backend, threads).
pub fn csv_header() -> String {
    let mut h = String::from(
        "scene,width,height,spp,triangles,backend,threads,render_rays,records,\
         render_s,render_mrays_per_s,render_cpu_per_wall,record_s,replay_s,raw_mrays_per_s,\
         replay_cpu_per_wall,replay_imbalance,ratio,query_share,render_cpu_s,replay_cpu_s,\
         ratio_cpu",
    );
    for k in Kind::ALL {
        let n = k.name();
        let _ = write!(
            h,
            ",{n}_queries,{n}_hits,{n}_s,{n}_mrays_per_s,{n}_share_of_render,{n}_cpu_s"
        );
    }
    h
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |c| format!("{c:.2}"))
}

fn opt6(v: Option<f64>) -> String {
    v.map_or(String::new(), |c| format!("{c:.6}"))
}

fn csv_line(r: &MixRow, scene_name: &str, scene: &Scene, spp: u32) -> String {
    let mut l = format!(
        "{scene_name},{},{},{spp},{},{},{},{},{},{:.6},{:.4},{},{:.6},{:.6},{:.4},{},{:.3},{:.4},{:.4}",
        scene.camera.width,
        scene.camera.height,
        scene.triangle_count(),
        r.backend,
        r.threads,
        r.render_rays,
        r.records,
        r.render_seconds,
        r.render_mrays(),
        opt(r.render_cpu_per_wall),
        r.record_seconds,
        r.replay_seconds,
        r.raw_mrays(),
        opt(r.replay_cpu_per_wall),
        r.replay_imbalance,
        r.ratio(),
        r.query_share()
    );
    let _ = write!(
        l,
        ",{},{},{}",
        opt6(r.render_cpu_seconds),
        opt6(r.replay_cpu_seconds),
        r.ratio_cpu().map_or(String::new(), |x| format!("{x:.4}"))
    );
    for k in &r.kinds {
        let _ = write!(
            l,
            ",{},{},{:.6},{:.4},{:.4},{}",
            k.queries,
            k.hits,
            k.seconds,
            k.mrays(),
            k.seconds / r.render_seconds,
            opt6(k.cpu_seconds)
        );
    }
    l
}

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
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::Bvh;
    use std::sync::Arc;

    /// A marble sphere on a floor under an area light: every query kind.
    const SCENE: &str = include_str!("../../../tests/fixtures/marble-ball.toml");

    fn scene() -> Scene {
        crate::scene::load::load_str(SCENE, Path::new("test.toml")).unwrap()
    }

    fn record(
        scene: &Scene,
        accel: &dyn Accel,
        threads: usize,
    ) -> (Vec<Vec<Record>>, Digests, u64) {
        let rec = Recorder::new(accel, scene.camera.look_from, threads, 1 << 24);
        let opts = RenderOptions {
            threads: Some(threads),
            ..RenderOptions::default()
        };
        let (_, stats) = render::render(scene, &rec, &opts).unwrap();
        let (logs, d, dropped) = rec.finish();
        assert_eq!(dropped, 0);
        (logs, d, stats.counters.rays)
    }

    #[test]
    fn recording_counts_every_ray_and_replay_reproduces_the_answers() {
        let scene = scene();
        for backend in crate::tools::bench::available_backends() {
            let accel = accel::build(&scene.meshes, backend).unwrap();
            let accel = accel.as_ref();
            for threads in [1, 2] {
                let (logs, recorded, rays) = record(&scene, accel, threads);
                assert_eq!(logs.len(), threads);
                let n: u64 = logs.iter().map(|l| l.len() as u64).sum();
                assert_eq!(n, rays, "one record per ray the renderer counts");
                // Every kind occurs, and the camera rays are one per sample.
                for k in Kind::ALL {
                    assert!(recorded[k.index()].queries > 0, "{}", k.name());
                }
                assert_eq!(recorded[Kind::Camera.index()].queries, 24 * 16 * 2);
                let mut replayed = Digests::default();
                for l in &logs {
                    sum_digests(&mut replayed, &replay_digest(accel, l));
                }
                assert_eq!(replayed, recorded, "{}", backend.name());
                let mut out = ProbeHits::new();
                let hits: u64 = logs.iter().map(|l| replay_hits(accel, l, &mut out)).sum();
                assert_eq!(hits, recorded.iter().map(|d| d.hits).sum::<u64>());
            }
        }
    }

    #[test]
    fn a_changed_query_or_order_changes_the_digest() {
        let scene = scene();
        let bvh = Bvh::build(&scene.meshes);
        let (logs, recorded, _) = record(&scene, &bvh, 1);
        let log = &logs[0];
        // Shorten one probe segment and reverse one nearest ray: the first
        // of its kind whose own answer that changes (a bounce ray that
        // missed may miss reversed too, a probe's hits may all lie in the
        // first half), so the test does not depend on the random stream.
        for kind in [Kind::Probe, Kind::Nearest] {
            let nudge = |r: &Record| {
                let mut r = *r;
                match kind {
                    Kind::Probe => r.tmax *= 0.5,
                    _ => r.ray.d = -r.ray.d,
                }
                r
            };
            let i = log
                .iter()
                .position(|r| {
                    r.kind == kind && replay_digest(&bvh, &[*r]) != replay_digest(&bvh, &[nudge(r)])
                })
                .unwrap();
            let mut bad = log.clone();
            bad[i] = nudge(&log[i]);
            assert_ne!(replay_digest(&bvh, &bad), recorded, "{}", kind.name());
        }
        // The same queries in another order: the same hit counts, another
        // digest (an answer is bound to its position in the thread's log).
        let mut swapped = log.clone();
        let i = swapped
            .iter()
            .position(|r| r.kind == Kind::Nearest)
            .unwrap();
        let j = swapped.iter().position(|r| r.kind == Kind::Camera).unwrap();
        swapped.swap(i, j);
        let d = replay_digest(&bvh, &swapped);
        assert_ne!(d, recorded);
        // Without the floor (and with the ball's geom id shifted) the
        // answers differ too.
        let floorless = Bvh::build(&Arc::new(scene.meshes[1..].to_vec()));
        let without: Vec<Record> = log
            .iter()
            .filter(|r| r.kind != Kind::Probe)
            .copied()
            .collect();
        assert_ne!(
            replay_digest(&floorless, &without),
            replay_digest(&bvh, &without)
        );
    }

    #[test]
    fn the_recorder_stops_logging_at_its_cap() {
        let scene = scene();
        let bvh = Bvh::build(&scene.meshes);
        let rec = Recorder::new(&bvh, scene.camera.look_from, 1, 100);
        let opts = RenderOptions {
            threads: Some(1),
            ..RenderOptions::default()
        };
        let (_, stats) = render::render(&scene, &rec, &opts).unwrap();
        let (logs, _, dropped) = rec.finish();
        assert_eq!(logs[0].len(), 100);
        assert_eq!(dropped + 100, stats.counters.rays);
    }

    #[test]
    fn derived_figures_are_consistent() {
        let r = MixRow {
            backend: "bvh".into(),
            threads: 1,
            render_rays: 1_000_000,
            records: 1_000_000,
            render_seconds: 2.0,
            render_cpu_seconds: Some(2.0),
            render_cpu_per_wall: None,
            record_seconds: 3.0,
            replay_seconds: 1.0,
            replay_cpu_seconds: Some(0.5),
            replay_cpu_per_wall: None,
            replay_imbalance: 1.0,
            kinds: vec![],
        };
        assert!((r.render_mrays() - 0.5).abs() < 1e-12);
        assert!((r.raw_mrays() - 1.0).abs() < 1e-12);
        assert!((r.ratio() - 0.5).abs() < 1e-12);
        assert!((r.query_share() - 0.5).abs() < 1e-12);
        assert!((r.ratio_cpu().unwrap() - 0.25).abs() < 1e-12);
        assert!((r.other_ns_per_ray() - 1000.0).abs() < 1e-6);
        // Ratio 0.7 at 1000 ns of queries per ray: 428.6 ns of the rest.
        assert!((r.other_ns_for_target(0.7) - 1000.0 * 0.3 / 0.7).abs() < 1e-6);
    }
}
