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

/// Passes are run several at a time (`Estimator::run_passes`) in chunks of about this long:
/// the threads then wait for each other once per chunk instead of once per pass, while a
/// stop request or a time budget is still seen within a fraction of a second.
const CHUNK_SECONDS: f64 = 0.05;

/// The most passes in one chunk.
const MAX_CHUNK: u32 = 64;

/// Runs `estimator` on `scene` until `budget` is spent, or, after at least one pass, until a
/// stop is requested (`interrupt`). `on_pass(done, elapsed)` is called after every chunk of
/// passes (for progress bars). The image is the same bits as one pass at a time.
pub fn render(
    scene: &Scene,
    estimator: &mut dyn Estimator,
    budget: Budget,
    mut on_pass: impl FnMut(u32, Duration),
) -> RenderOutput {
    let start = Instant::now();
    let mut pass = 0u32;
    let mut interrupted = false;
    // Start with one pass to time it, then chunks of about CHUNK_SECONDS.
    let mut chunk = 1u32;
    loop {
        if budget.is_spent(pass, start) {
            break;
        }
        if pass > 0 && crate::interrupt::requested() {
            interrupted = true;
            break;
        }
        let count = match budget {
            Budget::Passes(n) => chunk.min(n - pass),
            Budget::Seconds(_) => chunk,
        };
        let chunk_start = Instant::now();
        estimator.run_passes(scene, pass, count);
        pass += count;
        on_pass(pass, start.elapsed());
        let seconds_per_pass = chunk_start.elapsed().as_secs_f64() / count as f64;
        chunk = (CHUNK_SECONDS / seconds_per_pass.max(1e-9)).clamp(1.0, MAX_CHUNK as f64) as u32;
        if let Budget::Seconds(s) = budget {
            // No more passes than the time left holds (rounded up, as one pass at a time
            // would start its last pass before the time is up).
            let left = (s - start.elapsed().as_secs_f64()).max(0.0);
            chunk = chunk.min((left / seconds_per_pass.max(1e-9)).ceil().max(1.0) as u32);
        }
    }
    RenderOutput {
        image: estimator.image(),
        stats: estimator.stats(),
        seconds: start.elapsed().as_secs_f64(),
        interrupted,
    }
}
