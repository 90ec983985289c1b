//! The render driver: renders a region of the frame over a range of sample
//! indices, in passes over tiles on a rayon pool, and sums each pixel's
//! samples exactly.
//!
//! Each sample draws from its own counter-based stream keyed by (seed,
//! pixel, sample index), and each pixel sums its samples in the fixed-point
//! accumulator of [`crate::film::accumulate`], whose sums do not depend on
//! order or grouping. So the image is bitwise identical for any thread
//! count, tile order and pass size, and the sums of disjoint regions and
//! sample ranges (parts rendered apart, or a render resumed from a saved
//! part) add up to exactly the sums of one uninterrupted run: a frame
//! merged from parts is the frame (docs/farm.md).
//!
//! A render runs in **passes**: each pass adds the samples `s0..s1` to
//! every pixel of the region, writing `previous sums + pass` into a second
//! buffer, which replaces the first only once every tile finished. A signal
//! ([`crate::interrupt`]) stops the pass under way at the next pixel and
//! drops it, so what is left is the sums of whole passes, `start..done`:
//! a valid part. Pass sizes adapt to take about
//! [`Job::pass_seconds`] each (the first is one sample); they change when
//! a render can stop, never what it computes.
//!
//! Passes (AOVs, `crate::integrator::aov`) are summed in the same loop,
//! exactly and order-free like the beauty (`crate::film::pass_sums`),
//! into sums that persist across passes, are kept at a signal, saved in
//! parts and merged: everything said above of the beauty holds for them.
//! Whether passes are computed is decided once per render, by which
//! instance of the tile loop runs: without passes the recorder does
//! nothing, so a render without passes costs what it did before passes.

use std::ops::Range;
use std::time::Instant;

use rayon::prelude::*;

use crate::accel::Accel;
use crate::error::Error;
use crate::film::layers::{Coverage, Layer};
use crate::film::pass_layout::Layout;
use crate::film::passes::PassSet;
use crate::film::region::Region;
use crate::film::{Film, Sums};
use crate::integrator::aov::{NoAov, PixelPasses, Setup, TilePasses};
use crate::integrator::path::Scratch;
use crate::integrator::{Clock, Context, Counters, IntegratorKind, NoClock, Stopwatch};
use crate::interrupt;
use crate::progress::{Progress, ProgressSink};
use crate::sampling::{Draw, Rng, SampleRng, SamplerKind};
use crate::scene::Scene;

pub use crate::film::sums::TILE;

/// The most worker threads a render, a study or a benchmark accepts: far
/// above any core count, far below what exhausts memory in thread stacks.
pub const MAX_THREADS: usize = 1024;

#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel (overrides the scene's when Some).
    pub spp: Option<u32>,
    /// Seed (overrides the scene's when Some).
    pub seed: Option<u64>,
    /// Sampler (overrides the scene's `[render] sampler` when Some).
    pub sampler: Option<SamplerKind>,
    /// Worker threads, 1 to [`MAX_THREADS`]; None: rayon's default (all
    /// cores).
    pub threads: Option<usize>,
    /// Told the render's progress (None: nobody is).
    pub progress: Option<ProgressSink>,
    /// The estimator: the diffusion BSSRDF (default) or the random-walk
    /// reference at subsurface objects.
    pub integrator: IntegratorKind,
    /// Measure the share of time per effect (`--stats`,
    /// [`crate::integrator::effects`]): the tile loop's timed instance.
    pub stats: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            spp: None,
            seed: None,
            sampler: None,
            threads: None,
            progress: None,
            integrator: IntegratorKind::Path,
            stats: false,
        }
    }
}

#[derive(Clone, Debug)]
pub struct RenderStats {
    pub seconds: f64,
    pub samples: u64,
    pub threads: usize,
    pub counters: Counters,
}

impl RenderStats {
    pub fn summary(&self, backend: &str) -> String {
        format!(
            "{:.2} s wall, {:.3} Msamples/s, {:.2} Mrays/s ({} rays, {} threads, {backend}){}{}{}",
            self.seconds,
            self.samples as f64 / self.seconds / 1e6,
            self.counters.rays as f64 / self.seconds / 1e6,
            self.counters.rays,
            self.threads,
            if self.counters.nonfinite > 0 {
                format!(", {} non-finite samples discarded", self.counters.nonfinite)
            } else {
                String::new()
            },
            if self.counters.clamped > 0 {
                format!(
                    ", {} sample channels beyond ±{:e} clamped",
                    self.counters.clamped,
                    Sums::FORMAT.max_sample()
                )
            } else {
                String::new()
            },
            match (self.counters.walks_capped, self.counters.walks_escaped) {
                (0, 0) => String::new(),
                (c, e) => format!(", random walks: {c} capped, {e} escaped through holes"),
            }
        )
    }
}

/// What to render: the pixels of `region` (frame coordinates) and the
/// sample indices `samples` of each.
#[derive(Clone, Debug, PartialEq)]
pub struct Job {
    pub region: Region,
    pub samples: Range<u32>,
    /// The wall time a pass aims at (after a first pass of one sample):
    /// how much work a signal may drop, and how often a checkpoint can be
    /// written.
    pub pass_seconds: f64,
    /// The passes (AOVs) summed besides the beauty.
    pub passes: PassSet,
}

impl Job {
    /// The whole frame of `scene`, samples `0..spp`.
    pub fn full(scene: &Scene, spp: u32) -> Job {
        Job {
            region: Region::full(scene.camera.width, scene.camera.height),
            samples: 0..spp,
            pass_seconds: 2.0,
            passes: PassSet::EMPTY,
        }
    }
}

/// The tiles of `region`, TILE × TILE from its top-left corner, row by
/// row (the last row and column smaller).
fn tiles(region: &Region) -> Vec<Region> {
    let mut v = Vec::new();
    for y0 in (region.y0..region.y1).step_by(TILE as usize) {
        for x0 in (region.x0..region.x1).step_by(TILE as usize) {
            v.push(Region {
                x0,
                y0,
                x1: (x0 + TILE).min(region.x1),
                y1: (y0 + TILE).min(region.y1),
            });
        }
    }
    v
}

/// A finished or stopped [`render_job`].
#[derive(Debug)]
pub struct Rendered {
    /// The sums of every finished pass (and of the resumed part).
    pub sums: Sums,
    pub stats: RenderStats,
    /// The signal that stopped the render before `job.samples.end`, if one
    /// did; `sums` then holds the passes finished before it.
    pub interrupted: Option<i32>,
}

/// The settings of one render, each fixed once from the scene and the
/// options: what the tile loop, the frame header and a part's identity
/// read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    pub spp: u32,
    pub seed: u64,
    pub max_depth: u32,
    pub integrator: IntegratorKind,
    pub sampler: SamplerKind,
}

impl Settings {
    /// `opts`' spp, seed and sampler where given, else the scene's.
    pub fn resolved(scene: &Scene, opts: &RenderOptions) -> Settings {
        Settings {
            spp: opts.spp.unwrap_or(scene.settings.spp),
            seed: opts.seed.unwrap_or(scene.settings.seed),
            max_depth: scene.settings.max_depth,
            integrator: opts.integrator,
            sampler: opts.sampler.unwrap_or(scene.settings.sampler),
        }
    }
}

/// Renders the whole frame at the scene's (or `opts`') spp: the image and
/// its statistics; [`Error::Interrupted`] if a signal stopped it.
pub fn render(
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
) -> Result<(Film, RenderStats), Error> {
    let spp = Settings::resolved(scene, opts).spp;
    let r = render_job(
        scene,
        accel,
        opts,
        &Job::full(scene, spp),
        None,
        &mut |_| Ok(()),
    )?;
    if let Some(sig) = r.interrupted {
        return Err(Error::Interrupted(sig));
    }
    Ok((r.sums.film()?, r.stats))
}

/// Renders `job`: continues `resume` (sums of the same region over
/// `job.samples.start..resume.done`) when given, else starts at zero;
/// calls `after_pass` with the sums after every finished pass (a checkpoint
/// writer; its error stops the render). `opts.spp` is not used: the job
/// says which samples.
pub fn render_job(
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
    job: &Job,
    resume: Option<Sums>,
    after_pass: &mut dyn FnMut(&Sums) -> Result<(), Error>,
) -> Result<Rendered, Error> {
    let settings = Settings::resolved(scene, opts);
    check_job(scene, opts, job)?;
    let ctx = Context::new(scene, accel);
    let setup = (!job.passes.is_empty()).then(|| Setup::new(scene, &ctx.lights, job.passes));
    let layout = setup.as_ref().map(Setup::layout);
    let mut sums = starting_sums(resume, job, layout.as_ref())?;
    let pool = worker_pool(opts.threads)?;
    let threads = pool.current_num_threads();
    let tiles = tiles(&job.region);
    let areas: Vec<usize> = tiles.iter().map(|t| t.area() as usize).collect();
    let mut next = Sums::with_passes(job.region, job.samples.start, layout.as_ref())?;
    let first = sums.done;

    let total = job.region.area() * (job.samples.end - first) as u64;
    let bar = opts.progress.as_deref();
    if let Some(b) = bar {
        b.start(total);
    }

    let start = Instant::now();
    let mut interrupted = None;
    let mut size = 1u32;
    while sums.done < job.samples.end {
        let s = sums.done..sums.done + size.min(job.samples.end - sums.done);
        let pass_start = Instant::now();
        let pass = Pass {
            ctx: &ctx,
            integrator: settings.integrator,
            seed: settings.seed,
            sampler: settings.sampler,
            samples: s.clone(),
            pool: &pool,
            bar,
            stats: opts.stats,
        };
        let grid = Grid {
            tiles: &tiles,
            areas: &areas,
            setup: setup.as_ref(),
            layout: layout.as_ref(),
        };
        let counters = grid.run(&pass, &sums, &mut next);
        // stopped by a signal: this pass is incomplete, drop it
        if let Some(sig) = interrupt::requested() {
            interrupted = Some(sig);
            break;
        }
        sums.swap_sums(&mut next);
        sums.done = s.end;
        for c in counters {
            sums.counters += c;
        }
        after_pass(&sums)?;
        let per_sample = pass_start.elapsed().as_secs_f64() / s.len() as f64;
        size = (job.pass_seconds / per_sample.max(1e-9)).clamp(1.0, u32::MAX as f64) as u32;
    }
    let seconds = start.elapsed().as_secs_f64();
    if let Some(b) = bar {
        b.finish();
    }
    let stats = RenderStats {
        seconds,
        samples: job.region.area() * (sums.done - first) as u64,
        threads,
        counters: sums.counters,
    };
    Ok(Rendered {
        sums,
        stats,
        interrupted,
    })
}

/// Refuses a thread count out of range and a job with nothing to render.
fn check_job(scene: &Scene, opts: &RenderOptions, job: &Job) -> Result<(), Error> {
    if let Some(n) = opts.threads.filter(|n| !(1..=MAX_THREADS).contains(n)) {
        return Err(Error::Argument {
            argument: "--threads".into(),
            problem: format!("{n} is not a thread count (1 to {MAX_THREADS})"),
        });
    }
    let frame = Region::full(scene.camera.width, scene.camera.height);
    if job.region.is_empty() || !job.region.within(&frame) || job.samples.is_empty() {
        return Err(Error::Input(format!(
            "nothing to render: region {} of a {}×{} frame, samples {}..{}",
            job.region, frame.x1, frame.y1, job.samples.start, job.samples.end
        )));
    }
    Ok(())
}

/// The sums the job starts from: `resume`'s when they hold the job's
/// passes, region and first sample, else empty ones.
fn starting_sums(resume: Option<Sums>, job: &Job, layout: Option<&Layout>) -> Result<Sums, Error> {
    match resume {
        Some(a) => {
            if a.passes.as_ref().map(|p| &p.layout) != layout {
                return Err(Error::Input(
                    "cannot resume: the saved sums hold other passes than the job's".into(),
                ));
            }
            if a.region != job.region || a.start != job.samples.start || a.done > job.samples.end {
                return Err(Error::Input(format!(
                    "cannot resume: the saved sums cover region {} samples {}..{}, the job \
                     region {} samples {}..{}",
                    a.region, a.start, a.done, job.region, job.samples.start, job.samples.end
                )));
            }
            Ok(a)
        }
        None => Ok(Sums::with_passes(job.region, job.samples.start, layout)?),
    }
}

/// The worker threads (`None`: one per core).
fn worker_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, Error> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::Runtime(format!("cannot start worker threads: {e}")))
}

/// The job's tiles and passes: what every pass splits its sums by.
struct Grid<'a> {
    tiles: &'a [Region],
    /// Each tile's pixel count.
    areas: &'a [usize],
    setup: Option<&'a Setup>,
    layout: Option<&'a Layout>,
}

impl Grid<'_> {
    /// Runs `pass` over every tile: each reads its previous sums from
    /// `sums` and writes previous + pass into `next`.
    fn run(&self, pass: &Pass, sums: &Sums, next: &mut Sums) -> Vec<Counters> {
        let mut chunks = Vec::with_capacity(self.tiles.len());
        let (out, out_passes) = next.sums_mut();
        let (mut prev, mut rest) = (sums.beauty(), out);
        for t in self.tiles {
            let n = t.area() as usize * Sums::CHANNELS;
            let (a, b) = prev.split_at(n);
            let (c, d) = rest.split_at_mut(n);
            chunks.push((t, a, c));
            (prev, rest) = (b, d);
        }
        match (self.setup, self.layout, &sums.passes, out_passes) {
            (Some(setup), Some(layout), Some(p), Some(q)) => {
                let views = p.sums.views(layout, self.areas);
                let outs = q.sums.views_mut(layout, self.areas);
                let with = views
                    .into_iter()
                    .zip(outs)
                    .map(|(v, o)| TilePasses::new(setup, layout, v, o));
                pass.run(chunks.into_iter().zip(with).collect())
            }
            _ => pass.run(chunks.into_iter().map(|c| (c, NoAov)).collect()),
        }
    }
}

/// One pass over the tiles: what every tile of it needs.
struct Pass<'a> {
    ctx: &'a Context<'a>,
    integrator: IntegratorKind,
    seed: u64,
    sampler: SamplerKind,
    samples: Range<u32>,
    pool: &'a rayon::ThreadPool,
    bar: Option<&'a dyn Progress>,
    /// Time the effects (`--stats`): the timed instance of the tile loop.
    stats: bool,
}

/// A tile, its previous sums and where its new ones go.
type Chunk<'a> = (&'a Region, &'a [i128], &'a mut [i128]);

impl Pass<'_> {
    /// Renders every tile with its passes' recorder; the tiles' counters.
    fn run<P: PixelPasses>(&self, tiles: Vec<(Chunk, P)>) -> Vec<Counters> {
        self.pool.install(|| {
            tiles
                .into_par_iter()
                .map(|((t, prev, out), passes)| {
                    let (ctx, i, s) = (self.ctx, self.integrator, self.samples.clone());
                    let key = (self.sampler, Rng::seed_key(self.seed));
                    // the timed instance only with --stats (integrator::effects)
                    let c = if self.stats {
                        render_tile::<_, Stopwatch>(ctx, i, key, t, s, prev, out, passes)
                    } else {
                        render_tile::<_, NoClock>(ctx, i, key, t, s, prev, out, passes)
                    };
                    if let Some(b) = self.bar {
                        b.advance(t.area() * self.samples.len() as u64);
                    }
                    c
                })
                .collect()
        })
    }
}

// Kept out of line so profiles (scripts/profile.sh) can name the tile loop.
/// Adds the samples `samples` (drawn with `sampler`, keyed by `seed_key`,
/// [`Rng::seed_key`]) of every pixel of `tile` to its sums `prev`
/// (the tile's pixels row by row), writing the result to `out`, and to the
/// sums of its `passes` (with [`NoAov`]: none, and this instance is the
/// loop without passes). Stops at the next pixel once a signal came (the
/// pass is then dropped).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn render_tile<P: PixelPasses, T: Clock>(
    ctx: &Context,
    integrator: IntegratorKind,
    (sampler, seed_key): (SamplerKind, u64),
    tile: &Region,
    samples: Range<u32>,
    prev: &[i128],
    out: &mut [i128],
    mut passes: P,
) -> Counters {
    const C: usize = Sums::CHANNELS;
    let scene = ctx.scene;
    let w = scene.camera.width;
    let mut counters = Counters::default();
    let mut scratch = Scratch::default();
    let mut i = 0;
    for y in tile.y0..tile.y1 {
        for x in tile.x0..tile.x1 {
            // a signal stops the render between pixels (see crate::interrupt);
            // the pass is then incomplete and dropped
            if interrupt::requested().is_some() {
                counters.camera_rays(i as u64 * samples.len() as u64);
                return counters;
            }
            let pixel = y as u64 * w as u64 + x as u64;
            let pixel_key = Rng::pixel_key(seed_key, pixel);
            let mut sum: [i128; C] = prev[i * C..(i + 1) * C].try_into().unwrap();
            passes.begin_pixel(i);
            for s in samples.clone() {
                // keyed by (seed, pixel, s), hashing the seed and pixel once
                let mut rng = SampleRng::with_sampler(sampler, pixel_key, s);
                let [jx, jy] = rng.uniform2_packed();
                let (fx, fy) = (x as f32 + jx, y as f32 + jy);
                let ray = match scene.camera.lens() {
                    None => scene.camera.ray(fx, fy),
                    Some(_) => scene.camera.ray_through_lens(fx, fy, rng.uniform2_packed()),
                };
                let rec = passes.begin_sample();
                let t0 = T::now();
                let l = integrator.radiance::<_, T>(
                    ctx,
                    ray,
                    &mut rng,
                    &mut scratch,
                    &mut counters,
                    rec,
                );
                T::lap_sample(&mut counters, t0);
                let finite = l.is_finite();
                if finite {
                    counters.clamped += Sums::FORMAT.add(&mut sum, &[l.x, l.y, l.z]) as u64;
                } else {
                    counters.nonfinite += 1;
                }
                passes.end_sample(s, l, finite);
            }
            out[i * C..(i + 1) * C].copy_from_slice(&sum);
            passes.end_pixel(i);
            i += 1;
        }
    }
    counters.camera_rays(i as u64 * samples.len() as u64);
    counters
}

/// A render's beauty, its passes (layers in output order, and ID
/// coverage) and its statistics.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub film: Film,
    pub layers: Vec<Layer>,
    pub coverage: Vec<Coverage>,
    pub stats: RenderStats,
}

/// Renders the beauty image and `passes` over the whole frame in one run
/// (none: exactly [`render`]).
pub fn render_passes(
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
    passes: PassSet,
) -> Result<RenderOutput, Error> {
    let spp = Settings::resolved(scene, opts).spp;
    // a transparent film's A is the object coverage's count of hits
    let transparent = scene.output.file.transparent == Some(true);
    let mut passes = passes;
    if transparent {
        passes.insert(crate::film::passes::Pass::CryptoObject);
    }
    let job = Job {
        passes,
        ..Job::full(scene, spp)
    };
    let r = render_job(scene, accel, opts, &job, None, &mut |_| Ok(()))?;
    if let Some(sig) = r.interrupted {
        return Err(Error::Interrupted(sig));
    }
    let (layers, coverage) = r.sums.layers(transparent)?;
    Ok(RenderOutput {
        film: r.sums.film()?,
        layers,
        coverage,
        stats: r.stats,
    })
}
