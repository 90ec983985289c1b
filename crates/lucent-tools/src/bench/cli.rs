//! `lucent bench` on the command line: its arguments and their run.

use std::io::Write as _;
use std::path::PathBuf;

use lucent::accel::Backend;
use lucent::Error;

/// `lucent bench`'s arguments.
#[derive(clap::Args)]
pub struct BenchArgs {
    /// Output directory for bench.csv, report.txt and the plots.
    #[arg(short, long, default_value = "bench")]
    output: PathBuf,
    /// Sizes up to 80k triangles, 16k rays, short timing: under a minute.
    #[arg(long)]
    quick: bool,
    /// Triangle counts, comma separated (1k, 16k, 1.3M; each becomes the
    /// displaced sphere of 20·4^level triangles nearest to it).
    #[arg(long, value_delimiter = ',', value_parser = super::parse_size)]
    sizes: Vec<usize>,
    /// Thread counts, comma separated (default: 1 and all cores).
    #[arg(long, value_delimiter = ',', value_parser = super::parse_threads)]
    threads: Vec<usize>,
    /// Rays per query set (default 500000, quick 16384).
    #[arg(long, value_parser = super::parse_rays)]
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

#[derive(Clone, Copy, clap::ValueEnum)]
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
        None | Some(BenchAccelArg::Both) => return Ok(super::available_backends()),
        Some(BenchAccelArg::Bvh) => Backend::Bvh,
        Some(BenchAccelArg::Embree) => Backend::Embree,
        Some(BenchAccelArg::Embree3) => Backend::Embree3,
        Some(BenchAccelArg::Embree4) => Backend::Embree4,
    };
    Ok(vec![want.resolve()?])
}

/// Runs the benchmark `a` asks for and prints its report.
pub fn run_bench(a: BenchArgs) -> Result<(), Error> {
    let backends = bench_backends(a.accel)?;
    if let Some(scene) = &a.scene {
        let mut s = super::replay::Settings::new(scene, &a.output);
        s.spp = a.spp.unwrap_or(s.spp);
        if !a.threads.is_empty() {
            s.threads = a.threads;
        }
        s.backends = backends;
        s.progress = !a.quiet;
        let o = super::replay::run(&s)?;
        let _ = write!(std::io::stdout(), "{}", o.report);
        if !a.quiet {
            let _ = writeln!(
                std::io::stderr(),
                "{} rows in {}",
                o.rows.len(),
                o.csv.display()
            );
        }
        return Ok(());
    }
    let mut s = super::Settings::new(&a.output, a.quick);
    s.backends = backends;
    if !a.sizes.is_empty() {
        s.sizes = a.sizes;
    }
    if !a.threads.is_empty() {
        s.threads = a.threads;
    }
    s.rays = a.rays.unwrap_or(s.rays);
    s.progress = !a.quiet;
    let o = super::run(&s)?;
    let _ = write!(std::io::stdout(), "{}", o.report);
    if !a.quiet {
        let _ = writeln!(
            std::io::stderr(),
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
