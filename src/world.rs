//! The simulated world: its state, how it is built and changed, and its time step.

use crate::body::Bodies;
use crate::contact::{ContactStore, StoreLayout};
use crate::contact_law::PolyhedralLaw;
use crate::flow::FlowMeter;
use crate::integrate::{self, BodyMotion, Closing, Kick};
use crate::material::{Material, PairTable};
use crate::math::{Aabb, DVec3};
use crate::shape::Shape;
use crate::step::{
    self, space_order, LawInputs, NeighbourSearch, RegionOutput, StageTimes, Stopwatch, WallLoads,
};
use crate::time_table::TimeTable;
use crate::wall::Plane;
use crate::wall::{MeshWall, WallState};

mod config;
mod interventions;
mod ledger;
mod population;
mod share;
mod snapshot;
mod surroundings;
mod view;

#[cfg(test)]
pub(crate) use config::spheres_among_walls;
pub use config::WorldConfig;
pub use interventions::WallMotionChangeError;
pub use share::{RunningTotals, ShareOutlook, SharePart};
pub use snapshot::{RestoreError, ShapeRecord, WorldState, WorldStateRef};

/// How a step's contact pipeline ends ([`World::update_forces`]).
enum Ending {
    /// The bodies' force sums completed, and the step's closing half kick given if any (none
    /// when the forces are found again between steps).
    Now(Option<Kick>),
    /// Both left to the next step's opening pass (`integrate::Closing`).
    LeftToNextStep(Kick),
}

/// A world: bodies, walls and contacts with their history, the time, and the step that advances
/// them. Built complete by [`World::new`] (and the `with_*` parts that a world may lack: mesh
/// walls, flow meters, a domain); read through the methods of `world/view.rs`.
pub struct World {
    time: f64,
    steps_done: u64,
    time_step: f64,
    gravity: DVec3,
    /// Gravity over time, for runs in stages; `None`: `gravity` throughout.
    gravity_table: Option<TimeTable<DVec3>>,
    /// Potential energy the bodies gained when gravity changed [J] (see [`World::follow_gravity`]).
    gravity_work: f64,
    bodies: Bodies,
    shapes: Vec<Shape>,
    materials: Vec<Material>,
    pair_laws: PairTable,
    planes: Vec<Plane>,
    /// Triangle-mesh walls, fixed or moving.
    mesh_walls: Vec<MeshWall>,
    /// Energy taken out by damping, sliding and rolling resistance since the start [J].
    dissipated: f64,
    /// Bodies whose centre leaves this box are removed (an open boundary); `None`: never.
    domain: Option<Aabb>,
    /// The contact law of polyhedra (volume law by default).
    polyhedral_law: PolyhedralLaw,
    /// Kinetic and potential energy brought in by bodies inserted during the run [J].
    energy_inserted: f64,
    /// Kinetic, potential and contact energy carried out by removed bodies [J].
    energy_removed: f64,
    /// Bodies removed so far.
    bodies_removed: u64,
    /// Counters of the mass that crosses a plane or leaves a region.
    flow_meters: Vec<FlowMeter>,
    /// Every contact, with bodies and walls alike, and its history.
    contacts: ContactStore,
    /// Impulses on the walls and the work of moving walls.
    wall_loads: WallLoads,
    /// Time the mesh walls' poses are at.
    wall_time: f64,
    /// Each mesh wall's motion over the step and at its end; `None` for a fixed wall.
    wall_states: Vec<Option<[WallState; 2]>>,
    next_id: u64,
    /// See [`WorldConfig::skin`]; `None` until bodies exist to size it from.
    skin_setting: Option<f64>,
    search: NeighbourSearch,
    regions: RegionOutput,
    motion: Vec<BodyMotion>,
    /// Per-chunk sums of the dissipated energy (working memory of `step::detect_and_evaluate`).
    dissipated_chunks: Vec<f64>,
    forces_current: bool,
    /// Where a share of a decomposed world's bodies were when the shares were drawn; `None` in
    /// a world that is no share.
    drawing: Option<share::Drawing>,
    /// What the next opening half kick gives beyond the work the ledger books for it, when the
    /// forces were found again since the last step ([`World::update_contacts`]).
    kick_excess: f64,
    /// The last step's closing half kick, when it and the bodies' force sums were left to the
    /// next step's opening pass (between two steps of one [`World::run_steps`], where nothing
    /// reads the forces or the velocities): `bodies.force` and `bodies.torque` then hold only
    /// each body's own contacts' sums. `None` whenever outside code can see the world.
    closing_kick: Option<Kick>,
    /// See [`World::set_sort_interval`].
    sort_interval: u64,
    times: StageTimes,
    pool: std::sync::Arc<rayon::ThreadPool>,
}

impl World {
    pub fn new(config: WorldConfig) -> Result<Self, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(config.threads)
            .build()?;
        let pool = std::sync::Arc::new(pool);
        Ok(Self {
            time: 0.0,
            steps_done: 0,
            time_step: config.time_step,
            gravity: config.gravity,
            gravity_table: None,
            gravity_work: 0.0,
            bodies: Bodies::default(),
            shapes: Vec::new(),
            materials: config.materials,
            pair_laws: config.pair_laws,
            planes: config.planes,
            mesh_walls: Vec::new(),
            dissipated: 0.0,
            domain: None,
            polyhedral_law: PolyhedralLaw::default(),
            energy_inserted: 0.0,
            energy_removed: 0.0,
            bodies_removed: 0,
            flow_meters: Vec::new(),
            contacts: ContactStore::default(),
            wall_loads: WallLoads::default(),
            wall_time: 0.0,
            wall_states: Vec::new(),
            next_id: 0,
            skin_setting: config.skin,
            search: NeighbourSearch::new(config.broad_phase, config.skin.unwrap_or(f64::INFINITY)),
            regions: RegionOutput::default(),
            motion: Vec::new(),
            dissipated_chunks: Vec::new(),
            forces_current: false,
            closing_kick: None,
            drawing: None,
            kick_excess: 0.0,
            sort_interval: space_order::SORT_INTERVAL,
            times: StageTimes::default(),
            pool,
        })
    }

    /// Advances the world by one time step.
    pub fn step(&mut self) {
        self.run_steps(1);
    }

    /// Advances the world by `n` time steps. Cheaper than `n` calls of [`World::step`] because the
    /// thread pool is entered once, and its other workers look for the steps' parallel work
    /// without sleeping until the last step ends (`busy`: on two threads, a tenth of the step
    /// went to waking them between stages).
    pub fn run_steps(&mut self, n: u64) {
        // The pool is shared (Arc) so that it can run a closure that borrows the world mutably.
        let pool = std::sync::Arc::clone(&self.pool);
        pool.install(|| {
            crate::busy::with_workers_awake(|| {
                for k in 0..n {
                    self.advance(k + 1 < n);
                }
            })
        });
        debug_assert!(self.closing_kick.is_none());
    }

    /// Finds the contacts of the current state and their forces, if bodies were added since they
    /// were last found (the first step does it anyway). The energy ledger and the outputs read
    /// the contacts: without this, springs of overlaps present at the start would be missing from
    /// the first report, and the ledger's total would jump at the first step (issue #11, point 4).
    ///
    /// The forces found here replace the last step's for the next opening half kick only. The
    /// ledger books a dashpot's work against the velocity between its two half kicks, which is
    /// exact when the same force acts in both: the terms of second order in the step,
    /// ±|F|² (dt/2)²/2m, then cancel. Here they do not, and what the new forces give beyond the
    /// work booked is booked as well (for a plastic contact hit at the moment of the change, a
    /// sixteenth of its energy), by the next step, whose kick gives it. Before the first step no
    /// force has acted: the first half kick is velocity Verlet's own start for the springs, and
    /// only the dashpots' part of it is booked.
    pub fn update_contacts(&mut self) {
        if !self.forces_current {
            let after_a_step = self.steps_done > 0;
            let before = self.half_kick_excess(None);
            self.move_walls_to(self.time);
            integrate::motion::pack(&self.bodies, &mut self.motion);
            self.update_forces(0.0, Ending::Now(None));
            let before = if after_a_step {
                before
            } else {
                self.half_kick_excess(Some(&self.dashpot_loads()))
            };
            self.kick_excess += self.half_kick_excess(None) - before;
        }
    }

    /// One time step. The stages, in order: half kick with the current forces and drift (one pass
    /// over the bodies), neighbour search, narrow phase, contact laws, force sums with the closing
    /// half kick (one pass). When `another_follows` (in the same [`World::run_steps`]), the sums
    /// and the closing half kick are left to the next step's first pass, which reads the forces
    /// and velocities anyway, unless something between the two reads them: bodies leaving the
    /// domain (their energy is booked), a share's look-ahead at the bodies' next move, the
    /// bodies put in a new order.
    fn advance(&mut self, another_follows: bool) {
        self.update_contacts();
        if self.sort_interval > 0
            && self.steps_done.is_multiple_of(self.sort_interval)
            && self.bodies.len() >= space_order::SORT_MIN_BODIES
        {
            self.sort_bodies_in_space();
        }
        self.follow_gravity();
        let dt = self.time_step;
        let mut clock = Stopwatch::start();
        let sums = step::IncomingSums(&self.contacts);
        let closing = self
            .closing_kick
            .take()
            .map(|kick| Closing { kick, sums: &sums });
        integrate::kick_drift(
            &mut self.bodies,
            self.gravity,
            dt,
            &mut self.motion,
            closing,
        );
        self.dissipated -= std::mem::take(&mut self.kick_excess);
        clock.lap(&mut self.times.integrate);
        for meter in &mut self.flow_meters {
            meter.record(&self.bodies, dt);
        }
        self.move_walls_to(self.time + dt);
        clock.lap(&mut self.times.other);
        let kick = Kick {
            gravity: self.gravity,
            h: 0.5 * dt,
        };
        let sort_next =
            self.sort_interval > 0 && (self.steps_done + 1).is_multiple_of(self.sort_interval);
        if another_follows && self.domain.is_none() && self.drawing.is_none() && !sort_next {
            self.update_forces(dt, Ending::LeftToNextStep(kick));
        } else {
            self.update_forces(dt, Ending::Now(Some(kick)));
        }
        let mut clock = Stopwatch::start();
        self.remove_bodies_outside_domain();
        clock.lap(&mut self.times.other);
        self.time += dt;
        self.steps_done += 1;
    }

    /// Runs the contact pipeline (`step/`) at the current positions: who may touch whom, who
    /// touches whom, with what force. `dt` is the interval the contact histories advance by (0 at
    /// the start), with the bodies' motion already packed; `ending` says how the step ends.
    fn update_forces(&mut self, dt: f64, ending: Ending) {
        let mut clock = Stopwatch::start();
        self.update_candidates();
        clock.lap(&mut self.times.candidates);
        self.update_wall_states(dt);
        // The contact loop adds up each body's own contacts into its force and torque, which
        // no stage before the sums reads; they are the bodies' again for the sums.
        let mut force = std::mem::take(&mut self.bodies.force);
        let mut torque = std::mem::take(&mut self.bodies.torque);
        let scene = step::Scene {
            bodies: &self.bodies,
            shapes: &self.shapes,
            planes: &self.planes,
            walls: &self.mesh_walls,
            law: self.polyhedral_law,
        };
        let reach = (self.search.skin(), self.search.margins());
        self.dissipated +=
            step::detect_regions(scene, &mut self.contacts, &mut self.regions, reach);
        clock.lap(&mut self.times.regions);
        let laws = LawInputs {
            scene,
            wall_states: &self.wall_states,
            laws: &self.pair_laws,
            motion: &self.motion,
            near_triangles: self.regions.near_triangles(),
            inverse_step: 1.0 / self.time_step,
        };
        clock.lap(&mut self.times.other);
        let own = step::OwnSums {
            force: &mut force,
            torque: &mut torque,
        };
        self.dissipated += step::detect_and_evaluate(
            laws,
            &mut self.contacts,
            own,
            dt,
            &mut self.dissipated_chunks,
        );
        (self.bodies.force, self.bodies.torque) = (force, torque);
        clock.lap(&mut self.times.detect_and_evaluate);
        match ending {
            Ending::Now(kick) => {
                let ahead = kick
                    .and(self.drawing.as_ref())
                    .and_then(|d| d.lookahead(&self.search, self.bodies.len(), self.time_step));
                let found = ahead.is_some();
                let moves = step::accumulate(&mut self.bodies, &self.contacts, kick, ahead);
                if let Some(d) = &mut self.drawing {
                    d.next = found.then_some(moves);
                }
            }
            Ending::LeftToNextStep(kick) => self.closing_kick = Some(kick),
        }
        self.book_wall_loads(dt);
        clock.lap(&mut self.times.accumulate);
        self.forces_current = true;
    }

    /// Makes the candidate list again if it may have gone stale (`step::candidates`), carrying
    /// the contacts' histories over.
    fn update_candidates(&mut self) {
        let walls = (&self.planes, &self.mesh_walls);
        if let Some(list) = self
            .search
            .update(&self.bodies, &self.shapes, walls.0, walls.1)
        {
            let rolling = self.pair_laws.iter().any(|l| l.rolling_friction > 0.0);
            let layout = StoreLayout::of(&self.shapes, !self.mesh_walls.is_empty(), rolling);
            // The list is dropped here, once the store holds it.
            self.dissipated += self.contacts.set_candidates(&list, &self.bodies, layout);
        }
    }
}
