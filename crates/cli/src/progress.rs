//! Progress bars (indicatif) behind the library's `Progress` trait.

use indicatif::{ProgressBar, ProgressStyle};
use wscg_math::progress::Progress;

/// Draws one progress bar per stage on standard error (hidden when it is not a terminal).
pub struct Bars {
    bar: ProgressBar,
    prefix: String,
}

impl Bars {
    /// A progress receiver whose bars are labelled `prefix`.
    pub fn new(prefix: &str) -> Self {
        Self {
            bar: ProgressBar::hidden(),
            prefix: prefix.to_string(),
        }
    }
}

impl Progress for Bars {
    fn begin(&self, stage: &str, total: u64) {
        if !crate::logging::quiet() {
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        self.bar.reset();
        self.bar.set_length(total);
        self.bar.set_style(
            ProgressStyle::with_template("{prefix} {msg} [{bar:30}] {pos}/{len} {elapsed}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        self.bar.set_prefix(self.prefix.clone());
        self.bar.set_message(stage.to_string());
    }
    fn advance(&self, steps: u64) {
        self.bar.inc(steps);
    }
    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
