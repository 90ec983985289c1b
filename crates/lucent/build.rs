//! Links Embree 3 when the `embree` feature is on (the default).
//!
//! Whether lucent has the Embree backend is the feature's choice alone; this
//! script only finds where Embree is: in `EMBREE_DIR` if that is set (a
//! prefix with `include/embree3/rtcore.h` and `lib/libembree3.so`, the only
//! place looked at then), else with `pkg-config embree3`, else in the
//! standard Debian locations. Not found is a build error that says what to
//! install. Without the feature (`--no-default-features`) it does nothing
//! and lucent has only its own BVH. Embree 4 (the `embree4` feature) needs
//! nothing here: it is opened at run time (crates/lucent/src/accel/embree4/load.rs).

use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Where Embree was found: the directory holding `embree3/rtcore.h` and the
/// directory holding `libembree3.so`.
struct Embree {
    include: PathBuf,
    lib: PathBuf,
}

const LIB_NAMES: [&str; 2] = ["libembree3.so", "libembree3.dylib"];

fn has_header(include: &Path) -> bool {
    include.join("embree3").join("rtcore.h").is_file()
}

fn has_lib(lib: &Path) -> bool {
    LIB_NAMES.iter().any(|n| lib.join(n).exists())
}

/// `EMBREE_DIR` names the one place to look: a prefix that lacks Embree is
/// an error, not a reason to look elsewhere.
fn from_embree_dir(dir: &Path) -> Result<Embree, String> {
    let include = dir.join("include");
    let lib = [
        "lib",
        "lib64",
        "lib/x86_64-linux-gnu",
        "lib/aarch64-linux-gnu",
    ]
    .iter()
    .map(|l| dir.join(l))
    .find(|l| has_lib(l));
    match lib {
        Some(lib) if has_header(&include) => Ok(Embree { include, lib }),
        _ => Err(format!(
            "EMBREE_DIR={} has no include/embree3/rtcore.h with lib/libembree3.so",
            dir.display()
        )),
    }
}

/// Runs `pkg-config embree3` and keeps the first -I / -L paths that hold the
/// header and the library. pkg-config is optional: a missing binary or
/// package is not an error.
fn from_pkg_config() -> Option<Embree> {
    let out = Command::new("pkg-config")
        .args(["--cflags", "--libs", "embree3"])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8(out.stdout).ok()?;
    let mut include = None;
    let mut lib = None;
    for tok in text.split_whitespace() {
        if let Some(p) = tok.strip_prefix("-I") {
            // The .pc file may name either the prefix/include dir or include/embree3.
            let p = PathBuf::from(p);
            let cand = if p.ends_with("embree3") {
                p.parent().map(Path::to_path_buf).unwrap_or(p)
            } else {
                p
            };
            if include.is_none() && has_header(&cand) {
                include = Some(cand);
            }
        } else if let Some(p) = tok.strip_prefix("-L") {
            let p = PathBuf::from(p);
            if lib.is_none() && has_lib(&p) {
                lib = Some(p);
            }
        }
    }
    // A .pc file without -I/-L means the compiler's default paths.
    let include =
        include.or_else(|| Some(PathBuf::from("/usr/include")).filter(|p| has_header(p)))?;
    let lib = lib.or_else(default_lib_dir)?;
    Some(Embree { include, lib })
}

fn default_lib_dir() -> Option<PathBuf> {
    [
        "/usr/lib/x86_64-linux-gnu",
        "/usr/lib/aarch64-linux-gnu",
        "/usr/lib",
        "/usr/local/lib",
    ]
    .iter()
    .map(PathBuf::from)
    .find(|p| has_lib(p))
}

fn from_standard_paths() -> Option<Embree> {
    let include = ["/usr/include", "/usr/local/include"]
        .iter()
        .map(PathBuf::from)
        .find(|p| has_header(p))?;
    Some(Embree {
        include,
        lib: default_lib_dir()?,
    })
}

/// The build's identity for the frames' `lucent/build` attribute
/// (`LUCENT_BUILD_ID`): the crate version, the git commit, and for a tree
/// with uncommitted changes a hash of its diff, so that two development
/// builds of one commit are told apart; the profile (`release`, `debug`).
/// Without git, the version and profile alone.
fn build_id() -> String {
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| o.stdout)
    };
    let version = env::var("CARGO_PKG_VERSION").unwrap_or_default();
    let profile = env::var("PROFILE").unwrap_or_default();
    let Some(commit) = git(&["rev-parse", "--short=12", "HEAD"]) else {
        return format!("{version} ({profile})");
    };
    let commit = String::from_utf8_lossy(&commit).trim().to_string();
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        let dir = PathBuf::from(String::from_utf8_lossy(&dir).trim());
        for f in ["HEAD", "index"] {
            println!("cargo::rerun-if-changed={}", dir.join(f).display());
        }
    }
    println!("cargo::rerun-if-changed=src");
    let diff = git(&["diff", "HEAD"]).unwrap_or_default();
    if diff.is_empty() {
        return format!("{version} {commit} ({profile})");
    }
    // FNV-1a: stable across Rust versions, unlike std's hashers
    let h = diff.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{version} {commit}+dirty.{h:016x} ({profile})")
}

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-env=LUCENT_BUILD_ID={}", build_id());
    // The feature decides whether lucent has the Embree backend; nothing on
    // the build machine does.
    if env::var_os("CARGO_FEATURE_EMBREE").is_none() {
        return;
    }
    println!("cargo::rerun-if-env-changed=EMBREE_DIR");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_PATH");

    let found = match env::var_os("EMBREE_DIR") {
        Some(dir) => from_embree_dir(Path::new(&dir)),
        None => from_pkg_config()
            .or_else(from_standard_paths)
            .ok_or_else(|| {
                "Embree 3 was found neither by `pkg-config embree3` nor in /usr/include and \
                 /usr/lib"
                    .to_string()
            }),
    };
    match found {
        Ok(e) => {
            // Rebuild if the installed Embree changes (upgraded or replaced).
            println!(
                "cargo::rerun-if-changed={}",
                e.include.join("embree3/rtcore_config.h").display()
            );
            println!("cargo::rustc-link-search=native={}", e.lib.display());
            println!("cargo::rustc-link-lib=dylib=embree3");
            println!(
                "cargo::rustc-env=LUCENT_EMBREE_INCLUDE={}",
                e.include.display()
            );
        }
        Err(why) => {
            // A failed build script is rerun by the next build, so installing
            // Embree and building again is enough.
            println!(
                "cargo::error=the `embree` feature (on by default) needs Embree 3, but {why}. \
                 Install it (Debian 12: `apt-get install -y --no-install-recommends \
                 libembree-dev`, or scripts/install-deps.sh), or set EMBREE_DIR to an Embree 3 \
                 prefix, or build the BVH-only renderer with `cargo build --no-default-features`."
            );
        }
    }
}
