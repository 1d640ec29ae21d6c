//! Progress bars on standard error for the library's [`Progress`] reports.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pt_spectra::progress::{Progress, Stage};
use std::collections::HashMap;
use std::sync::Mutex;

/// One bar per stage, drawn on standard error from the first report of the stage and cleared when the
/// stage is done.
#[derive(Default)]
pub struct Bars {
    bars: Mutex<HashMap<Stage, ProgressBar>>,
}

fn template(stage: Stage) -> &'static str {
    match stage {
        Stage::TwoLoopPoints => "{msg} [{bar:40}] {percent}% ({eta})",
        Stage::OneLoop | Stage::Gamma2Weights | Stage::TwoLoopBasis => {
            "{msg} [{bar:40}] {percent}% ({eta})"
        }
        _ => "{msg} [{bar:40}] {pos}/{len} nodes ({eta})",
    }
}

impl Progress for Bars {
    fn update(&self, stage: Stage, done: usize, total: usize) {
        let mut bars = self
            .bars
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let bar = bars.entry(stage).or_insert_with(|| {
            let bar =
                ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(template(stage)) {
                bar.set_style(style);
            }
            bar.set_message(stage.to_string());
            bar
        });
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        if done >= total {
            bar.finish_and_clear();
            bars.remove(&stage);
        }
    }

    fn note(&self, message: &str) {
        eprintln!("note: {message}");
    }
}
