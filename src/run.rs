//! Running a prepared scene to its end: steps, insertions during the run, output at intervals,
//! checkpoints at intervals, at the end and when asked to stop; and resuming from a checkpoint
//! (`run/resume.rs`).

use crate::checkpoint::{
    self, Checkpoint, CheckpointError, RunProgress, SceneRecord, ScheduleRecord,
};
use crate::io::body_values::ShapeNames;
use crate::io::output::RunOutput;
use crate::scene::format::WatchdogMode;
use crate::scene::{InsertionReport, Prepared};
use crate::shape::Shape;
use crate::World;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

mod resume;
mod shared;
mod stepwise;
mod trial;
mod watchdog;

pub use resume::{resume, ResumeOptions};
pub use shared::{SharedCheck, SharedSteps};
pub use stepwise::SteppedRun;
pub use trial::{bodies_to_come, Trial};
pub use watchdog::{too_fast, EnergyWatch, WallSides, ALLOWED_DRIFT};

/// Why a run stopped before its end.
#[derive(Debug)]
pub enum RunError {
    /// Writing the output failed.
    Output(std::io::Error),
    /// The state stopped being finite: the run blew up. The outputs written before stay valid.
    BlowUp(String),
    /// Writing or reading a checkpoint failed.
    Checkpoint(CheckpointError),
    /// The run was asked to stop ([`Control::stop`]) and did, at `time`, after writing
    /// `checkpoint` (if it writes checkpoints) and a last frame `frame` (the particles file of
    /// it; `None` when the step was an output time anyway and its frame is a regular one).
    Interrupted {
        time: f64,
        checkpoint: Option<PathBuf>,
        frame: Option<PathBuf>,
    },
    /// A checkpoint cannot be resumed with this scene: why.
    Resume(String),
    /// The shares of a run on several MPI ranks could not go on: why.
    Ranks(String),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            RunError::Output(e) => write!(f, "{e}"),
            RunError::BlowUp(why) | RunError::Resume(why) | RunError::Ranks(why) => {
                f.write_str(why)
            }
            RunError::Checkpoint(e) => write!(f, "{e}"),
            RunError::Interrupted {
                time,
                checkpoint,
                frame,
            } => {
                write!(f, "interrupted at t = {time:.6e} s")?;
                if let Some(frame) = frame {
                    write!(
                        f,
                        "; the state now is the last frame of the series, '{}' (marked \
                         `polydem_state` = \"interrupted\"; `polydem resume` removes it)",
                        frame.display()
                    )?;
                }
                match checkpoint {
                    Some(path) => write!(
                        f,
                        "; checkpoint written to '{}'; continue with `polydem resume`",
                        path.display()
                    ),
                    None => write!(f, " (no checkpoint)"),
                }
            }
        }
    }
}

impl From<CheckpointError> for RunError {
    fn from(e: CheckpointError) -> Self {
        RunError::Checkpoint(e)
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
    /// Before the first step: the run goes from step `from` to step `to` (the scene's duration).
    Start { from: u64, to: u64 },
    /// After each chunk of steps.
    Progress(&'a World),
    /// After an insertion during the run.
    Inserted(&'a InsertionReport),
    /// After a checkpoint was written.
    Checkpoint(&'a Path),
    /// Something the user should know (a checkpoint that could not be read and was passed over).
    Note(String),
}

/// How a run is steered from outside: checkpoints, and a request to stop.
#[derive(Clone, Default)]
pub struct Control {
    /// The scene the run comes from, stored in its checkpoints; `None`: no checkpoints.
    pub scene: Option<SceneRecord>,
    /// When set (by a signal handler, say), the run stops after the chunk of steps under way,
    /// writes a checkpoint, then a final frame and CSV rows marked as the interrupt's (which
    /// `resume` takes back), and returns [`RunError::Interrupted`].
    pub stop: Option<Arc<AtomicBool>>,
}

/// A run under way: the prepared world, its outputs, and what its checkpoints need.
struct Session<'a> {
    prepared: &'a mut Prepared,
    /// Where the world is stepped when not in `prepared.world` (shares on MPI ranks), and
    /// whether `prepared.world` is behind it (only its clock is current).
    shared: Option<&'a mut dyn SharedSteps>,
    stale: bool,
    /// What the shares' checks found after the last chunk of steps.
    checked: Option<SharedCheck>,
    output: RunOutput,
    control: Control,
    /// The polyhedral shapes the scene built (see [`templates`]).
    templates: Vec<Shape>,
    fingerprint: u64,
    /// Stops a run whose energy ledger no longer closes.
    watch: EnergyWatch,
    /// Whether a warning of the watchdog was given (`watchdog = "warn"`).
    warned: bool,
    /// The closed mesh walls, to find bodies that went through them.
    sides: WallSides,
    /// Whether a warning of a body behind a wall was given (`watchdog = "warn"`).
    warned_sides: bool,
}

/// Steps `prepared.world` to `prepared.duration`, writing a frame at the start and after every
/// output interval, and doing scheduled insertions at their times. Stops with
/// [`RunError::BlowUp`] as soon as the state is no longer finite or the watchdog finds energy
/// growing or a body too fast (checked after every chunk) or a body behind a closed mesh wall
/// (at every output), after writing the state then as a last frame marked as the blow-up.
/// Chunks of steps are short enough for a lively progress display and long enough to keep the
/// per-chunk overhead negligible. Writes no checkpoints: see [`run_with`].
pub fn run(
    prepared: &mut Prepared,
    out_dir: &Path,
    observe: impl FnMut(RunEvent),
) -> Result<RunOutput, RunError> {
    run_with(prepared, out_dir, Control::default(), observe)
}

/// [`run`], with checkpoints (every `prepared.checkpoint_interval`, at the end and when stopped)
/// if `control` names the scene, and stopping when `control.stop` is set.
pub fn run_with(
    prepared: &mut Prepared,
    out_dir: &Path,
    control: Control,
    mut observe: impl FnMut(RunEvent),
) -> Result<RunOutput, RunError> {
    let mut session = start(prepared, out_dir, control, &mut observe)?;
    session.drive(observe)?;
    Ok(session.output)
}

/// [`run_with`] of a world stepped as `shared` (shares on MPI ranks, which every rank built
/// from the same `prepared` scene): this process writes the outputs and checkpoints, from the
/// whole world assembled at each output; bodies inserted during the run are inserted into the
/// whole, from which the shares start again.
pub fn run_shared(
    prepared: &mut Prepared,
    out_dir: &Path,
    control: Control,
    shared: &mut dyn SharedSteps,
    mut observe: impl FnMut(RunEvent),
) -> Result<RunOutput, RunError> {
    let mut session = start(prepared, out_dir, control, &mut observe)?;
    session.shared = Some(shared);
    session.drive(observe)?;
    Ok(session.output)
}

/// A run set up and its first frame written, before its first step: [`run_with`] drives it to
/// the end at once, a [`SteppedRun`] in pieces.
fn start<'a>(
    prepared: &'a mut Prepared,
    out_dir: &Path,
    control: Control,
    observe: &mut impl FnMut(RunEvent),
) -> Result<Session<'a>, RunError> {
    let cleared = crate::io::output::clear_previous_run(out_dir)?;
    if cleared > 0 {
        observe(RunEvent::Note(format!(
            "removed {cleared} files of an earlier run in '{}' (its frames, series and \
             checkpoints)",
            out_dir.display()
        )));
    }
    prepared.world.update_contacts();
    let names = ShapeNames::new(prepared.shape_names.clone());
    let mut output = RunOutput::create(out_dir, &prepared.world, &prepared.output, names)?;
    output.write(&prepared.world)?;
    let templates = templates(prepared);
    let fingerprint = fingerprint(prepared, &templates);
    let watch = EnergyWatch::new(&prepared.world);
    let sides = WallSides::new(&prepared.world);
    Ok(Session {
        prepared,
        shared: None,
        stale: false,
        checked: None,
        output,
        control,
        templates,
        fingerprint,
        watch,
        warned: false,
        sides,
        warned_sides: false,
    })
}

impl Session<'_> {
    /// Runs from the world's current step to the end.
    fn drive(&mut self, observe: impl FnMut(RunEvent)) -> Result<(), RunError> {
        self.drive_until(u64::MAX, observe)
    }

    /// Runs from the world's current step to step `pause` or the end, whichever comes first. A
    /// run paused and driven on writes what it would have written had it not paused: outputs
    /// and checkpoints fall on their own steps, the end's (a last frame, row and checkpoint)
    /// only at the end.
    fn drive_until(
        &mut self,
        pause: u64,
        mut observe: impl FnMut(RunEvent),
    ) -> Result<(), RunError> {
        let total_steps = total_steps(self.prepared);
        let pause = pause.min(total_steps);
        observe(RunEvent::Start {
            from: self.prepared.world.steps_done(),
            to: total_steps,
        });
        let dt = self.prepared.world.time_step();
        // Output k falls on the step nearest k·interval, so outputs stay on the user's times and
        // the last one coincides with the end when the duration is a multiple of the interval.
        // The next one is the first after the current step: what happened at this step (a
        // resumed run's first) is done.
        let schedule =
            |interval: f64| move |k: u64| ((k as f64 * interval / dt).round() as u64).max(k);
        let first = self.prepared.world.steps_done();
        let frame_step = schedule(self.prepared.output_interval);
        let mut next_frame = frame_step(first_after(first, frame_step));
        let row_step = schedule(self.prepared.csv_interval);
        let mut next_row = row_step(first_after(first, row_step));
        let checkpoint_step = self
            .prepared
            .checkpoint_interval
            .filter(|_| self.control.scene.is_some())
            .map(schedule);
        let mut next_checkpoint = checkpoint_step
            .map(|at| at(first_after(self.prepared.world.steps_done(), at)))
            .unwrap_or(u64::MAX);
        while self.prepared.world.steps_done() < pause {
            let next_insertion = self
                .prepared
                .next_insertion_time()
                .map(|t| (t / dt).round() as u64);
            let until = (next_frame.min(next_row).min(pause).min(next_checkpoint)).min(
                next_insertion
                    .unwrap_or(u64::MAX)
                    .max(self.prepared.world.steps_done() + 1),
            );
            let mut stopped = false;
            while self.prepared.world.steps_done() < until && !stopped {
                let chunk = (until - self.prepared.world.steps_done()).min(200);
                if let Some(why) = self.run_steps(chunk)? {
                    return Err(self.blown_up(why));
                }
                if let Some(why) = self.suspect()? {
                    if self.prepared.watchdog == WatchdogMode::Stop {
                        return Err(self.blown_up(why));
                    }
                    // An expert asked to go on: say it once.
                    if !self.warned {
                        self.warned = true;
                        observe(RunEvent::Note(format!(
                            "{why} (`watchdog = \"warn\"`: the run goes on; said once)"
                        )));
                    }
                }
                observe(RunEvent::Progress(&self.prepared.world));
                stopped = self
                    .control
                    .stop
                    .as_ref()
                    .is_some_and(|s| s.load(Ordering::Relaxed));
            }
            let done = self.prepared.world.steps_done();
            let frame_now = done == next_frame || done == total_steps;
            let rows_now = done == next_row || done == total_steps;
            let insert_now = next_insertion.is_some_and(|s| s <= done);
            if frame_now || rows_now || stopped || insert_now || done == next_checkpoint {
                self.sync()?;
            }
            if insert_now {
                for report in self.prepared.insert_due() {
                    observe(RunEvent::Inserted(&report));
                }
                if let Some(shared) = self.shared.as_deref_mut() {
                    shared.scatter(&self.prepared.world, &self.templates)?;
                }
            }
            // Bodies behind closed walls, once per output (a ray cast per body and wall).
            if frame_now || rows_now {
                self.check_wall_sides(&mut observe)?;
            }
            if frame_now {
                self.output.write_frame(&self.prepared.world)?;
                next_frame = frame_step(first_after(done, frame_step));
            }
            if rows_now {
                self.output.write_rows(&self.prepared.world)?;
                next_row = row_step(first_after(done, row_step));
            }
            if stopped {
                // The checkpoint first, so that it records the series without the frame off the
                // output times that follows; a resumed run drops that frame (`rewind`).
                let checkpoint = self.checkpoint(&mut observe)?;
                let frame = if frame_now && rows_now {
                    None
                } else {
                    let w = &self.prepared.world;
                    let state = format!(
                        "interrupted at t = {:.6e} s (step {}): the state at which the run was \
                         stopped by a signal, off the output times; `polydem resume` removes \
                         this frame and continues the series",
                        w.time(),
                        w.steps_done()
                    );
                    let path = self.output.write_marked(
                        w,
                        &state,
                        "interrupted: the state at which a signal stopped the run (removed by polydem resume)",
                        !frame_now,
                        !rows_now,
                    )?;
                    (!frame_now).then_some(path)
                };
                return Err(RunError::Interrupted {
                    time: self.prepared.world.time(),
                    checkpoint,
                    frame,
                });
            }
            if done == next_checkpoint && done < total_steps {
                self.checkpoint(&mut observe)?;
                let at = checkpoint_step.expect("a checkpoint step comes from an interval");
                next_checkpoint = at(first_after(done, at));
            }
        }
        if self.prepared.world.steps_done() < total_steps {
            return Ok(()); // paused
        }
        self.sync()?;
        self.checkpoint(&mut observe)?;
        Ok(())
    }

    /// Takes `n` steps of the world, here or in its shares. Returns why the run blew up if the
    /// state is no longer finite.
    fn run_steps(&mut self, n: u64) -> Result<Option<String>, RunError> {
        let Some(shared) = self.shared.as_deref_mut() else {
            self.prepared.world.run_steps(n);
            return Ok(blow_up(&self.prepared.world));
        };
        let (time, steps) = shared.steps(n)?;
        self.prepared.world.set_clock(time, steps);
        self.stale = true;
        let check = shared.check(self.prepared.speed_limit)?;
        self.checked = Some(check);
        if !check.not_finite {
            return Ok(None);
        }
        self.sync()?;
        Ok(Some(blow_up(&self.prepared.world).unwrap_or_else(|| {
            "the run blew up: a body's state is no longer finite".to_string()
        })))
    }

    /// Why the watchdog finds the run unsound after the steps just taken: the energy ledger
    /// grew, or a body moves too fast.
    fn suspect(&mut self) -> Result<Option<String>, RunError> {
        let limit = self.prepared.speed_limit;
        let Some(check) = self.checked.take() else {
            let w = &self.prepared.world;
            return Ok(self.watch.check(w).or_else(|| too_fast(w, limit)));
        };
        let w = &self.prepared.world;
        let why = self
            .watch
            .check_ledger(&check.energy, w.time(), w.steps_done());
        if why.is_some() || !check.too_fast {
            return Ok(why);
        }
        self.sync()?;
        Ok(too_fast(&self.prepared.world, limit))
    }

    /// Makes `prepared.world` the whole world now, if it is a view of shares behind them.
    fn sync(&mut self) -> Result<(), RunError> {
        let Some(shared) = self.shared.as_deref_mut() else {
            return Ok(());
        };
        if self.stale {
            shared.gather(&mut self.prepared.world)?;
            self.stale = false;
        }
        Ok(())
    }

    /// Stops the run (`watchdog = "stop"`) or warns once (`"warn"`) when a body's centre lies
    /// behind a closed mesh wall.
    fn check_wall_sides(&mut self, observe: &mut impl FnMut(RunEvent)) -> Result<(), RunError> {
        if self.sides.is_empty() {
            return Ok(());
        }
        let Some(why) = self
            .sides
            .check(&self.prepared.world, &self.prepared.output.wall_names)
        else {
            return Ok(());
        };
        if self.prepared.watchdog == WatchdogMode::Stop {
            return Err(self.blown_up(why));
        }
        if !self.warned_sides {
            self.warned_sides = true;
            observe(RunEvent::Note(format!(
                "{why} (`watchdog = \"warn\"`: the run goes on; said once)"
            )));
        }
        Ok(())
    }

    /// The error of a run the watchdog stops: `why`, after writing the state now as the last
    /// frame of every series and the last rows of the CSV files, marked as the blow-up (values
    /// that are no longer finite are written as they are: `NaN`, `inf`).
    fn blown_up(&mut self, why: String) -> RunError {
        let w = &self.prepared.world;
        let state = format!("blow-up: {why}");
        let note = "blow-up: the state at which the watchdog stopped the run";
        match self.output.write_marked(w, &state, note, true, true) {
            Ok(frame) => RunError::BlowUp(format!(
                "{why}\nThe state at the blow-up is the last frame of the series, '{}' (t = \
                 {:.6e} s; its field data `polydem_state` begins with \"blow-up\"), and the last \
                 row of energy.csv; non-finite values are written as NaN or inf.",
                frame.display(),
                w.time()
            )),
            Err(e) => RunError::BlowUp(format!(
                "{why}\n(The state at the blow-up could not be written: {e}.)"
            )),
        }
    }

    /// Writes a checkpoint of the run as it is now, if the run writes checkpoints.
    fn checkpoint(&self, observe: &mut impl FnMut(RunEvent)) -> Result<Option<PathBuf>, RunError> {
        let Some(scene) = &self.control.scene else {
            return Ok(None);
        };
        let p = &*self.prepared;
        let world = p
            .world
            .state_ref(&self.templates)
            .map_err(|e| RunError::Checkpoint(CheckpointError::Encode(e.to_string())))?;
        let progress = RunProgress {
            schedule: p
                .schedule
                .iter()
                .map(|s| ScheduleRecord {
                    index: s.index,
                    next_time: s.next_time,
                    done: s.done,
                })
                .collect(),
            output: self.output.clone(),
        };
        let checkpoint = Checkpoint {
            polydem_version: env!("CARGO_PKG_VERSION").to_string(),
            scene: scene.clone(),
            fingerprint: self.fingerprint,
            world,
            progress,
        };
        let path =
            checkpoint::write_keeping_two(self.output.dir(), p.world.steps_done(), &checkpoint)?;
        observe(RunEvent::Checkpoint(&path));
        Ok(Some(path))
    }
}

/// The first k ≥ 1 whose step `at(k)` comes after `step` (`at` increasing).
fn first_after(step: u64, at: impl Fn(u64) -> u64) -> u64 {
    let mut k = 1;
    // Gallop, then bisect: `at` is about linear, so this takes a few dozen calls at most.
    while at(k) <= step {
        k *= 2;
    }
    let mut lo = k / 2;
    while lo + 1 < k {
        let mid = (lo + k) / 2;
        if at(mid) <= step {
            lo = mid;
        } else {
            k = mid;
        }
    }
    k
}

/// The polyhedral shapes a prepared scene built, in a fixed order: those of the bodies placed at
/// the start, then those of the insertions to come. Checkpoints name shapes by their place here.
pub fn templates(prepared: &Prepared) -> Vec<Shape> {
    let placed = prepared
        .world
        .shapes()
        .iter()
        .filter(|s| !matches!(s, Shape::Sphere(_)))
        .cloned();
    let inserted = prepared
        .schedule
        .iter()
        .filter_map(|s| s.shape.as_ref().map(|b| b.shape.clone()));
    placed.chain(inserted).collect()
}

/// What a checkpoint holds of the files a scene reads, to refuse a resumed run whose files have
/// changed: its shapes and walls (`checkpoint::fingerprint`), and the faces of inlets read from
/// mesh files (they place the bodies still to come).
fn fingerprint(prepared: &Prepared, templates: &[Shape]) -> u64 {
    let base = checkpoint::fingerprint(&prepared.world, templates);
    let corners: Vec<f64> = prepared
        .schedule
        .iter()
        .filter_map(|s| s.spec.inlet.as_ref()?.face.as_ref())
        .flat_map(|f| f.triangles.iter().flatten().flat_map(|v| v.to_array()))
        .collect();
    if corners.is_empty() {
        return base; // as before inlet faces existed
    }
    // FNV-1a over the base and the corners' bits.
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for byte in std::iter::once(base)
        .chain(corners.iter().map(|x| x.to_bits()))
        .flat_map(u64::to_le_bytes)
    {
        h = (h ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Number of steps a prepared scene will take.
pub fn total_steps(prepared: &Prepared) -> u64 {
    (prepared.duration / prepared.world.time_step())
        .round()
        .max(1.0) as u64
}
