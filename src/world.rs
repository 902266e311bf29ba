//! The simulated world and its time step.

use crate::body::{Bodies, BodyInit};
use crate::broad_phase::{self, BroadPhase, Pair};
use crate::contact::ContactList;
use crate::contact::{assign_slots, Contact};
use crate::contact_law::{self, Kinematics, PolyhedralLaw};
use crate::energy::EnergyReport;
use crate::flow::FlowMeter;
use crate::integrate;
use crate::material::{Material, PairTable};
use crate::math::{Aabb, DVec3};
use crate::narrow_phase::{
    self, ClipScratch, ConvexMeshScratch, Geometry, MeshScratch, RegionScratch, MAX_REGIONS,
};
use crate::shape::Shape;
use crate::wall::Plane;
use crate::wall::{MeshWall, WallState};
use rayon::prelude::*;
use std::f64::consts::FRAC_1_SQRT_2;

/// Contacts one body can have with one mesh wall at a time (distinct regions, e.g. the faces of a
/// corner it sits in).
pub const MESH_REGIONS: usize = 4;

/// Everything about a world except its bodies.
pub struct WorldConfig {
    pub time_step: f64,
    pub gravity: DVec3,
    pub materials: Vec<Material>,
    pub pair_laws: PairTable,
    pub planes: Vec<Plane>,
    pub broad_phase: broad_phase::Method,
    /// Extra distance [m] by which the broad phase's boxes are enlarged so that its pair list
    /// can be reused over several steps; `None` picks a default from the body sizes
    /// ([`World::default_skin`]).
    pub skin: Option<f64>,
    /// Worker threads for the parallel loops (0: one per core).
    pub threads: usize,
}

pub struct World {
    pub time: f64,
    pub steps_done: u64,
    pub time_step: f64,
    pub gravity: DVec3,
    pub bodies: Bodies,
    pub shapes: Vec<Shape>,
    pub materials: Vec<Material>,
    pub pair_laws: PairTable,
    pub planes: Vec<Plane>,
    /// Body–body contacts, `a < b`.
    pub contacts: ContactList,
    /// Body–plane contacts, `a` the body, `b` the plane.
    pub plane_contacts: ContactList,
    /// Triangle-mesh walls, fixed or moving.
    pub mesh_walls: Vec<MeshWall>,
    /// Body–mesh contacts, `a` the body, `b` = wall × [`MESH_REGIONS`] + region: a body can
    /// touch one wall in several places (a corner), each a contact with its own history.
    pub mesh_contacts: ContactList,
    /// Energy taken out by damping, sliding and rolling resistance since the start [J].
    pub dissipated: f64,
    /// Bodies whose centre leaves this box are removed (an open boundary); `None`: never.
    pub domain: Option<Aabb>,
    /// The contact law of polyhedra (volume law by default).
    pub polyhedral_law: PolyhedralLaw,
    /// Kinetic and potential energy brought in by bodies inserted during the run [J].
    pub energy_inserted: f64,
    /// Kinetic, potential and contact energy carried out by removed bodies [J].
    pub energy_removed: f64,
    /// Bodies removed so far.
    pub bodies_removed: u64,
    /// Work done on the bodies by moving walls (and belt surfaces) since the start [J]: the
    /// energy they bring in.
    pub wall_work: f64,
    /// Time integral of the contact force on each wall since the start [N s]: planes first,
    /// then mesh walls (the numbering of the `wall` field in the output).
    pub wall_impulse: Vec<DVec3>,
    /// Time integral of the torque on each wall about its reference point (the rotation axis
    /// point of a mesh wall, the point of a plane) [N m s].
    pub wall_angular_impulse: Vec<DVec3>,
    /// Counters of the mass that crosses a plane or leaves a region.
    pub flow_meters: Vec<FlowMeter>,
    /// Time the mesh walls' poses are at.
    wall_time: f64,
    /// Power of the wall forces at the last evaluation (for the trapezoidal work integral).
    wall_power: f64,
    /// Each mesh wall's motion over the step and at its end; `None` for a fixed wall.
    wall_states: Vec<Option<[WallState; 2]>>,
    next_id: u64,
    broad_phase_method: broad_phase::Method,
    /// See [`WorldConfig::skin`]; `None` until bodies exist to size it from.
    skin_setting: Option<f64>,
    skin: f64,
    /// Times the broad phase has rebuilt the candidate pairs (for diagnostics and tests).
    pub pair_rebuilds: u64,
    broad_phase: Box<dyn BroadPhase>,
    reference_position: Vec<DVec3>,
    pairs_valid: bool,
    boxes: Vec<Aabb>,
    pairs: Vec<Pair>,
    found: Vec<(u32, u32, Geometry)>,
    /// One slot per candidate pair (or body and plane, or body, mesh wall and region) for the
    /// narrow phase's answer.
    detected: Vec<Option<Geometry>>,
    /// Contacts of pairs that may touch in several regions (non-convex bodies).
    regions: RegionBuffers,
    velocity_end: Vec<DVec3>,
    angular_velocity_end: Vec<DVec3>,
    forces_current: bool,
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
            bodies: Bodies::default(),
            shapes: Vec::new(),
            materials: config.materials,
            pair_laws: config.pair_laws,
            planes: config.planes,
            contacts: ContactList::default(),
            plane_contacts: ContactList::default(),
            mesh_walls: Vec::new(),
            mesh_contacts: ContactList::default(),
            dissipated: 0.0,
            domain: None,
            polyhedral_law: PolyhedralLaw::default(),
            energy_inserted: 0.0,
            energy_removed: 0.0,
            bodies_removed: 0,
            wall_work: 0.0,
            wall_impulse: Vec::new(),
            wall_angular_impulse: Vec::new(),
            flow_meters: Vec::new(),
            wall_time: 0.0,
            wall_power: 0.0,
            wall_states: Vec::new(),
            next_id: 0,
            broad_phase_method: config.broad_phase,
            skin_setting: config.skin,
            skin: config.skin.unwrap_or(f64::INFINITY),
            pair_rebuilds: 0,
            broad_phase: config.broad_phase.build(),
            reference_position: Vec::new(),
            pairs_valid: false,
            boxes: Vec::new(),
            pairs: Vec::new(),
            found: Vec::new(),
            detected: Vec::new(),
            regions: RegionBuffers::default(),
            velocity_end: Vec::new(),
            angular_velocity_end: Vec::new(),
            forces_current: false,
            pool,
        })
    }

    /// Adds a body while setting up; its id is its insertion number. Returns the body's index.
    pub fn add_body(&mut self, init: BodyInit) -> usize {
        let density = self.materials[init.material as usize].density;
        let unit = init.shape.unit_mass_properties();
        if self.shapes.last() != Some(&init.shape) {
            self.shapes.push(init.shape.clone());
        }
        let shape_id = (self.shapes.len() - 1) as u32;
        let radius = init.shape.bounding_radius();
        self.bodies.push(
            self.next_id,
            shape_id,
            init.material,
            radius,
            init.shape.equivalent_radius(),
            density * unit.volume,
            density * unit.principal_inertia_per_density,
            &init,
        );
        self.next_id += 1;
        self.structure_changed();
        if self.skin_setting.is_none() {
            self.skin = self.skin.min(Self::default_skin(radius));
        }
        self.bodies.len() - 1
    }

    /// Adds a body during a run; its energy is booked as brought in, so the ledger still closes.
    pub fn insert_body(&mut self, init: BodyInit) -> usize {
        let i = self.add_body(init);
        self.energy_inserted += self.body_energy(i);
        i
    }

    /// Removes the bodies whose `keep` flag is false, with their contacts; their energy is
    /// booked as carried out.
    pub fn remove_bodies(&mut self, keep: &[bool]) {
        let mut new_index = Vec::with_capacity(keep.len());
        let mut next = 0u32;
        for (i, &k) in keep.iter().enumerate() {
            if k {
                new_index.push(next);
                next += 1;
            } else {
                new_index.push(u32::MAX);
                self.energy_removed += self.body_energy(i);
                self.bodies_removed += 1;
            }
        }
        if next as usize == keep.len() {
            return;
        }
        self.energy_removed += self.contacts.renumber(&new_index, true);
        self.energy_removed += self.plane_contacts.renumber(&new_index, false);
        self.energy_removed += self.mesh_contacts.renumber(&new_index, false);
        self.bodies.retain(keep);
        self.structure_changed();
    }

    /// Removes every body whose centre is outside [`World::domain`].
    fn remove_bodies_outside_domain(&mut self) {
        let Some(domain) = self.domain else { return };
        let outside = |x: &DVec3| x.cmplt(domain.min).any() || x.cmpgt(domain.max).any();
        if !self.bodies.position.par_iter().any(outside) {
            return;
        }
        let keep: Vec<bool> = self.bodies.position.iter().map(|x| !outside(x)).collect();
        self.remove_bodies(&keep);
    }

    /// Kinetic (translational and rotational) plus gravitational energy of one body.
    fn body_energy(&self, i: usize) -> f64 {
        let b = &self.bodies;
        0.5 * b.mass[i] * b.velocity[i].length_squared()
            + integrate::rotation::rotational_energy(
                b.orientation[i],
                b.angular_momentum[i],
                b.inv_inertia[i],
            )
            - b.mass[i] * self.gravity.dot(b.position[i])
    }

    /// Bodies were added or removed: indices changed, so the broad phase starts afresh and the
    /// forces are recomputed before the next step.
    fn structure_changed(&mut self) {
        self.forces_current = false;
        self.pairs_valid = false;
        self.broad_phase = self.broad_phase_method.build();
    }

    /// A fifth of the smallest bounding radius: small enough that the extra candidate pairs cost
    /// little, large enough that the list lasts many steps at the speeds DEM time steps allow.
    pub fn default_skin(smallest_radius: f64) -> f64 {
        0.2 * smallest_radius
    }

    /// The skin distance in use [m].
    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// Advances the world by one time step.
    pub fn step(&mut self) {
        self.run_steps(1);
    }

    /// Advances the world by `n` time steps. Cheaper than `n` calls of [`World::step`] because the
    /// thread pool is entered once.
    pub fn run_steps(&mut self, n: u64) {
        // The pool is shared (Arc) so that it can run a closure that borrows the world mutably.
        let pool = std::sync::Arc::clone(&self.pool);
        pool.install(|| {
            for _ in 0..n {
                self.advance();
            }
        });
    }

    /// One time step. The stages, in order: half kick with the current forces, drift, broad
    /// phase, narrow phase, contact laws, force accumulation, half kick with the new forces.
    fn advance(&mut self) {
        if !self.forces_current {
            self.move_walls_to(self.time);
            self.update_forces(0.0);
        }
        let dt = self.time_step;
        integrate::kick(&mut self.bodies, self.gravity, 0.5 * dt);
        integrate::drift(&mut self.bodies, dt);
        for meter in &mut self.flow_meters {
            meter.record(&self.bodies, dt);
        }
        self.move_walls_to(self.time + dt);
        self.update_forces(dt);
        integrate::kick(&mut self.bodies, self.gravity, 0.5 * dt);
        self.remove_bodies_outside_domain();
        self.time += dt;
        self.steps_done += 1;
    }

    /// Puts the moving mesh walls where they are at time `t`.
    fn move_walls_to(&mut self, t: f64) {
        self.wall_time = t;
        for wall in &mut self.mesh_walls {
            wall.set_time(t);
        }
    }

    /// Runs the contact pipeline at the current positions: who is near whom, who touches whom,
    /// with what force. `dt` is the interval the contact histories advance by (0 at the start).
    fn update_forces(&mut self, dt: f64) {
        self.find_candidate_pairs();
        self.detect_contacts();
        self.evaluate_contacts(dt);
        self.accumulate_forces(dt);
        self.forces_current = true;
    }

    /// Candidate pairs from boxes enlarged by half the skin on each side. The list stays valid
    /// until some body has moved more than half the skin since it was made: until then no two
    /// bodies outside each other's enlarged boxes can touch (Verlet 1967's neighbour list idea).
    fn find_candidate_pairs(&mut self) {
        let bodies = &self.bodies;
        let half_skin = 0.5 * self.skin;
        if self.pairs_valid {
            let limit = half_skin * half_skin;
            let moved_too_far = bodies
                .position
                .par_iter()
                .zip(self.reference_position.par_iter())
                .any(|(x, x0)| (*x - *x0).length_squared() > limit);
            if !moved_too_far {
                return;
            }
        }
        self.boxes.clear();
        self.boxes.extend(
            bodies
                .position
                .iter()
                .zip(&bodies.bounding_radius)
                .map(|(&x, &r)| Aabb::around_sphere(x, r + half_skin)),
        );
        self.broad_phase.find_pairs(&self.boxes, &mut self.pairs);
        self.reference_position.clone_from(&bodies.position);
        self.pairs_valid = true;
        self.pair_rebuilds += 1;
    }

    fn detect_contacts(&mut self) {
        let law = self.polyhedral_law;
        let bodies = &self.bodies;
        let shapes = &self.shapes;
        let posed = |i: usize| narrow_phase::Posed {
            shape: &shapes[bodies.shape[i] as usize],
            position: bodies.position[i],
            orientation: bodies.orientation[i],
        };
        // Each candidate writes its own slot, then the contacts are gathered in pair order:
        // deterministic, and no allocation once the buffers have grown.
        let detected = &mut self.detected;
        detected.clear();
        detected.resize(self.pairs.len(), None);
        let regional = |i: u32| shapes[bodies.shape[i as usize] as usize].has_regions();
        let any_regional = shapes.iter().any(Shape::has_regions);
        detected
            .par_iter_mut()
            .zip(self.pairs.par_iter())
            .with_min_len(256)
            .for_each_init(ClipScratch::default, |scratch, (slot, &(i, j))| {
                *slot = if any_regional && (regional(i) || regional(j)) {
                    None // below, region by region
                } else {
                    narrow_phase::body_body(posed(i as usize), posed(j as usize), law, scratch)
                };
            });
        // Pairs that may touch in several regions: up to MAX_REGIONS contacts each.
        let r = &mut self.regions;
        r.items.clear();
        if any_regional {
            r.items.extend((0..self.pairs.len() as u32).filter(|&k| {
                regional(self.pairs[k as usize].0) || regional(self.pairs[k as usize].1)
            }));
        }
        r.detect(|k, scratch, out| {
            let (i, j) = self.pairs[k as usize];
            narrow_phase::body_body_regions(
                posed(i as usize),
                posed(j as usize),
                law,
                scratch,
                out,
            );
        });
        r.found.clear();
        let mut cursor = 0;
        let mut next = 0;
        for (k, &(i, j)) in self.pairs.iter().enumerate() {
            if r.items.get(next) == Some(&(k as u32)) {
                let reach = 0.5
                    * bodies.equivalent_radius[i as usize]
                        .min(bodies.equivalent_radius[j as usize]);
                let previous = self.contacts.of_pair(i, j, &mut cursor);
                r.gather(next, i, j, previous, reach);
                next += 1;
            } else if let Some(g) = detected[k] {
                r.found.push((i, j, 0, g));
            }
        }
        self.dissipated += self.contacts.update_slots(&self.regions.found);

        let planes = &self.planes;
        let r = &mut self.regions;
        r.found.clear();
        if !planes.is_empty() {
            detected.clear();
            detected.resize(bodies.len() * planes.len(), None);
            detected
                .par_chunks_mut(planes.len())
                .enumerate()
                .with_min_len(256)
                .for_each(|(a, slots)| {
                    if any_regional && regional(a as u32) {
                        return; // below, region by region
                    }
                    for (slot, plane) in slots.iter_mut().zip(planes) {
                        *slot = narrow_phase::body_plane(posed(a), plane.point, plane.normal, law);
                    }
                });
            // Bodies that may touch a plane in several regions: each (body, plane) an item.
            let per_body = planes.len();
            r.items.clear();
            if any_regional {
                for a in (0..bodies.len() as u32).filter(|&a| regional(a)) {
                    r.items
                        .extend((0..per_body as u32).map(|p| a * per_body as u32 + p));
                }
            }
            r.detect(|k, scratch, out| {
                let (a, p) = ((k as usize) / per_body, (k as usize) % per_body);
                let plane = &planes[p];
                narrow_phase::body_plane_regions(
                    posed(a),
                    plane.point,
                    plane.normal,
                    law,
                    scratch,
                    out,
                );
            });
            let mut cursor = 0;
            let mut next = 0;
            for (k, g) in detected.iter().enumerate() {
                let (a, p) = ((k / per_body) as u32, (k % per_body) as u32);
                if r.items.get(next) == Some(&(k as u32)) {
                    let reach = 0.5 * bodies.equivalent_radius[a as usize];
                    let previous = self.plane_contacts.of_pair(a, p, &mut cursor);
                    r.gather(next, a, p, previous, reach);
                    next += 1;
                } else if let Some(g) = g {
                    r.found.push((a, p, 0, *g));
                }
            }
        }
        self.dissipated += self.plane_contacts.update_slots(&self.regions.found);
        self.detect_mesh_contacts();
    }

    /// Contacts of bodies with mesh walls (`sphere_mesh` for spheres, `convex_mesh` for
    /// polyhedra). A body may touch a wall in up to [`MESH_REGIONS`] places; each keeps its
    /// history from step to step by following its normal: a region takes the slot of last step's
    /// region of that body and wall whose normal is closest (within 45°), so a body moving
    /// across triangles keeps its friction spring.
    fn detect_mesh_contacts(&mut self) {
        self.found.clear();
        let walls = &self.mesh_walls;
        if walls.is_empty() {
            self.dissipated += self.mesh_contacts.update(&self.found);
            return;
        }
        let bodies = &self.bodies;
        let shapes = &self.shapes;
        let law = self.polyhedral_law;
        let per_body = walls.len() * MESH_REGIONS;
        let detected = &mut self.detected;
        detected.clear();
        detected.resize(bodies.len() * per_body, None);
        detected
            .par_chunks_mut(per_body)
            .enumerate()
            .with_min_len(64)
            .for_each_init(
                || {
                    let convex = (ConvexMeshScratch::default(), Vec::new());
                    (MeshScratch::default(), Vec::new(), convex)
                },
                |(scratch, out, (convex_scratch, convex_out)), (i, slots)| {
                    let shape = &shapes[bodies.shape[i] as usize];
                    let sphere = match shape {
                        Shape::Sphere(sphere) => sphere,
                        Shape::Convex(_) | Shape::NonConvex(_) => {
                            for (w, wall) in walls.iter().enumerate() {
                                // In the wall's reference placement, as for spheres below.
                                let pose = wall.pose();
                                let x = pose.to_reference(bodies.position[i]);
                                let q = pose.rotation.inverse() * bodies.orientation[i];
                                match shape {
                                    Shape::Convex(p) => narrow_phase::convex_mesh_contacts(
                                        p,
                                        x,
                                        q,
                                        wall,
                                        law,
                                        convex_scratch,
                                        convex_out,
                                    ),
                                    // The vertex law on its mesh, whether or not it has parts.
                                    Shape::NonConvex(p) => narrow_phase::nonconvex_mesh_contacts(
                                        p,
                                        x,
                                        q,
                                        wall,
                                        convex_scratch,
                                        convex_out,
                                    ),
                                    Shape::Sphere(_) => unreachable!("spheres are below"),
                                }
                                for (slot, g) in slots[w * MESH_REGIONS..(w + 1) * MESH_REGIONS]
                                    .iter_mut()
                                    .zip(convex_out.iter())
                                {
                                    *slot = Some(g.moved(&pose));
                                }
                            }
                            return;
                        }
                    };
                    let r = sphere.radius;
                    for (w, wall) in walls.iter().enumerate() {
                        // A moving wall is searched in its reference placement, with the body
                        // taken there; the contacts are brought back to the world.
                        let pose = wall.pose();
                        let x = pose.to_reference(bodies.position[i]);
                        if !wall.bounds().overlaps(&Aabb::around_sphere(x, r)) {
                            continue;
                        }
                        narrow_phase::sphere_mesh_contacts(x, r, wall, scratch, out);
                        for (slot, c) in slots[w * MESH_REGIONS..(w + 1) * MESH_REGIONS]
                            .iter_mut()
                            .zip(out.iter())
                        {
                            *slot = Some(c.geometry.moved(&pose));
                        }
                    }
                },
            );
        // Give each region the slot of the matching region of the last step.
        let previous = &self.mesh_contacts.contacts;
        let mut cursor = 0;
        for (i, slots) in detected.chunks(per_body).enumerate() {
            while cursor < previous.len() && (previous[cursor].a as usize) < i {
                cursor += 1;
            }
            let start = cursor;
            while cursor < previous.len() && previous[cursor].a as usize == i {
                cursor += 1;
            }
            let before = &previous[start..cursor];
            let first = self.found.len();
            for (w, regions) in slots.chunks(MESH_REGIONS).enumerate() {
                let key = |slot: usize| (w * MESH_REGIONS + slot) as u32;
                let mut used = [false; MESH_REGIONS];
                let mut pending = [None; MESH_REGIONS];
                for (k, g) in regions.iter().enumerate() {
                    let Some(g) = g else { continue };
                    // Of last step's regions facing about the same way, the nearest: a jack's
                    // arms on a floor share the normal but not the place.
                    let matched = before
                        .iter()
                        .filter(|c| (c.b as usize) / MESH_REGIONS == w)
                        .filter(|c| c.geometry.normal.dot(g.normal) > FRAC_1_SQRT_2)
                        .map(|c| {
                            let slot = c.b as usize % MESH_REGIONS;
                            (slot, (c.geometry.point - g.point).length_squared())
                        })
                        .filter(|&(slot, _)| !used[slot])
                        .min_by(|p, q| p.1.total_cmp(&q.1))
                        .map(|(slot, _)| slot);
                    if let Some(slot) = matched {
                        used[slot] = true;
                        self.found.push((i as u32, key(slot), *g));
                    } else {
                        pending[k] = Some(*g);
                    }
                }
                for g in pending.into_iter().flatten() {
                    let slot = used
                        .iter()
                        .position(|u| !u)
                        .expect("as many slots as regions");
                    used[slot] = true;
                    self.found.push((i as u32, key(slot), g));
                }
            }
            self.found[first..].sort_by_key(|&(_, b, _)| b);
        }
        self.dissipated += self.mesh_contacts.update(&self.found);
    }

    fn evaluate_contacts(&mut self, dt: f64) {
        predict_end_velocities(
            &self.bodies,
            self.gravity,
            0.5 * dt,
            &mut self.velocity_end,
            &mut self.angular_velocity_end,
        );
        let motion = Motion {
            bodies: &self.bodies,
            velocity_end: &self.velocity_end,
            angular_velocity_end: &self.angular_velocity_end,
        };
        let bodies = &self.bodies;
        let shapes = &self.shapes;
        let laws = &self.pair_laws;
        self.contacts
            .contacts
            .par_iter_mut()
            .with_min_len(256)
            .for_each(|c| {
                let (a, b) = (c.a as usize, c.b as usize);
                // R* from the volume-equivalent radii (the sphere's radius on a polyhedron), as
                // the laws and the time-step estimate define it; the bounding radius of a
                // polyhedron would soften every contact (by 1.4 for a cube).
                let effective_radius = narrow_phase::effective_radius(
                    &shapes[bodies.shape[a] as usize],
                    &shapes[bodies.shape[b] as usize],
                );
                let (ma, mb) = (bodies.mass[a], bodies.mass[b]);
                let (va, va_end) = motion.at(a, c.geometry.point);
                let (vb, vb_end) = motion.at(b, c.geometry.point);
                let k = kinematics(
                    &c.geometry,
                    va - vb,
                    va_end - vb_end,
                    bodies.angular_velocity[a] - bodies.angular_velocity[b],
                    effective_radius,
                    ma * mb / (ma + mb),
                );
                let law = laws.get(bodies.material[a], bodies.material[b]);
                c.response = contact_law::evaluate(law, &k, &mut c.history, dt);
            });
        let planes = &self.planes;
        let walls = &self.mesh_walls;
        // `wall`: the wall's surface velocity at the contact point over the step and at its end,
        // and its angular velocity.
        let wall_contact =
            |c: &mut crate::contact::Contact, wall_material: u32, wall: [DVec3; 3]| {
                let a = c.a as usize;
                let (va, va_end) = motion.at(a, c.geometry.point);
                let k = kinematics(
                    &c.geometry,
                    va - wall[0],
                    va_end - wall[1],
                    bodies.angular_velocity[a] - wall[2],
                    bodies.equivalent_radius[a],
                    bodies.mass[a],
                );
                let law = laws.get(bodies.material[a], wall_material);
                c.response = contact_law::evaluate(law, &k, &mut c.history, dt);
            };
        self.plane_contacts
            .contacts
            .par_iter_mut()
            .with_min_len(256)
            .for_each(|c| wall_contact(c, planes[c.b as usize].material, [DVec3::ZERO; 3]));
        let (now, end) = (self.wall_time - 0.5 * dt, self.wall_time);
        self.wall_states.clear();
        self.wall_states.extend(
            walls.iter().map(|w| {
                (!w.motion.is_fixed()).then(|| [w.motion.state(now), w.motion.state(end)])
            }),
        );
        let states = &self.wall_states;
        self.mesh_contacts
            .contacts
            .par_iter_mut()
            .with_min_len(256)
            .for_each(|c| {
                let w = c.b as usize / MESH_REGIONS;
                let (p, n) = (c.geometry.point, c.geometry.normal);
                let velocity = match &states[w] {
                    None => [DVec3::ZERO; 3],
                    Some([over_step, at_end]) => [
                        over_step.surface_velocity(p, n),
                        at_end.surface_velocity(p, n),
                        at_end.angular_velocity,
                    ],
                };
                wall_contact(c, walls[w].material, velocity)
            });
    }

    /// Sums contact forces onto bodies, in contact order so the sums do not depend on threads;
    /// books the walls' impulses and the work of moving walls over the step `dt`.
    fn accumulate_forces(&mut self, dt: f64) {
        let b = &mut self.bodies;
        b.force.iter_mut().for_each(|f| *f = DVec3::ZERO);
        b.torque.iter_mut().for_each(|t| *t = DVec3::ZERO);
        for c in &self.contacts.contacts {
            let (i, j) = (c.a as usize, c.b as usize);
            let f = c.response.force;
            let p = c.geometry.point;
            b.force[i] += f;
            b.force[j] -= f;
            b.torque[i] += (p - b.position[i]).cross(f) + c.response.torque;
            b.torque[j] -= (p - b.position[j]).cross(f) + c.response.torque;
            self.dissipated += c.response.dissipated;
        }
        let walls = self.planes.len() + self.mesh_walls.len();
        self.wall_impulse.resize(walls, DVec3::ZERO);
        self.wall_angular_impulse.resize(walls, DVec3::ZERO);
        let mut power = 0.0;
        let contacts = self
            .plane_contacts
            .contacts
            .iter()
            .map(|c| (c, c.b as usize));
        let mesh_contacts = self
            .mesh_contacts
            .contacts
            .iter()
            .map(|c| (c, self.planes.len() + c.b as usize / MESH_REGIONS));
        for (c, w) in contacts.chain(mesh_contacts) {
            let i = c.a as usize;
            let (f, p) = (c.response.force, c.geometry.point);
            b.force[i] += f;
            b.torque[i] += (p - b.position[i]).cross(f) + c.response.torque;
            self.dissipated += c.response.dissipated;
            let centre = match w.checked_sub(self.planes.len()) {
                None => self.planes[w].point,
                // Fixed walls report torques about the origin of their reference placement.
                Some(m) => match &self.wall_states[m] {
                    None => self.mesh_walls[m].motion.reference_point(self.wall_time),
                    Some([_, at_end]) => {
                        let v = at_end.surface_velocity(p, c.geometry.normal);
                        power += f.dot(v) + c.response.torque.dot(at_end.angular_velocity);
                        at_end.centre
                    }
                },
            };
            self.wall_impulse[w] -= f * dt;
            self.wall_angular_impulse[w] -= ((p - centre).cross(f) + c.response.torque) * dt;
        }
        // Trapezoidal rule over the step; a fresh evaluation (dt = 0) only sets the start value.
        self.wall_work += 0.5 * dt * (self.wall_power + power);
        self.wall_power = power;
    }

    /// The energy ledger at the current state.
    pub fn energy(&self) -> EnergyReport {
        EnergyReport::of(self)
    }

    /// Number of threads the world's parallel loops use.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }
}

/// Working memory of the contacts of pairs (of bodies, or of a body and a plane) that may touch
/// in several regions at once: the items to look at, up to [`MAX_REGIONS`] contacts for each,
/// and the contacts gathered with their slots.
#[derive(Default)]
struct RegionBuffers {
    /// The items (indices of pairs, or body × planes + plane), in increasing order.
    items: Vec<u32>,
    /// [`MAX_REGIONS`] slots per item.
    detected: Vec<Option<Geometry>>,
    found: Vec<(u32, u32, u16, Geometry)>,
    slots: Vec<(u16, Geometry)>,
}

impl RegionBuffers {
    /// Runs `regions(item, scratch, out)` for every item in parallel, each writing its own slots.
    fn detect(&mut self, regions: impl Fn(u32, &mut RegionScratch, &mut Vec<Geometry>) + Sync) {
        self.detected.clear();
        self.detected.resize(self.items.len() * MAX_REGIONS, None);
        self.detected
            .par_chunks_mut(MAX_REGIONS)
            .zip(self.items.par_iter())
            .with_min_len(16)
            .for_each_init(
                || (RegionScratch::default(), Vec::new()),
                |(scratch, out), (slots, &item)| {
                    regions(item, scratch, out);
                    for (slot, g) in slots.iter_mut().zip(out.iter()) {
                        *slot = Some(*g);
                    }
                },
            );
    }

    /// Appends the regions of item number `n` (the pair `a`, `b`) to `found`, each in the slot of
    /// the matching contact of last step (`previous`, see [`assign_slots`]).
    fn gather(&mut self, n: usize, a: u32, b: u32, previous: &[Contact], reach: f64) {
        self.slots.clear();
        let regions = self.detected[n * MAX_REGIONS..(n + 1) * MAX_REGIONS]
            .iter()
            .flatten()
            .copied();
        assign_slots(previous, regions, reach, &mut self.slots);
        self.found
            .extend(self.slots.iter().map(|&(slot, g)| (a, b, slot, g)));
    }
}

/// Velocities of body points at the moment contact forces are evaluated.
struct Motion<'a> {
    bodies: &'a Bodies,
    velocity_end: &'a [DVec3],
    angular_velocity_end: &'a [DVec3],
}

impl Motion<'_> {
    /// Velocity of the body point at `point` over the step just taken (the half-step velocity),
    /// and predicted at the end of the step (see [`predict_end_velocities`]).
    fn at(&self, body: usize, point: DVec3) -> (DVec3, DVec3) {
        let b = self.bodies;
        let arm = point - b.position[body];
        let now = b.velocity[body] + b.angular_velocity[body].cross(arm);
        let end = self.velocity_end[body] + self.angular_velocity_end[body].cross(arm);
        (now, end)
    }
}

/// Velocities at the end of the step predicted from the first half-kick's forces, which are
/// still in the force arrays: v_{n+1} ≈ v_{n+½} + (F_n/m + g) dt/2, and likewise for ω. Once per
/// body, not once per contact.
fn predict_end_velocities(
    b: &Bodies,
    gravity: DVec3,
    half_step: f64,
    velocity_end: &mut Vec<DVec3>,
    angular_velocity_end: &mut Vec<DVec3>,
) {
    velocity_end.resize(b.len(), DVec3::ZERO);
    angular_velocity_end.resize(b.len(), DVec3::ZERO);
    velocity_end
        .par_iter_mut()
        .zip(angular_velocity_end.par_iter_mut())
        .enumerate()
        .with_min_len(1024)
        .for_each(|(i, (v, w))| {
            *v = b.velocity[i] + (b.force[i] * b.inv_mass[i] + gravity) * half_step;
            *w = integrate::rotation::angular_velocity(
                b.orientation[i],
                b.angular_momentum[i] + b.torque[i] * half_step,
                b.inv_inertia[i],
            );
        });
}

/// Relative motion at a contact, from the relative velocities of the contact points.
fn kinematics(
    g: &Geometry,
    relative_velocity: DVec3,
    relative_velocity_end: DVec3,
    relative_angular_velocity: DVec3,
    effective_radius: f64,
    effective_mass: f64,
) -> Kinematics {
    let normal_speed = relative_velocity.dot(g.normal);
    let normal_speed_end = relative_velocity_end.dot(g.normal);
    Kinematics {
        normal: g.normal,
        overlap: g.overlap,
        overlap_rate: -normal_speed_end,
        tangential_velocity: relative_velocity - g.normal * normal_speed,
        tangential_velocity_end: relative_velocity_end - g.normal * normal_speed_end,
        relative_angular_velocity,
        effective_radius,
        effective_mass,
        overlap_volume: g.volume,
    }
}
