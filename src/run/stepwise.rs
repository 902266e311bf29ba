//! A run driven in pieces: the run loop of [`super::run_with`] paused at any step and driven on,
//! with the world open to changes between the pieces (a loading protocol written in a script:
//! the Python package drives runs this way). Paused and driven on, a run writes what it would
//! have written in one go: frames, rows and checkpoints fall on their own steps.

use super::{Control, EnergyWatch, RunError, RunEvent, Session, SharedSteps, WallSides};
use crate::body::BodyInit;
use crate::checkpoint::SceneRecord;
use crate::io::output::RunOutput;
use crate::scene::Prepared;
use crate::shape::Shape;
use crate::World;
use std::path::{Path, PathBuf};

/// A run that owns its prepared world and is driven step by step ([`SteppedRun::advance_to`]).
pub struct SteppedRun {
    pub(super) prepared: Prepared,
    /// The rest of the run's session; `None` only while a piece is being driven.
    pub(super) rest: Option<Detached>,
}

/// A [`Session`] without its prepared world, kept between the pieces of a [`SteppedRun`].
pub(super) struct Detached {
    pub(super) output: RunOutput,
    pub(super) control: Control,
    pub(super) templates: Vec<Shape>,
    pub(super) fingerprint: u64,
    pub(super) watch: EnergyWatch,
    pub(super) warned: bool,
    pub(super) sides: WallSides,
    pub(super) warned_sides: bool,
}

impl Detached {
    fn of(session: Session<'_>) -> Self {
        Self {
            output: session.output,
            control: session.control,
            templates: session.templates,
            fingerprint: session.fingerprint,
            watch: session.watch,
            warned: session.warned,
            sides: session.sides,
            warned_sides: session.warned_sides,
        }
    }

    fn attach(self, prepared: &mut Prepared) -> Session<'_> {
        Session {
            prepared,
            shared: None,
            stale: false,
            checked: None,
            output: self.output,
            control: self.control,
            templates: self.templates,
            fingerprint: self.fingerprint,
            watch: self.watch,
            warned: self.warned,
            sides: self.sides,
            warned_sides: self.warned_sides,
        }
    }
}

impl SteppedRun {
    /// Starts a run of `prepared` into `out_dir` as [`super::run_with`] does (clearing an earlier
    /// run's files there and writing the first frame), without taking a step.
    pub fn start(
        mut prepared: Prepared,
        out_dir: &Path,
        control: Control,
        mut observe: impl FnMut(RunEvent),
    ) -> Result<Self, RunError> {
        let rest = Detached::of(super::start(&mut prepared, out_dir, control, &mut observe)?);
        Ok(Self {
            prepared,
            rest: Some(rest),
        })
    }

    /// Drives the run to step `step` (counted from the run's start), or to its end if that
    /// comes first: the run loop of [`super::run_with`], outputs, insertions, checkpoints and
    /// watchdog included. At the end it writes the last frame, row and checkpoint.
    pub fn advance_to(&mut self, step: u64, observe: impl FnMut(RunEvent)) -> Result<(), RunError> {
        self.with_session(|session| session.drive_until(step, observe))
    }

    /// Writes a checkpoint now (if the run's [`Control`] names its scene), as a stopped run does;
    /// returns its path.
    pub fn checkpoint(
        &mut self,
        mut observe: impl FnMut(RunEvent),
    ) -> Result<Option<PathBuf>, RunError> {
        self.with_session(|session| session.checkpoint(&mut observe))
    }

    /// The step at which the run ends (its duration over the time step).
    pub fn end_step(&self) -> u64 {
        super::total_steps(&self.prepared)
    }

    pub fn prepared(&self) -> &Prepared {
        &self.prepared
    }

    /// The prepared world, to change between pieces: the world through the `World` methods
    /// that keep the energy ledger (`set_gravity`, `set_wall_motion`, `set_velocity`,
    /// `insert_body`, `remove_bodies`), the duration to run on further.
    pub fn prepared_mut(&mut self) -> &mut Prepared {
        &mut self.prepared
    }

    pub fn world(&self) -> &World {
        &self.prepared.world
    }

    /// Inserts a body during the run (its energy booked as brought in, see
    /// `World::insert_body`) and returns its index. A polyhedron must have one of the shapes the
    /// scene built, which checkpoints name by their place; any sphere will do.
    pub fn insert_body(&mut self, body: BodyInit) -> Result<usize, String> {
        let rest = self
            .rest
            .as_ref()
            .expect("a run is detached between pieces");
        let known = matches!(body.shape, Shape::Sphere(_)) || rest.templates.contains(&body.shape);
        if !known && rest.control.scene.is_some() {
            return Err("a polyhedron inserted into a run with checkpoints must have a shape that                         the scene's bodies or insertions already use"
                .into());
        }
        Ok(self.prepared.world.insert_body(body))
    }

    /// The output series written so far.
    pub fn output(&self) -> &RunOutput {
        &self
            .rest
            .as_ref()
            .expect("a run is detached between pieces")
            .output
    }

    /// The prepared world at the end, with the outputs written.
    pub fn into_parts(self) -> (Prepared, RunOutput) {
        let rest = self.rest.expect("a run is detached between pieces");
        (self.prepared, rest.output)
    }

    /// The scene the run goes on with, as its checkpoints store it (`None`: no checkpoints).
    pub fn scene_record(&self) -> Option<&SceneRecord> {
        self.rest.as_ref()?.control.scene.as_ref()
    }

    /// The polyhedral shapes of the run, in the order its checkpoints name them
    /// ([`super::templates`]).
    pub fn templates(&self) -> &[Shape] {
        &self
            .rest
            .as_ref()
            .expect("a run is detached between pieces")
            .templates
    }

    /// [`SteppedRun::advance_to`] with the world stepped as `shared` (shares on MPI ranks), which
    /// starts from this run's world as it is now (`SharedSteps::scatter`); this run's world is
    /// the whole again when the piece ends.
    pub fn advance_shared(
        &mut self,
        step: u64,
        shared: &mut dyn SharedSteps,
        observe: impl FnMut(RunEvent),
    ) -> Result<(), RunError> {
        shared.scatter(&self.prepared.world, self.templates())?;
        let rest = self.rest.take().expect("a run is detached between pieces");
        let mut session = rest.attach(&mut self.prepared);
        session.shared = Some(shared);
        let result = session
            .drive_until(step, observe)
            .and_then(|_| session.sync());
        session.shared = None;
        self.rest = Some(Detached::of(session));
        result
    }

    fn with_session<T>(&mut self, f: impl FnOnce(&mut Session<'_>) -> T) -> T {
        let rest = self.rest.take().expect("a run is detached between pieces");
        let mut session = rest.attach(&mut self.prepared);
        let result = f(&mut session);
        self.rest = Some(Detached::of(session));
        result
    }
}
