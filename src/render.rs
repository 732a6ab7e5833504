//! Running an estimator for a number of passes or a time budget.

use std::time::{Duration, Instant};

use crate::estimator::{Estimator, Stats};
use crate::image::Image;
use crate::scene::Scene;

/// How much work to do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// Exactly this many passes (equal work; reproducible bit for bit).
    Passes(u32),
    /// Passes until this much wall-clock time has gone by (equal time; at least one pass).
    Seconds(f64),
}

impl Budget {
    /// True once `passes` passes begun at `start` use the budget up (a time budget always
    /// allows the first pass).
    pub fn is_spent(self, passes: u32, start: Instant) -> bool {
        match self {
            Budget::Passes(n) => passes >= n,
            Budget::Seconds(s) => passes > 0 && start.elapsed().as_secs_f64() >= s,
        }
    }
}

/// What a finished render hands back.
pub struct RenderOutput {
    pub image: Image,
    pub stats: Stats,
    pub seconds: f64,
    /// The budget was cut short by a stop request (`interrupt`): the image holds the passes
    /// done (`stats.passes`, at least one).
    pub interrupted: bool,
}

/// Runs `estimator` on `scene` until `budget` is spent, or, after at least one pass, until a
/// stop is requested (`interrupt`). `on_pass(done, elapsed)` is called after every pass (for
/// progress bars).
pub fn render(
    scene: &Scene,
    estimator: &mut dyn Estimator,
    budget: Budget,
    mut on_pass: impl FnMut(u32, Duration),
) -> RenderOutput {
    let start = Instant::now();
    let mut pass = 0u32;
    let mut interrupted = false;
    loop {
        if budget.is_spent(pass, start) {
            break;
        }
        if pass > 0 && crate::interrupt::requested() {
            interrupted = true;
            break;
        }
        estimator.run_pass(scene, pass);
        pass += 1;
        on_pass(pass, start.elapsed());
    }
    RenderOutput {
        image: estimator.image(),
        stats: estimator.stats(),
        seconds: start.elapsed().as_secs_f64(),
        interrupted,
    }
}
