//! The `lucent` command line: parses arguments, calls the library, and maps
//! errors to exit codes in one place, [`exit_code`] (2: bad input —
//! arguments, scene, meshes; 1: a failure while running or writing output).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use lucent::accel::{self, Backend};
#[cfg(feature = "subsurface")]
use lucent::bssrdf::{ChannelStrategy, ProbeAxes, RadiusSampler};
use lucent::error::InputError;
#[cfg(feature = "subsurface")]
use lucent::error::{Param, ParamError};
use lucent::farm::part::{self, Identity};
use lucent::film::cryptomatte;
use lucent::film::exr_layers::{
    self, ExrCompression, FrameHeader, OutputOptions, Precision, Preview,
};
use lucent::film::passes::PassSet;
use lucent::film::region::Region;
use lucent::film::ToneMap;
use lucent::integrator::{effects, plan, IntegratorKind};
#[cfg(feature = "subsurface")]
use lucent::materials::{LodMode, SubsurfaceOverrides, WalkBoundary};
use lucent::render::{self, RenderOptions};
use lucent::scene;
use lucent::Error;

#[derive(Parser)]
#[command(
    name = "lucent",
    version,
    about = "A path tracer for translucent materials"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum IntegratorArg {
    Path,
    #[cfg(feature = "subsurface")]
    Randomwalk,
}

#[derive(Clone, Copy, ValueEnum)]
enum AccelArg {
    /// The best Embree available (Embree 4, else Embree 3).
    Embree,
    Embree3,
    Embree4,
    Bvh,
}

impl From<AccelArg> for Backend {
    fn from(a: AccelArg) -> Backend {
        match a {
            AccelArg::Embree => Backend::Embree,
            AccelArg::Embree3 => Backend::Embree3,
            AccelArg::Embree4 => Backend::Embree4,
            AccelArg::Bvh => Backend::Bvh,
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a float OpenEXR plus a PNG preview beside it.
    Render {
        /// The scene description (TOML; see docs/scene-format.md).
        scene: PathBuf,
        /// Output OpenEXR path; the preview goes to the same path with `.png`.
        #[arg(short, long, default_value = "out.exr")]
        output: PathBuf,
        /// Samples per pixel (default: the scene's `render.spp`).
        #[arg(long)]
        spp: Option<u32>,
        /// Worker threads, 1 to 1024 (default: all cores).
        #[arg(long, value_parser = lucent::tools::bench::parse_threads)]
        threads: Option<usize>,
        /// Random seed (default: the scene's `render.seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Ray-query backend: embree (the best available: embree4, else
        /// embree3), embree3, embree4 or bvh (default: embree if any is
        /// available, else bvh).
        #[arg(long, value_enum)]
        accel: Option<AccelArg>,
        /// Tone map of the PNG preview (the EXR is always linear).
        #[arg(long, value_enum, default_value = "filmic")]
        tonemap: ToneMap,
        /// Exposure of the PNG preview in stops.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        exposure: f32,
        /// No progress bar and no summary line.
        #[arg(short, long)]
        quiet: bool,
        /// Estimator at subsurface objects: path (diffusion BSSRDF) |
        /// randomwalk (volumetric reference).
        #[arg(long, value_enum, default_value = "path")]
        integrator: IntegratorArg,
        /// Passes besides the beauty, comma separated (replaces the scene's
        /// `[output] aovs`): light paths (emission, background,
        /// diffuse_direct, diffuse_indirect, specular_direct,
        /// specular_indirect, transmission, sss_direct, sss_indirect),
        /// lightgroups, albedo, N, P, Z, object_id, material_id,
        /// crypto_object, crypto_material, sample_count, variance; groups:
        /// all, lightpaths, data, ids, cryptomatte, noise (docs/output.md).
        #[arg(long, value_parser = parse_aov)]
        aov: Option<PassSet>,
        /// Print the render plan (each effect, the method chosen and why)
        /// and exit without rendering: as text, or `--explain=json`
        /// (docs/output.md, "The render plan").
        #[arg(
            long,
            value_enum,
            num_args = 0..=1,
            require_equals = true,
            default_missing_value = "text"
        )]
        explain: Option<ExplainArg>,
        /// After the render, ray queries and share of time per effect
        /// (docs/performance.md, "Per-effect statistics").
        #[arg(long)]
        stats: bool,
        #[command(flatten)]
        subsurface: SubsurfaceArgs,
        #[command(flatten)]
        file: FileArgs,
        #[command(flatten)]
        split: SplitArgs,
    },
    /// Merge parts (`render --crop/--tile/--samples`) into the frame they
    /// split: bitwise the frame one uncut render gives. Checks that they
    /// are of one scene, seed, spp, options, passes and lucent version and
    /// cover the frame's pixels and samples exactly once; writes the EXR
    /// (with every pass the parts carry) and its PNG preview, or nothing.
    Merge {
        /// The part files.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output OpenEXR path; the preview goes to the same path with `.png`.
        #[arg(short, long)]
        output: PathBuf,
        /// Tone map of the PNG preview (the EXR is always linear).
        #[arg(long, value_enum, default_value = "filmic")]
        tonemap: ToneMap,
        /// Exposure of the PNG preview in stops.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        exposure: f32,
        /// No summary line.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Benchmark the ray-query backends on the same meshes and rays: build
    /// time and memory, Mrays/s of camera, incoherent, shadow and probe
    /// rays; bench.csv, report.txt and plots in the output directory. With
    /// --scene: the render's end-to-end ray rate against the backend's raw
    /// rate on the render's own queries (render-mix.csv, render-mix.txt).
    Bench(BenchArgs),
    /// Print the build's ray-query backends and versions.
    Info,
    /// Measure error against time for every sampling choice of the
    /// subsurface estimator: results.csv, plots and report.md in the output
    /// directory (resumes from results.csv; see src/tools/study/mod.rs).
    #[cfg(feature = "subsurface")]
    Study(StudyArgs),
}

/// Splitting a frame into parts, checkpoints and resuming (docs/farm.md).
#[derive(clap::Args)]
struct SplitArgs {
    /// Render only the pixels X0 ≤ x < X1, Y0 ≤ y < Y1; the output is a
    /// part for `lucent merge`.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop, conflicts_with = "tile")]
    crop: Option<Region>,
    /// Render band I (0-based) of N balanced horizontal bands; the output
    /// is a part for `lucent merge`.
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    tile: Option<(u32, u32)>,
    /// Render only the sample indices A ≤ s < B of each pixel; the output
    /// is a part for `lucent merge`.
    #[arg(long, value_name = "A..B", value_parser = parse_samples)]
    samples: Option<std::ops::Range<u32>>,
    /// Every SECONDS (at the end of a pass), save the finished samples to
    /// OUT.partial.exr, atomically, for --resume.
    #[arg(long, value_name = "SECONDS", value_parser = parse_checkpoint)]
    checkpoint: Option<f64>,
    /// Continue from a part this same render left (at a signal or a
    /// checkpoint): the result is bitwise the uninterrupted render's.
    #[arg(long, value_name = "PART.exr")]
    resume: Option<PathBuf>,
}

impl SplitArgs {
    /// Whether the output is a part rather than a frame.
    fn is_part(&self) -> bool {
        self.crop.is_some() || self.tile.is_some() || self.samples.is_some()
    }
}

fn parse_crop(s: &str) -> Result<Region, String> {
    Region::parse(s)
        .filter(|r| !r.is_empty())
        .ok_or_else(|| format!("expected X0,Y0,X1,Y1 with X0 < X1 and Y0 < Y1, found \"{s}\""))
}

fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    s.split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)))
        .filter(|&(i, n)| i < n)
        .ok_or_else(|| format!("expected I/N with 0 ≤ I < N, found \"{s}\""))
}

fn parse_samples(s: &str) -> Result<std::ops::Range<u32>, String> {
    part::parse_samples(s).ok_or_else(|| format!("expected A..B with A < B, found \"{s}\""))
}

fn parse_checkpoint(s: &str) -> Result<f64, String> {
    s.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a positive number of seconds, found \"{s}\""))
}

/// Subsurface sampling choices that override every subsurface material's
/// own (see docs/scene-format.md for what each means).
#[cfg(feature = "subsurface")]
#[derive(clap::Args)]
struct SubsurfaceArgs {
    /// Radius sampler: uniform | table[:N] | table-uniform[:N] | analytic | mixture.
    #[arg(long, value_parser = parse_radius)]
    radius: Option<RadiusSampler>,
    /// Probe sphere radius as a quantile of the widest channel's profile, in (0, 1).
    #[arg(long)]
    rmax_quantile: Option<f64>,
    /// Probe axes: curvature (N/T/B with MIS, T/B probabilities from the
    /// curvature) | normal (the seed) | mis3 (N/T/B at ½, ¼, ¼ with MIS).
    #[arg(long, value_enum)]
    axes: Option<AxesArg>,
    /// Channel choice: single (the seed) | mis (all channels, balance heuristic).
    #[arg(long, value_enum)]
    channel: Option<ChannelArg>,
    /// Divide the profile by CDF(Rmax) so truncation loses no energy.
    #[arg(long)]
    renormalize: Option<bool>,
    /// Normalized Fresnel lobe Sw at the entry point (false: cosine lobe).
    #[arg(long)]
    exit_sw: Option<bool>,
    /// Specular reflection layer on top.
    #[arg(long)]
    specular: Option<bool>,
    /// Roughness of that layer in [0, 1] (0: a mirror; GGX with α = roughness²).
    #[arg(long)]
    roughness: Option<f32>,
    /// Random-walk boundary: dielectric (exact, smooth) | diffuse (diffuse
    /// Fresnel transmission with light sampling at the exit; another model).
    #[arg(long, value_enum)]
    boundary: Option<BoundaryArg>,
    /// Subsurface level of detail: auto (albedo A where the path's
    /// footprint is wide against the profile, per material threshold) | off
    /// (always probe) | force (every hit shaded with albedo A; for tests).
    #[arg(long, value_enum)]
    lod: Option<LodArg>,
    /// At the camera vertex, the plane control variate on the light
    /// sampled at the entry point (true by default).
    #[arg(long)]
    control_variate: Option<bool>,
    /// At the camera vertex, an antithetic pair of probes (false by
    /// default).
    #[arg(long)]
    probe_pair: Option<bool>,
}

/// How the EXR is stored (docs/output.md); each overrides the scene's
/// `[output]` key of the same name.
#[derive(clap::Args)]
struct FileArgs {
    /// Precision of light passes: half | float (data passes, IDs and beauty
    /// are always float).
    #[arg(long, value_enum)]
    aov_precision: Option<PrecisionArg>,
    /// Lossless EXR compression: none | rle | zips | zip (default) | piz.
    #[arg(long, value_enum)]
    exr_compression: Option<CompressionArg>,
    /// One file per pass (OUT.PASS.exr beside OUT.exr) instead of one
    /// multi-layer file.
    #[arg(long, num_args = 0..=1, default_missing_value = "true")]
    aov_split: Option<bool>,
    /// Cryptomatte ranks per pixel, 1 to 64 (default 6).
    #[arg(long)]
    cryptomatte_ranks: Option<usize>,
}

#[derive(Clone, Copy, ValueEnum)]
enum PrecisionArg {
    Half,
    Float,
}

#[derive(Clone, Copy, ValueEnum)]
enum CompressionArg {
    None,
    Rle,
    Zips,
    Zip,
    Piz,
}

impl FileArgs {
    /// The command line's settings, in the scene's form (they override it).
    fn settings(&self) -> Result<scene::OutputSettings, Error> {
        if let Some(n) = self
            .cryptomatte_ranks
            .filter(|n| !(1..=cryptomatte::MAX_RANKS).contains(n))
        {
            return Err(Error::Argument {
                argument: "--cryptomatte-ranks".into(),
                problem: format!("{n} is not in 1 to {}", cryptomatte::MAX_RANKS),
            });
        }
        Ok(scene::OutputSettings {
            precision: self.aov_precision.map(|p| match p {
                PrecisionArg::Half => Precision::Half,
                PrecisionArg::Float => Precision::Float,
            }),
            compression: self.exr_compression.map(|c| match c {
                CompressionArg::None => ExrCompression::None,
                CompressionArg::Rle => ExrCompression::Rle,
                CompressionArg::Zips => ExrCompression::Zips,
                CompressionArg::Zip => ExrCompression::Zip,
                CompressionArg::Piz => ExrCompression::Piz,
            }),
            split: self.aov_split,
            cryptomatte_ranks: self.cryptomatte_ranks,
        })
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ExplainArg {
    Text,
    Json,
}

#[cfg(feature = "subsurface")]
#[derive(Clone, Copy, ValueEnum)]
enum LodArg {
    Auto,
    Off,
    Force,
}

#[cfg(feature = "subsurface")]
#[derive(Clone, Copy, ValueEnum)]
enum BoundaryArg {
    Dielectric,
    Diffuse,
}

#[cfg(feature = "subsurface")]
#[derive(Clone, Copy, ValueEnum)]
enum AxesArg {
    Curvature,
    Normal,
    Mis3,
}

#[cfg(feature = "subsurface")]
#[derive(Clone, Copy, ValueEnum)]
enum ChannelArg {
    Single,
    Mis,
}

#[cfg(feature = "subsurface")]
fn parse_radius(s: &str) -> Result<RadiusSampler, ParamError> {
    RadiusSampler::parse(s)
}

fn parse_aov(s: &str) -> Result<PassSet, String> {
    PassSet::parse_list(s).map_err(|e| e.problem())
}

#[cfg(feature = "subsurface")]
impl SubsurfaceArgs {
    /// Applies the overrides to every subsurface material of `materials`;
    /// returns them as the render's identity records them.
    fn apply(&self, materials: &mut [lucent::materials::Material]) -> Result<String, Error> {
        let o = self.overrides();
        o.apply_all(materials).map_err(option_error)?;
        Ok(format!("{o:?}"))
    }

    fn overrides(&self) -> SubsurfaceOverrides {
        SubsurfaceOverrides {
            radius: self.radius,
            rmax_quantile: self.rmax_quantile,
            axes: self.axes.map(|a| match a {
                AxesArg::Curvature => ProbeAxes::Curvature,
                AxesArg::Normal => ProbeAxes::Normal,
                AxesArg::Mis3 => ProbeAxes::Mis3,
            }),
            channel: self.channel.map(|c| match c {
                ChannelArg::Single => ChannelStrategy::Single,
                ChannelArg::Mis => ChannelStrategy::Mis,
            }),
            renormalize: self.renormalize,
            exit_sw: self.exit_sw,
            specular: self.specular,
            boundary: self.boundary.map(|b| match b {
                BoundaryArg::Dielectric => WalkBoundary::Dielectric,
                BoundaryArg::Diffuse => WalkBoundary::Diffuse { exit_nee: true },
            }),
            roughness: self.roughness,
            lod: self.lod.map(|l| match l {
                LodArg::Auto => LodMode::Auto,
                LodArg::Off => LodMode::Off,
                LodArg::Force => LodMode::Force,
            }),
            control_variate: self.control_variate,
            probe_pair: self.probe_pair,
        }
    }
}

/// A build without the `subsurface` feature has no subsurface materials,
/// and so no options that override them.
#[cfg(not(feature = "subsurface"))]
#[derive(clap::Args)]
struct SubsurfaceArgs {}

#[cfg(not(feature = "subsurface"))]
impl SubsurfaceArgs {
    fn apply(&self, _: &mut [lucent::materials::Material]) -> Result<String, Error> {
        Ok(String::new())
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = lucent::interrupt::install() {
        eprintln!("warning: cannot catch SIGINT/SIGTERM ({e}); an interrupted command may leave temporary files");
    }
    let result = match cli.command {
        Command::Render {
            scene,
            output,
            spp,
            threads,
            seed,
            accel,
            tonemap,
            exposure,
            quiet,
            integrator,
            aov,
            explain,
            stats,
            subsurface,
            file,
            split,
        } => {
            let backend = accel
                .map(Backend::from)
                .unwrap_or_else(Backend::default_available);
            let integrator = match integrator {
                IntegratorArg::Path => IntegratorKind::Path,
                #[cfg(feature = "subsurface")]
                IntegratorArg::Randomwalk => IntegratorKind::RandomWalk,
            };
            let opts = RenderOptions {
                spp,
                seed,
                threads,
                progress: !quiet,
                integrator,
                stats,
            };
            if let Some(format) = explain {
                return finish(run_explain(&scene, integrator, aov, &subsurface, format));
            }
            file.settings().and_then(|file| {
                run_render(
                    &scene,
                    &output,
                    backend,
                    &opts,
                    aov,
                    &subsurface,
                    &file,
                    &split,
                    Preview { tonemap, exposure },
                    quiet,
                )
            })
        }
        Command::Merge {
            parts,
            output,
            tonemap,
            exposure,
            quiet,
        } => run_merge(&parts, &output, tonemap, exposure, quiet),
        #[cfg(feature = "subsurface")]
        Command::Study(args) => run_study(args),
        Command::Bench(args) => run_bench(args),
        Command::Info => {
            println!("{}", info());
            Ok(())
        }
    };
    finish(result)
}

/// The exit code of a command's result, its error (if any) printed.
fn finish(result: Result<(), Error>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let shown = match lucent::interrupt::requested() {
                Some(sig)
                    if !matches!(e, Error::Interrupted(_) | Error::InterruptedKept { .. }) =>
                {
                    Error::Interrupted(sig).to_string()
                }
                _ => e.to_string(),
            };
            eprintln!("error: {}", without_control_characters(&shown));
            ExitCode::from(exit_code(&e))
        }
    }
}

/// The exit code of a failed command: 2 for bad input (arguments, scene,
/// meshes, parameters, a backend this build lacks), 1 for a failure while
/// running or writing output, 128 + the signal's number (130 for SIGINT,
/// 143 for SIGTERM) when a signal stopped it (whatever error the stopped
/// work then reported: see src/interrupt.rs).
fn exit_code(e: &Error) -> u8 {
    if let Some(sig) = lucent::interrupt::requested() {
        return u8::try_from(lucent::interrupt::exit_code(sig)).unwrap_or(1);
    }
    if e.is_input() {
        2
    } else {
        1
    }
}

/// A subsurface override from the command line out of its domain, named by
/// its option.
#[cfg(feature = "subsurface")]
fn option_error(e: ParamError) -> Error {
    let (argument, problem) = match e.param {
        Param::RmaxQuantile => ("--rmax-quantile", e.problem()),
        Param::RadiusSampler => ("--radius", e.problem()),
        Param::TableSize => ("--radius", format!("table size {}", e.problem())),
        _ => ("subsurface option", e.to_string()),
    };
    Error::Argument {
        argument: argument.into(),
        problem,
    }
}

/// An output path that ends in `.exr` and lies in an existing directory.
fn check_exr_output(output: &Path) -> Result<(), Error> {
    if output
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        != Some("exr".into())
    {
        return Err(Error::Argument {
            argument: format!("output {}", output.display()),
            problem: "expected a path ending in .exr".into(),
        });
    }
    let dir = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(Error::Argument {
            argument: format!("output directory {}", dir.display()),
            problem: "does not exist".into(),
        });
    }
    Ok(())
}

/// Where a render keeps its finished samples for `--resume` (at a signal,
/// at checkpoints): `OUT.partial.exr` beside `OUT.exr`.
fn checkpoint_path(output: &Path) -> PathBuf {
    output.with_extension("partial.exr")
}

#[allow(clippy::too_many_arguments)]
fn run_render(
    scene_path: &Path,
    output: &Path,
    backend: Backend,
    opts: &RenderOptions,
    aov: Option<PassSet>,
    subsurface: &SubsurfaceArgs,
    file: &scene::OutputSettings,
    split: &SplitArgs,
    preview: Preview,
    quiet: bool,
) -> Result<(), Error> {
    check_exr_output(output)?;
    if opts.spp == Some(0) {
        return Err(Error::Argument {
            argument: "--spp".into(),
            problem: "must be at least 1".into(),
        });
    }
    if opts.threads == Some(0) {
        return Err(Error::Argument {
            argument: "--threads".into(),
            problem: "must be at least 1".into(),
        });
    }
    let mut scene = scene::load(scene_path)?;
    let scene_bytes = scene::load::read_regular_file(scene_path, scene::load::MAX_SCENE_BYTES)
        .map_err(|e| InputError::new(scene_path, format!("cannot read scene file: {e}")))?;
    let overrides = subsurface.apply(&mut scene.materials)?;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let spp = opts.spp.unwrap_or(scene.settings.spp);
    let region = match (split.crop, split.tile) {
        (Some(c), _) if !c.within(&Region::full(w, h)) => {
            return Err(Error::Argument {
                argument: "--crop".into(),
                problem: format!("{c} is not inside the {w}×{h} frame"),
            })
        }
        (Some(c), _) => c,
        (None, Some((i, n))) => Region::band(i, n, w, h).ok_or_else(|| Error::Argument {
            argument: "--tile".into(),
            problem: format!("{i}/{n}: the {w}×{h} frame splits into at most {h} bands"),
        })?,
        (None, None) => Region::full(w, h),
    };
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
    let passes = aov.unwrap_or(scene.output.aovs);
    let layout = (!passes.is_empty()).then(|| lucent::integrator::aov::layout(&scene, passes));
    let mut out = file.over(scene.output.file.over(OutputOptions::default()));
    let identity = Identity {
        passes: part::passes_text(layout.as_ref()),
        names: part::names_text(layout.as_ref()),
        output: part::output_text(&out),
        version: env!("CARGO_PKG_VERSION").into(),
        scene_hash: lucent::farm::scene_hash(scene_bytes.as_bytes(), &scene),
        seed: opts.seed.unwrap_or(scene.settings.seed),
        spp,
        options: format!(
            "accel={} integrator={:?} {overrides}",
            backend.name(),
            opts.integrator
        ),
        frame: (w, h),
    };
    let scene_name = scene_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let header = |sums: &lucent::film::Sums| part::Header {
        identity: identity.clone(),
        scene: scene_name.clone(),
        region,
        samples: sums.start..sums.done,
        requested: samples.clone(),
        layers: part::layers_of(layout.as_ref()),
        counters: sums.counters,
    };
    let job = render::Job {
        region,
        samples: samples.clone(),
        pass_seconds: split.checkpoint.map_or(2.0, |c| (c / 2.0).min(2.0)),
        passes,
    };
    let resume = match &split.resume {
        Some(p) => Some(resumable(p, &identity, &job)?),
        None => None,
    };
    stop_if_interrupted()?;
    let traversal = opts.integrator.traversal(scene.settings.traversal);
    let accel = accel::build_with(&scene.meshes, backend, traversal)?;
    stop_if_interrupted()?;
    out.preview = Some(preview);
    let keep = checkpoint_path(output);
    let mut last = std::time::Instant::now();
    let mut checkpoint = |sums: &lucent::film::Sums| -> Result<(), Error> {
        match split.checkpoint {
            Some(every) if last.elapsed().as_secs_f64() >= every && sums.done < samples.end => {
                lucent::film::commit_all(vec![part::stage(&keep, &header(sums), sums)?])?;
                last = std::time::Instant::now();
                Ok(())
            }
            _ => Ok(()),
        }
    };
    let r = render::render_job(&scene, accel.as_ref(), opts, &job, resume, &mut checkpoint)?;
    if let Some(signal) = r.interrupted {
        if r.sums.count() == 0 {
            return Err(Error::Interrupted(signal));
        }
        let staged = part::stage(&keep, &header(&r.sums), &r.sums)?;
        lucent::film::commit_even_if_interrupted(vec![staged])?;
        return Err(Error::InterruptedKept {
            signal,
            part: keep,
            samples: r.sums.start..r.sums.done,
            requested: samples,
        });
    }
    if split.is_part() {
        lucent::film::commit_all(vec![part::stage(output, &header(&r.sums), &r.sums)?])?;
    } else {
        let header = frame_header(
            scene_path,
            &scene,
            accel.name(),
            backend,
            opts,
            PassSet::EMPTY,
            r.stats.seconds,
        )?;
        let (layers, coverage) = r.sums.layers()?;
        exr_layers::write_frame(output, &r.sums.film()?, &layers, &coverage, &header, &out)?;
    }
    // the finished output replaces what was kept to resume from
    if keep.is_file() {
        let _ = std::fs::remove_file(&keep);
    }
    // and a checkpoint a killed process was writing
    lucent::film::stale::clean(&keep);
    if !quiet {
        eprintln!(
            "{}: {}{region} of {w}×{h}, samples {}..{} of {spp}, {} triangles: {}",
            output.display(),
            if split.is_part() { "part, " } else { "" },
            samples.start,
            samples.end,
            scene.triangle_count(),
            r.stats.summary(accel.name())
        );
    }
    if opts.stats {
        eprint!("{}", effects::summary(&r.stats.counters));
    }
    report_rejected_rays(accel.as_ref());
    Ok(())
}

/// Prints the plan of rendering `scene_path` with these options (no
/// render, no file written): the scene's errors are those of a render.
fn run_explain(
    scene_path: &Path,
    integrator: IntegratorKind,
    aov: Option<PassSet>,
    subsurface: &SubsurfaceArgs,
    format: ExplainArg,
) -> Result<(), Error> {
    let mut scene = scene::load(scene_path)?;
    subsurface.apply(&mut scene.materials)?;
    let plan = render_plan(&scene, integrator, aov.unwrap_or(scene.output.aovs));
    match format {
        ExplainArg::Text => print!("{}", plan::text::render(&plan)),
        ExplainArg::Json => println!("{}", plan.to_json_pretty()),
    }
    Ok(())
}

/// The plan a render of `scene` with `integrator` and `passes` follows.
fn render_plan(
    scene: &scene::Scene,
    integrator: IntegratorKind,
    passes: PassSet,
) -> plan::Explanation {
    plan::Explanation::new(
        scene,
        &plan::PlanOptions {
            integrator,
            passes,
            ..plan::PlanOptions::default()
        },
    )
}

/// What the EXR header records about this render (docs/output.md): the
/// scene file and its SHA-256, samples, seed, depth, backend and version,
/// integrator, every subsurface material's sampling options (named by the
/// objects that use it) and the render time.
fn frame_header(
    scene_path: &Path,
    scene: &scene::Scene,
    accel_name: &str,
    backend: Backend,
    opts: &RenderOptions,
    passes: PassSet,
    seconds: f64,
) -> Result<FrameHeader, Error> {
    use sha2::{Digest, Sha256};
    let text =
        scene::load::read_regular_file(scene_path, scene::load::MAX_SCENE_BYTES).map_err(|e| {
            Error::Read {
                path: scene_path.to_path_buf(),
                problem: e.to_string(),
            }
        })?;
    let sha: String = Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    #[cfg_attr(not(feature = "subsurface"), allow(unused_mut))]
    let mut sampling = Vec::new();
    #[cfg(feature = "subsurface")]
    for (i, m) in scene.materials.iter().enumerate() {
        let lucent::materials::Material::Subsurface(ss) = m else {
            continue;
        };
        let users: Vec<&str> = scene
            .objects
            .iter()
            .filter(|o| o.material == i)
            .map(|o| o.name.as_str())
            .collect();
        if !users.is_empty() {
            sampling.push((users.join(","), ss.sampling_description()));
        }
    }
    Ok(FrameHeader {
        scene_path: Some(scene_path.display().to_string()),
        scene_sha256: Some(sha),
        spp: Some(opts.spp.unwrap_or(scene.settings.spp)),
        seed: Some(opts.seed.unwrap_or(scene.settings.seed)),
        max_depth: Some(scene.settings.max_depth),
        backend: Some(accel_name.into()),
        backend_version: Some(backend_version(backend)?),
        integrator: Some(
            match opts.integrator {
                IntegratorKind::Path => "path",
                #[cfg(feature = "subsurface")]
                IntegratorKind::RandomWalk => "randomwalk",
            }
            .into(),
        ),
        sampling,
        plan: Some(render_plan(scene, opts.integrator, passes).to_json()),
        render_seconds: Some(seconds),
    })
}

/// The backend's version: the Embree in use (the one `backend` resolves
/// to), or lucent's for its own BVH.
fn backend_version(backend: Backend) -> Result<String, Error> {
    Ok(match backend.resolve()? {
        #[cfg(feature = "embree")]
        Backend::Embree3 => format!("Embree {}", accel::embree::version()),
        #[cfg(feature = "embree4")]
        Backend::Embree4 => format!("Embree {}", accel::embree4::version()?),
        _ => format!("lucent {}", env!("CARGO_PKG_VERSION")),
    })
}

/// The sums of the part at `path`, checked to be a start of `job` of the
/// frame `identity`.
fn resumable(
    path: &Path,
    identity: &Identity,
    job: &render::Job,
) -> Result<lucent::film::Sums, Error> {
    let (h, sums) = part::read(path)?;
    let located = |field: &str, problem: String| -> Error {
        InputError::new(path, problem).in_field(field).into()
    };
    if let Some((field, theirs, ours)) = h.identity.difference(identity) {
        return Err(located(
            field,
            format!("`{theirs}`, but this render has `{ours}`: not a part of this render"),
        ));
    }
    if h.region != job.region {
        return Err(located(
            "lucent.region",
            format!("{}, but this render covers {}", h.region, job.region),
        ));
    }
    if h.samples.start != job.samples.start || h.samples.end > job.samples.end {
        return Err(located(
            "lucent.samples",
            format!(
                "{}..{}, not a start of this render's samples {}..{}",
                h.samples.start, h.samples.end, job.samples.start, job.samples.end
            ),
        ));
    }
    Ok(sums)
}

fn run_merge(
    parts: &[PathBuf],
    output: &Path,
    tonemap: ToneMap,
    exposure: f32,
    quiet: bool,
) -> Result<(), Error> {
    check_exr_output(output)?;
    let start = std::time::Instant::now();
    let m = lucent::farm::merge::merge(parts)?;
    let header = lucent::film::exr_attributes::FrameHeader {
        spp: Some(m.identity.spp),
        seed: Some(m.identity.seed),
        ..Default::default()
    };
    let out = OutputOptions {
        preview: Some(Preview { tonemap, exposure }),
        ..m.output
    };
    exr_layers::write_frame(output, &m.film, &m.layers, &m.coverage, &header, &out)?;
    if !quiet {
        eprintln!(
            "{}: {} parts merged, {}×{} at {} spp, {:.2} s{}",
            output.display(),
            parts.len(),
            m.film.width,
            m.film.height,
            m.identity.spp,
            start.elapsed().as_secs_f64(),
            if m.counters.nonfinite > 0 {
                format!(", {} non-finite samples discarded", m.counters.nonfinite)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

/// `s` with every control character (from a file name, an OBJ line or a
/// key quoted in the message) shown as its escape: a message is one line,
/// and input cannot send escape sequences to the terminal.
fn without_control_characters(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// [`Error::Interrupted`] once a signal asked the process to stop.
fn stop_if_interrupted() -> Result<(), Error> {
    match lucent::interrupt::requested() {
        Some(sig) => Err(Error::Interrupted(sig)),
        None => Ok(()),
    }
}

/// Says on stderr (even with `--quiet`: it means the image may be wrong)
/// how many ray queries the backend refused as out of range, if any.
fn report_rejected_rays(accel: &dyn accel::Accel) {
    let n = accel.rejected_rays();
    if n > 0 {
        eprintln!(
            "warning: {n} ray queries had a non-finite or out-of-range origin, direction or \
             interval (beyond ±{:e}) and were answered as misses; the image may be missing \
             light there (see \"Supported ranges\" in docs/scene-format.md)",
            accel::MAX_RAY_COMPONENT
        );
    }
}

#[cfg(feature = "subsurface")]
#[derive(clap::Args)]
struct StudyArgs {
    /// The scene description (TOML; needs a subsurface material).
    scene: PathBuf,
    /// Output directory (created; default: study-<scene name>).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Small images, few configurations, short ladders: under two minutes.
    #[arg(long)]
    quick: bool,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = lucent::tools::bench::parse_threads)]
    threads: Option<usize>,
    /// Integrator of the reference render: diffusion | randomwalk.
    #[arg(long, default_value = "diffusion", value_parser = parse_study_integrator)]
    reference: lucent::integrator::IntegratorKind,
    /// Samples per pixel of the reference (default 4096, quick 512).
    #[arg(long)]
    reference_spp: Option<u32>,
    /// Largest sample count of the ladder 1, 2, 4, … (default 128, quick 16).
    #[arg(long)]
    max_spp: Option<u32>,
    /// Image width in pixels, aspect kept (default 128, quick 48).
    #[arg(long)]
    width: Option<u32>,
    /// Base seed (default: the scene's).
    #[arg(long)]
    seed: Option<u64>,
    /// Firefly threshold: pixels above K times the reference.
    #[arg(long, default_value_t = 10.0)]
    firefly_k: f64,
    /// Only these axes (comma separated: radius, rmax, axes, channel,
    /// renormalize, exit_sw, specular, backend, integrator, boundary, lod,
    /// variance); the baseline always runs.
    #[arg(long, value_delimiter = ',', value_parser = parse_study_axis)]
    only: Vec<lucent::tools::study::Axis>,
    /// No progress bars.
    #[arg(short, long)]
    quiet: bool,
}

#[cfg(feature = "subsurface")]
fn parse_study_integrator(s: &str) -> Result<lucent::integrator::IntegratorKind, String> {
    lucent::tools::study::config::parse_integrator(s)
        .ok_or_else(|| format!("expected diffusion or randomwalk, found \"{s}\""))
}

#[cfg(feature = "subsurface")]
fn parse_study_axis(s: &str) -> Result<lucent::tools::study::Axis, String> {
    lucent::tools::study::Axis::parse(s).ok_or_else(|| format!("unknown axis \"{s}\""))
}

#[cfg(feature = "subsurface")]
fn run_study(a: StudyArgs) -> Result<(), Error> {
    use lucent::tools::study;
    let out = a.output.clone().unwrap_or_else(|| {
        let stem = a
            .scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        PathBuf::from(format!("study-{stem}"))
    });
    let mut s = study::Settings::new(&a.scene, out, a.quick);
    s.threads = a.threads;
    s.reference = a.reference;
    s.reference_spp = a.reference_spp.unwrap_or(s.reference_spp);
    s.max_spp = a.max_spp.unwrap_or(s.max_spp);
    s.width = a.width.unwrap_or(s.width);
    s.seed = a.seed;
    s.firefly_k = a.firefly_k;
    s.only = a.only;
    s.progress = !a.quiet;
    let o = study::run(&s)?;
    if !a.quiet {
        eprintln!(
            "{}: {} configurations, {} rows ({} rendered now), reference {} at {} spp",
            o.report.display(),
            o.configs.len(),
            o.rows.len(),
            o.rendered_rows,
            study::config::integrator_name(o.reference.integrator),
            o.reference.spp
        );
    }
    Ok(())
}

#[derive(clap::Args)]
struct BenchArgs {
    /// Output directory for bench.csv, report.txt and the plots.
    #[arg(short, long, default_value = "bench")]
    output: PathBuf,
    /// Sizes up to 80k triangles, 16k rays, short timing: under a minute.
    #[arg(long)]
    quick: bool,
    /// Triangle counts, comma separated (1k, 16k, 1.3M; each becomes the
    /// displaced sphere of 20·4^level triangles nearest to it).
    #[arg(long, value_delimiter = ',', value_parser = lucent::tools::bench::parse_size)]
    sizes: Vec<usize>,
    /// Thread counts, comma separated (default: 1 and all cores).
    #[arg(long, value_delimiter = ',', value_parser = lucent::tools::bench::parse_threads)]
    threads: Vec<usize>,
    /// Rays per query set (default 500000, quick 16384).
    #[arg(long, value_parser = lucent::tools::bench::parse_rays)]
    rays: Option<usize>,
    /// Backends to measure: bvh | embree (the best available) | embree3 |
    /// embree4 | both (every backend available; the default).
    #[arg(long, value_enum)]
    accel: Option<BenchAccelArg>,
    /// Render this scene, record its ray queries and replay them on the bare
    /// backend: end-to-end against raw ray rate (instead of the meshes).
    #[arg(long, conflicts_with_all = ["quick", "sizes", "rays"])]
    scene: Option<PathBuf>,
    /// Samples per pixel of the scene's renders (with --scene; default 2).
    #[arg(long, requires = "scene")]
    spp: Option<u32>,
    /// No progress bar.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchAccelArg {
    Bvh,
    Embree,
    Embree3,
    Embree4,
    Both,
}

/// The backends `--accel` asks for, each concrete (`embree` resolved); one
/// this process lacks is bad input, with why and how to get it.
fn bench_backends(a: Option<BenchAccelArg>) -> Result<Vec<Backend>, Error> {
    let want = match a {
        None | Some(BenchAccelArg::Both) => return Ok(lucent::tools::bench::available_backends()),
        Some(BenchAccelArg::Bvh) => Backend::Bvh,
        Some(BenchAccelArg::Embree) => Backend::Embree,
        Some(BenchAccelArg::Embree3) => Backend::Embree3,
        Some(BenchAccelArg::Embree4) => Backend::Embree4,
    };
    Ok(vec![want.resolve()?])
}

fn run_bench(a: BenchArgs) -> Result<(), Error> {
    use lucent::tools::bench;
    let backends = bench_backends(a.accel)?;
    if let Some(scene) = &a.scene {
        let mut s = bench::replay::Settings::new(scene, &a.output);
        s.spp = a.spp.unwrap_or(s.spp);
        if !a.threads.is_empty() {
            s.threads = a.threads;
        }
        s.backends = backends;
        s.progress = !a.quiet;
        let o = bench::replay::run(&s)?;
        print!("{}", o.report);
        if !a.quiet {
            eprintln!("{} rows in {}", o.rows.len(), o.csv.display());
        }
        return Ok(());
    }
    let mut s = bench::Settings::new(&a.output, a.quick);
    s.backends = backends;
    if !a.sizes.is_empty() {
        s.sizes = a.sizes;
    }
    if !a.threads.is_empty() {
        s.threads = a.threads;
    }
    s.rays = a.rays.unwrap_or(s.rays);
    s.progress = !a.quiet;
    let o = bench::run(&s)?;
    print!("{}", o.report);
    if !a.quiet {
        eprintln!(
            "{} rows in {}; plots: {}",
            o.rows.len(),
            o.csv.display(),
            o.plots
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

fn info() -> String {
    let names: Vec<&str> = Backend::all_available().iter().map(|b| b.name()).collect();
    let mut s = format!(
        "lucent {}\nbackends: {}",
        env!("CARGO_PKG_VERSION"),
        names.join(", ")
    );
    for line in accel::embree_report() {
        s.push('\n');
        s.push_str(&line);
    }
    let default = Backend::default_available();
    s.push_str(&format!("\ndefault backend: {}", default.name()));
    if let Ok(b) = default.resolve() {
        if b != default {
            s.push_str(&format!(" ({})", b.name()));
        }
    }
    s.push_str(if cfg!(feature = "subsurface") {
        "\nsubsurface: yes"
    } else {
        "\nsubsurface: no (built without the `subsurface` feature)"
    });
    s
}
