//! What `polydem check` tells about a run before it is started: the bodies still to come by
//! insertion, and how long the run will take, from a short timed trial of its first steps.

use super::total_steps;
use crate::scene::{Prepared, ScheduledInsertion};
use std::time::Instant;

/// The bodies a scheduled insertion will add at most, and how many times it inserts.
pub fn bodies_to_come(s: &ScheduledInsertion, duration: f64) -> (u64, u64) {
    let end = s.spec.until.unwrap_or(f64::INFINITY).min(duration);
    let times = match s.spec.every {
        Some(every) if s.next_time <= end => ((end - s.next_time) / every).floor() as u64 + 1,
        _ => u64::from(s.next_time <= end),
    };
    // A volume fraction asks for as many bodies as fill it: known only when placing them.
    let bodies = (s.done..s.done + times)
        .map(|k| s.spec.count_at(k).map_or(0, |c| c as u64))
        .sum();
    (bodies, times)
}

/// A timed trial of a run's first steps.
pub struct Trial {
    pub steps: u64,
    /// Σ bodies × steps over the trial.
    pub particle_steps: f64,
    pub seconds: f64,
}

impl Trial {
    /// Runs `prepared` (as the run would, insertions included, writing nothing) for about
    /// `seconds` of wall-clock time or to its end, whichever comes first. The world is left
    /// where the trial stopped: build the scene again for the run itself.
    pub fn run(prepared: &mut Prepared, seconds: f64) -> Self {
        let total = total_steps(prepared);
        let dt = prepared.world.time_step();
        let start = Instant::now();
        let mut trial = Trial {
            steps: 0,
            particle_steps: 0.0,
            seconds: 0.0,
        };
        while trial.steps < total && start.elapsed().as_secs_f64() < seconds {
            let next_insertion = prepared
                .next_insertion_time()
                .map_or(u64::MAX, |t| (t / dt).round() as u64);
            let done = prepared.world.steps_done();
            let chunk = 20
                .min(total - trial.steps)
                .min(next_insertion.max(done + 1) - done);
            prepared.world.run_steps(chunk);
            trial.steps += chunk;
            trial.particle_steps += chunk as f64 * prepared.world.bodies().len() as f64;
            if next_insertion <= prepared.world.steps_done() {
                prepared.insert_due();
            }
        }
        trial.seconds = start.elapsed().as_secs_f64();
        trial
    }

    /// Wall-clock seconds for `steps` steps of `bodies` bodies at the trial's pace
    /// (particle-steps per second), or per step when the trial had no bodies.
    pub fn estimate(&self, steps: u64, bodies: f64) -> f64 {
        if self.particle_steps > 0.0 && bodies > 0.0 {
            steps as f64 * bodies * self.seconds / self.particle_steps
        } else {
            steps as f64 * self.seconds / self.steps.max(1) as f64
        }
    }
}
