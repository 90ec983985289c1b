//! Checkpoints: the finished samples saved as a part beside the output,
//! atomically, for `--resume` (docs/farm.md, "Interruption, checkpoints,
//! resume"). A checkpoint is a snapshot of the sums (the part's channels,
//! copied between passes) written by a thread of its own while the render
//! goes on; a signal never loses a committed
//! checkpoint, and the interrupted render's own part replaces it only with
//! more samples.

use std::path::{Path, PathBuf};
use std::thread::JoinHandle;
use std::time::Instant;

use crate::error::Error;
use crate::farm::part::{self, Header};
use crate::film::Sums;

/// Where a render keeps its finished samples for `--resume` (at a signal,
/// at checkpoints): `OUT.partial.exr` beside `OUT.exr`.
pub(crate) fn checkpoint_path(output: &Path) -> PathBuf {
    output.with_extension("partial.exr")
}

/// Saves the sums after a pass once `every` seconds — and at least
/// [`SPACING`] times the last save's own duration — passed since the last
/// save finished, unless the render is about to finish (at `end`) or a
/// save is still being written: the snapshot is written in the background
/// ([`Checkpoints::after_pass`]), the render does not wait for it.
/// A save waits at least this many times the last one's duration after
/// it: the writer thread takes at most 1/(1 + SPACING) of one core.
pub(crate) const SPACING: f64 = 4.0;

pub(crate) struct Checkpoints<'a> {
    path: &'a Path,
    every: Option<f64>,
    end: u32,
    /// When the last save finished (at first, the render's start).
    last: Instant,
    /// How long the last save took, seconds.
    took: f64,
    /// The save being written, if any.
    writing: Option<Writing>,
    /// The samples end of the last committed save (0: none).
    committed: u32,
}

/// A checkpoint being written: the samples end of its snapshot and its
/// thread.
struct Writing {
    done: u32,
    /// The save's outcome, when it started and when it ended.
    thread: JoinHandle<(Result<(), Error>, Instant, Instant)>,
}

impl<'a> Checkpoints<'a> {
    /// Checkpoints at `path` every `every` seconds (None: never) of a
    /// render whose samples end at `end`.
    pub(crate) fn new(path: &'a Path, every: Option<f64>, end: u32) -> Self {
        Checkpoints {
            path,
            every,
            end,
            last: Instant::now(),
            took: 0.0,
            writing: None,
            committed: 0,
        }
    }

    /// Called after every pass with its sums and their part header: starts
    /// a save of a snapshot when one is due. A save that failed stops the
    /// render with its error (reported here, at the pass after it).
    pub(crate) fn after_pass(&mut self, sums: &Sums, header: &Header) -> Result<(), Error> {
        if self
            .writing
            .as_ref()
            .is_some_and(|w| w.thread.is_finished())
        {
            self.join()?;
        }
        let Some(every) = self.every else {
            return Ok(());
        };
        if self.writing.is_some()
            || sums.done >= self.end
            || self.last.elapsed().as_secs_f64() < every.max(SPACING * self.took)
        {
            return Ok(());
        }
        // the channels copied now (what a synchronous write copies too);
        // compressed and written while the render goes on
        let (path, image) = (self.path.to_path_buf(), part::prepare(header, sums));
        let thread = std::thread::Builder::new()
            .name("checkpoint".into())
            .spawn(move || {
                let start = Instant::now();
                let saved = image
                    .stage(&path, false)
                    .and_then(|staged| crate::film::commit_all(vec![staged]));
                (saved, start, Instant::now())
            })
            .map_err(|e| Error::Write {
                path: self.path.to_path_buf(),
                problem: format!("cannot start the checkpoint's thread: {e}"),
            })?;
        self.writing = Some(Writing {
            done: sums.done,
            thread,
        });
        Ok(())
    }

    /// Waits for the save being written, if any. A save a signal kept from
    /// being committed is no error: the interrupted render writes its own.
    fn join(&mut self) -> Result<(), Error> {
        let Some(w) = self.writing.take() else {
            return Ok(());
        };
        let (result, start, end) = w.thread.join().unwrap_or_else(|_| {
            let problem = "the checkpoint's thread panicked".into();
            let path = self.path.to_path_buf();
            (
                Err(Error::Write { path, problem }),
                Instant::now(),
                Instant::now(),
            )
        });
        self.last = end;
        self.took = (end - start).as_secs_f64();
        match result {
            Ok(()) => {
                self.committed = w.done;
                Ok(())
            }
            Err(Error::Interrupted(_)) => Ok(()),
            Err(e) => Err(e),
        }
    }

    /// Waits for the save being written; then whether a part with `done`
    /// samples would hold more than the last committed save.
    pub(crate) fn finish(&mut self, done: u32) -> Result<bool, Error> {
        self.join()?;
        Ok(done > self.committed)
    }
}

impl Drop for Checkpoints<'_> {
    /// A render that stops with an error still lets its save finish or
    /// fail, so that no temporary file of it outlives the process.
    fn drop(&mut self) {
        let _ = self.join();
    }
}

/// Removes what was kept to resume from (the finished output replaces it)
/// and a checkpoint a killed process was writing.
pub fn clean(path: &Path) {
    if path.is_file() {
        let _ = std::fs::remove_file(path);
    }
    crate::film::stale::clean(path);
}
