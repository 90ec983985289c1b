//! Temporaries a killed process left beside an output. An output is
//! written to `.lu<key>.<pid>.tmp` and renamed into place
//! ([`super::Staged`]); a file it replaces waits as `.lu<key>.<pid>.old.tmp`
//! until every rename of the command succeeded. `<key>` is `key`, eight
//! hex digits of the output's file name, so the names stay short whatever
//! the output's name. A process that handles a signal removes its
//! temporaries ([`crate::interrupt`]), but SIGKILL (the OOM killer, a
//! scheduler's hard limit) cannot be handled: whatever it was writing
//! stays. The next command that writes the same output removes it, so a
//! killed and resumed render leaves nothing behind.
//!
//! A temporary is stale when the process its name records no longer runs
//! on this machine (`/proc/PID` is gone; elsewhere than Linux, none is
//! treated as stale and nothing is removed). A live process, even one that
//! reused the PID, keeps its files. Only a regular file owned by this user
//! is removed: a symlink or another user's file under such a name was not
//! written by lucent for this user and is left alone. A set-aside
//! `.old.tmp` is never moved into place nor removed: a file planted under
//! that name would otherwise become the output; the previous output a
//! killed commit set aside stays there for the user to take back.
//!
//! The PIDs are this machine's: two machines that write the same output
//! path on a shared file system at once are already racing for it, and
//! this does not make that safe.

use std::fs;
use std::path::Path;

/// The key of an output's temporary names: FNV-1a (32 bits) of its file
/// name, as eight hex digits.
pub(crate) fn key(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.as_encoded_bytes())
        .unwrap_or_default();
    let h = name.iter().fold(0x811c_9dc5u32, |h, &b| {
        (h ^ b as u32).wrapping_mul(0x0100_0193)
    });
    format!("{h:08x}")
}

/// Removes the temporaries of `path` that processes no longer running
/// left (see the module docs for which). Best effort: what cannot be read
/// or removed stays.
pub fn clean(path: &Path) {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".lu{}.", key(path));
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some((pid, set_aside)) = file.to_str().and_then(|f| parse(f, &prefix)) else {
            continue;
        };
        if set_aside || pid == std::process::id() || runs(pid) {
            continue;
        }
        let stale = entry.path();
        if fs::symlink_metadata(&stale).is_ok_and(|m| ours(&m)) {
            let _ = fs::remove_file(&stale);
        }
    }
}

/// Whether `m` is a regular file (not a symlink) owned by this user.
fn ours(m: &fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        // SAFETY: getuid has no preconditions and cannot fail.
        let uid = unsafe { libc::getuid() };
        m.file_type().is_file() && m.uid() == uid
    }
    #[cfg(not(unix))]
    {
        m.file_type().is_file()
    }
}

/// The PID in `.lu<key>.PID.tmp` or `.lu<key>.PID.old.tmp` (prefix
/// `.lu<key>.`), and whether it is the set-aside form.
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
        let p = ".lu0000abcd.";
        assert_eq!(parse(".lu0000abcd.123.tmp", p), Some((123, false)));
        assert_eq!(parse(".lu0000abcd.123.old.tmp", p), Some((123, true)));
        // another output's temporaries, and names that only look alike
        for f in [
            ".lu0000abcd.5.exr.123.tmp",
            ".lu0000abcd..tmp",
            ".lu0000abcd.12a.tmp",
            ".lu0000abcd.+12.tmp",
            ".lu0000abcd.123",
            ".lu0000abce.123.tmp",
            "lu0000abcd.123.tmp",
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
        let (a, b) = (key(&out), key(Path::new("b.exr")));
        let write = |n: String| fs::write(d.join(n), b"x").unwrap();
        write(format!(".lu{a}.{dead}.tmp"));
        write(format!(".lu{a}.{me}.tmp"));
        // PID 1 runs as long as the machine (or container) does
        write(format!(".lu{a}.1.tmp"));
        write(format!(".lu{b}.{dead}.tmp"));
        fs::write(&out, b"current").unwrap();
        clean(&out);
        let mut left: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        left.sort();
        let mut want = vec![
            format!(".lu{a}.{me}.tmp"),
            format!(".lu{a}.1.tmp"),
            format!(".lu{b}.{dead}.tmp"),
            "a.exr".to_string(),
        ];
        want.sort();
        assert_eq!(left, want);
        assert_eq!(fs::read(&out).unwrap(), b"current");
    }

    /// The mistake: moving a planted `.old.tmp` into place (it would
    /// become the output), or following a planted symlink to remove its
    /// target's name.
    #[test]
    fn a_set_aside_file_is_never_moved_into_place_and_symlinks_stay() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a.exr");
        let (dead, a) = (dead_pid(), key(&out));
        let aside = dir.path().join(format!(".lu{a}.{dead}.old.tmp"));
        fs::write(&aside, b"planted").unwrap();
        let target = dir.path().join("target");
        fs::write(&target, b"keep").unwrap();
        let link = dir.path().join(format!(".lu{a}.{dead}.tmp"));
        std::os::unix::fs::symlink(&target, &link).unwrap();
        clean(&out);
        assert!(!out.exists());
        assert_eq!(fs::read(&aside).unwrap(), b"planted");
        assert!(fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&target).unwrap(), b"keep");
    }
}
