//! Checkpoints: a run's complete state on disk, from which `polydem resume` continues it exactly as
//! if it had never stopped (bit for bit, for any thread count).
//!
//! A checkpoint holds the scene file's text (the world is rebuilt from it, so meshes and shapes
//! need not be stored), a fingerprint of what the scene built from other files (meshes, shapes:
//! a changed STL is noticed), the world's state ([`WorldState`]: bodies, contacts with their
//! history, walls' time, energy ledger, flow meters, neighbour search) and the run's progress
//! (outputs written, insertions to come, the output series so far). `file.rs` is the format,
//! `folder.rs` where checkpoints live and which are kept, `scene_changes.rs` which changes of the
//! scene a resumed run accepts.

mod file;
mod folder;
mod scene_changes;

pub use file::{fnv1a, read, write, CheckpointError, FORMAT_VERSION};
pub use folder::{checkpoint_path, checkpoints_in, folder, latest, write_keeping_two, Latest};
pub use scene_changes::{change_allowed, changed_keys, ALLOWED_CHANGES};

use crate::io::output::RunOutput;
use crate::shape::Shape;
use crate::world::WorldState;
use crate::World;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Everything a resumed run needs. A run writes it with its world's state borrowed
/// (`Checkpoint<WorldStateRef>`, see [`crate::world::WorldStateRef`]: the same bytes) and reads it
/// back owned.
#[derive(Serialize, Deserialize)]
pub struct Checkpoint<W = WorldState> {
    /// The polydem that wrote it (for messages; the format version decides what can be read).
    pub polydem_version: String,
    pub scene: SceneRecord,
    /// See [`fingerprint`].
    pub fingerprint: u64,
    pub world: W,
    pub progress: RunProgress,
}

/// The scene a run was started from.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneRecord {
    /// The scene file, as an absolute path where it can be found (files it names are found
    /// relative to its folder, whatever folder `resume` is called from).
    pub file: PathBuf,
    /// The text the run was built from: the file's, with `overrides` applied.
    pub text: String,
    /// [`fnv1a`] of `text`.
    pub hash: u64,
    /// The command line's `--set KEY=VALUE`s (a resumed run applies them to a new scene file too).
    #[serde(default)]
    pub overrides: Vec<String>,
}

impl SceneRecord {
    pub fn new(file: PathBuf, text: String) -> Self {
        let hash = fnv1a(text.as_bytes());
        let file = std::fs::canonicalize(&file).unwrap_or(file);
        Self {
            file,
            text,
            hash,
            overrides: Vec::new(),
        }
    }

    /// The record of a scene changed by these command-line overrides.
    pub fn with_overrides(mut self, overrides: &[impl ToString]) -> Self {
        self.overrides = overrides.iter().map(ToString::to_string).collect();
        self
    }
}

/// How far a run has come, beyond the world's own state.
#[derive(Serialize, Deserialize)]
pub struct RunProgress {
    /// The insertions still to come. (The next frame and checkpoint follow from the step.)
    pub schedule: Vec<ScheduleRecord>,
    /// The output series written so far.
    pub output: RunOutput,
}

/// The state of one scheduled `[[insert]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScheduleRecord {
    /// Which `[[insert]]` of the scene (from 0).
    pub index: usize,
    /// Simulated time of its next insertion [s].
    pub next_time: f64,
    /// Insertions it has done.
    pub done: u64,
}

/// A hash of what a scene builds from files other than itself and what checkpoints do not store:
/// the polyhedral shapes (`templates`) and the walls. Equal fingerprints mean a rebuilt world
/// has the geometry the checkpoint's bodies and contacts were computed with.
pub fn fingerprint(world: &World, templates: &[Shape]) -> u64 {
    let mut bytes: Vec<u8> = Vec::new();
    let mut put = |x: f64| bytes.extend_from_slice(&x.to_bits().to_le_bytes());
    for shape in templates {
        let unit = shape.unit_mass_properties();
        put(unit.volume);
        for v in unit.principal_inertia_per_density.to_array() {
            put(v);
        }
        put(shape.bounding_radius());
        let vertices = match shape {
            Shape::Sphere(_) => &[][..],
            Shape::Convex(p) => p.vertices(),
            Shape::NonConvex(p) => p.vertices(),
        };
        vertices
            .iter()
            .flat_map(|v| v.to_array())
            .for_each(&mut put);
    }
    for plane in world.planes() {
        plane
            .point
            .to_array()
            .into_iter()
            .chain(plane.normal.to_array())
            .for_each(&mut put);
    }
    for wall in world.mesh_walls() {
        wall.vertices()
            .iter()
            .flat_map(|v| v.to_array())
            .for_each(&mut put);
        for t in wall.triangles() {
            t.iter().for_each(|&i| put(i as f64));
        }
    }
    fnv1a(&bytes)
}
