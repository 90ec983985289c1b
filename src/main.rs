//! The `lucent` command line: parses arguments, calls the library, and maps
//! errors to exit codes (2: bad input — arguments, scene, meshes; 1: a
//! failure while running or writing output).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use lucent::accel::{self, Backend};
use lucent::film::{self, ToneMap};
use lucent::render::{self, RenderOptions};
use lucent::scene;

#[derive(Parser)]
#[command(name = "lucent", version, about = "A path tracer for translucent materials")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum AccelArg {
    Embree,
    Bvh,
}

impl From<AccelArg> for Backend {
    fn from(a: AccelArg) -> Backend {
        match a {
            AccelArg::Embree => Backend::Embree,
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
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Random seed (default: the scene's `render.seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Ray-query backend (default: embree when built with it, else bvh).
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
    },
    /// Print the build's ray-query backends and versions.
    Info,
}

enum Failure {
    Input(String),
    Runtime(String),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render { scene, output, spp, threads, seed, accel, tonemap, exposure, quiet } => {
            let backend = accel.map(Backend::from).unwrap_or_else(Backend::default_available);
            let opts = RenderOptions { spp, seed, threads, progress: !quiet };
            run_render(&scene, &output, backend, &opts, tonemap, exposure, quiet)
        }
        Command::Info => {
            println!("{}", info());
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(Failure::Runtime(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
    }
}

fn run_render(
    scene_path: &Path,
    output: &Path,
    backend: Backend,
    opts: &RenderOptions,
    tonemap: ToneMap,
    exposure: f32,
    quiet: bool,
) -> Result<(), Failure> {
    if output.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()) != Some("exr".into()) {
        return Err(Failure::Input(format!("output {}: expected a path ending in .exr", output.display())));
    }
    let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(Failure::Input(format!("output directory {} does not exist", dir.display())));
    }
    if opts.spp == Some(0) {
        return Err(Failure::Input("--spp must be at least 1".into()));
    }
    if opts.threads == Some(0) {
        return Err(Failure::Input("--threads must be at least 1".into()));
    }
    let scene = scene::load(scene_path).map_err(|e| Failure::Input(e.to_string()))?;
    let accel = accel::build(&scene.meshes, backend).map_err(Failure::Input)?;
    let (film, stats) = render::render(&scene, accel.as_ref(), opts).map_err(Failure::Runtime)?;
    film.write_exr(output).map_err(Failure::Runtime)?;
    film.write_png(&film::preview_path(output), tonemap, exposure).map_err(Failure::Runtime)?;
    if !quiet {
        eprintln!(
            "{}: {}x{} at {} spp, {} triangles: {}",
            output.display(),
            film.width,
            film.height,
            opts.spp.unwrap_or(scene.settings.spp),
            scene.triangle_count(),
            stats.summary(accel.name())
        );
    }
    Ok(())
}

fn info() -> String {
    let mut s = format!("lucent {}\nbackends: bvh", env!("CARGO_PKG_VERSION"));
    #[cfg(lucent_embree)]
    s.push_str(&format!(", embree (Embree {})", accel::embree::version()));
    #[cfg(not(lucent_embree))]
    s.push_str(
        "\nbuilt without Embree: install it with `apt-get install -y --no-install-recommends \
         libembree-dev` and rebuild to enable --accel embree",
    );
    s.push_str(&format!("\ndefault backend: {}", Backend::default_available().name()));
    s
}
