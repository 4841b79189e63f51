//! A spinner on stages that take more than a moment (hidden with --quiet or
//! when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};
use std::time::Duration;

/// Shows `message` with a spinner until the returned guard is dropped.
pub struct Stage(Option<ProgressBar>);

impl Stage {
    pub fn start(quiet: bool, message: &str) -> Self {
        if quiet {
            return Self(None);
        }
        let pb = ProgressBar::new_spinner();
        pb.set_style(
            ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        pb.set_message(message.to_string());
        pb.enable_steady_tick(Duration::from_millis(100));
        Self(Some(pb))
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some(pb) = &self.0 {
            pb.finish_and_clear();
        }
    }
}
