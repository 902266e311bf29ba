//! What outside code reads of a world (its state is private to `world`), and the one door for
//! changing bodies between steps.

use super::World;
use crate::body::Bodies;
use crate::contact::{Contacts, Placement};
use crate::contact_law::PolyhedralLaw;
use crate::flow::FlowMeter;
use crate::material::{Material, PairTable};
use crate::math::{Aabb, DVec3};
use crate::shape::Shape;
use crate::step::{StageTimes, WallLoads};
use crate::wall::{MeshWall, Plane};

impl World {
    /// Simulated time [s].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken since the world was built.
    pub fn steps_done(&self) -> u64 {
        self.steps_done
    }

    /// The time step [s].
    pub fn time_step(&self) -> f64 {
        self.time_step
    }

    /// Gravitational acceleration [m/s²].
    pub fn gravity(&self) -> DVec3 {
        self.gravity
    }

    pub fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    /// The bodies, to set positions, velocities or spins between steps (tests, settling a bed).
    /// The forces of the last step stay in use until the next step's contact pass.
    pub fn bodies_mut(&mut self) -> &mut Bodies {
        &mut self.bodies
    }

    /// The shapes bodies refer to by `Bodies::shape`.
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// The materials bodies and walls refer to by index.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// The mixed contact parameters of every pair of materials.
    pub fn pair_laws(&self) -> &PairTable {
        &self.pair_laws
    }

    pub fn planes(&self) -> &[Plane] {
        &self.planes
    }

    /// Triangle-mesh walls, fixed or moving, where they are now.
    pub fn mesh_walls(&self) -> &[MeshWall] {
        &self.mesh_walls
    }

    /// The open boundary, if any: bodies whose centre leaves it are removed.
    pub fn domain(&self) -> Option<Aabb> {
        self.domain
    }

    /// The contact law of polyhedra.
    pub fn polyhedral_law(&self) -> PolyhedralLaw {
        self.polyhedral_law
    }

    /// Counters of the mass that crosses a plane or leaves a region.
    pub fn flow_meters(&self) -> &[FlowMeter] {
        &self.flow_meters
    }

    /// Energy taken out by damping, sliding and rolling resistance since the start [J].
    pub fn dissipated(&self) -> f64 {
        self.dissipated
    }

    /// Bodies removed so far (they left the domain).
    pub fn bodies_removed(&self) -> u64 {
        self.bodies_removed
    }

    /// Every contact of the world (bodies with bodies, planes and mesh walls) and its history.
    pub fn contacts(&self) -> Contacts<'_> {
        Contacts::new(&self.contacts, self.placement())
    }

    /// Where the bodies and planes are, which a contact's geometry that the store does not keep
    /// is found again from.
    pub(crate) fn placement(&self) -> Placement<'_> {
        Placement {
            bodies: &self.bodies,
            shapes: &self.shapes,
            planes: &self.planes,
            laws: &self.pair_laws,
        }
    }

    /// Impulses on the walls since the start and the work of moving walls.
    pub fn wall_loads(&self) -> &WallLoads {
        &self.wall_loads
    }

    /// Times the neighbour search has made its candidate list (for diagnostics and tests).
    pub fn pair_rebuilds(&self) -> u64 {
        self.search.rebuilds
    }

    /// Wall-clock time spent in each stage of the step since the world was built.
    pub fn stage_times(&self) -> &StageTimes {
        &self.times
    }

    /// Number of threads the world's parallel loops use.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// The thread pool the world's parallel loops run in (a rank of a decomposed run steps on
    /// it, MPI calls included: see `MpiRanks::run_steps`).
    #[cfg(feature = "mpi")]
    pub(crate) fn thread_pool(&self) -> std::sync::Arc<rayon::ThreadPool> {
        std::sync::Arc::clone(&self.pool)
    }

    /// The skin distance in use [m].
    pub fn skin(&self) -> f64 {
        self.search.skin()
    }
}
