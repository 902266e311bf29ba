//! Running a prepared scene to its end: steps, insertions during the run, output at intervals.

use crate::io::output::RunOutput;
use crate::scene::{InsertionReport, Prepared};
use crate::World;
use std::path::Path;

/// What a run tells its caller as it goes.
pub enum RunEvent<'a> {
    /// After each chunk of steps.
    Progress(&'a World),
    /// After an insertion during the run.
    Inserted(&'a InsertionReport),
}

/// Steps `prepared.world` to `prepared.duration`, writing a frame at the start and after every
/// output interval, and doing scheduled insertions at their times. Chunks of steps are short
/// enough for a lively progress display and long enough to keep the per-chunk overhead negligible.
pub fn run(
    prepared: &mut Prepared,
    out_dir: &Path,
    mut observe: impl FnMut(RunEvent),
) -> std::io::Result<RunOutput> {
    let total_steps = total_steps(prepared);
    let dt = prepared.world.time_step();
    let step_of = |time: f64| (time / dt).round() as u64;
    // Output k falls on the step nearest k·interval, so outputs stay on the user's times and the
    // last one coincides with the end when the duration is a multiple of the interval.
    let interval = prepared.output_interval;
    let output_step = |k: u64| step_of(k as f64 * interval).max(k);
    let mut output = RunOutput::create(out_dir, &prepared.world, &prepared.output)?;
    output.write(&prepared.world)?;
    let mut outputs = 1;
    let mut next_output = output_step(outputs);
    while prepared.world.steps_done() < total_steps {
        let next_insertion = prepared.next_insertion_time().map(step_of);
        let until = next_output.min(total_steps).min(
            next_insertion
                .unwrap_or(u64::MAX)
                .max(prepared.world.steps_done() + 1),
        );
        while prepared.world.steps_done() < until {
            let chunk = (until - prepared.world.steps_done()).min(200);
            prepared.world.run_steps(chunk);
            observe(RunEvent::Progress(&prepared.world));
        }
        if next_insertion.is_some_and(|s| s <= prepared.world.steps_done()) {
            for report in prepared.insert_due() {
                observe(RunEvent::Inserted(&report));
            }
        }
        let w = &prepared.world;
        if w.steps_done() == next_output || w.steps_done() == total_steps {
            output.write(w)?;
            while next_output <= w.steps_done() {
                outputs += 1;
                next_output = output_step(outputs);
            }
        }
    }
    Ok(output)
}

/// Number of steps a prepared scene will take.
pub fn total_steps(prepared: &Prepared) -> u64 {
    (prepared.duration / prepared.world.time_step())
        .round()
        .max(1.0) as u64
}
