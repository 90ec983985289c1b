//! `lucent study` on the command line: its arguments and their run.

use std::io::Write as _;
use std::path::PathBuf;

use lucent::integrator::IntegratorKind;
use lucent::Error;

/// `lucent study`'s arguments.
// The fields' docs are the --help text, not HTML.
#[allow(rustdoc::invalid_html_tags)]
#[derive(clap::Args)]
pub struct StudyArgs {
    /// The scene description (TOML; needs a subsurface material).
    scene: PathBuf,
    /// Output directory (created; default: study-<scene name>).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Small images, few configurations, short ladders: under two minutes.
    #[arg(long)]
    quick: bool,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = crate::bench::parse_threads)]
    threads: Option<usize>,
    /// Integrator of the reference render: diffusion | randomwalk.
    #[arg(long, default_value = "diffusion", value_parser = parse_study_integrator)]
    reference: IntegratorKind,
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
    /// variance, sampler, denoise); the baseline always runs.
    #[arg(long, value_delimiter = ',', value_parser = parse_study_axis)]
    only: Vec<super::Axis>,
    /// No progress bars.
    #[arg(short, long)]
    quiet: bool,
}

/// A value of `lucent study`'s arguments that clap cannot take (clap shows
/// the message after the argument's name).
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum ArgError {
    /// `--reference` is not an integrator a study can use.
    #[error("expected diffusion or randomwalk, found \"{0}\"")]
    Integrator(String),
    /// An `--only` value is not an axis of the matrix.
    #[error("unknown axis \"{0}\"")]
    Axis(String),
}

fn parse_study_integrator(s: &str) -> Result<IntegratorKind, ArgError> {
    super::config::parse_integrator(s).ok_or_else(|| ArgError::Integrator(s.to_string()))
}

fn parse_study_axis(s: &str) -> Result<super::Axis, ArgError> {
    super::Axis::parse(s).ok_or_else(|| ArgError::Axis(s.to_string()))
}

/// Runs the study `a` asks for and says where its report is (unless
/// `--quiet`).
pub fn run_study(a: StudyArgs) -> Result<(), Error> {
    let out = a.output.clone().unwrap_or_else(|| {
        let stem = a
            .scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        PathBuf::from(format!("study-{stem}"))
    });
    let mut s = super::Settings::new(&a.scene, out, a.quick);
    s.threads = a.threads;
    s.reference = a.reference;
    s.reference_spp = a.reference_spp.unwrap_or(s.reference_spp);
    s.max_spp = a.max_spp.unwrap_or(s.max_spp);
    s.width = a.width.unwrap_or(s.width);
    s.seed = a.seed;
    s.firefly_k = a.firefly_k;
    s.only = a.only;
    s.progress = !a.quiet;
    let o = super::run(&s)?;
    if let Some(why) = &o.no_denoise {
        let _ = writeln!(
            std::io::stderr(),
            "no denoised curve: Open Image Denoise is unavailable ({why})"
        );
    }
    if !a.quiet {
        let _ = writeln!(
            std::io::stderr(),
            "{}: {} configurations, {} rows ({} rendered now), reference {} at {} spp",
            o.report.display(),
            o.configs.len(),
            o.rows.len(),
            o.rendered_rows,
            super::config::integrator_name(o.reference.integrator),
            o.reference.spp
        );
    }
    Ok(())
}
