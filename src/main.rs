//! The `lucent` command line: parses arguments, calls the library, and maps
//! errors to exit codes in one place, [`exit_code`] (2: bad input —
//! arguments, scene, meshes; 1: a failure while running or writing output).

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use lucent::accel::{self, Backend};
use lucent::film::exr_layers::Preview;
use lucent::film::passes::PassSet;
use lucent::film::ToneMap;
use lucent::integrator::{effects, plan, IntegratorKind};
#[cfg(feature = "subsurface")]
use lucent::materials::{EstimatorOptions, OPTIONS};
use lucent::render::RenderOptions;
use lucent::sampling::SamplerKind;
use lucent::scene;
use lucent::session;
use lucent::Error;

mod args;
mod denoise;
mod values;
use args::{FileArgs, FrameDenoiseArgs, SplitArgs};
use values::parse_aov;

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

#[derive(Clone, Copy, ValueEnum)]
enum ToneMapArg {
    /// Clip each channel to [0, 1].
    Clamp,
    /// The ACES filmic curve fit of Narkowicz (2015): a soft shoulder so
    /// bright lights keep detail instead of clipping.
    Filmic,
}

impl From<ToneMapArg> for ToneMap {
    fn from(t: ToneMapArg) -> ToneMap {
        match t {
            ToneMapArg::Clamp => ToneMap::Clamp,
            ToneMapArg::Filmic => ToneMap::Filmic,
        }
    }
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
        #[arg(long, value_parser = lucent_tools::bench::parse_threads)]
        threads: Option<usize>,
        /// Random seed (default: the scene's `render.seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Sampler: sobol (Owen-scrambled Sobol' points) | random
        /// (pseudo-random stream) (default: the scene's `render.sampler`,
        /// else sobol).
        #[arg(long, value_parser = parse_sampler)]
        sampler: Option<SamplerKind>,
        /// Ray-query backend: embree (the best available: embree4, else
        /// embree3), embree3, embree4 or bvh (default: embree if any is
        /// available, else bvh).
        #[arg(long, value_enum)]
        accel: Option<AccelArg>,
        /// Tone map of the PNG preview (the EXR is always linear).
        #[arg(long, value_enum, default_value = "filmic")]
        tonemap: ToneMapArg,
        /// Exposure of the PNG preview in stops.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = exposure_stops)]
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
        denoise: FrameDenoiseArgs,
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
        tonemap: ToneMapArg,
        /// Exposure of the PNG preview in stops.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = exposure_stops)]
        exposure: f32,
        /// No summary line.
        #[arg(short, long)]
        quiet: bool,
        /// Merge parts rendered on different ray-query backends (they
        /// answer alike; the frame's `lucent/backend` then names each).
        /// Without it such parts are refused.
        #[arg(long)]
        mixed_backends: bool,
        #[command(flatten)]
        denoise: FrameDenoiseArgs,
        /// The denoiser's threads, 1 to 1024 (default: all cores).
        #[arg(long, value_parser = lucent_tools::bench::parse_threads)]
        threads: Option<usize>,
    },
    /// Denoise a finished frame (a render or a merge) with Open Image
    /// Denoise from its own beauty, albedo and N layers: the frame is
    /// written with the layer `denoised` added, and the PNG preview from
    /// it (docs/output.md, "Denoising").
    Denoise(denoise::DenoiseArgs),
    /// Paste a region render (`render --region`) into a frame: only the
    /// region's pixels change, bit for bit, in every channel; the frame's
    /// header and storage stay. The files must have the same display
    /// window and channels. Writes the EXR and its PNG preview.
    Paste {
        /// The region render.
        region: PathBuf,
        /// The frame it goes into.
        frame: PathBuf,
        /// Output OpenEXR path; the preview goes to the same path with `.png`.
        #[arg(short, long)]
        output: PathBuf,
        /// Tone map of the PNG preview (the EXR is always linear).
        #[arg(long, value_enum, default_value = "filmic")]
        tonemap: ToneMapArg,
        /// Exposure of the PNG preview in stops.
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = exposure_stops)]
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
    Bench(lucent_tools::bench::cli::BenchArgs),
    /// Print the build's ray-query backends and versions.
    Info,
    /// Measure error against time for every sampling choice of the
    /// subsurface estimator: results.csv, plots and report.md in the output
    /// directory (resumes from results.csv; see src/tools/study/mod.rs).
    #[cfg(feature = "subsurface")]
    Study(lucent_tools::study::cli::StudyArgs),
}

/// The subsurface sampling options, one flag per row of the option table
/// (`lucent::materials::estimator_options`); each replaces every
/// subsurface material's own.
#[cfg(feature = "subsurface")]
#[derive(Clone, Debug, Default)]
struct SubsurfaceArgs(session::Overrides);

#[cfg(feature = "subsurface")]
impl clap::FromArgMatches for SubsurfaceArgs {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut given = session::Overrides::default();
        for row in OPTIONS.iter().filter(|o| o.flag) {
            if let Some(v) = m.get_one::<String>(row.name) {
                given
                    .push(row, v)
                    .map_err(|e| clap::Error::raw(clap::error::ErrorKind::ValueValidation, e))?;
            }
        }
        Ok(SubsurfaceArgs(given))
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

#[cfg(feature = "subsurface")]
impl clap::Args for SubsurfaceArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        OPTIONS.iter().filter(|o| o.flag).fold(cmd, |cmd, row| {
            // clap keeps flag names for the program's life
            let long: &'static str = Box::leak(row.flag_name().into_boxed_str());
            cmd.arg(
                clap::Arg::new(row.name)
                    .long(long)
                    .help(row.help())
                    .value_parser(move |s: &str| {
                        (row.set)(&mut EstimatorOptions::default(), s).map(|()| s.to_string())
                    }),
            )
        })
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

#[cfg(feature = "subsurface")]
impl SubsurfaceArgs {
    fn overrides(&self) -> session::Overrides {
        self.0.clone()
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ExplainArg {
    Text,
    Json,
}

/// A build without the `subsurface` feature has no subsurface materials,
/// and so no options that override them.
#[cfg(not(feature = "subsurface"))]
#[derive(clap::Args)]
struct SubsurfaceArgs {}

#[cfg(not(feature = "subsurface"))]
impl SubsurfaceArgs {
    fn overrides(&self) -> session::Overrides {
        session::Overrides
    }
}

mod out_of_memory;

#[global_allocator]
static ALLOCATOR: out_of_memory::ReportingAllocator = out_of_memory::ReportingAllocator;

/// `println!` that never panics: a closed stdout (`lucent info | head -0`,
/// a closed descriptor) drops the text, and the command ends with its own
/// exit status (docs/output.md, "Closed output streams").
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

/// `eprintln!` that never panics: a closed stderr drops the message, and
/// the exit status still says how the command ended.
macro_rules! tell {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($t)*);
    }};
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Err(e) = lucent::interrupt::install() {
        tell!("warning: cannot catch SIGINT/SIGTERM/SIGHUP ({e}); an interrupted command may leave temporary files");
    }
    let result = match cli.command {
        Command::Render {
            scene,
            output,
            spp,
            threads,
            seed,
            sampler,
            accel,
            tonemap,
            exposure,
            quiet,
            integrator,
            aov,
            explain,
            stats,
            denoise,
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
                sampler,
                threads,
                progress: (!quiet).then(lucent_tools::progress::Bar::sink),
                integrator,
                stats,
            };
            if let Some(format) = explain {
                let run = |file| {
                    run_explain(
                        &scene,
                        (integrator, sampler),
                        aov,
                        &subsurface,
                        &file,
                        format,
                    )
                };
                return finish(file.settings().and_then(run));
            }
            file.settings().and_then(|file| {
                let r = session::Request {
                    scene,
                    output,
                    backend,
                    opts,
                    aov,
                    overrides: subsurface.overrides(),
                    file,
                    split: split.into(),
                    preview: Preview {
                        tonemap: tonemap.into(),
                        exposure,
                    },
                    denoise: denoise.options(threads),
                };
                run_render(&r, quiet)
            })
        }
        Command::Merge {
            parts,
            output,
            tonemap,
            exposure,
            quiet,
            mixed_backends,
            denoise,
            threads,
        } => {
            let preview = Preview {
                tonemap: tonemap.into(),
                exposure,
            };
            let d = denoise.options(threads);
            session::merge_parts(&parts, &output, preview, mixed_backends, d.as_ref()).map(|m| {
                if !quiet {
                    tell!("{}", m.summary(&output));
                }
            })
        }
        Command::Denoise(args) => denoise::run(args),
        Command::Paste {
            region,
            frame,
            output,
            tonemap,
            exposure,
            quiet,
        } => {
            let preview = Preview {
                tonemap: tonemap.into(),
                exposure,
            };
            session::paste(&region, &frame, &output, preview).map(|p| {
                if !quiet {
                    tell!("{}", p.summary(&output));
                }
            })
        }
        #[cfg(feature = "subsurface")]
        Command::Study(args) => lucent_tools::study::cli::run_study(args),
        Command::Bench(args) => lucent_tools::bench::cli::run_bench(args),
        Command::Info => {
            say!("{}", session::build_info());
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
            tell!("error: {}", without_control_characters(&shown));
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

/// Renders `r` and says how it went (unless `quiet`).
fn run_render(r: &session::Request, quiet: bool) -> Result<(), Error> {
    // warned even with --quiet: the frame is not rendered where the user
    // pointed
    if let Some(w) = session::embree4_warning(r.backend) {
        eprintln!("{w}");
    }
    let o = session::run(r)?;
    // said even with --quiet: input the render did not use
    for note in &o.notes {
        eprintln!("note: {note}");
    }
    if !quiet {
        tell!("{}", o.summary(&r.output));
    }
    if r.opts.stats {
        let _ = write!(std::io::stderr(), "{}", effects::summary(&o.stats.counters));
        let (n, bytes) = o.textures;
        if n > 0 {
            eprintln!(
                "textures: {n}, {bytes} bytes with their MIP levels ({:.1} MiB)",
                bytes as f64 / (1u64 << 20) as f64
            );
        }
    }
    report_rejected_rays(o.rejected_rays);
    Ok(())
}

/// Prints the plan of rendering `scene_path` with these options (no
/// render, no file written): the scene's errors are those of a render.
fn run_explain(
    scene_path: &Path,
    (integrator, sampler): (IntegratorKind, Option<SamplerKind>),
    aov: Option<PassSet>,
    subsurface: &SubsurfaceArgs,
    file: &scene::OutputSettings,
    format: ExplainArg,
) -> Result<(), Error> {
    let mut scene = scene::load(scene_path)?;
    session::overrides::apply(&subsurface.overrides(), &mut scene)?;
    session::apply_film(&mut scene, file);
    let passes = aov.unwrap_or(scene.output.aovs);
    let sampler = sampler.unwrap_or(scene.settings.sampler);
    let plan = session::identity::render_plan(&scene, integrator, sampler, passes);
    match format {
        ExplainArg::Text => {
            let _ = write!(std::io::stdout(), "{}", plan::text::render(&plan));
        }
        ExplainArg::Json => say!("{}", plan.to_json_pretty()),
    }
    Ok(())
}

/// The largest `--exposure` in stops either way: 2^64 already turns any
/// pixel a render can hold white or black.
const MAX_EXPOSURE: f32 = 64.0;

/// Parses `--exposure`: a finite number of stops within ±[`MAX_EXPOSURE`].
fn exposure_stops(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|e| format!("{e}"))?;
    if !v.is_finite() || v.abs() > MAX_EXPOSURE {
        return Err(format!(
            "expected a finite number of stops from -{MAX_EXPOSURE} to {MAX_EXPOSURE}, found {s}"
        ));
    }
    Ok(v)
}

/// Parses `--sampler` by the names of [`SamplerKind`].
fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    SamplerKind::parse(s)
        .ok_or_else(|| format!("expected {}, found \"{s}\"", SamplerKind::expected()))
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

/// Says on stderr (even with `--quiet`: it means the image may be wrong)
/// how many ray queries the backend refused as out of range, if any.
fn report_rejected_rays(n: u64) {
    if n > 0 {
        tell!(
            "warning: {n} ray queries had a non-finite or out-of-range origin, direction or \
             interval (beyond ±{:e}) and were answered as misses; the image may be missing \
             light there (see \"Supported ranges\" in docs/scene-format.md)",
            accel::MAX_RAY_COMPONENT
        );
    }
}
