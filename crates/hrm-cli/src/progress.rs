//! Progress bars on standard error for work that takes more than a moment (the main job, sweeps
//! and a single run's controller samples). indicatif hides them when standard error is not a
//! terminal, so logs and pipes stay clean.

use indicatif::{ProgressBar, ProgressStyle};
use sim_core::{ControlSample, LoopHooks};

/// The bar's layout: label, elapsed time, bar, count, estimated time left, current message.
const TEMPLATE: &str = "{prefix:>8} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta}) {msg}";

/// A progress bar over `len` tasks, labelled `label`. It is `Sync`: parallel workers may call
/// [`ProgressBar::inc`] on a shared reference.
pub fn bar(len: u64, label: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template(TEMPLATE) {
        bar.set_style(style);
    }
    bar.set_prefix(label.to_owned());
    bar
}

/// How many controller samples a [`SampleProgress`] counts between two updates of its bar, so
/// that the loop pays for the bar once in that many samples.
const SAMPLES_PER_UPDATE: u64 = 1024;

/// The loop's observer that advances a bar over one run's controller samples
/// ([`LoopHooks::observe`]).
pub struct SampleProgress {
    bar: ProgressBar,
    seen: u64,
}

impl SampleProgress {
    /// A bar over `samples` controller samples.
    pub fn new(samples: u64) -> Self {
        Self {
            bar: bar(samples, "samples"),
            seen: 0,
        }
    }

    /// Removes the bar from the terminal once the run is over.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl LoopHooks for SampleProgress {
    fn observe(&mut self, _: &ControlSample) {
        self.seen += 1;
        if self.seen.is_multiple_of(SAMPLES_PER_UPDATE) {
            self.bar.set_position(self.seen);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_advances_the_sample_bar_to_its_last_update() {
        let mut scenario = sim_study::Scenario::builtin("paper-responses-step").unwrap();
        scenario.duration = 0.25; // 2,500 controller periods of 0.1 ms: 2,501 samples
        let mut progress = SampleProgress::new(2501);
        let kind = sim_study::ControllerKind::Pd;
        let run = sim_study::study::run_one_with(&scenario, kind, &mut progress);
        assert!(run.result.is_ok());
        assert_eq!(progress.seen, 2501);
        assert_eq!(progress.bar.position(), 2048);
        progress.finish();
        assert!(progress.bar.is_finished());
    }

    #[test]
    fn the_template_is_valid_and_the_bar_counts() {
        assert!(ProgressStyle::with_template(TEMPLATE).is_ok());
        let bar = bar(3, "runs");
        bar.inc(2);
        assert_eq!(bar.position(), 2);
        assert_eq!(bar.length(), Some(3));
    }
}
