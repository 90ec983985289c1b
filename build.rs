//! Finds Embree 3 and, if present, links it and enables `cfg(lucent_embree)`.
//!
//! Lookup order: `EMBREE_DIR` (a prefix with `include/embree3/rtcore.h` and
//! `lib/libembree3.so`), then `pkg-config embree3`, then the standard Debian
//! locations. Without Embree (or with `LUCENT_NO_EMBREE=1`) lucent still
//! builds, with only its own BVH.

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

fn from_embree_dir() -> Option<Embree> {
    let dir = PathBuf::from(env::var_os("EMBREE_DIR")?);
    let include = dir.join("include");
    let lib = ["lib", "lib64", "lib/x86_64-linux-gnu"]
        .iter()
        .map(|l| dir.join(l))
        .find(|l| has_lib(l));
    match lib {
        Some(lib) if has_header(&include) => Some(Embree { include, lib }),
        _ => {
            println!(
                "cargo::warning=EMBREE_DIR={} has no include/embree3/rtcore.h with \
                 lib/libembree3.so; looking elsewhere",
                dir.display()
            );
            None
        }
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

fn main() {
    println!("cargo::rustc-check-cfg=cfg(lucent_embree)");
    println!("cargo::rerun-if-env-changed=EMBREE_DIR");
    println!("cargo::rerun-if-env-changed=LUCENT_NO_EMBREE");
    println!("cargo::rerun-if-env-changed=PKG_CONFIG_PATH");
    println!("cargo::rerun-if-changed=build.rs");
    // Cargo only reruns this script for the paths named here, so installing
    // or removing Embree with apt would go unnoticed; dpkg's status file
    // changes on every package operation (named only if it exists, since a
    // missing path would make Cargo rerun the script on every build).
    if Path::new("/var/lib/dpkg/status").is_file() {
        println!("cargo::rerun-if-changed=/var/lib/dpkg/status");
    }

    // Forces a BVH-only build even where Embree is installed, so CI can
    // check that configuration compiles and passes too.
    if env::var_os("LUCENT_NO_EMBREE").is_some_and(|v| !v.is_empty() && v != "0") {
        println!("cargo::warning=LUCENT_NO_EMBREE is set: lucent is built with its own BVH only.");
        return;
    }

    match from_embree_dir()
        .or_else(from_pkg_config)
        .or_else(from_standard_paths)
    {
        Some(e) => {
            // Rebuild if the installed Embree changes (upgraded or replaced).
            println!(
                "cargo::rerun-if-changed={}",
                e.include.join("embree3/rtcore_config.h").display()
            );
            println!("cargo::rustc-link-search=native={}", e.lib.display());
            println!("cargo::rustc-link-lib=dylib=embree3");
            println!("cargo::rustc-cfg=lucent_embree");
            println!(
                "cargo::rustc-env=LUCENT_EMBREE_INCLUDE={}",
                e.include.display()
            );
        }
        None => {
            println!(
                "cargo::warning=Embree 3 not found: lucent is built with its own BVH only. \
                 To enable the Embree backend install it (Debian/Ubuntu: \
                 `apt-get install -y --no-install-recommends libembree-dev`) or set \
                 EMBREE_DIR to an Embree 3 prefix, then rebuild (`touch build.rs` if Cargo does \
                 not notice)."
            );
        }
    }
}
