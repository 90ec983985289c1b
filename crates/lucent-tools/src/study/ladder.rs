//! The progressive ladder of sample counts 1, 2, 4, … every configuration
//! is rendered at.
//!
//! Rung j renders samples 2^(j−1) .. 2^j (0 .. 1 at j = 0) of the one
//! seed, the sample split farm parts use (`lucent::render::Job`), and
//! mixes them into the running mean ([`Running`]): the image at 2^j spp
//! is the single render of 2^j samples up to the rounding of the mix, so
//! a sequence sampler's points continue across rungs instead of starting
//! over. It costs 2^j spp of render time in total (not 2^(j+1) − 1), and
//! its time is the sum of the chunks' wall times, plus the denoise of
//! that rung's image when the configuration denoises ([`denoised`]).
//! Rungs are rendered round-robin (every configuration's rung j before any
//! rung j + 1), so load drift on a shared machine spreads over all
//! configurations instead of penalizing whichever ran in a busy minute.

use std::fs;
use std::ops::Range;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::config::{self, Config};
use super::denoised;
use super::metrics;
use super::results::{Results, Row};
use super::resume::Job;
use super::running::{slug, Guides, Running};
use super::settings::Settings;
use super::{render_opts, runtime};
use lucent::film::passes::{Pass, PassSet};
use lucent::film::{Film, ToneMap};
use lucent::render;
use lucent::Error;

/// The ladder of sample counts: 1, 2, 4, … ≤ `max_spp`.
pub fn ladder(max_spp: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&s| s.checked_mul(2))
        .take_while(|&s| s <= max_spp)
        .collect()
}

/// A bar on stderr counting the renders still missing from `results`, or
/// a hidden one (no progress asked for, or nothing to render).
pub(super) fn progress_bar(
    s: &Settings,
    configs: &[Config],
    spps: &[u32],
    results: &Results,
) -> ProgressBar {
    let pending = configs
        .iter()
        .map(|c| {
            spps.iter()
                .filter(|&&n| results.get(&c.name, n).is_none())
                .count() as u64
        })
        .sum::<u64>();
    if !(s.progress && pending > 0) {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(Some(pending), ProgressDrawTarget::stderr());
    b.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} renders, eta {eta} {msg}",
        )
        .unwrap()
        .progress_chars("=> "),
    );
    b
}

/// What every rung of every configuration is rendered and judged with.
pub(super) struct Ladder<'a> {
    pub(super) settings: &'a Settings,
    /// The sample counts, [`ladder`]`(max_spp)`.
    pub(super) spps: &'a [u32],
    /// The acceleration structure of each backend, by name.
    pub(super) accels: &'a super::Accels,
    pub(super) reference: &'a Film,
    /// The seed every rung renders with (its own range of samples).
    pub(super) seed: u64,
}

impl Ladder<'_> {
    /// Renders every job's missing rungs, round-robin, appending a row to
    /// `results` for every rung it has none for; returns how many rows it
    /// appended. Each job's running mean is left in its `acc`.
    pub(super) fn render(
        &self,
        jobs: &mut [Job],
        results: &mut Results,
        bar: &ProgressBar,
    ) -> Result<usize, Error> {
        let mut rendered_rows = 0;
        for j in 0..self.spps.len() {
            for job in jobs.iter_mut().filter(|job| job.start <= j) {
                if self.rung(job, j, results, bar)? {
                    rendered_rows += 1;
                }
            }
        }
        Ok(rendered_rows)
    }

    /// Renders rung `j` of one job, keeps its running mean in the state
    /// directory (removing the previous rung's) and appends its row unless
    /// `results` has it; returns whether it appended one.
    fn rung(
        &self,
        job: &mut Job,
        j: usize,
        results: &mut Results,
        bar: &ProgressBar,
    ) -> Result<bool, Error> {
        let s = self.settings;
        let n = self.spps[j];
        let prev_n = if j == 0 { 0 } else { self.spps[j - 1] };
        let c = job.config;
        bar.set_message(format!("{} @ {n} spp", c.name));
        let chunk = self.chunk(job, prev_n..n)?;
        let mean = match job.acc.take() {
            None => chunk,
            Some(m) => m.extended(chunk, prev_n, n),
        };
        // The running mean of the last finished rung, kept also after the
        // last one so a rerun with a larger max_spp extends the ladder.
        mean.save(&s.out_dir, &c.name, n, prev_n)?;
        let mut appended = false;
        if results.get(&c.name, n).is_none() {
            let judged = match &mean.guides {
                Some(g) => denoised::denoise(&mean.film, g, s.threads)?,
                None => denoised::Judged::raw(&mean.film),
            };
            let m = metrics::compare(&judged.film, self.reference, s.firefly_k).map_err(runtime)?;
            results
                .append(Row {
                    config: c.name.clone(),
                    axis: c.axis.name().into(),
                    value: c.value.clone(),
                    backend: c.backend.name().into(),
                    integrator: config::integrator_name(c.integrator).into(),
                    spp: n,
                    seconds: mean.seconds + judged.seconds,
                    rmse: m.rmse,
                    rel_mse: m.rel_mse,
                    bias: m.bias,
                    bias_stderr: m.bias_stderr,
                    fireflies: m.fireflies,
                    denoise_seconds: judged.seconds,
                })
                .map_err(runtime)?;
            appended = true;
            bar.inc(1);
        }
        job.acc = Some(mean);
        Ok(appended)
    }

    /// The mean of the job's samples `samples` of the one seed (with the
    /// guides when it denoises) and their render time.
    fn chunk(&self, job: &Job, samples: Range<u32>) -> Result<Running, Error> {
        let c = job.config;
        let scene = &job.scene;
        let mut passes = PassSet::EMPTY;
        if c.denoise {
            passes.insert(Pass::Albedo);
            passes.insert(Pass::Normal);
        }
        let work = render::Job {
            samples,
            passes,
            ..render::Job::full(scene, 1)
        };
        let accel = self.accels[&(
            c.backend.name(),
            c.integrator.traversal(scene.settings.traversal),
        )]
            .as_ref();
        let opts = render_opts(
            self.settings,
            1,
            self.seed,
            c.integrator,
            Some(c.sampler),
            false,
        );
        let r = render::render_job(scene, accel, &opts, &work, None, &mut |_| Ok(()))?;
        if let Some(sig) = r.interrupted {
            return Err(Error::Interrupted(sig));
        }
        let film = r.sums.film()?;
        let guides = if c.denoise {
            let (layers, _) = r.sums.layers(false)?;
            Some(Guides::from_layers(&layers, film.width, film.height)?)
        } else {
            None
        };
        Ok(Running {
            film,
            guides,
            seconds: r.stats.seconds,
        })
    }
}

/// The final image of each configuration rendered by this run, for
/// looking at: `DIR/images/<config>.exr` and `.png`.
pub(super) fn write_final_images(s: &Settings, jobs: &[Job]) -> Result<(), Error> {
    for job in jobs {
        if let Some(Running { film, .. }) = &job.acc {
            let img = s
                .out_dir
                .join("images")
                .join(format!("{}.exr", slug(&job.config.name)));
            fs::create_dir_all(img.parent().unwrap()).map_err(runtime)?;
            film.write_exr_and_preview(&img, ToneMap::Filmic, 0.0)
                .map_err(runtime)?;
        }
    }
    Ok(())
}
