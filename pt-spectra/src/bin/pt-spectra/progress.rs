//! Progress bars on standard error for the library's [`Progress`] reports; when standard error is not
//! a terminal (redirected to a log), a line for a stage that runs longer than [`QUIET`], every [`EVERY`]
//! after, and at its end.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pt_spectra::progress::{Progress, Stage};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// A stage shorter than this prints nothing off a terminal.
const QUIET: Duration = Duration::from_secs(2);
/// Off a terminal, a line at most this often per stage.
const EVERY: Duration = Duration::from_secs(30);

/// One bar per stage, drawn on standard error from the first report of the stage and cleared when the
/// stage is done; or, off a terminal, a line now and then.
#[derive(Default)]
pub struct Bars {
    bars: Mutex<HashMap<Stage, ProgressBar>>,
    /// Off a terminal: per stage, its first report and the last line printed.
    lines: Mutex<HashMap<Stage, (Instant, Option<Instant>)>>,
}

impl Bars {
    /// The lines of a redirected standard error.
    fn lines(&self, stage: Stage, done: usize, total: usize) {
        let mut lines = self
            .lines
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let now = Instant::now();
        let (first, last) = *lines.entry(stage).or_insert((now, None));
        let elapsed = now.duration_since(first).as_secs_f64();
        if done >= total {
            if last.is_some() {
                eprintln!("progress: {stage}: done in {elapsed:.0} s");
            }
            lines.remove(&stage);
        } else if now.duration_since(first) >= QUIET
            && last.is_none_or(|t| now.duration_since(t) >= EVERY)
        {
            let percent = 100.0 * done as f64 / total.max(1) as f64;
            eprintln!("progress: {stage}: {percent:.0}% after {elapsed:.0} s");
            lines.insert(stage, (first, Some(now)));
        }
    }
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
        if !std::io::stderr().is_terminal() {
            return self.lines(stage, done, total);
        }
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
