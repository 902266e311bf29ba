//! Scene files: reading, validating, and building a [`World`] from them.
//!
//! Everything a user can get wrong is checked here, before any output is written, and reported
//! with the file, the line and key, and what is allowed (see [`SceneError`]).

// A scene error is built once, when loading fails; its size costs nothing worth boxing for.
#![allow(clippy::result_large_err)]

mod error;
pub mod format;
pub mod insert;
pub mod overrides;
pub mod shapes;
mod time_step;
mod validate;
mod wall_sides;
pub mod walls;

pub use error::{KeyPath, SceneError};
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

/// A world ready to run, with the facts the run needs and the user should be told.
pub struct Prepared {
    pub world: World,
    pub duration: f64,
    /// Simulated seconds between VTK frames.
    pub output_interval: f64,
    /// Simulated seconds between rows of the CSV series (`energy.csv`, `wall_forces.csv`,
    /// `flow.csv`).
    pub csv_interval: f64,
    /// Simulated seconds between checkpoints (`[output] checkpoint_interval`); `None`: only at
    /// the end and when interrupted.
    pub checkpoint_interval: Option<f64>,
    /// No body goes faster in a sound run [m/s]: ten times the fastest impact the scene can
    /// bring (initial and insertion speeds, a fall across the whole scene, walls' surfaces).
    pub speed_limit: f64,
    /// Whether the watchdog stops the run or warns (`[simulation] watchdog`).
    pub watchdog: format::WatchdogMode,
    /// The stable-step estimate, and whether the step was chosen automatically.
    pub estimate: timestep::Estimate,
    pub automatic_time_step: bool,
    /// Insertions still to come during the run, in file order.
    pub schedule: Vec<ScheduledInsertion>,
    /// What the run writes beyond the defaults.
    pub output: crate::io::output::OutputOptions,
    /// What building the scene repaired or decided that the user should know (welded mesh
    /// vertices, turned triangles).
    pub notes: Vec<String>,
    /// The scene's `[shape.NAME]`s, by name (for the outputs' `shape` numbers).
    pub shape_names: Vec<(String, Shape)>,
}

/// An `[[insert]]` that happens during the run, once or repeatedly.
#[derive(Clone, Debug)]
pub struct ScheduledInsertion {
    /// Which `[[insert]]` of the file (from 0).
    pub index: usize,
    pub spec: format::InsertSpec,
    pub material: u32,
    /// The shape inserted, or `None` for spheres of the spec's radius or distribution.
    pub shape: Option<shapes::BuiltShape>,
    /// Simulated time of the next insertion [s].
    pub next_time: f64,
    /// Insertions done so far (varies the random stream of repeats).
    pub done: u64,
}

/// What one insertion during the run did.
#[derive(Clone, Debug, PartialEq)]
pub struct InsertionReport {
    pub index: usize,
    pub time: f64,
    pub inserted: usize,
    /// Set when fewer spheres than asked for fitted: why.
    pub shortfall: Option<String>,
}

impl Prepared {
    /// Simulated time of the next scheduled insertion, if any.
    pub fn next_insertion_time(&self) -> Option<f64> {
        self.schedule.iter().map(|s| s.next_time).reduce(f64::min)
    }

    /// Does every insertion due at the world's current time (to within half a step), placing the
    /// spheres that fit among the bodies present now.
    pub fn insert_due(&mut self) -> Vec<InsertionReport> {
        let world = &mut self.world;
        let now = world.time() + 0.5 * world.time_step();
        let mut reports = Vec::new();
        for s in self.schedule.iter_mut().filter(|s| s.next_time <= now) {
            let existing: Vec<Placed> = (0..world.bodies().len())
                .map(|i| Placed {
                    centre: world.bodies().position[i],
                    radius: world.bodies().bounding_radius[i],
                })
                .collect();
            let planes = plane_obstacles(world.planes());
            let size = s.shape.as_ref().map(shape_size);
            let (placed, shortfall) = match insert::insert(
                &s.spec,
                size,
                &existing,
                &planes,
                world.mesh_walls(),
                s.done,
            ) {
                Ok(placed) => (placed, None),
                Err(e) => (e.placed, Some(e.message)),
            };
            let mut orientations = orientation_stream(&s.spec, s.done);
            for p in &placed {
                world.insert_body(inserted_body(
                    &s.spec,
                    s.shape.as_ref(),
                    s.material,
                    p,
                    &mut orientations,
                ));
            }
            reports.push(InsertionReport {
                index: s.index,
                time: world.time(),
                inserted: placed.len(),
                shortfall,
            });
            s.done += 1;
            let until = s.spec.until.unwrap_or(f64::INFINITY);
            s.next_time = match s.spec.every {
                Some(every) if s.next_time + every <= until + 0.5 * world.time_step() => {
                    s.next_time + every
                }
                _ => f64::INFINITY,
            };
        }
        self.schedule.retain(|s| s.next_time.is_finite());
        reports
    }
}

fn shape_size(shape: &shapes::BuiltShape) -> insert::ShapeSize {
    insert::ShapeSize {
        bounding_radius: shape.shape.bounding_radius(),
        volume: shape.shape.unit_mass_properties().volume,
    }
}

/// The random orientations of one insertion: its own stream, so that turning random orientation
/// on or off does not move the bodies.
fn orientation_stream(spec: &format::InsertSpec, repetition: u64) -> crate::rng::SplitMix64 {
    crate::rng::SplitMix64::new(
        spec.seed ^ 0x0123_4567_89AB_CDEF ^ repetition.wrapping_mul(0x9E37_79B9_7F4A_7C15),
    )
}

/// The body an insertion puts at a placed bounding sphere.
fn inserted_body(
    spec: &format::InsertSpec,
    shape: Option<&shapes::BuiltShape>,
    material: u32,
    placed: &Placed,
    orientations: &mut crate::rng::SplitMix64,
) -> BodyInit {
    let velocity = DVec3::from(spec.initial_velocity());
    match shape {
        None => sphere(placed.radius, material, placed.centre, velocity),
        Some(built) => {
            let rotation = if spec.random_orientation {
                shapes::random_rotation(orientations)
            } else {
                DQuat::IDENTITY
            };
            BodyInit {
                shape: built.shape.clone(),
                material,
                // The bounding sphere is centred on the centre of mass.
                position: placed.centre,
                orientation: (rotation * built.principal).normalize(),
                velocity,
                angular_velocity: DVec3::ZERO,
            }
        }
    }
}

fn plane_obstacles(planes: &[Plane]) -> Vec<insert::PlaneObstacle> {
    planes
        .iter()
        .map(|p| insert::PlaneObstacle {
            point: p.point,
            normal: p.normal,
        })
        .collect()
}

/// Whether `name` can head CSV columns as it is: letters, digits, `_` and `-`.
fn usable_as_column(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
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

    /// Builds the world: materials and their pairs, walls, particles and insertions; checks the
    /// initial overlaps and the time step.
    pub fn build(&self) -> Result<Prepared, SceneError> {
        let spec = &self.spec;
        let materials: Vec<Material> = spec
            .materials
            .iter()
            .map(|m| Material {
                name: m.name.clone(),
                density: m.density,
                youngs_modulus: m.youngs_modulus,
                poisson_ratio: m.poisson_ratio,
                restitution: m.restitution,
                friction: m.friction,
                rolling_friction: m.rolling_friction,
            })
            .collect();
        let normal = match spec.contact.normal {
            NormalModel::Hertz => NormalLaw::Hertz,
            NormalModel::Linear => NormalLaw::Linear {
                stiffness: spec.contact.stiffness.ok_or_else(|| {
                    self.error(
                        KeyPath::table("contact").key("stiffness"),
                        "normal = \"linear\" needs `stiffness` [N/m]",
                    )
                })?,
            },
        };
        let mut overrides = Vec::new();
        for (n, p) in spec.pairs.iter().enumerate() {
            let key = KeyPath::entry("pair", n).key("materials");
            let a = self.material_index(&p.materials[0], key.clone())?;
            let b = self.material_index(&p.materials[1], key)?;
            overrides.push((
                (a as usize, b as usize),
                PairOverride {
                    restitution: p.restitution,
                    friction: p.friction,
                    rolling_friction: p.rolling_friction,
                },
            ));
        }
        let pair_laws = PairTable::new(
            &materials,
            normal,
            spec.contact.tangential_stiffness_ratio,
            &overrides,
        );

        let mut planes = Vec::new();
        for (n, p) in spec.planes.iter().enumerate() {
            planes.push(Plane {
                point: DVec3::from(p.point),
                normal: DVec3::from(p.normal).normalize(),
                material: self
                    .material_index(&p.material, KeyPath::entry("plane", n).key("material"))?,
            });
        }

        let mesh_walls = walls::build(self)?;
        let shapes = shapes::build(self)?;
        let bodies = self.bodies(&shapes, &plane_obstacles(&planes), &mesh_walls)?;
        let overlapping = self.check_initial_overlaps(&bodies, &planes)?;
        // Sides first: a body behind a wall also overlaps it, and the side is the fault.
        self.check_mesh_wall_sides(&bodies, &mesh_walls, self.falling_direction())?;
        self.check_bodies_behind_closed_walls(&bodies, &mesh_walls)?;
        self.check_mesh_wall_overlaps(&bodies, &mesh_walls)?;
        let mut schedule = Vec::new();
        for (index, i) in spec.insertions.iter().enumerate() {
            if i.time > 0.0 || i.every.is_some() {
                let key = KeyPath::entry("insert", index).key("material");
                let first = i.time > 0.0;
                schedule.push(ScheduledInsertion {
                    index,
                    spec: i.clone(),
                    material: self.material_index(&i.material, key)?,
                    shape: self.shape_of(&shapes, i.shape.as_deref(), index)?,
                    next_time: if first {
                        i.time
                    } else {
                        i.every.unwrap_or(0.0)
                    },
                    done: u64::from(!first),
                });
            }
        }

        let flow_meters = self.flow_meters()?;
        let gravity_table = self.gravity_table()?;
        let gravity = DVec3::from(spec.simulation.gravity());
        // The time step allows for the fastest fall any stage of the run brings.
        let strongest = gravity_table
            .iter()
            .flat_map(|t| t.knots().iter().map(|&(_, g)| g))
            .fold(gravity, |a, g| if g.length() > a.length() { g } else { a });
        let (time_step, estimate, automatic) = self.time_step(time_step::StepInputs {
            bodies: &bodies,
            schedule: &schedule,
            materials: &materials,
            planes: &planes,
            mesh_walls: &mesh_walls,
            law: normal,
            gravity: strongest,
        })?;
        let extent = self.extent(&bodies, &planes, &mesh_walls);
        let impact_speed = self.impact_speed(strongest, &bodies, &mesh_walls);
        self.check_threads()?;
        let world = World::new(WorldConfig {
            time_step,
            gravity,
            materials,
            pair_laws,
            planes,
            broad_phase: spec.simulation.broad_phase,
            skin: spec.simulation.skin,
            threads: spec.simulation.threads,
        })
        .map_err(|e| {
            self.error(
                KeyPath::table("simulation").key("threads"),
                format!("cannot start the worker threads: {e}"),
            )
        })?
        .with_polyhedral_law(spec.contact.polyhedra)
        .with_mesh_walls(mesh_walls)
        .with_flow_meters(flow_meters);
        let world = match gravity_table {
            Some(table) => world.with_gravity_table(table),
            None => world,
        };
        let mut world = match &spec.domain {
            Some(d) => world.with_domain(crate::math::Aabb::new(
                DVec3::from(d.min),
                DVec3::from(d.max),
            )),
            None => world,
        };
        for (init, _) in bodies {
            world.add_body(init);
        }
        // The overlaps present at the start are contacts from the first report on. (Only when
        // there are any: the first step finds the contacts anyway, and finding them here, with
        // the scene's working memory still held, raised the peak memory by a tenth.)
        if overlapping || !world.mesh_walls().is_empty() {
            world.update_contacts();
        }
        // Their springs push bodies apart: the lightest body could take all their energy.
        let release_speed = {
            let b = world.bodies();
            let lightest = b.mass.iter().copied().fold(f64::INFINITY, f64::min);
            let elastic: f64 = world
                .contacts()
                .iter()
                .map(|c| c.report.elastic_energy)
                .sum();
            if lightest.is_finite() && lightest > 0.0 {
                (2.0 * elastic / lightest).sqrt()
            } else {
                0.0
            }
        };
        let speed_limit = (10.0 * impact_speed.max(release_speed)).max(1.0);
        let duration = spec.simulation.duration;
        Ok(Prepared {
            world,
            duration,
            output_interval: spec
                .output
                .vtk_interval
                .or(spec.simulation.output_interval)
                .unwrap_or(duration / 100.0),
            csv_interval: spec
                .output
                .csv_interval
                .or(spec.simulation.output_interval)
                .unwrap_or(duration / 100.0),
            checkpoint_interval: spec.output.checkpoint_interval,
            speed_limit,
            watchdog: spec.simulation.watchdog,
            estimate,
            automatic_time_step: automatic,
            schedule,
            output: crate::io::output::OutputOptions {
                force_network: spec.output.force_network,
                packing_region: spec
                    .output
                    .packing_region
                    .as_ref()
                    .map(|r| crate::math::Aabb::new(DVec3::from(r.min), DVec3::from(r.max))),
                extent,
                wall_names: self.wall_names()?,
            },
            notes: shapes
                .iter()
                .filter_map(|(name, b)| b.note.as_ref().map(|n| format!("[shape.{name}] {n}")))
                .collect(),
            shape_names: shapes
                .iter()
                .map(|(name, b)| (name.clone(), b.shape.clone()))
                .collect(),
        })
    }

    /// Where the scene happens: its bodies at the start, insertion regions, plane walls' points,
    /// mesh walls and the domain (for drawing plane walls as far as that). `None` for a scene of
    /// nothing.
    fn extent(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        planes: &[Plane],
        mesh_walls: &[crate::wall::MeshWall],
    ) -> Option<crate::math::Aabb> {
        use crate::math::Aabb;
        let spec = &self.spec;
        let boxes = bodies
            .iter()
            .map(|(b, _)| Aabb::around_sphere(b.position, b.shape.bounding_radius()))
            .chain(spec.insertions.iter().map(|i| {
                let (lo, hi) = i.bounds();
                Aabb::new(DVec3::from(lo), DVec3::from(hi))
            }))
            .chain(planes.iter().map(|p| Aabb::new(p.point, p.point)))
            .chain(mesh_walls.iter().map(|w| w.bounds()))
            .chain(
                spec.domain
                    .iter()
                    .map(|d| Aabb::new(DVec3::from(d.min), DVec3::from(d.max))),
            );
        boxes.reduce(|a, b| a.union(&b))
    }

    /// Refuses more worker threads than any use of this machine could want (`--threads 100000`
    /// tried to start them all): 16 per core, and at least 64.
    fn check_threads(&self) -> Result<(), SceneError> {
        let threads = self.spec.simulation.threads;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let most = (16 * cores).max(64);
        if threads > most {
            return Err(self.error(
                KeyPath::table("simulation").key("threads"),
                format!(
                    "{threads} threads on a machine with {cores} cores: at most {most} are \
                     allowed, and more than one per core gains nothing; 0 takes one per core"
                ),
            ));
        }
        Ok(())
    }

    /// The direction bodies fall at the start: gravity, or under a gravity table its first
    /// non-zero row (zero if there is none).
    fn falling_direction(&self) -> DVec3 {
        let sim = &self.spec.simulation;
        let first = DVec3::from(sim.gravity());
        if first != DVec3::ZERO {
            return first;
        }
        sim.gravity_table
            .iter()
            .flatten()
            .map(|r| DVec3::new(r[1], r[2], r[3]))
            .find(|g| *g != DVec3::ZERO)
            .unwrap_or(DVec3::ZERO)
    }

    /// `[simulation] gravity_table`, checked.
    fn gravity_table(&self) -> Result<Option<TimeTable<DVec3>>, SceneError> {
        let sim = &self.spec.simulation;
        let Some(rows) = &sim.gravity_table else {
            return Ok(None);
        };
        let key = KeyPath::table("simulation").key("gravity_table");
        if sim.gravity.is_some() {
            return Err(self.error(
                key,
                "give either `gravity` (constant) or `gravity_table`, not both",
            ));
        }
        let knots = rows
            .iter()
            .map(|r| (r[0], DVec3::new(r[1], r[2], r[3])))
            .collect();
        TimeTable::new(knots)
            .map(Some)
            .map_err(|e| self.error(key, format!("{e} (rows are [time, gx, gy, gz])")))
    }

    /// The names of the walls in `wall_forces.csv`: planes first, then mesh walls, each its
    /// `name` or `wallN`; checked to be usable as column heads and distinct.
    fn wall_names(&self) -> Result<Vec<String>, SceneError> {
        let spec = &self.spec;
        let given =
            spec.planes
                .iter()
                .enumerate()
                .map(|(n, p)| (KeyPath::entry("plane", n).key("name"), p.name.as_ref()))
                .chain(
                    spec.mesh_walls.iter().enumerate().map(|(n, w)| {
                        (KeyPath::entry("mesh_wall", n).key("name"), w.name.as_ref())
                    }),
                );
        let mut names: Vec<String> = Vec::new();
        for (w, (key, name)) in given.enumerate() {
            let name = match name {
                None => format!("wall{w}"),
                Some(name) => {
                    if !usable_as_column(name) {
                        return Err(self.error(
                            key,
                            format!(
                                "{name:?}: a wall's name heads its columns in wall_forces.csv; \
                                 use letters, digits, `_` and `-`"
                            ),
                        ));
                    }
                    name.clone()
                }
            };
            if names.contains(&name) {
                return Err(self.error(
                    key,
                    format!("two walls are called {name:?}: give each its own name"),
                ));
            }
            names.push(name);
        }
        Ok(names)
    }

    /// The `[[output.flow_meter]]`s.
    fn flow_meters(&self) -> Result<Vec<FlowMeter>, SceneError> {
        let mut meters: Vec<FlowMeter> = Vec::new();
        for (n, m) in self.spec.output.flow_meters.iter().enumerate() {
            let key = |k: &str| KeyPath::table("output").key(&format!("flow_meter[{n}].{k}"));
            if !usable_as_column(&m.name) {
                return Err(self.error(
                    key("name"),
                    format!(
                        "{:?}: a meter's name heads its columns in flow.csv; use letters, digits, \
                         `_` and `-`",
                        m.name
                    ),
                ));
            }
            if meters.iter().any(|other| other.name == m.name) {
                return Err(self.error(
                    key("name"),
                    format!(
                        "two flow meters are called {:?}: give each its own name",
                        m.name
                    ),
                ));
            }
            let finite = |v: [f64; 3]| crate::math::is_finite_vec(DVec3::from(v));
            let surface = match (m.point, m.normal, m.min, m.max) {
                (Some(point), Some(normal), None, None) => {
                    let normal = DVec3::from(normal)
                        .try_normalize()
                        .filter(|_| finite(point))
                        .ok_or_else(|| {
                            self.error(
                                key("normal"),
                                "point and normal must be finite, the normal non-zero",
                            )
                        })?;
                    FlowSurface::Plane {
                        point: DVec3::from(point),
                        normal,
                    }
                }
                (None, None, Some(min), Some(max)) => {
                    let (lo, hi) = (DVec3::from(min), DVec3::from(max));
                    if !(finite(min) && finite(max)) || lo.cmpge(hi).any() {
                        return Err(self.error(
                            key("max"),
                            "min and max must be finite, max greater than min on every axis",
                        ));
                    }
                    FlowSurface::RegionOutflow(crate::math::Aabb::new(lo, hi))
                }
                _ => {
                    return Err(self.error(
                        key("point"),
                        "give `point` and `normal` (flow through a plane) or `min` and `max` \
                         (flow out of a box), not a mix",
                    ))
                }
            };
            meters.push(FlowMeter::new(m.name.clone(), surface));
        }
        Ok(meters)
    }

    /// Every body the scene places, in file order: single particles, then each insertion. Each
    /// comes with the key that placed it, for messages.
    fn bodies(
        &self,
        shapes: &BTreeMap<String, shapes::BuiltShape>,
        planes: &[insert::PlaneObstacle],
        meshes: &[crate::wall::MeshWall],
    ) -> Result<Vec<(BodyInit, KeyPath)>, SceneError> {
        let mut bodies = Vec::new();
        let mut placed: Vec<Placed> = Vec::new();
        for (n, p) in self.spec.particles.iter().enumerate() {
            let key = KeyPath::entry("particle", n);
            let material = self.material_index(&p.material, key.clone().key("material"))?;
            let position = DVec3::from(p.position);
            let velocity = DVec3::from(p.velocity);
            let mut body = match (p.radius, &p.shape) {
                (Some(radius), None) => sphere(radius, material, position, velocity),
                (None, Some(name)) => {
                    let built = self.named_shape(shapes, name, key.clone().key("shape"))?;
                    let rotation = DQuat::from_scaled_axis(DVec3::from(p.rotation));
                    let (position, orientation) = built.pose(position, rotation);
                    BodyInit {
                        shape: built.shape.clone(),
                        material,
                        position,
                        orientation,
                        velocity,
                        angular_velocity: DVec3::ZERO,
                    }
                }
                _ => {
                    return Err(self.error(
                        key.key("radius"),
                        "give exactly one of `radius` (a sphere) and `shape` (a [shape.NAME])",
                    ))
                }
            };
            body.angular_velocity = DVec3::from(p.angular_velocity);
            placed.push(Placed {
                centre: body.position,
                radius: body.shape.bounding_radius(),
            });
            bodies.push((body, key));
        }
        for (n, spec) in self.spec.insertions.iter().enumerate() {
            if spec.time > 0.0 {
                continue; // happens during the run
            }
            let key = KeyPath::entry("insert", n);
            let material = self.material_index(&spec.material, key.clone().key("material"))?;
            let shape = self.shape_of(shapes, spec.shape.as_deref(), n)?;
            let size = shape.as_ref().map(shape_size);
            let new = insert::insert(spec, size, &placed, planes, meshes, 0)
                .map_err(|e| self.error(key.clone(), e.message))?;
            let mut orientations = orientation_stream(spec, 0);
            for p in &new {
                let body = inserted_body(spec, shape.as_ref(), material, p, &mut orientations);
                bodies.push((body, key.clone()));
            }
            placed.extend(new);
        }
        Ok(bodies)
    }

    fn named_shape<'s>(
        &self,
        shapes: &'s BTreeMap<String, shapes::BuiltShape>,
        name: &str,
        key: KeyPath,
    ) -> Result<&'s shapes::BuiltShape, SceneError> {
        shapes.get(name).ok_or_else(|| {
            let known: Vec<&String> = shapes.keys().collect();
            self.error(
                key,
                format!("no shape named '{name}'; the scene defines {known:?} ([shape.NAME])"),
            )
        })
    }

    /// The shape an insertion places, if it names one.
    fn shape_of(
        &self,
        shapes: &BTreeMap<String, shapes::BuiltShape>,
        name: Option<&str>,
        index: usize,
    ) -> Result<Option<shapes::BuiltShape>, SceneError> {
        name.map(|name| {
            self.named_shape(shapes, name, KeyPath::entry("insert", index).key("shape"))
                .cloned()
        })
        .transpose()
    }

    /// Refuses bodies that start overlapping a mesh wall by more than the tolerance (times the
    /// sphere's radius, or the polyhedron's volume-equivalent radius; for a polyhedron the
    /// overlap is the mean depth of the run's volume-law contact, as between bodies).
    fn check_mesh_wall_overlaps(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        walls: &[crate::wall::MeshWall],
    ) -> Result<(), SceneError> {
        let tolerance = self.spec.simulation.initial_overlap_tolerance;
        for (b, key) in bodies {
            for (n, wall) in walls.iter().enumerate() {
                let contacts = match &b.shape {
                    Shape::Sphere(s) => {
                        crate::narrow_phase::sphere_mesh(b.position, s.radius, wall)
                    }
                    Shape::Convex(p) => crate::narrow_phase::convex_mesh(
                        p,
                        b.position,
                        b.orientation,
                        wall,
                        crate::contact_law::PolyhedralLaw::Volume,
                    ),
                    Shape::NonConvex(p) => {
                        let mut found = Vec::new();
                        crate::narrow_phase::nonconvex_mesh_contacts(
                            p,
                            b.position,
                            b.orientation,
                            wall,
                            &mut Default::default(),
                            &mut found,
                        );
                        found
                    }
                };
                let deepest = contacts.iter().map(|g| g.overlap).fold(0.0, f64::max);
                if deepest > tolerance * b.shape.equivalent_radius() {
                    return Err(self.error(
                        key.clone(),
                        format!(
                            "the particle at {:?} overlaps [[mesh_wall]] #{} by {deepest:.3e} m; \
                             move it to the side the wall faces",
                            b.position.to_array(),
                            n + 1
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Refuses a start in which bodies overlap each other or a wall by more than the tolerance:
    /// such a start would fire bodies apart with energy the user never put in. Returns whether
    /// any body overlaps at all (within the tolerance).
    fn check_initial_overlaps(
        &self,
        bodies: &[(BodyInit, KeyPath)],
        planes: &[Plane],
    ) -> Result<bool, SceneError> {
        use crate::broad_phase::{BroadPhase, CellGrid};
        use crate::math::Aabb;
        let tolerance = self.spec.simulation.initial_overlap_tolerance;
        let radius = |b: &BodyInit| b.shape.bounding_radius();
        let boxes: Vec<Aabb> = bodies
            .iter()
            .map(|(b, _)| Aabb::around_sphere(b.position, radius(b)))
            .collect();
        let mut pairs = Vec::new();
        CellGrid::default().find_pairs(&boxes, &mut pairs);
        let mut scratch = crate::narrow_phase::ClipScratch::default();
        let mut overlapping = false;
        for (i, j) in pairs {
            let ((a, key_a), (b, key_b)) = (&bodies[i as usize], &bodies[j as usize]);
            // The contact detection of the run itself: mean depth for polyhedra.
            let overlap = crate::narrow_phase::body_body(
                posed(a),
                posed(b),
                crate::contact_law::PolyhedralLaw::Volume,
                &mut scratch,
            )
            .map_or(0.0, |g| g.overlap);
            let size = |b: &BodyInit| b.shape.equivalent_radius();
            let allowed = tolerance * size(a).min(size(b));
            overlapping |= overlap > 0.0;
            if overlap > allowed {
                return Err(self.error(
                    key_b.clone(),
                    format!(
                        "this particle at {:?} overlaps {key_a} at {:?} by {overlap:.3e} m, more \
                         than initial_overlap_tolerance allows ({allowed:.3e} m); move them apart",
                        b.position.to_array(),
                        a.position.to_array()
                    ),
                ));
            }
        }
        for (b, key) in bodies {
            for (n, plane) in planes.iter().enumerate() {
                let overlap = depth_behind_plane(b, plane);
                overlapping |= overlap > 0.0;
                if overlap > tolerance * b.shape.equivalent_radius() {
                    return Err(self.error(
                        key.clone(),
                        format!(
                            "the particle at {:?} overlaps [[plane]] #{} by {overlap:.3e} m (or \
                             lies behind it); move it to the side the plane's normal points to",
                            b.position.to_array(),
                            n + 1
                        ),
                    ));
                }
            }
        }
        Ok(overlapping)
    }
}

fn posed(b: &BodyInit) -> crate::narrow_phase::Posed<'_> {
    crate::narrow_phase::Posed {
        shape: &b.shape,
        position: b.position,
        orientation: b.orientation,
    }
}

/// How far a body reaches behind a plane (negative: the gap in front of it).
fn depth_behind_plane(b: &BodyInit, plane: &Plane) -> f64 {
    let height = |x: DVec3| (x - plane.point).dot(plane.normal);
    match &b.shape {
        Shape::Sphere(s) => s.radius - height(b.position),
        Shape::Convex(p) => -p
            .vertices()
            .iter()
            .map(|&v| height(b.position + b.orientation * v))
            .fold(f64::INFINITY, f64::min),
        Shape::NonConvex(p) => -p
            .vertices()
            .iter()
            .map(|&v| height(b.position + b.orientation * v))
            .fold(f64::INFINITY, f64::min),
    }
}

fn sphere(radius: f64, material: u32, position: DVec3, velocity: DVec3) -> BodyInit {
    BodyInit {
        shape: Shape::Sphere(Sphere::new(radius)),
        material,
        position,
        orientation: DQuat::IDENTITY,
        velocity,
        angular_velocity: DVec3::ZERO,
    }
}
