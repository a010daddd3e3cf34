//! Progress bars for runs (indicatif), drawn on stderr and hidden when it is not a terminal.

use std::ops::ControlFlow;

use dirac::prelude::*;
use indicatif::{ProgressBar, ProgressStyle};

/// A bar for a run from `t` to `t_end` in steps of `h`.
pub fn bar(t: f64, t_end: f64, h: f64) -> ProgressBar {
    let steps = ((t_end - t) / h).round().max(0.0) as u64;
    let bar = ProgressBar::new(steps);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} steps, {eta} left")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar
}

/// An observer that moves `bar` every 1 000 steps (and at the end).
pub fn observer<const N: usize, M: dirac::Manifold<N>>(
    bar: &ProgressBar,
) -> impl FnMut(&Progress<'_, N, M>) -> ControlFlow<()> + '_ {
    move |progress| {
        if progress.steps % 1000 == 0 || progress.steps == progress.total {
            bar.set_length(progress.total);
            bar.set_position(progress.steps);
            bar.set_message(format!("t = {:.1}", progress.state.t()));
        }
        ControlFlow::Continue(())
    }
}
