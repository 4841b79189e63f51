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

impl Stage {
    /// A library [`Control`](waam_slicer::Control) whose progress reports
    /// show the stage's name and percentage on this spinner.
    pub fn control(&self) -> waam_slicer::Control {
        let pb = self.0.clone();
        let start = std::time::Instant::now();
        waam_slicer::Control::default().with_progress(move |stage, fraction| {
            if let Some(pb) = &pb {
                // time left from the rate so far, once there is a rate
                let t = start.elapsed().as_secs_f64();
                let left = if fraction > 0.02 && t > 1.0 {
                    format!(", about {:.0} s left", t * (1.0 - fraction) / fraction)
                } else {
                    String::new()
                };
                pb.set_message(format!("{stage} ({:.0} %{left})", 100.0 * fraction));
            }
        })
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some(pb) = &self.0 {
            pb.finish_and_clear();
        }
    }
}
