//! The world's state as plain data, for checkpoints: everything a run changes, so that a world
//! rebuilt from the same scene and given this state continues exactly as the original would have.
//!
//! What the scene file rebuilds the same way every time is left out: materials and pair laws,
//! planes, the mesh walls' triangles and motion, the domain, the geometry of polyhedral shapes.
//! Polyhedral shapes are named by their place in a list of *templates* (the shapes the scene
//! builds, which bodies share by reference), spheres by their radius. The broad phase's sorted
//! lists are left out too: they only make its next search cheaper, and a fresh broad phase finds
//! the same candidates (the neighbour search keeps when it must search again).

use super::World;
use crate::body::Bodies;
use crate::contact::ContactStore;
use crate::flow::FlowMeter;
use crate::math::DVec3;
use crate::shape::{Shape, Sphere};
use crate::step::{SearchState, WallLoads};
use crate::wall::{MeshWall, WallPose, WallState};
use serde::{Deserialize, Serialize};

/// One entry of the world's shape table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ShapeRecord {
    Sphere(Sphere),
    /// A polyhedron: this entry of the templates.
    Template(u32),
}

/// Everything of a [`World`] that changes during a run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WorldState {
    pub time: f64,
    pub steps_done: u64,
    pub time_step: f64,
    pub gravity: DVec3,
    pub gravity_work: f64,
    pub bodies: Bodies,
    pub shapes: Vec<ShapeRecord>,
    pub dissipated: f64,
    pub energy_inserted: f64,
    pub energy_removed: f64,
    pub bodies_removed: u64,
    pub flow_meters: Vec<FlowMeter>,
    pub contacts: ContactStore,
    pub wall_loads: WallLoads,
    pub wall_time: f64,
    /// Where the mesh walls are at `wall_time` (a resumed run with a changed motion must agree).
    pub wall_poses: Vec<WallPose>,
    pub wall_states: Vec<Option<[WallState; 2]>>,
    pub next_id: u64,
    pub search: SearchState,
    pub forces_current: bool,
    /// See `World::kick_excess` (absent from checkpoints written before it).
    #[serde(default)]
    pub kick_excess: f64,
}

/// Why a state does not fit a world.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RestoreError {
    #[error("shape {entry} of the world is a polyhedron that is none of the scene's shapes")]
    UnknownShape { entry: usize },
    #[error("the checkpoint names polyhedral shape {template}, but the scene builds only {count}")]
    MissingTemplate { template: u32, count: usize },
    #[error(
        "mesh wall {wall} would be {distance:.3e} m away from where the run had it at \
         t = {time:.6} s: a changed motion must agree with the old one until then (give it as a \
         table that changes only after that time, e.g. `rpm_table = [[0, OLD], [{after}, \
         OLD], [LATER, NEW]]`)"
    )]
    WallElsewhere {
        wall: usize,
        time: f64,
        /// `time` rounded up to a microsecond, for the advice.
        after: f64,
        distance: f64,
    },
    #[error(
        "the checkpoint has {saved} {what}, the scene {built}: the scene is not the one the \
         checkpoint was written from"
    )]
    Mismatch {
        what: &'static str,
        saved: usize,
        built: usize,
    },
}

/// The same state as [`WorldState`], borrowed from the world rather than copied: what a
/// checkpoint writes. Serialized, it gives the same bytes as the [`WorldState`] it stands for
/// (the same fields in the same order), so a checkpoint can be written without a second copy of
/// the bodies and contacts (at 65,000 spheres, about 60 MB).
#[derive(Serialize)]
pub struct WorldStateRef<'a> {
    pub time: f64,
    pub steps_done: u64,
    pub time_step: f64,
    pub gravity: DVec3,
    pub gravity_work: f64,
    pub bodies: &'a Bodies,
    pub shapes: Vec<ShapeRecord>,
    pub dissipated: f64,
    pub energy_inserted: f64,
    pub energy_removed: f64,
    pub bodies_removed: u64,
    pub flow_meters: &'a [FlowMeter],
    pub contacts: &'a ContactStore,
    pub wall_loads: &'a WallLoads,
    pub wall_time: f64,
    pub wall_poses: Vec<WallPose>,
    pub wall_states: &'a [Option<[WallState; 2]>],
    pub next_id: u64,
    pub search: SearchState,
    pub forces_current: bool,
    pub kick_excess: f64,
}

impl WorldStateRef<'_> {
    /// The state as owned data.
    pub fn to_owned(&self) -> WorldState {
        WorldState {
            time: self.time,
            steps_done: self.steps_done,
            time_step: self.time_step,
            gravity: self.gravity,
            gravity_work: self.gravity_work,
            bodies: self.bodies.clone(),
            shapes: self.shapes.clone(),
            dissipated: self.dissipated,
            energy_inserted: self.energy_inserted,
            energy_removed: self.energy_removed,
            bodies_removed: self.bodies_removed,
            flow_meters: self.flow_meters.to_vec(),
            contacts: self.contacts.clone(),
            wall_loads: self.wall_loads.clone(),
            wall_time: self.wall_time,
            wall_poses: self.wall_poses.clone(),
            wall_states: self.wall_states.to_vec(),
            next_id: self.next_id,
            search: self.search.clone(),
            forces_current: self.forces_current,
            kick_excess: self.kick_excess,
        }
    }
}

impl World {
    /// The world's state, with polyhedral shapes named by their place in `templates` (compared
    /// by identity: the shapes the scene built, which the bodies share).
    pub fn snapshot(&self, templates: &[Shape]) -> Result<WorldState, RestoreError> {
        Ok(self.state_ref(templates)?.to_owned())
    }

    /// The world's state as [`World::snapshot`] gives it, borrowed where it is large.
    pub fn state_ref(&self, templates: &[Shape]) -> Result<WorldStateRef<'_>, RestoreError> {
        let shapes = self
            .shapes
            .iter()
            .enumerate()
            .map(|(entry, shape)| match shape {
                Shape::Sphere(s) => Ok(ShapeRecord::Sphere(*s)),
                _ => templates
                    .iter()
                    .position(|t| t == shape)
                    .map(|k| ShapeRecord::Template(k as u32))
                    .ok_or(RestoreError::UnknownShape { entry }),
            })
            .collect::<Result<_, _>>()?;
        Ok(WorldStateRef {
            time: self.time,
            steps_done: self.steps_done,
            time_step: self.time_step,
            gravity: self.gravity,
            gravity_work: self.gravity_work,
            bodies: &self.bodies,
            shapes,
            dissipated: self.dissipated,
            energy_inserted: self.energy_inserted,
            energy_removed: self.energy_removed,
            bodies_removed: self.bodies_removed,
            flow_meters: &self.flow_meters,
            contacts: &self.contacts,
            wall_loads: &self.wall_loads,
            wall_time: self.wall_time,
            wall_poses: self.mesh_walls.iter().map(|w| w.pose()).collect(),
            wall_states: &self.wall_states,
            next_id: self.next_id,
            search: self.search.state(),
            forces_current: self.forces_current,
            kick_excess: self.kick_excess,
        })
    }

    /// Puts `state` into this world, which must have been built from the same scene (its walls,
    /// flow meters and `templates`, as in [`World::snapshot`]). The world then continues as the
    /// one the state was taken from, bit for bit.
    pub fn restore(&mut self, state: WorldState, templates: &[Shape]) -> Result<(), RestoreError> {
        let shapes = state
            .shapes
            .iter()
            .map(|record| match record {
                ShapeRecord::Sphere(s) => Ok(Shape::Sphere(*s)),
                ShapeRecord::Template(k) => {
                    templates
                        .get(*k as usize)
                        .cloned()
                        .ok_or(RestoreError::MissingTemplate {
                            template: *k,
                            count: templates.len(),
                        })
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        let counts = [
            ("mesh walls", state.wall_poses.len(), self.mesh_walls.len()),
            (
                "flow meters",
                state.flow_meters.len(),
                self.flow_meters.len(),
            ),
            (
                "moving-wall states",
                state.wall_states.len(),
                if state.wall_states.is_empty() {
                    0
                } else {
                    self.mesh_walls.len()
                },
            ),
        ];
        for (what, saved, built) in counts {
            if saved != built {
                return Err(RestoreError::Mismatch { what, saved, built });
            }
        }
        self.time = state.time;
        self.steps_done = state.steps_done;
        self.time_step = state.time_step;
        self.gravity = state.gravity;
        self.gravity_work = state.gravity_work;
        self.bodies = state.bodies;
        self.drawing = None;
        self.shapes = shapes;
        self.dissipated = state.dissipated;
        self.energy_inserted = state.energy_inserted;
        self.energy_removed = state.energy_removed;
        self.bodies_removed = state.bodies_removed;
        self.flow_meters = state.flow_meters;
        self.contacts = state.contacts;
        self.wall_loads = state.wall_loads;
        self.wall_states = state.wall_states;
        self.next_id = state.next_id;
        self.search.restore(state.search);
        if !self.contacts.in_order(&self.bodies.id) {
            // A checkpoint of a version that oriented body pairs by index: the contacts are
            // turned and sorted as this version keeps them, and found again from there.
            let identity: Vec<u32> = (0..self.bodies.len() as u32).collect();
            self.contacts
                .permute(&identity, &self.bodies.id, &self.bodies.position);
            self.search.invalidate();
        }
        self.forces_current = state.forces_current;
        self.kick_excess = state.kick_excess;
        // The walls' poses follow from their motion and the time.
        self.wall_time = state.wall_time;
        for (n, (wall, saved)) in self
            .mesh_walls
            .iter_mut()
            .zip(&state.wall_poses)
            .enumerate()
        {
            wall.set_time(state.wall_time);
            let distance = farthest_move(wall, saved, &wall.pose());
            // A few ulps of the wall's size: the same motion written another way (a table
            // instead of a constant) may round differently.
            let size = wall.bounds().extent().length().max(f64::MIN_POSITIVE);
            if distance > 1e-12 * size {
                return Err(RestoreError::WallElsewhere {
                    wall: n,
                    time: state.wall_time,
                    after: (state.wall_time * 1e6).ceil() / 1e6,
                    distance,
                });
            }
        }
        Ok(())
    }
}

/// The farthest a corner of the wall's bounding box is between two poses (the most any of its
/// points is, the distance being convex in the point).
pub(super) fn farthest_move(wall: &MeshWall, a: &WallPose, b: &WallPose) -> f64 {
    let bounds = wall.bounds();
    (0..8)
        .map(|k| {
            let pick = |bit: usize, lo: f64, hi: f64| if k & bit == 0 { lo } else { hi };
            let corner = DVec3::new(
                pick(1, bounds.min.x, bounds.max.x),
                pick(2, bounds.min.y, bounds.max.y),
                pick(4, bounds.min.z, bounds.max.z),
            );
            (a.to_world(corner) - b.to_world(corner)).length()
        })
        .fold(0.0, f64::max)
}
