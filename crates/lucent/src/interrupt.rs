//! Interruption by SIGINT, SIGTERM or SIGHUP (a closed terminal, a
//! scheduler's hang-up): a flag that long work polls, and a
//! registry of the temporary files that must not outlive the process
//! (`docs/farm.md`, "Interruption, checkpoints, resume").
//!
//! [`install`] (the CLI calls it first thing) starts a thread that waits for
//! the signals through `signal-hook`'s self-pipe. The **first** signal only
//! records itself ([`requested`]): the renderer stops between pixels, the CLI
//! commits only `OUT.partial.exr` ([`crate::film::commit_even_if_interrupted`];
//! [`crate::film::commit_all`] refuses once the flag is set) and exits with
//! [`exit_code`], 128 + the signal's number. A **second** signal exits at
//! once with the same code, after removing every temporary file still
//! registered ([`register_temporary`]). Without [`install`] nothing is
//! caught, the flag is never set, and the registry only costs a lock per
//! output file.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicI32, Ordering};
use std::sync::Mutex;

/// SIGINT's number (Ctrl-C).
pub const SIGINT: i32 = signal_hook::consts::SIGINT;
/// SIGTERM's number (`kill`'s default).
pub const SIGTERM: i32 = signal_hook::consts::SIGTERM;
/// SIGHUP's number (the terminal closed; some schedulers' first notice).
pub const SIGHUP: i32 = signal_hook::consts::SIGHUP;

/// The first signal received, 0 before any.
static SIGNAL: AtomicI32 = AtomicI32::new(0);

/// Temporary files written now, removed on an exit at the second signal.
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Starts catching SIGINT, SIGTERM and SIGHUP (see the module docs). Call
/// once.
pub fn install() -> std::io::Result<()> {
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                if SIGNAL
                    .compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst)
                    .is_err()
                {
                    remove_temporaries_and_exit(exit_code(sig));
                }
            }
        })?;
    Ok(())
}

/// The signal that asked the process to stop, if one did.
pub fn requested() -> Option<i32> {
    match SIGNAL.load(Ordering::Relaxed) {
        0 => None,
        s => Some(s),
    }
}

/// [`crate::Error::Interrupted`] once a signal asked the process to stop.
pub(crate) fn stop_if_requested() -> Result<(), crate::Error> {
    match requested() {
        Some(sig) => Err(crate::Error::Interrupted(sig)),
        None => Ok(()),
    }
}

/// Records `signal` as if it had been received (the first one wins): for
/// callers that stop work for their own reasons, and for tests.
pub fn request(signal: i32) {
    let _ = SIGNAL.compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst);
}

/// The exit status of a process stopped by `signal`: 128 + its number.
pub fn exit_code(signal: i32) -> i32 {
    128 + signal
}

/// The signal's name for messages (`SIGINT`), or its number.
pub(crate) fn signal_name(signal: i32) -> String {
    match signal {
        SIGINT => "SIGINT".into(),
        SIGTERM => "SIGTERM".into(),
        SIGHUP => "SIGHUP".into(),
        s => format!("signal {s}"),
    }
}

/// Registers a temporary file being written, to be removed if the process
/// exits at a second signal.
pub fn register_temporary(path: &Path) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        t.push(path.to_path_buf());
    }
}

/// Creates the temporary file `path` with `create` and registers it, both
/// under the registry's lock: an exit at a second signal, which holds the
/// lock from its removals to the end, either removes the file or comes
/// before it exists.
pub(crate) fn create_temporary<T, E>(
    path: &Path,
    create: impl FnOnce() -> Result<T, E>,
) -> Result<T, E> {
    let mut t = TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner());
    let file = create()?;
    t.push(path.to_path_buf());
    Ok(file)
}

/// The temporary file was renamed into place or removed: forget it.
pub(crate) fn unregister_temporary(path: &Path) {
    if let Ok(mut t) = TEMPORARIES.lock() {
        if let Some(i) = t.iter().rposition(|p| p == path) {
            t.swap_remove(i);
        }
    }
}

/// Removes every registered temporary file and exits with `code`, holding
/// the registry's lock to the end so no temporary is created after the
/// removals.
fn remove_temporaries_and_exit(code: i32) -> ! {
    let t = TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner());
    for p in t.iter() {
        let _ = std::fs::remove_file(p);
    }
    std::process::exit(code)
}

/// Removes every registered temporary file, unless the registry is in use
/// (for an exit from a state that may hold its lock: an allocation that
/// failed while registering).
pub fn remove_temporaries_if_free() {
    if let Ok(t) = TEMPORARIES.try_lock() {
        for p in t.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_and_names_follow_the_shell_convention() {
        assert_eq!(
            (exit_code(SIGINT), exit_code(SIGTERM), exit_code(SIGHUP)),
            (130, 143, 129)
        );
        assert_eq!(signal_name(SIGINT), "SIGINT");
        assert_eq!(signal_name(SIGTERM), "SIGTERM");
        assert_eq!(signal_name(SIGHUP), "SIGHUP");
        assert_eq!(signal_name(3), "signal 3");
    }

    #[test]
    fn temporaries_are_registered_until_unregistered() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.tmp"), dir.path().join("b.tmp"));
        register_temporary(&a);
        register_temporary(&b);
        unregister_temporary(&b);
        // (other tests register their own files meanwhile: look only at
        // these two, and remove nothing of theirs)
        let listed = |p: &Path| TEMPORARIES.lock().unwrap().contains(&p.to_path_buf());
        assert!(listed(&a) && !listed(&b));
        unregister_temporary(&a);
        assert!(!listed(&a));
    }
}
