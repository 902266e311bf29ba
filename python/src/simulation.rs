//! `polydem.Simulation`: a run driven from Python. It owns a `polydem::run::SteppedRun`, the
//! library's run loop paused between calls, so a run driven with `run` and `step` writes the
//! outputs and checkpoints the `polydem run` command writes; state is read as NumPy arrays
//! (`state.rs`) and changed between steps (`changes.rs`).

use crate::arrays::{optional_vector, vector, vector_rows};
use crate::changes::{self, NewBody};
use crate::errors::{self, value_error};
use crate::observer::Observer;
use crate::scene_source::{self, DICT_FILE};
use crate::state::{self, BodyArray};
use numpy::{PyArray1, PyArray2};
use polydem::checkpoint::SceneRecord;
use polydem::run::{Control, ResumeOptions, SteppedRun};
use polydem::World;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A simulation loaded from a scene (a TOML file or a dict with the same keys) and run into an
/// output folder, driven with `run` and `step`.
#[pyclass(module = "polydem")]
pub struct Simulation {
    run: SteppedRun,
    /// Set when Ctrl-C arrives during a run: the run stops with a checkpoint.
    stop: Arc<AtomicBool>,
    notes: Vec<String>,
}

impl Simulation {
    fn world(&self) -> &World {
        self.run.world()
    }

    /// Drives the run to step `target` (moving the run's end there if it lies beyond it).
    fn drive(&mut self, py: Python<'_>, target: u64, progress: bool) -> PyResult<()> {
        if target > self.run.end_step() {
            let dt = self.world().time_step();
            self.run.prepared_mut().duration = target as f64 * dt;
        }
        self.stop.store(false, Ordering::Relaxed);
        let mut observer = Observer::new(progress, Arc::clone(&self.stop));
        let run = &mut self.run;
        let result = py.detach(|| run.advance_to(target, |event| observer.observe(event)));
        observer.finish();
        self.notes.append(&mut observer.notes);
        result.map_err(errors::run_error)?;
        // A Ctrl-C that came as the run ended anyway.
        match observer.interrupt {
            Some(interrupt) => Err(interrupt),
            None => Ok(()),
        }
    }

    /// Steps in `seconds` of simulated time, at least one.
    fn steps_in(&self, seconds: f64) -> PyResult<u64> {
        if !(seconds.is_finite() && seconds > 0.0) {
            return Err(value_error(format!(
                "duration: {seconds} s; give a time > 0"
            )));
        }
        Ok(((seconds / self.world().time_step()).round() as u64).max(1))
    }

    fn id_list(ids: &Bound<'_, PyAny>) -> PyResult<Vec<u64>> {
        let ids = if ids.hasattr("tolist")? {
            ids.call_method0("tolist")?
        } else {
            ids.clone()
        };
        ids.extract()
            .map_err(|_| value_error("ids: give body ids (integers, as in `Simulation.ids`)"))
    }
}

#[pymethods]
impl Simulation {
    /// Loads `scene` (a path to a TOML file, or a dict with the keys of one), builds it (every
    /// check of `polydem check`), and starts its run into the folder `out` (default
    /// `output/<scene name>`), writing the first frame. `threads` overrides the scene's
    /// `simulation.threads` (0: one per core; results do not depend on it); `set` overrides
    /// scene keys as `polydem run --set` does, e.g. `{"material[0].friction": 0.3}`;
    /// `checkpoints=False` writes none. Raises `polydem.SceneError` for a bad scene.
    #[new]
    #[pyo3(signature = (scene, out=None, *, threads=None, set=None, checkpoints=true))]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        out: Option<PathBuf>,
        threads: Option<usize>,
        set: Option<&Bound<'_, PyDict>>,
        checkpoints: bool,
    ) -> PyResult<Self> {
        let overrides = scene_source::overrides(set)?;
        let mut loaded = scene_source::load(py, scene, &overrides)?;
        if let Some(threads) = threads {
            loaded.spec.simulation.threads = threads;
        }
        let record = checkpoints.then(|| {
            SceneRecord::new(loaded.file.clone(), loaded.source.clone()).with_overrides(&overrides)
        });
        let prepared = loaded.build().map_err(|e| errors::scene_error(py, &e))?;
        let out = out.unwrap_or_else(|| {
            let stem = match loaded.file.to_str() {
                Some(DICT_FILE) => "scene".into(),
                _ => loaded.file.file_stem().unwrap_or_default().to_os_string(),
            };
            Path::new("output").join(stem)
        });
        let stop = Arc::new(AtomicBool::new(false));
        let control = Control {
            scene: record,
            stop: Some(Arc::clone(&stop)),
        };
        let mut notes = prepared.notes.clone();
        let run = py
            .detach(|| {
                SteppedRun::start(prepared, &out, control, |event| {
                    if let polydem::run::RunEvent::Note(note) = event {
                        notes.push(note);
                    }
                })
            })
            .map_err(errors::run_error)?;
        Ok(Self { run, stop, notes })
    }

    /// Continues the run in the output folder `out` from its newest checkpoint, as `polydem
    /// resume` does: with a new end time `duration` [s], another `threads` count, or another
    /// scene file `scene` that differs only where a resumed run allows. The motion of walls,
    /// gravity and other changes made from Python are not in the checkpoint's scene: make them
    /// again after resuming.
    #[staticmethod]
    #[pyo3(signature = (out, *, duration=None, threads=None, scene=None, stored_scene=false))]
    fn resume(
        py: Python<'_>,
        out: PathBuf,
        duration: Option<f64>,
        threads: Option<usize>,
        scene: Option<PathBuf>,
        stored_scene: bool,
    ) -> PyResult<Self> {
        let options = ResumeOptions {
            scene,
            threads,
            duration,
            stored_scene,
        };
        let stop = Arc::new(AtomicBool::new(false));
        let control = Control {
            scene: None,
            stop: Some(Arc::clone(&stop)),
        };
        let mut notes = Vec::new();
        let run = py
            .detach(|| {
                SteppedRun::resume(&out, &options, control, |event| {
                    if let polydem::run::RunEvent::Note(note) = event {
                        notes.push(note);
                    }
                })
            })
            .map_err(errors::run_error)?;
        Ok(Self { run, stop, notes })
    }

    /// Runs on for `duration` seconds of simulated time, or to the scene's end if not given
    /// (past the end, the end moves there). Frames, CSV rows, insertions and checkpoints happen
    /// at their own times, as in `polydem run`; at the end the last frame, row and checkpoint
    /// are written. The GIL is released meanwhile. `progress=True` shows a progress bar.
    /// Raises `polydem.RunError` if the run blows up, KeyboardInterrupt (after a checkpoint)
    /// on Ctrl-C.
    #[pyo3(signature = (duration=None, *, progress=false))]
    fn run(&mut self, py: Python<'_>, duration: Option<f64>, progress: bool) -> PyResult<()> {
        let target = match duration {
            None => self.run.end_step().max(self.world().steps_done()),
            Some(seconds) => self.world().steps_done() + self.steps_in(seconds)?,
        };
        self.drive(py, target, progress)
    }

    /// Takes `n` time steps (as `run` does, outputs included).
    #[pyo3(signature = (n=1, *, progress=false))]
    fn step(&mut self, py: Python<'_>, n: u64, progress: bool) -> PyResult<()> {
        let target = self.world().steps_done() + n;
        self.drive(py, target, progress)
    }

    /// Writes a checkpoint of the run now into `out/checkpoints/` (the two newest are kept) and
    /// returns its path; `Simulation.resume(out)` continues from it.
    fn checkpoint(&mut self) -> PyResult<String> {
        let path = self
            .run
            .checkpoint(|_| {})
            .map_err(errors::run_error)?
            .ok_or_else(|| value_error("this simulation was made with checkpoints=False"))?;
        Ok(path.display().to_string())
    }

    /// Simulated time [s].
    #[getter]
    fn time(&self) -> f64 {
        self.world().time()
    }

    /// Time steps taken since the run started.
    #[getter]
    fn steps(&self) -> u64 {
        self.world().steps_done()
    }

    /// The time step [s].
    #[getter]
    fn time_step(&self) -> f64 {
        self.world().time_step()
    }

    /// The time the run ends at [s] (the scene's duration, or later if run past it).
    #[getter]
    fn end_time(&self) -> f64 {
        self.run.prepared().duration
    }

    /// The step at which the run ends (`end_time` over the time step).
    #[getter]
    fn end_step(&self) -> u64 {
        self.run.end_step()
    }

    /// The output folder.
    #[getter]
    fn out(&self) -> String {
        self.run.output().dir().display().to_string()
    }

    /// What loading and running reported that the user should know (welded mesh vertices, an
    /// earlier run's files removed from the output folder, …).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// Worker threads of the run's parallel loops.
    #[getter]
    fn threads(&self) -> usize {
        self.world().threads()
    }

    /// Gravity [m/s²] as (gx, gy, gz). Setting it replaces the scene's gravity (and gravity
    /// table) from now on; the change of potential energy is booked as `gravity_work`.
    #[getter]
    fn gravity(&self) -> (f64, f64, f64) {
        self.world().gravity().into()
    }

    #[setter]
    fn set_gravity(&mut self, gravity: &Bound<'_, PyAny>) -> PyResult<()> {
        let g = vector(gravity, "gravity")?;
        self.run.prepared_mut().world.set_gravity(g);
        Ok(())
    }

    /// Names of the materials, by their number (`material_ids`).
    #[getter]
    fn material_names(&self) -> Vec<String> {
        self.world()
            .materials()
            .iter()
            .map(|m| m.name.clone())
            .collect()
    }

    /// Names of the scene's shapes (`[shape.NAME]`), for `insert(shape=…)`.
    #[getter]
    fn shape_names(&self) -> Vec<String> {
        self.run
            .prepared()
            .shape_names
            .iter()
            .map(|(n, _)| n.clone())
            .collect()
    }

    /// Names of the walls: planes first, then mesh walls, as in `wall_forces.csv`.
    #[getter]
    fn wall_names(&self) -> Vec<String> {
        self.run.prepared().output.wall_names.clone()
    }

    fn __len__(&self) -> usize {
        self.world().bodies().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "<polydem.Simulation: {} bodies, t = {:.6} s of {} s, step {}, output '{}'>",
            self.world().bodies().len(),
            self.world().time(),
            self.run.prepared().duration,
            self.world().steps_done(),
            self.run.output().dir().display()
        )
    }

    /// Body ids (N,), uint64: stable over the run, while the order of the bodies in the arrays
    /// changes (the run sorts them in space); every per-body array is in this order.
    #[getter]
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        PyArray1::from_vec(py, self.world().bodies().id.clone())
    }

    /// Positions of the centres of mass (N, 3) [m].
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state::body_vectors(py, self.world(), BodyArray::Positions)
    }

    /// Orientations (N, 4) as quaternions (w, x, y, z) of the principal frame, as in the VTK
    /// output.
    #[getter]
    fn orientations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state::orientations(py, self.world())
    }

    /// Velocities (N, 3) [m/s].
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state::body_vectors(py, self.world(), BodyArray::Velocities)
    }

    /// Angular velocities (N, 3) [rad/s].
    #[getter]
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state::body_vectors(py, self.world(), BodyArray::AngularVelocities)
    }

    /// Contact forces on the bodies (N, 3) [N] (without gravity).
    #[getter]
    fn forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state::body_vectors(py, self.world(), BodyArray::Forces)
    }

    /// Contact torques on the bodies (N, 3) [N m].
    #[getter]
    fn torques<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        state::body_vectors(py, self.world(), BodyArray::Torques)
    }

    /// Bounding radii (N,) [m]: a sphere's radius, a polyhedron's circumscribed radius (the
    /// `radius` of the VTK output).
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.world().bodies().bounding_radius.clone())
    }

    /// Radii of the spheres of equal volume (N,) [m].
    #[getter]
    fn equivalent_radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.world().bodies().equivalent_radius.clone())
    }

    /// Masses (N,) [kg].
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.world().bodies().mass.clone())
    }

    /// Shape numbers (N,), uint32: entries of the run's shape table (spheres of each radius
    /// and the polyhedral shapes).
    #[getter]
    fn shape_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        PyArray1::from_vec(py, self.world().bodies().shape.clone())
    }

    /// Material numbers (N,), uint32: indices into `material_names`.
    #[getter]
    fn material_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        PyArray1::from_vec(py, self.world().bodies().material.clone())
    }

    /// The contacts that touch now: a dict of arrays, `bodies` (M, 2) int64 body ids (the second
    /// −1 for a wall), `wall` (M,) the wall's number as in `wall_names` (−1 between bodies),
    /// `points`, `normals` (from the partner towards the first body) and `forces` (on the first
    /// body) (M, 3), `normal_force` and `overlap` (M,).
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        state::contacts(py, self.world())
    }

    /// The energy ledger now, under the column names of `energy.csv` (J; `contacts` and
    /// `bodies` as counts).
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        state::energy(py, self.world())
    }

    /// The loads on the walls (planes first, then mesh walls): `names`, `force` (W, 3) [N] the
    /// bodies' contact force on each wall now, `impulse` and `angular_impulse` (W, 3) since the
    /// start (`wall_forces.csv` holds their changes over each interval divided by it), `work`
    /// [J] of the moving walls on the bodies.
    fn wall_loads<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        state::wall_loads(py, self.world(), &self.run.prepared().output.wall_names)
    }

    /// The flow meters by name: `mass` [kg] and `bodies` that have passed since the start (net).
    fn flow<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        state::flow(py, self.world())
    }

    /// Makes mesh wall `wall` (its number among the mesh walls, or its name) translate at
    /// `velocity` (vx, vy, vz) [m/s] from now on, reached linearly over `ramp` seconds (default:
    /// one time step). Where the wall is now does not change.
    #[pyo3(signature = (wall, velocity, *, ramp=None))]
    fn set_wall_velocity(
        &mut self,
        wall: &Bound<'_, PyAny>,
        velocity: &Bound<'_, PyAny>,
        ramp: Option<f64>,
    ) -> PyResult<()> {
        let wall = changes::mesh_wall_index(&self.run, wall)?;
        let velocity = vector(velocity, "velocity")?;
        changes::set_wall_velocity(&mut self.run, wall, velocity, ramp)
    }

    /// Makes mesh wall `wall` turn at `rpm` revolutions per minute from now on, reached
    /// linearly over `ramp` seconds (default: one time step). A wall that has no rotation axis
    /// in its scene needs one: `axis` (a direction) through `axis_point` (default the origin).
    #[pyo3(signature = (wall, rpm, *, axis=None, axis_point=None, ramp=None))]
    fn set_wall_rpm(
        &mut self,
        wall: &Bound<'_, PyAny>,
        rpm: f64,
        axis: Option<&Bound<'_, PyAny>>,
        axis_point: Option<&Bound<'_, PyAny>>,
        ramp: Option<f64>,
    ) -> PyResult<()> {
        let wall = changes::mesh_wall_index(&self.run, wall)?;
        let axis = match axis {
            None => None,
            Some(axis) => {
                let point = match axis_point {
                    Some(p) => vector(p, "axis_point")?,
                    None => polydem::math::DVec3::ZERO,
                };
                Some((point, vector(axis, "axis")?))
            }
        };
        changes::set_wall_rpm(&mut self.run, wall, rpm, axis, ramp)
    }

    /// Sets the velocities (K, 3) [m/s], and angular velocities (K, 3) [rad/s] if given, of the
    /// bodies with these `ids`; the kinetic energy given or taken is booked as `inserted`.
    #[pyo3(signature = (ids, velocities, angular_velocities=None))]
    fn set_velocities(
        &mut self,
        ids: &Bound<'_, PyAny>,
        velocities: &Bound<'_, PyAny>,
        angular_velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let ids = Self::id_list(ids)?;
        let velocities = vector_rows(velocities, "velocities")?;
        let spins = angular_velocities
            .map(|w| vector_rows(w, "angular_velocities"))
            .transpose()?;
        changes::set_velocities(&mut self.run, &ids, &velocities, spins.as_deref())
    }

    /// Inserts a body at `position` (its centre of mass) [m]: a sphere of `radius` [m], or a
    /// shape of the scene by name (`shape_names`; turned by `orientation`, a quaternion (w, x,
    /// y, z) of its principal frame). Its energy is booked as brought in. Nothing checks that
    /// it is clear of other bodies and walls. Returns its id.
    #[pyo3(signature = (position, *, material, radius=None, shape=None,
                        velocity=None, angular_velocity=None,
                        orientation=(1.0, 0.0, 0.0, 0.0)))]
    #[allow(clippy::too_many_arguments)]
    fn insert(
        &mut self,
        position: &Bound<'_, PyAny>,
        material: &str,
        radius: Option<f64>,
        shape: Option<&str>,
        velocity: Option<&Bound<'_, PyAny>>,
        angular_velocity: Option<&Bound<'_, PyAny>>,
        orientation: (f64, f64, f64, f64),
    ) -> PyResult<u64> {
        let new = NewBody {
            position: vector(position, "position")?,
            radius,
            shape,
            material,
            velocity: optional_vector(velocity, "velocity")?,
            angular_velocity: optional_vector(angular_velocity, "angular_velocity")?,
            orientation: orientation.into(),
        };
        changes::insert(&mut self.run, new)
    }

    /// Removes the bodies with these `ids` and their contacts; their energy is booked as
    /// carried out (`removed`).
    fn remove(&mut self, ids: &Bound<'_, PyAny>) -> PyResult<()> {
        let ids = Self::id_list(ids)?;
        changes::remove(&mut self.run, &ids)
    }
}
