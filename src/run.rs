//! Running a prepared scene to its end, writing output at fixed intervals.

use crate::io::output::RunOutput;
use crate::scene::Prepared;
use std::path::Path;

/// Steps `prepared.world` to `prepared.duration`, writing a frame at the start and after every
/// output interval. `progress` is called after each chunk of steps with the world, so a caller can
/// show progress; chunks are short enough for a lively display and long enough to keep the
/// per-chunk overhead negligible.
pub fn run(
    prepared: &mut Prepared,
    out_dir: &Path,
    mut progress: impl FnMut(&crate::World),
) -> std::io::Result<RunOutput> {
    let total_steps = total_steps(prepared);
    let world = &mut prepared.world;
    let dt = world.time_step;
    let steps_per_output = ((prepared.output_interval / dt).round() as u64).max(1);
    let mut output = RunOutput::create(out_dir, world)?;
    output.write(world)?;
    let mut next_output = steps_per_output;
    while world.steps_done < total_steps {
        let until = next_output.min(total_steps);
        while world.steps_done < until {
            let chunk = (until - world.steps_done).min(200);
            world.run_steps(chunk);
            progress(world);
        }
        if world.steps_done == next_output || world.steps_done == total_steps {
            output.write(world)?;
            next_output += steps_per_output;
        }
    }
    Ok(output)
}

/// Number of steps a prepared scene will take.
pub fn total_steps(prepared: &Prepared) -> u64 {
    (prepared.duration / prepared.world.time_step)
        .round()
        .max(1.0) as u64
}
