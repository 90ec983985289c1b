//! What a render tells of its progress, to whoever shows it: the library
//! draws nothing itself (the command line draws a bar with indicatif).

use std::fmt;
use std::sync::Arc;

/// Told how much work a render has ([`start`](Progress::start)), each
/// tile's share as it completes (from the worker threads), and when it
/// ends. The units are pixel samples.
pub trait Progress: Send + Sync {
    /// The render has `total` pixel samples to take.
    fn start(&self, total: u64);
    /// `n` more pixel samples are done.
    fn advance(&self, n: u64);
    /// The render has ended (done, or stopped by a signal).
    fn finish(&self);
}

impl fmt::Debug for dyn Progress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("dyn Progress")
    }
}

/// Where a render reports its progress: shared, so options stay `Clone`.
pub type ProgressSink = Arc<dyn Progress>;
