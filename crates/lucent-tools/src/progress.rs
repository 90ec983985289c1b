//! A render's progress drawn as a bar on stderr: the library's
//! [`Progress`] told to an indicatif bar, for the command line and the
//! tools' own renders.

use std::sync::{Arc, OnceLock};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use lucent::progress::{Progress, ProgressSink};

/// A bar on stderr: elapsed time, the bar, the percentage done and the
/// time left; drawn from the render's start.
#[derive(Debug, Default)]
pub struct Bar(OnceLock<ProgressBar>);

impl Bar {
    /// A bar to hand a render (see [`lucent::render::RenderOptions`]).
    pub fn sink() -> ProgressSink {
        Arc::new(Bar::default())
    }
}

impl Progress for Bar {
    fn start(&self, total: u64) {
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}%, eta {eta}")
                .unwrap()
                .progress_chars("=> "),
        );
        // a second start (a bar handed to two renders) keeps the first bar
        let _ = self.0.set(b);
    }

    fn advance(&self, n: u64) {
        if let Some(b) = self.0.get() {
            b.inc(n);
        }
    }

    fn finish(&self) {
        if let Some(b) = self.0.get() {
            b.finish_and_clear();
        }
    }
}
