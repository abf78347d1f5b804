//! Progress bars on standard error for work that takes more than a moment (the main job and
//! sweeps). indicatif hides them when standard error is not a terminal, so logs and pipes stay
//! clean.

use indicatif::{ProgressBar, ProgressStyle};

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_template_is_valid_and_the_bar_counts() {
        assert!(ProgressStyle::with_template(TEMPLATE).is_ok());
        let bar = bar(3, "runs");
        bar.inc(2);
        assert_eq!(bar.position(), 2);
        assert_eq!(bar.length(), Some(3));
    }
}
