//! Running a prepared scene to its end: steps, insertions during the run, output at intervals.

use crate::io::output::RunOutput;
use crate::scene::{InsertionReport, Prepared};
use crate::World;
use std::fmt;
use std::path::Path;

/// Why a run stopped before its end.
#[derive(Debug)]
pub enum RunError {
    /// Writing the output failed.
    Output(std::io::Error),
    /// The state stopped being finite: the run blew up. The outputs written before stay valid.
    BlowUp(String),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            RunError::Output(e) => write!(f, "{e}"),
            RunError::BlowUp(why) => f.write_str(why),
        }
    }
}

impl From<std::io::Error> for RunError {
    fn from(e: std::io::Error) -> Self {
        RunError::Output(e)
    }
}

/// The first body whose position, velocity (squared: a speed of 1e200 m/s has no finite kinetic
/// energy) or angular momentum is not finite, as a message saying what, where and when; `None`
/// while the state is sound. O(bodies): run after every chunk of steps.
pub fn blow_up(world: &World) -> Option<String> {
    let b = world.bodies();
    let bad = (0..b.len()).find(|&i| {
        !(b.position[i].is_finite()
            && b.velocity[i].length_squared().is_finite()
            && b.angular_momentum[i].length_squared().is_finite())
    })?;
    let vector = |v: crate::math::DVec3| format!("({:.3e}, {:.3e}, {:.3e}) ", v.x, v.y, v.z);
    let what = if !b.position[bad].is_finite() {
        format!("position {}m", vector(b.position[bad]))
    } else if !b.velocity[bad].length_squared().is_finite() {
        format!("velocity {}m/s", vector(b.velocity[bad]))
    } else {
        format!(
            "angular momentum {}kg m²/s",
            vector(b.angular_momentum[bad])
        )
    };
    Some(format!(
        "the run blew up at t = {:.6e} s (step {}): body {} has {what}. Likely causes: a time \
         step above the stable one (`force_time_step`; `polydem check` prints the estimate), \
         initial velocities or gravity far beyond the scene's scale, or material values (E, \
         density, restitution) out of any physical range. The frames written before are valid.",
        world.time(),
        world.steps_done(),
        b.id[bad],
    ))
}

/// What a run tells its caller as it goes.
pub enum RunEvent<'a> {
    /// After each chunk of steps.
    Progress(&'a World),
    /// After an insertion during the run.
    Inserted(&'a InsertionReport),
}

/// Steps `prepared.world` to `prepared.duration`, writing a frame at the start and after every
/// output interval, and doing scheduled insertions at their times. Stops with
/// [`RunError::BlowUp`] as soon as the state is no longer finite (checked after every chunk). Chunks of steps are short
/// enough for a lively progress display and long enough to keep the per-chunk overhead negligible.
pub fn run(
    prepared: &mut Prepared,
    out_dir: &Path,
    mut observe: impl FnMut(RunEvent),
) -> Result<RunOutput, RunError> {
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
            if let Some(why) = blow_up(&prepared.world) {
                return Err(RunError::BlowUp(why));
            }
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
