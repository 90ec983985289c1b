//! The render driver: splits the image into tiles, renders them on a rayon
//! pool, and averages the samples of each pixel.
//!
//! Each sample draws from its own counter-based stream keyed by (seed,
//! pixel, sample index) and each pixel sums its samples in index order, so
//! the image is bitwise identical for any thread count and tile order.
//!
//! [`render_passes`] also computes passes (AOVs, `crate::integrator::aov`);
//! whether it does is decided once per render, by which instance of the
//! tile loop runs: without passes it is the loop with a recorder that does
//! nothing, so a render without passes costs what it did before passes.

use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::accel::Accel;
use crate::error::Error;
use crate::film::layers::{Coverage, Layer};
use crate::film::passes::PassSet;
use crate::film::Film;
use crate::geometry::Vec3;
use crate::integrator::aov::pixels::{assemble, Layout};
use crate::integrator::aov::{NoAov, PixelPasses, Setup, TilePasses};
use crate::integrator::path::Scratch;
use crate::integrator::{Context, Counters, IntegratorKind};
use crate::interrupt;
use crate::sampling::{Draw, Rng, SampleRng};
use crate::scene::Scene;

pub const TILE: u32 = 16;

/// The most worker threads a render, a study or a benchmark accepts: far
/// above any core count, far below what exhausts memory in thread stacks.
pub const MAX_THREADS: usize = 1024;

#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Samples per pixel (overrides the scene's when Some).
    pub spp: Option<u32>,
    /// Seed (overrides the scene's when Some).
    pub seed: Option<u64>,
    /// Worker threads, 1 to [`MAX_THREADS`]; None: rayon's default (all
    /// cores).
    pub threads: Option<usize>,
    /// Draw a progress bar on stderr.
    pub progress: bool,
    /// The estimator: the diffusion BSSRDF (default) or the random-walk
    /// reference at subsurface objects.
    pub integrator: IntegratorKind,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            spp: None,
            seed: None,
            threads: None,
            progress: false,
            integrator: IntegratorKind::Path,
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
            "{:.2} s wall, {:.3} Msamples/s, {:.2} Mrays/s ({} rays, {} threads, {backend}){}{}",
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
            match (self.counters.walks_capped, self.counters.walks_escaped) {
                (0, 0) => String::new(),
                (c, e) => format!(", random walks: {c} capped, {e} escaped through holes"),
            }
        )
    }
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

/// Renders the beauty image alone.
pub fn render(
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
) -> Result<(Film, RenderStats), Error> {
    let out = render_passes(scene, accel, opts, PassSet::EMPTY)?;
    Ok((out.film, out.stats))
}

/// Renders the beauty image and `passes` (none: exactly [`render`]).
pub fn render_passes(
    scene: &Scene,
    accel: &dyn Accel,
    opts: &RenderOptions,
    passes: PassSet,
) -> Result<RenderOutput, Error> {
    let mut scene_settings = scene.settings;
    if let Some(s) = opts.spp {
        scene_settings.spp = s;
    }
    if let Some(s) = opts.seed {
        scene_settings.seed = s;
    }
    let scene_local;
    let scene = if scene_settings != scene.settings {
        scene_local = Scene {
            settings: scene_settings,
            ..scene.clone()
        };
        &scene_local
    } else {
        scene
    };
    if let Some(n) = opts.threads.filter(|n| !(1..=MAX_THREADS).contains(n)) {
        return Err(Error::Argument {
            argument: "--threads".into(),
            problem: format!("{n} is not a thread count (1 to {MAX_THREADS})"),
        });
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::Runtime(format!("cannot start worker threads: {e}")))?;
    let threads = pool.current_num_threads();
    let ctx = Context::new(scene, accel);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();

    let bar = if opts.progress {
        let b =
            ProgressBar::with_draw_target(Some(tiles.len() as u64), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {pos}/{len} tiles, eta {eta}",
            )
            .unwrap()
            .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };

    let run = Run {
        ctx: &ctx,
        integrator: opts.integrator,
        tiles: &tiles,
        pool: &pool,
        bar: &bar,
    };
    let (done, layers, coverage) = if passes.is_empty() {
        (
            run.tiles(|_| NoAov)?.without_passes(),
            Vec::new(),
            Vec::new(),
        )
    } else {
        let setup = Setup::new(scene, &ctx.lights, passes);
        let layout = Layout::new(&setup);
        let done = run.tiles(|pixels| TilePasses::new(&setup, &layout, pixels))?;
        let tile_width = |x0: u32| TILE.min(w - x0);
        let parts = tiles
            .iter()
            .zip(&done.passes)
            .map(|(&(x0, y0), t)| ((x0, y0), tile_width(x0), t));
        let (layers, coverage) = assemble(&setup, &layout, w, h, parts)?;
        (done.without_passes(), layers, coverage)
    };
    let stats = RenderStats {
        seconds: done.seconds,
        samples: w as u64 * h as u64 * scene.settings.spp as u64,
        threads,
        counters: done.counters,
    };
    Ok(RenderOutput {
        film: done.film,
        layers,
        coverage,
        stats,
    })
}

/// The rendered tiles: the film, the summed counters, the seconds the tiles
/// took, and each tile's passes in tile order.
struct Tiles<T> {
    film: Film,
    counters: Counters,
    seconds: f64,
    passes: Vec<T>,
}

impl<T> Tiles<T> {
    fn without_passes(self) -> Tiles<()> {
        Tiles {
            film: self.film,
            counters: self.counters,
            seconds: self.seconds,
            passes: Vec::new(),
        }
    }
}

/// What rendering the tiles needs.
struct Run<'a> {
    ctx: &'a Context<'a>,
    integrator: IntegratorKind,
    tiles: &'a [(u32, u32)],
    pool: &'a rayon::ThreadPool,
    bar: &'a ProgressBar,
}

impl Run<'_> {
    /// Renders every tile with the passes `passes(pixels)` makes for it.
    fn tiles<P: PixelPasses>(
        &self,
        passes: impl Fn(usize) -> P + Sync,
    ) -> Result<Tiles<P::Tile>, Error> {
        let ctx = self.ctx;
        let start = Instant::now();
        let (w, h) = (ctx.scene.camera.width, ctx.scene.camera.height);
        let results: Vec<(Vec<Vec3>, Counters, P::Tile)> = self.pool.install(|| {
            self.tiles
                .par_iter()
                .map(|&(x0, y0)| {
                    let pixels = (TILE.min(w - x0) * TILE.min(h - y0)) as usize;
                    let r = render_tile(ctx, self.integrator, x0, y0, passes(pixels));
                    self.bar.inc(1);
                    r
                })
                .collect()
        });
        let seconds = start.elapsed().as_secs_f64();
        self.bar.finish_and_clear();
        // stopped by a signal: the tiles after it are incomplete
        if let Some(sig) = interrupt::requested() {
            return Err(Error::Interrupted(sig));
        }

        let mut film = Film::try_new(w, h)?;
        let mut counters = Counters::default();
        let mut out = Vec::with_capacity(results.len());
        for (&(x0, y0), (pixels, c, t)) in self.tiles.iter().zip(results) {
            counters += c;
            let tw = TILE.min(w - x0);
            for (i, p) in pixels.into_iter().enumerate() {
                film.set(x0 + i as u32 % tw, y0 + i as u32 / tw, p);
            }
            out.push(t);
        }
        Ok(Tiles {
            film,
            counters,
            seconds,
            passes: out,
        })
    }
}

// Kept out of line so profiles (scripts/profile.sh) can name the tile loop.
#[inline(never)]
fn render_tile<P: PixelPasses>(
    ctx: &Context,
    integrator: IntegratorKind,
    x0: u32,
    y0: u32,
    mut passes: P,
) -> (Vec<Vec3>, Counters, P::Tile) {
    let scene = ctx.scene;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
    let spp = scene.settings.spp;
    let mut counters = Counters::default();
    let mut scratch = Scratch::default();
    let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
    let seed_key = Rng::seed_key(scene.settings.seed);
    for y in y0..y1 {
        for x in x0..x1 {
            // a signal stops the render between pixels (see crate::interrupt);
            // the tile is then incomplete and the render discarded
            if interrupt::requested().is_some() {
                return (out, counters, passes.finish());
            }
            let pixel = y as u64 * w as u64 + x as u64;
            let pixel_key = Rng::pixel_key(seed_key, pixel);
            let mut sum = [0f64; 3];
            for s in 0..spp {
                // = SampleRng::new(seed, pixel, s), hashing the seed and
                // pixel once
                let mut rng = SampleRng::for_sample(pixel_key, s as u64);
                let [jx, jy] = rng.uniform2_packed();
                let ray = scene.camera.ray(x as f32 + jx, y as f32 + jy);
                let rec = passes.begin_sample();
                let l = integrator.radiance(ctx, ray, &mut rng, &mut scratch, &mut counters, rec);
                let finite = l.is_finite();
                if finite {
                    sum[0] += l.x as f64;
                    sum[1] += l.y as f64;
                    sum[2] += l.z as f64;
                } else {
                    counters.nonfinite += 1;
                }
                passes.end_sample(l, finite);
            }
            passes.end_pixel();
            let n = spp.max(1) as f64;
            out.push(Vec3::new(
                (sum[0] / n) as f32,
                (sum[1] / n) as f32,
                (sum[2] / n) as f32,
            ));
        }
    }
    (out, counters, passes.finish())
}
