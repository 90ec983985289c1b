//! What the process is doing, for the message of an allocation that fails
//! where no caller can handle it: the binary's allocator reports it as
//! "out of memory: cannot allocate N MB while PHASE" and exits 1
//! (docs/output.md, "Out of memory"). A phase is a plain atomic, so the
//! allocator reads it without allocating or locking.

use std::sync::atomic::{AtomicU8, Ordering};

/// The phases a command goes through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    Starting,
    LoadingScene,
    BuildingAccel,
    Rendering,
    ReadingParts,
    Writing,
}

static PHASE: AtomicU8 = AtomicU8::new(Phase::Starting as u8);

/// Says the process is now in `phase`.
pub fn enter(phase: Phase) {
    PHASE.store(phase as u8, Ordering::Relaxed);
}

/// How each phase is said, in [`Phase`] order.
const DOING: [&str; 6] = [
    "starting",
    "loading the scene and its meshes",
    "building the ray-query structure",
    "rendering",
    "reading parts",
    "writing the output",
];

/// What the process is doing, as the out-of-memory message says it.
pub fn doing() -> &'static str {
    DOING
        .get(PHASE.load(Ordering::Relaxed) as usize)
        .copied()
        .unwrap_or(DOING[0])
}
