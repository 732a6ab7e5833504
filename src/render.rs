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

/// How far a run of passes has come: passes done and the seconds they took. `render`,
/// `reference` and the experiment runner all move it on through `advance`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Progress {
    pub passes: u32,
    /// Time spent in passes (not in what the caller does between calls).
    pub seconds: f64,
    /// Passes to take in the next chunk (learned from the time the last chunk took).
    chunk: u32,
}

impl Progress {
    /// True once the budget is spent (a time budget always allows the first pass).
    pub fn is_spent(&self, budget: Budget) -> bool {
        match budget {
            Budget::Passes(n) => self.passes >= n,
            Budget::Seconds(s) => self.passes > 0 && self.seconds >= s,
        }
    }
}

/// Runs passes through `run_passes(first, count)` (an estimator's `run_passes`, or both
/// halves' of a reference in turn) until `budget` (passes, or seconds of passes, counted
/// from the start of `progress`) is spent, or, with `stoppable`, after at least one pass,
/// until a stop is requested (`interrupt`). Passes go in chunks of about `CHUNK_SECONDS`:
/// `Estimator::run_passes` gives the bits of one pass at a time. `on_chunk(progress)` is
/// called after every chunk. Returns true when a stop request cut the budget short.
pub fn advance(
    mut run_passes: impl FnMut(u32, u32),
    budget: Budget,
    progress: &mut Progress,
    stoppable: bool,
    mut on_chunk: impl FnMut(&Progress),
) -> bool {
    loop {
        if progress.is_spent(budget) {
            return false;
        }
        if stoppable && progress.passes > 0 && crate::interrupt::requested() {
            return true;
        }
        let chunk = progress.chunk.max(1);
        let count = match budget {
            Budget::Passes(n) => chunk.min(n - progress.passes),
            Budget::Seconds(_) => chunk,
        };
        let start = Instant::now();
        run_passes(progress.passes, count);
        let dt = start.elapsed().as_secs_f64();
        progress.passes += count;
        progress.seconds += dt;
        on_chunk(progress);
        let per_pass = dt / count as f64;
        let mut next = (CHUNK_SECONDS / per_pass.max(1e-9)).clamp(1.0, MAX_CHUNK as f64) as u32;
        if let Budget::Seconds(s) = budget {
            // No more passes than the time left holds (rounded up, as one pass at a time
            // would start its last pass before the time is up).
            let left = (s - progress.seconds).max(0.0);
            next = next.min((left / per_pass.max(1e-9)).ceil().max(1.0) as u32);
        }
        progress.chunk = next;
    }
}

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
    let mut progress = Progress::default();
    let interrupted = advance(
        |first, count| estimator.run_passes(scene, first, count),
        budget,
        &mut progress,
        true,
        |p| on_pass(p.passes, start.elapsed()),
    );
    RenderOutput {
        image: estimator.image(),
        stats: estimator.stats(),
        seconds: start.elapsed().as_secs_f64(),
        interrupted,
    }
}
