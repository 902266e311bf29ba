//! Scene files: reading, validating, and building a [`World`] from them.
//!
//! Everything a user can get wrong is checked here, before any output is written, and reported
//! with the file, the line and key, and what is allowed (see [`SceneError`]).

// A scene error is built once, when loading fails; its size costs nothing worth boxing for.
#![allow(clippy::result_large_err)]

mod build;
mod error;
pub mod format;
pub mod insert;
pub mod overrides;
mod prepared;
pub mod shapes;
mod time_step;
mod validate;
mod wall_sides;
pub mod walls;

pub use error::{KeyPath, SceneError};
pub use prepared::{InsertionReport, Prepared, ScheduledInsertion};
pub use time_step::MAX_OVERLAP;

use crate::body::BodyInit;
use crate::contact_law::NormalLaw;
use crate::flow::{FlowMeter, FlowSurface};
use crate::material::{Material, PairOverride, PairTable};
use crate::math::{DQuat, DVec3};
use crate::shape::{Shape, Sphere};
use crate::time_table::TimeTable;
use crate::timestep;
use crate::wall::Plane;
use crate::world::{World, WorldConfig};
use format::{NormalModel, SceneFile};
use insert::Placed;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A scene file read and checked for form, not yet built.
#[derive(Debug)]
pub struct Scene {
    pub file: PathBuf,
    pub source: String,
    pub spec: SceneFile,
}

impl Scene {
    /// Reads and parses a scene file.
    pub fn load(file: &Path) -> Result<Self, SceneError> {
        Self::load_with(file, &[])
    }

    /// Reads a scene file with some of its keys set otherwise (see [`overrides`]); the scene's
    /// `source` is then the edited text, which is what checkpoints store.
    pub fn load_with(file: &Path, set: &[overrides::Override]) -> Result<Self, SceneError> {
        let bytes = std::fs::read(file).map_err(|source| SceneError::Read {
            file: file.to_path_buf(),
            source,
        })?;
        let source = String::from_utf8(bytes).map_err(|e| SceneError::not_utf8(file, &e))?;
        let source = overrides::apply(&source, set).map_err(|message| SceneError::Override {
            file: file.to_path_buf(),
            message,
        })?;
        Self::parse(file, source)
    }

    /// Parses scene text; `file` names it in messages.
    pub fn parse(file: &Path, source: String) -> Result<Self, SceneError> {
        let spec: SceneFile =
            toml::from_str(&source).map_err(|e| SceneError::from_toml(file, &source, &e))?;
        let mut scene = Self {
            file: file.to_path_buf(),
            source,
            spec,
        };
        scene.read_inlet_faces()?;
        validate::check(&scene)?;
        Ok(scene)
    }

    /// Reads the faces of inlets given as mesh files, and sets their centre and normal.
    fn read_inlet_faces(&mut self) -> Result<(), SceneError> {
        for n in 0..self.spec.insertions.len() {
            let Some(inlet) = &self.spec.insertions[n].inlet else {
                continue;
            };
            let Some(file) = &inlet.file else { continue };
            let key = |k: &str| KeyPath::entry("insert", n).key(k);
            if inlet.centre.is_some() || inlet.normal.is_some() || inlet.side.is_some() {
                let k = match (inlet.centre, inlet.normal) {
                    (Some(_), _) => "inlet.centre",
                    (None, Some(_)) => "inlet.normal",
                    _ => "inlet.side",
                };
                return Err(self.error(
                    key(k),
                    "a face from a `file` has its centre and normal from the file (the side its \
                     triangles face; `flip = true` turns it): leave out `centre`, `normal` and \
                     `side`",
                ));
            }
            let path = shapes::scene_folder(self).join(file);
            let mesh = crate::io::mesh::read_mesh(&path, 1.0)
                .map_err(|e| self.error(key("inlet.file"), e.to_string()))?;
            let (face, centre, normal) = insert::flat_face(&mesh, inlet.flip)
                .map_err(|why| self.error(key("inlet.file"), format!("'{file}': {why}")))?;
            let inlet = self.spec.insertions[n]
                .inlet
                .as_mut()
                .expect("an inlet, matched above");
            inlet.face = Some(std::sync::Arc::new(face));
            inlet.centre = Some(centre.to_array());
            inlet.normal = Some(normal.to_array());
        }
        Ok(())
    }

    pub(crate) fn error(&self, key: KeyPath, message: impl Into<String>) -> SceneError {
        SceneError::invalid(&self.file, &self.source, key, message)
    }

    fn material_index(&self, name: &str, key: KeyPath) -> Result<u32, SceneError> {
        self.spec
            .materials
            .iter()
            .position(|m| m.name == name)
            .map(|i| i as u32)
            .ok_or_else(|| {
                let known: Vec<_> = self
                    .spec
                    .materials
                    .iter()
                    .map(|m| m.name.as_str())
                    .collect();
                self.error(
                    key,
                    format!("no material named '{name}'; the scene defines {known:?}"),
                )
            })
    }
}
