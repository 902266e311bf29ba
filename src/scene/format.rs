//! The scene file format (TOML). Every key is documented in `docs/scene-format.md`; keep the two in
//! step. Unknown keys are refused so that a misspelt key never silently falls back to a default.

use serde::Deserialize;

mod insertion;
pub use insertion::{
    CylinderRegion, InletFace, InletSpec, InsertMethod, InsertSpec, RadiusDistribution,
};

pub type Vec3 = [f64; 3];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub simulation: Simulation,
    #[serde(default)]
    pub contact: ContactSettings,
    #[serde(default, rename = "material")]
    pub materials: Vec<MaterialSpec>,
    #[serde(default, rename = "pair")]
    pub pairs: Vec<PairSpec>,
    #[serde(default, rename = "plane")]
    pub planes: Vec<PlaneSpec>,
    #[serde(default, rename = "mesh_wall")]
    pub mesh_walls: Vec<MeshWallSpec>,
    #[serde(default, rename = "particle")]
    pub particles: Vec<ParticleSpec>,
    #[serde(default, rename = "insert")]
    pub insertions: Vec<InsertSpec>,
    pub domain: Option<DomainSpec>,
    #[serde(default)]
    pub output: OutputSpec,
    /// Named particle shapes, `[shape.NAME]`, used by `[[particle]]` and `[[insert]]`.
    #[serde(default, rename = "shape")]
    pub shapes: std::collections::BTreeMap<String, ShapeSpec>,
}

/// A named particle shape. Sizes in metres.
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    Sphere {
        radius: f64,
    },
    /// A rectangular box with these edge lengths along x, y, z.
    Box {
        edges: Vec3,
    },
    Tetrahedron {
        edge: f64,
    },
    Octahedron {
        edge: f64,
    },
    Dodecahedron {
        edge: f64,
    },
    Icosahedron {
        edge: f64,
    },
    /// A regular prism: `sides`-gon of this circumradius, extruded along z by `height`.
    Prism {
        sides: usize,
        circumradius: f64,
        height: f64,
    },
    /// The convex hull of these points.
    Hull {
        points: Vec<Vec3>,
    },
    /// A seeded random convex rock: `vertices` points on an ellipsoid with axes in the ratio
    /// `elongation`, scaled to the volume of a sphere of diameter `size`.
    Rock {
        vertices: usize,
        size: f64,
        #[serde(default = "unit_elongation")]
        elongation: Vec3,
        #[serde(default)]
        seed: u64,
    },
    /// A particle read from a mesh file (`.stl`, ASCII or binary, or `.obj`), relative to the
    /// scene file's folder; coordinates multiplied by `scale` (file units → metres). Convex by
    /// default: a non-convex mesh is refused unless `convex_hull = true` (its convex hull) or
    /// `nonconvex = true` (the mesh itself, a non-convex particle).
    Mesh {
        file: String,
        #[serde(default = "unit_scale")]
        scale: f64,
        #[serde(default)]
        convex_hull: bool,
        /// Use the mesh as it is, convex or not.
        #[serde(default)]
        nonconvex: bool,
        /// Turn the triangles consistently outward instead of refusing a mesh whose orientation
        /// is inconsistent or inward (non-convex meshes).
        #[serde(default)]
        reorient: bool,
        /// The body as a union of convex parts, each the hull of its points (in the file's
        /// units, like the mesh): contacts then use the polyhedral law part by part.
        parts: Option<Vec<Vec<Vec3>>>,
    },
    /// A 3-D cross ("jack"): three square bars `width` thick and `length` long along x, y and z,
    /// crossing at their middles. Non-convex.
    Jack {
        length: f64,
        width: f64,
        /// Contacts by the convex parts (five bars) under the polyhedral law, instead of the
        /// vertex law on the mesh.
        #[serde(default)]
        parts: bool,
    },
    /// A flat cross (a plus sign) in the xy plane: two bars `length` × `width`, `thickness`
    /// along z.
    Cross {
        length: f64,
        width: f64,
        thickness: f64,
        #[serde(default)]
        parts: bool,
    },
    /// An L-shaped prism: arms `length_x` along x and `length_y` along y, `width` wide, meeting
    /// at a square corner; `height` along z.
    LShape {
        length_x: f64,
        length_y: f64,
        width: f64,
        height: f64,
        #[serde(default)]
        parts: bool,
    },
    /// A ring (hollow cylinder) along z with `segments` flat facets around.
    Ring {
        outer_radius: f64,
        inner_radius: f64,
        height: f64,
        #[serde(default = "ring_segments")]
        segments: usize,
        #[serde(default)]
        parts: bool,
    },
    /// A star: an octahedron (`spikes = 8`) or icosahedron (20) of circumradius `radius` with a
    /// pyramid of height `spike_length` on every face.
    Star {
        #[serde(default = "eight")]
        spikes: usize,
        radius: f64,
        spike_length: f64,
        #[serde(default)]
        parts: bool,
    },
    /// A screw-shaped grain along z: a core with helical blades.
    Screw {
        radius: f64,
        core_radius: f64,
        blade_width: f64,
        length: f64,
        turns: f64,
        #[serde(default = "two")]
        blades: usize,
        #[serde(default = "ring_segments")]
        segments: usize,
    },
}

fn two() -> usize {
    2
}

fn ring_segments() -> usize {
    24
}

fn eight() -> usize {
    8
}

fn unit_scale() -> f64 {
    1.0
}

fn yes() -> bool {
    true
}

fn unit_elongation() -> Vec3 {
    [1.0, 1.0, 1.0]
}

/// What a run writes beyond the defaults.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write the contact force network (`contacts.pvd`).
    #[serde(default)]
    pub force_network: bool,
    /// Report the packing fraction of this box in `energy.csv`.
    pub packing_region: Option<DomainSpec>,
    /// Mass flow meters (`flow.csv`).
    #[serde(default, rename = "flow_meter")]
    pub flow_meters: Vec<FlowMeterSpec>,
    /// Simulated seconds between checkpoints (`checkpoints/`); none: only at the end of the run
    /// and when it is interrupted.
    pub checkpoint_interval: Option<f64>,
    /// Seconds between VTK frames; default `[simulation] output_interval`.
    pub vtk_interval: Option<f64>,
    /// Seconds between rows of the CSV series; default `[simulation] output_interval`.
    pub csv_interval: Option<f64>,
}

/// A mass flow meter: through a plane (`point`, `normal`) or out of a box (`min`, `max`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowMeterSpec {
    pub name: String,
    pub point: Option<Vec3>,
    pub normal: Option<Vec3>,
    pub min: Option<Vec3>,
    pub max: Option<Vec3>,
}

/// An open boundary: bodies whose centre leaves this box are removed.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainSpec {
    pub min: Vec3,
    pub max: Vec3,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    /// Seconds, or "auto".
    #[serde(default)]
    pub time_step: TimeStep,
    #[serde(default)]
    pub force_time_step: bool,
    pub duration: f64,
    /// [m/s²]; default [0, 0, -9.81] (see [`Simulation::gravity`]).
    pub gravity: Option<Vec3>,
    /// Rows [time, gx, gy, gz]: gravity over time, linear between rows (runs in stages).
    pub gravity_table: Option<Vec<[f64; 4]>>,
    /// Seconds between outputs; default: 100 outputs over the duration.
    pub output_interval: Option<f64>,
    #[serde(default)]
    pub threads: usize,
    #[serde(default)]
    pub broad_phase: crate::broad_phase::Method,
    /// Metres by which broad-phase boxes are enlarged so the pair list lasts several steps;
    /// default: a fifth of the smallest particle radius.
    pub skin: Option<f64>,
    /// What the run's watchdog does when the energy grows or a body goes faster than the scene
    /// can make it: stop the run (default) or warn and go on (for experts who know why).
    #[serde(default)]
    pub watchdog: WatchdogMode,
    /// Largest initial overlap accepted, as a fraction of the smaller radius.
    #[serde(default = "default_overlap_tolerance")]
    pub initial_overlap_tolerance: f64,
}

impl Simulation {
    /// Gravity at the start: `gravity`, else the table's first row, else Earth's downwards.
    pub fn gravity(&self) -> Vec3 {
        match (self.gravity, &self.gravity_table) {
            (Some(g), _) => g,
            (None, Some(rows)) if !rows.is_empty() => [rows[0][1], rows[0][2], rows[0][3]],
            _ => [0.0, 0.0, -9.81],
        }
    }
}

fn default_overlap_tolerance() -> f64 {
    0.01
}

/// See [`Simulation::watchdog`].
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WatchdogMode {
    #[default]
    Stop,
    Warn,
}

#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub enum TimeStep {
    #[default]
    Auto,
    Seconds(f64),
}

impl<'de> Deserialize<'de> for TimeStep {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = TimeStep;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a time step in seconds or \"auto\"")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<TimeStep, E> {
                match v {
                    "auto" => Ok(TimeStep::Auto),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<TimeStep, E> {
                Ok(TimeStep::Seconds(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<TimeStep, E> {
                Ok(TimeStep::Seconds(v as f64))
            }
        }
        d.deserialize_any(Visitor)
    }
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum NormalModel {
    #[default]
    Hertz,
    Linear,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSettings {
    #[serde(default)]
    pub normal: NormalModel,
    /// N/m; required by the linear law.
    pub stiffness: Option<f64>,
    #[serde(default = "default_tangential_ratio")]
    pub tangential_stiffness_ratio: f64,
    /// Contact law of polyhedra: "volume" (default) or "vertex" (the seed paper's).
    #[serde(default)]
    pub polyhedra: crate::contact_law::PolyhedralLaw,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            normal: NormalModel::default(),
            stiffness: None,
            tangential_stiffness_ratio: default_tangential_ratio(),
            polyhedra: Default::default(),
        }
    }
}

fn default_tangential_ratio() -> f64 {
    2.0 / 7.0
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    pub density: f64,
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub restitution: f64,
    pub friction: f64,
    #[serde(default)]
    pub rolling_friction: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    pub materials: [String; 2],
    pub restitution: Option<f64>,
    pub friction: Option<f64>,
    pub rolling_friction: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneSpec {
    pub point: Vec3,
    pub normal: Vec3,
    pub material: String,
    /// Heads the wall's columns in `wall_forces.csv`; default `wallN`.
    pub name: Option<String>,
}

/// A triangle-mesh wall: from a mesh file or a generator, then scaled, rotated and moved.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshWallSpec {
    pub material: String,
    /// Heads the wall's columns in `wall_forces.csv`; default `wallN`.
    pub name: Option<String>,
    /// STL or OBJ file, relative to the scene file's folder.
    pub file: Option<String>,
    /// Reverse the winding of the file's triangles (a mesh that faces away from the bodies).
    #[serde(default)]
    pub flip: bool,
    pub generator: Option<WallGenerator>,
    #[serde(default = "unit_scale")]
    pub scale: f64,
    /// Axis times angle [rad].
    #[serde(default)]
    pub rotation: Vec3,
    #[serde(default)]
    pub translation: Vec3,
    /// Prescribed motion; none: the wall stays where it is.
    pub motion: Option<MotionSpec>,
}

/// How a mesh wall moves (all parts optional, combined when several are given).
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Constant translation velocity [m/s].
    pub velocity: Option<Vec3>,
    /// Rows [time, vx, vy, vz]: translation velocity, linear between rows.
    pub velocity_table: Option<Vec<[f64; 4]>>,
    /// Rotation rate [revolutions per minute] about `axis` through `axis_point`.
    pub rpm: Option<f64>,
    /// Rows [time, rpm]: rotation rate, linear between rows (runs in stages).
    pub rpm_table: Option<Vec<[f64; 2]>>,
    pub axis: Option<Vec3>,
    #[serde(default)]
    pub axis_point: Vec3,
    /// Conveyor-belt velocity of the wall's surface [m/s] (its tangential part acts).
    pub surface_velocity: Option<Vec3>,
}

/// Which side of a generated wall bodies are on.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum FacingSpec {
    #[default]
    Inward,
    Outward,
}

/// Which parts of a generated screw make the wall.
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum ScrewPartSpec {
    #[default]
    All,
    Screw,
    Casing,
}

/// Built-in wall meshes (sizes in metres, before `scale`).
#[derive(Debug, Deserialize, Clone, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum WallGenerator {
    /// The parallelogram origin + s u + t v, divided into cells of two triangles; bodies on the
    /// side of u × v.
    Rectangle {
        origin: Vec3,
        u: Vec3,
        v: Vec3,
        #[serde(default = "one_by_one")]
        divisions: [usize; 2],
    },
    /// A closed box.
    Box {
        min: Vec3,
        max: Vec3,
        #[serde(default = "one")]
        divisions: usize,
        #[serde(default)]
        facing: FacingSpec,
    },
    /// A cylinder along z from 0 to `height`, open (a tube) or closed (a drum).
    Cylinder {
        radius: f64,
        height: f64,
        #[serde(default = "segments")]
        segments: usize,
        #[serde(default = "one")]
        rings: usize,
        #[serde(default)]
        closed: bool,
        #[serde(default)]
        facing: FacingSpec,
    },
    /// A cone frustum along z (a hopper with an outlet when open).
    Frustum {
        bottom_radius: f64,
        top_radius: f64,
        height: f64,
        #[serde(default = "segments")]
        segments: usize,
        #[serde(default = "one")]
        rings: usize,
        #[serde(default)]
        closed: bool,
        #[serde(default)]
        facing: FacingSpec,
    },
    /// A helical screw flight along z with an optional shaft and a tube or trough around it.
    Screw {
        shaft_radius: f64,
        flight_radius: f64,
        pitch: f64,
        turns: f64,
        thickness: f64,
        #[serde(default)]
        left_handed: bool,
        #[serde(default = "segments")]
        segments_per_turn: usize,
        #[serde(default = "four")]
        radial_segments: usize,
        #[serde(default = "yes")]
        shaft: bool,
        tube_clearance: Option<f64>,
        trough_clearance: Option<f64>,
        /// Height of the trough's sides above the axis (default: its radius).
        trough_height: Option<f64>,
        #[serde(default)]
        part: ScrewPartSpec,
    },
}

fn one() -> usize {
    1
}

fn four() -> usize {
    4
}

fn segments() -> usize {
    48
}

fn one_by_one() -> [usize; 2] {
    [1, 1]
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    /// A sphere of this radius [m] ...
    pub radius: Option<f64>,
    /// ... or a shape named in `[shape.NAME]`.
    pub shape: Option<String>,
    pub material: String,
    pub position: Vec3,
    /// Rotation of the shape as an axis times an angle [rad].
    #[serde(default)]
    pub rotation: Vec3,
    #[serde(default)]
    pub velocity: Vec3,
    #[serde(default)]
    pub angular_velocity: Vec3,
}
