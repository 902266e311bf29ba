//! Where a step's time goes: wall-clock seconds per stage, summed over the steps taken (as Box2D's
//! `b2Profile`). Costs two clock reads per stage.

use std::time::Instant;

/// Seconds spent in each stage since the world was built.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Both half-kicks and the drift (integration of the bodies' motion); between two steps of a
    /// batch also the bodies' force sums, which the opening pass completes (`integrate::Closing`).
    pub integrate: f64,
    /// The neighbour search (when the candidate list is made again) and the store's update.
    pub candidates: f64,
    /// The narrow phase of pairs that may touch in several places.
    pub regions: f64,
    /// The narrow phase of the other pairs and the contact laws of all.
    pub detect_and_evaluate: f64,
    /// The sums onto walls, and onto bodies at the last step of a batch.
    pub accumulate: f64,
    /// Everything else: end-of-step velocity predictions, walls, flow meters, removals.
    pub other: f64,
}

impl StageTimes {
    pub fn total(&self) -> f64 {
        self.integrate
            + self.candidates
            + self.regions
            + self.detect_and_evaluate
            + self.accumulate
            + self.other
    }

    /// One line, each stage as a share of the total.
    pub fn summary(&self) -> String {
        let total = self.total().max(1e-300);
        let share = |s: f64| 100.0 * s / total;
        format!(
            "integrate {:.1} %, candidates {:.1} %, regions {:.1} %, detect+laws {:.1} %, \
             accumulate {:.1} %, other {:.1} %",
            share(self.integrate),
            share(self.candidates),
            share(self.regions),
            share(self.detect_and_evaluate),
            share(self.accumulate),
            share(self.other)
        )
    }
}

/// A running stopwatch that books each lap into a stage.
pub struct Stopwatch(Instant);

impl Stopwatch {
    pub fn start() -> Self {
        Self(Instant::now())
    }

    /// Adds the time since the last lap to `stage`.
    pub fn lap(&mut self, stage: &mut f64) {
        let now = Instant::now();
        *stage += (now - self.0).as_secs_f64();
        self.0 = now;
    }
}
