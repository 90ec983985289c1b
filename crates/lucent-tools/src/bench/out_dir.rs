//! The benchmark's output directory: checked before anything is measured,
//! created only when the results are written, and removed again if it was
//! created for results that then could not be written — so a benchmark
//! that fails (an error while measuring, a signal, a full disk) leaves the
//! file system as it was, not an empty or half-filled directory.

use std::path::{Path, PathBuf};

use lucent::Error;

/// Fails (as bad input) when `out` cannot become a directory: it is a
/// file, or its nearest existing ancestor is not a directory.
pub(super) fn check(out: &Path) -> Result<(), Error> {
    let bad = |what: &Path, problem: &str| {
        Err(Error::Input(format!(
            "output directory {}: {} {problem}",
            out.display(),
            what.display()
        )))
    };
    for p in out.ancestors().filter(|p| !p.as_os_str().is_empty()) {
        if let Ok(meta) = std::fs::metadata(p) {
            if !meta.is_dir() {
                return bad(p, "exists and is not a directory");
            }
            return Ok(());
        }
    }
    Ok(())
}

/// The output directory being written: [`create`] made it (and its missing
/// parents, the first of which is `created`) or found it.
pub(super) struct OutDir {
    created: Option<PathBuf>,
}

/// Creates `out` (with its parents) for writing the results.
pub(super) fn create(out: &Path) -> Result<OutDir, Error> {
    let created = out
        .ancestors()
        .filter(|p| !p.as_os_str().is_empty() && !p.exists())
        .last()
        .map(Path::to_path_buf);
    std::fs::create_dir_all(out).map_err(|e| Error::Runtime(format!("{}: {e}", out.display())))?;
    Ok(OutDir { created })
}

impl OutDir {
    /// Passes `result` through; on an error, removes what [`create`] made.
    pub(super) fn finish<T>(self, result: Result<T, Error>) -> Result<T, Error> {
        if result.is_err() {
            if let Some(dir) = &self.created {
                let _ = std::fs::remove_dir_all(dir);
            }
        }
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_created_for_results_that_fail_is_removed() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("a/b");
        check(&out).unwrap();
        let d = create(&out).unwrap();
        std::fs::write(out.join("bench.csv"), b"x").unwrap();
        let r: Result<(), Error> = d.finish(Err(Error::Runtime("disk full".into())));
        assert!(r.is_err());
        assert!(!tmp.path().join("a").exists());
        // one that existed stays, and a success keeps what it wrote
        std::fs::create_dir(tmp.path().join("c")).unwrap();
        let d = create(&tmp.path().join("c")).unwrap();
        let _ = d.finish::<()>(Err(Error::Runtime("x".into())));
        assert!(tmp.path().join("c").is_dir());
        let d = create(&out).unwrap();
        d.finish(Ok(())).unwrap();
        assert!(out.is_dir());
        // a file in the way is refused before anything runs
        std::fs::write(tmp.path().join("f"), b"").unwrap();
        let e = check(&tmp.path().join("f/out")).unwrap_err();
        assert!(
            e.is_input() && e.to_string().contains("not a directory"),
            "{e}"
        );
    }
}
