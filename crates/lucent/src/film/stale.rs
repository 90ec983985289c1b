//! Temporaries a killed process left beside an output. An output is
//! written to `.NAME.PID.tmp` and renamed into place
//! ([`super::Staged`]); a file it replaces waits as `.NAME.PID.old.tmp`
//! until every rename of the command succeeded. A process that handles a
//! signal removes both ([`crate::interrupt`]), but SIGKILL (the OOM
//! killer, a scheduler's hard limit) cannot be handled: whatever it was
//! writing stays. The next command that writes the same output removes
//! them, so a killed and resumed render leaves nothing behind.
//!
//! A temporary is stale when the process its name records no longer runs
//! on this machine (`/proc/PID` is gone; elsewhere than Linux, none is
//! treated as stale and nothing is removed). A live process, even one that
//! reused the PID, keeps its files. A stale `.old.tmp` is the previous
//! output, set aside by a commit that never finished: it goes back under
//! its name when nothing is there, and is removed otherwise.
//!
//! The PIDs are this machine's: two machines that write the same output
//! path on a shared file system at once are already racing for it, and
//! this does not make that safe.

use std::fs;
use std::path::Path;

/// Removes (or, for a set-aside previous output with nothing under its
/// name, restores) the temporaries of `path` that processes no longer
/// running left. Best effort: what cannot be read or removed stays.
pub fn clean(path: &Path) {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return;
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some((pid, set_aside)) = file.to_str().and_then(|f| parse(f, &prefix)) else {
            continue;
        };
        if pid == std::process::id() || runs(pid) {
            continue;
        }
        let stale = entry.path();
        if set_aside && fs::symlink_metadata(path).is_err() {
            let _ = fs::rename(&stale, path);
        } else {
            let _ = fs::remove_file(&stale);
        }
    }
}

/// The PID in `.NAME.PID.tmp` or `.NAME.PID.old.tmp` (prefix `.NAME.`),
/// and whether it is the set-aside form.
fn parse(file: &str, prefix: &str) -> Option<(u32, bool)> {
    let rest = file.strip_prefix(prefix)?;
    let (pid, set_aside) = match rest.strip_suffix(".old.tmp") {
        Some(pid) => (pid, true),
        None => (rest.strip_suffix(".tmp")?, false),
    };
    if pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((pid.parse().ok()?, set_aside))
}

/// Whether process `pid` runs on this machine.
fn runs(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PID no process has: a child that has finished and been reaped.
    fn dead_pid() -> u32 {
        let mut c = std::process::Command::new("true").spawn().unwrap();
        let pid = c.id();
        c.wait().unwrap();
        assert!(!runs(pid), "pid {pid} was reused at once");
        pid
    }

    #[test]
    fn names_are_read_strictly() {
        let p = ".a.exr.";
        assert_eq!(parse(".a.exr.123.tmp", p), Some((123, false)));
        assert_eq!(parse(".a.exr.123.old.tmp", p), Some((123, true)));
        // another output's temporaries, and names that only look alike
        for f in [
            ".a.exr.5.exr.123.tmp",
            ".a.exr..tmp",
            ".a.exr.12a.tmp",
            ".a.exr.+12.tmp",
            ".a.exr.123",
            ".b.exr.123.tmp",
            "a.exr.123.tmp",
        ] {
            assert_eq!(parse(f, p), None, "{f}");
        }
    }

    #[test]
    fn a_dead_process_leaves_nothing_a_live_one_keeps_its_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let out = d.join("a.exr");
        let dead = dead_pid();
        let me = std::process::id();
        let write = |n: String| fs::write(d.join(n), b"x").unwrap();
        write(format!(".a.exr.{dead}.tmp"));
        write(format!(".a.exr.{me}.tmp"));
        // PID 1 runs as long as the machine (or container) does
        write(".a.exr.1.tmp".into());
        write(format!(".b.exr.{dead}.tmp"));
        fs::write(&out, b"current").unwrap();
        write(format!(".a.exr.{dead}.old.tmp"));
        clean(&out);
        let mut left: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        left.sort();
        let mut want = vec![
            format!(".a.exr.{me}.tmp"),
            ".a.exr.1.tmp".to_string(),
            format!(".b.exr.{dead}.tmp"),
            "a.exr".to_string(),
        ];
        want.sort();
        assert_eq!(left, want);
        assert_eq!(fs::read(&out).unwrap(), b"current");
    }

    #[test]
    fn a_previous_output_set_aside_by_a_killed_commit_is_put_back() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a.exr");
        let dead = dead_pid();
        fs::write(
            dir.path().join(format!(".a.exr.{dead}.old.tmp")),
            b"previous",
        )
        .unwrap();
        clean(&out);
        assert_eq!(fs::read(&out).unwrap(), b"previous");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
