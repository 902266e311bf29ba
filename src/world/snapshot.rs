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
use crate::wall::WallState;
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
    pub wall_states: Vec<Option<[WallState; 2]>>,
    pub next_id: u64,
    pub search: SearchState,
    pub forces_current: bool,
}

/// Why a state does not fit a world.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RestoreError {
    #[error("shape {entry} of the world is a polyhedron that is none of the scene's shapes")]
    UnknownShape { entry: usize },
    #[error("the checkpoint names polyhedral shape {template}, but the scene builds only {count}")]
    MissingTemplate { template: u32, count: usize },
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

impl World {
    /// The world's state, with polyhedral shapes named by their place in `templates` (compared
    /// by identity: the shapes the scene built, which the bodies share).
    pub fn snapshot(&self, templates: &[Shape]) -> Result<WorldState, RestoreError> {
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
        Ok(WorldState {
            time: self.time,
            steps_done: self.steps_done,
            time_step: self.time_step,
            gravity: self.gravity,
            bodies: self.bodies.clone(),
            shapes,
            dissipated: self.dissipated,
            energy_inserted: self.energy_inserted,
            energy_removed: self.energy_removed,
            bodies_removed: self.bodies_removed,
            flow_meters: self.flow_meters.clone(),
            contacts: self.contacts.clone(),
            wall_loads: self.wall_loads.clone(),
            wall_time: self.wall_time,
            wall_states: self.wall_states.clone(),
            next_id: self.next_id,
            search: self.search.state(),
            forces_current: self.forces_current,
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
        self.bodies = state.bodies;
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
        self.forces_current = state.forces_current;
        // The walls' poses follow from their motion and the time.
        self.wall_time = state.wall_time;
        for wall in &mut self.mesh_walls {
            wall.set_time(state.wall_time);
        }
        Ok(())
    }
}
