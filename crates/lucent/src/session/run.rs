//! Running a [`Request`]: load, resolve, render (resuming and keeping
//! checkpoints), write the frame or the part.

use std::ops::Range;
use std::path::PathBuf;

use super::checkpoint::{self, Checkpoints};
use super::checkpoint_owner::ThisRender;
use super::identity;
use super::output::check_exr_output;
use super::resume::resumable;
use super::{overrides, Request, Split};
use crate::accel;
use crate::error::{Error, InputError};
use crate::farm::part;
use crate::film::exr_attributes::FrameHeader;
use crate::film::exr_layers::{self, OutputOptions, Window};
use crate::film::passes::PassSet;
use crate::film::region::Region;
use crate::film::Sums;
use crate::memory::{self, Phase};
use crate::render::{self, RenderStats, Settings};
use crate::scene::{self, Scene};

/// What a finished render did (for its summary line).
#[derive(Clone, Debug)]
pub struct Outcome {
    pub region: Region,
    pub frame: (u32, u32),
    pub samples: Range<u32>,
    pub spp: u32,
    pub is_part: bool,
    pub triangles: usize,
    pub accel_name: String,
    pub stats: RenderStats,
    /// Ray queries the backend refused as out of range.
    pub rejected_rays: u64,
    /// The scene's distinct textures and their bytes
    /// ([`crate::scene::Scene::texture_memory`]).
    pub textures: (usize, usize),
    /// What loading the scene read past ([`crate::scene::Scene::notes`]).
    pub notes: Vec<String>,
}

impl Outcome {
    /// The summary line of the render written to `output`.
    pub fn summary(&self, output: &std::path::Path) -> String {
        let (w, h) = self.frame;
        format!(
            "{}: {}{} of {w}×{h}, samples {}..{} of {}, {} triangles: {}",
            output.display(),
            if self.is_part { "part, " } else { "" },
            self.region,
            self.samples.start,
            self.samples.end,
            self.spp,
            self.triangles,
            self.stats.summary(&self.accel_name)
        )
    }
}

/// [`Error::Interrupted`] once a signal asked the process to stop.
pub fn stop_if_interrupted() -> Result<(), Error> {
    match crate::interrupt::requested() {
        Some(sig) => Err(Error::Interrupted(sig)),
        None => Ok(()),
    }
}

/// `--spp` and `--threads` of at least 1.
fn check_counts(r: &Request) -> Result<(), Error> {
    for (argument, v) in [
        ("--spp", r.opts.spp.map(|s| s as usize)),
        ("--threads", r.opts.threads),
    ] {
        if v == Some(0) {
            return Err(Error::Argument {
                argument: argument.into(),
                problem: "must be at least 1".into(),
            });
        }
    }
    Ok(())
}

/// The pixels `split` asks for, inside the `w`×`h` frame.
fn region_of(split: &Split, w: u32, h: u32) -> Result<Region, Error> {
    let rect = [("--crop", split.crop), ("--region", split.region)]
        .into_iter()
        .find_map(|(flag, r)| r.map(|r| (flag, r)));
    Ok(match (rect, split.tile) {
        (Some((flag, c)), _) if !c.within(&Region::full(w, h)) => {
            return Err(Error::Argument {
                argument: flag.into(),
                problem: format!("{c} is not inside the {w}×{h} frame"),
            })
        }
        (Some((_, c)), _) => c,
        (None, Some((i, n))) => Region::band(i, n, w, h).ok_or_else(|| Error::Argument {
            argument: "--tile".into(),
            problem: format!("{i}/{n}: the {w}×{h} frame splits into at most {h} bands"),
        })?,
        (None, None) => Region::full(w, h),
    })
}

/// The sample indices `split` asks for, within `0..spp`.
fn samples_of(split: &Split, spp: u32) -> Result<Range<u32>, Error> {
    let samples = split.samples.clone().unwrap_or(0..spp);
    if samples.end > spp {
        return Err(Error::Argument {
            argument: "--samples".into(),
            problem: format!(
                "{}..{} reaches beyond the {spp} samples per pixel",
                samples.start, samples.end
            ),
        });
    }
    Ok(samples)
}

/// The scene of `r` with its overrides applied, its text, and the
/// overrides' canonical text.
fn load(r: &Request) -> Result<(Scene, String, String), Error> {
    let mut scene = scene::load(&r.scene)?;
    let text = scene::load::read_regular_file(&r.scene, scene::load::MAX_SCENE_BYTES)
        .map_err(|e| InputError::new(&r.scene, format!("cannot read scene file: {e}")))?;
    let options = overrides::apply(&r.overrides, &mut scene)?;
    apply_film(&mut scene, &r.file);
    Ok((scene, text, options))
}

/// The command line's film settings in `scene`: the film is the
/// renderer's to know (`integrator::plan::Plan`), and the plan's.
pub fn apply_film(scene: &mut Scene, file: &crate::scene::OutputSettings) {
    if let Some(t) = file.transparent {
        scene.output.file.transparent = Some(t);
    }
}

/// Renders `r` and writes its frame or part; a signal keeps the finished
/// samples as a part to resume from ([`Error::InterruptedKept`]).
pub fn run(r: &Request) -> Result<Outcome, Error> {
    check_exr_output(&r.output)?;
    check_counts(r)?;
    check_denoise(r)?;
    memory::enter(Phase::LoadingScene);
    let (scene, text, options) = load(r)?;
    let settings = Settings::resolved(&scene, &r.opts);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let region = region_of(&r.split, w, h)?;
    let samples = samples_of(&r.split, settings.spp)?;
    let mut out = output_options(r, &scene);
    let passes = film_passes(
        r.aov.unwrap_or(scene.output.aovs),
        &out,
        r.denoise.is_some(),
    );
    let layout = (!passes.is_empty()).then(|| crate::integrator::aov::layout(&scene, passes));
    // parts and resumes record the backend this machine resolves to
    let backend = r.backend.resolve().unwrap_or(r.backend);
    let identity = identity::identity(
        text.as_bytes(),
        &scene,
        &settings,
        backend,
        &options,
        layout.as_ref(),
        &out,
    );
    let job = job_of(r, region, samples.clone(), passes);
    let keep = checkpoint::checkpoint_path(&r.output);
    let this = ThisRender {
        identity: &identity,
        region,
        requested: &samples,
    };
    this.check(&keep, r.split.resume.as_deref())?;
    let resume = match &r.split.resume {
        Some(p) => Some(resumable(p, &identity, &job)?),
        None => None,
    };
    stop_if_interrupted()?;
    let traversal = settings.integrator.traversal(scene.settings.traversal);
    memory::enter(Phase::BuildingAccel);
    let accel = accel::build_with(&scene.meshes, r.backend, traversal)?;
    stop_if_interrupted()?;
    let frame = identity::frame_header(
        &r.scene,
        &text,
        &scene,
        accel.name(),
        backend,
        &settings,
        passes,
    )?;
    let scene_name = scene_name(r);
    let header = |sums: &Sums| part::Header {
        identity: identity.clone(),
        scene: scene_name.clone(),
        region,
        samples: sums.start..sums.done,
        requested: samples.clone(),
        layers: part::layers_of(layout.as_ref()),
        counters: sums.counters,
        frame: frame.clone(),
    };
    out.preview = Some(r.preview);
    let mut checkpoints = Checkpoints::new(&keep, r.split.checkpoint, samples.end);
    let mut after_pass = |sums: &Sums| checkpoints.after_pass(sums, &header(sums));
    memory::enter(Phase::Rendering);
    let done = render::render_job(
        &scene,
        accel.as_ref(),
        &r.opts,
        &job,
        resume,
        &mut after_pass,
    )?;
    memory::enter(Phase::Writing);
    if let Some(signal) = done.interrupted {
        // A save that failed leaves the interrupted render's own to try.
        let more = checkpoints.finish(done.sums.done).unwrap_or(true);
        return keep_interrupted(
            signal,
            keep.clone(),
            more,
            &header(&done.sums),
            &done.sums,
            samples,
        );
    }
    checkpoints.finish(done.sums.done)?;
    if r.split.is_part() {
        crate::film::commit_all(vec![part::stage(
            &r.output,
            &header(&done.sums),
            &done.sums,
        )?])?;
    } else {
        let header = FrameHeader {
            render_seconds: Some(done.stats.seconds),
            date: Some(super::provenance::date_now()),
            ..frame.clone()
        };
        let window = Window {
            frame: (w, h),
            data: region,
        };
        write_frame(r, window, &done.sums, &header, &out)?;
    }
    if this.owns(&keep) {
        checkpoint::clean(&keep);
    }
    Ok(Outcome {
        region,
        frame: (w, h),
        samples,
        spp: settings.spp,
        is_part: r.split.is_part(),
        triangles: scene.triangle_count(),
        accel_name: accel.name().into(),
        stats: done.stats,
        rejected_rays: accel.rejected_rays(),
        textures: scene.texture_memory(),
        notes: scene.notes.clone(),
    })
}

/// The output options: the command line's over the scene's over the
/// defaults.
fn output_options(r: &Request, scene: &Scene) -> OutputOptions {
    r.file
        .over(scene.output.file.over(OutputOptions::default()))
}

/// The passes a render sums: those asked for, with a transparent film the
/// object coverage (its counts of camera rays that hit are `A`), and when
/// it is denoised the guides (albedo and normal).
fn film_passes(asked: PassSet, out: &OutputOptions, denoised: bool) -> PassSet {
    use crate::film::passes::Pass;
    let mut passes = asked;
    if out.transparent {
        passes.insert(Pass::CryptoObject);
    }
    if denoised {
        passes.insert(Pass::Albedo);
        passes.insert(Pass::Normal);
    }
    passes
}

/// `--denoise` only on a frame (a part is denoised after the merge), and
/// with the denoiser loaded before the render rather than after it.
fn check_denoise(r: &Request) -> Result<(), Error> {
    if r.denoise.is_none() {
        return Ok(());
    }
    if r.split.is_part() {
        return Err(Error::Argument {
            argument: "--denoise".into(),
            problem: "a part is not denoised: denoise the merged frame once \
                      (lucent merge --denoise, or lucent denoise)"
                .into(),
        });
    }
    crate::denoise::load::api().map(|_| ())
}

/// The scene file's name, for part headers.
fn scene_name(r: &Request) -> String {
    r.scene
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The render job: checkpoints pace the passes (at most 2 s each).
fn job_of(r: &Request, region: Region, samples: Range<u32>, passes: PassSet) -> render::Job {
    render::Job {
        region,
        samples,
        pass_seconds: r.split.checkpoint.map_or(2.0, |c| (c / 2.0).min(2.0)),
        passes,
    }
}

/// A render stopped by `signal`: keeps the finished passes as a part at
/// `keep` (none finished: nothing kept; `more` false: the last checkpoint
/// holds them all already) and reports the stop.
fn keep_interrupted(
    signal: i32,
    keep: PathBuf,
    more: bool,
    header: &part::Header,
    sums: &Sums,
    requested: Range<u32>,
) -> Result<Outcome, Error> {
    if sums.count() == 0 {
        return Err(Error::Interrupted(signal));
    }
    if more {
        let staged = part::stage(&keep, header, sums)?;
        crate::film::commit_even_if_interrupted(vec![staged])?;
    }
    Err(Error::InterruptedKept {
        signal,
        part: keep,
        samples: sums.start..sums.done,
        requested,
    })
}

/// Writes the finished frame's layers to the output EXR, its pixels at
/// `window`.
fn write_frame(
    r: &Request,
    window: Window,
    sums: &Sums,
    header: &FrameHeader,
    out: &OutputOptions,
) -> Result<(), Error> {
    let (layers, coverage) = sums.layers(out.transparent)?;
    let film = sums.film()?;
    match &r.denoise {
        None => exr_layers::write_window(&r.output, window, &film, &layers, &coverage, header, out),
        Some(d) => crate::film::commit_all(super::denoise::stage_denoised(
            &r.output, window, &film, &layers, &coverage, header, out, d,
        )?),
    }
}
