//! Bodies coming and going and changing places: added while setting up or during a run, removed
//! (by the user or on leaving the domain), and renumbered in space order. Each keeps the energy
//! ledger and the contact store consistent with the change.

use super::World;
use crate::body::BodyInit;
use crate::integrate;
use crate::math::DVec3;
use crate::step::space_order;
use rayon::prelude::*;

impl World {
    /// Room for `additional` more bodies ([`crate::body::Bodies::reserve`]), before adding a
    /// scene's.
    pub fn reserve_bodies(&mut self, additional: usize) {
        self.bodies.reserve(additional);
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
            let skin = self.search.skin().min(Self::default_skin(radius));
            self.search.set_skin(skin);
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
    /// booked as carried out (a ghost's by its owner).
    pub fn remove_bodies(&mut self, keep: &[bool]) {
        let mut new_index = Vec::with_capacity(keep.len());
        let mut next = 0u32;
        for (i, &k) in keep.iter().enumerate() {
            if k {
                new_index.push(next);
                next += 1;
            } else {
                new_index.push(u32::MAX);
                if self.bodies.counts(i) {
                    self.energy_removed += self.body_energy(i);
                    self.bodies_removed += 1;
                }
            }
        }
        if next as usize == keep.len() {
            return;
        }
        let bodies = &self.bodies;
        let lost = self
            .contacts
            .dropped_energy(&new_index, |i| bodies.counts(i), self.placement());
        self.energy_removed += lost;
        self.contacts.renumber(&new_index);
        self.bodies.retain(keep);
        self.structure_changed();
    }

    /// Removes every body whose centre is outside [`World::domain`].
    pub(super) fn remove_bodies_outside_domain(&mut self) {
        let Some(domain) = self.domain else { return };
        let outside = |x: &DVec3| x.cmplt(domain.min).any() || x.cmpgt(domain.max).any();
        if !self.bodies.position.par_iter().any(outside) {
            return;
        }
        let keep: Vec<bool> = self.bodies.position.iter().map(|x| !outside(x)).collect();
        self.remove_bodies(&keep);
    }

    /// Kinetic (translational and rotational) plus gravitational energy of one body.
    pub(super) fn body_energy(&self, i: usize) -> f64 {
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
    pub(super) fn structure_changed(&mut self) {
        self.forces_current = false;
        self.search.invalidate();
        self.drawing = None;
    }

    /// Renumbers the bodies along a space-filling curve (see `step::space_order`), with their
    /// forces and contacts, so that neighbours in space are neighbours in memory. The world does
    /// this itself every [`World::set_sort_interval`] steps once it has
    /// [`space_order::SORT_MIN_BODIES`] bodies: body indices are then not stable, body ids are.
    pub fn sort_bodies_in_space(&mut self) {
        let mut order = Vec::new();
        space_order::morton_order(&self.bodies.position, &mut order);
        self.permute_bodies(&order);
    }

    /// Puts the bodies in a new order, with their forces and contacts: body `k` becomes what body
    /// `order[k]` was (a permutation of `0..bodies`). Ids stay with their bodies, and since every
    /// body pair is seen from the body of smaller id and every body sums its contacts in the
    /// order of its partners' ids (`contact::ContactKey::order`), the run goes on bit for bit as
    /// it would have without the change.
    pub fn permute_bodies(&mut self, order: &[u32]) {
        assert_eq!(order.len(), self.bodies.len(), "one new place per body");
        let mut new_index = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_index[old as usize] = new as u32;
        }
        self.bodies.permute(order);
        self.contacts
            .permute(&new_index, &self.bodies.id, &self.bodies.position);
        // The broad phase's lists name bodies by index: it starts afresh (following a new order
        // fragments its lists' memory, see `SweepAndPrune::follow_renumbering`), and its first
        // list carries the contacts' histories over. A share's drawing names bodies by index too.
        self.search.invalidate();
        self.drawing = None;
    }

    /// Steps between two automatic [`World::sort_bodies_in_space`] (0: never; by default
    /// [`space_order::SORT_INTERVAL`]).
    pub fn set_sort_interval(&mut self, steps: u64) {
        self.sort_interval = steps;
    }

    /// Where the bodies' force sums are completed: in the contact loop (`Some(true)`), in the
    /// pass over the bodies after it (`Some(false)`), or by the world's size against the
    /// last-level cache (`None`, the default; see `contact::ContactStore::completes_sums`). The
    /// results are the same bits; only the time differs.
    pub fn set_sums_in_contact_loop(&mut self, choice: Option<bool>) {
        self.contacts.set_sums_in_loop(choice);
    }
}
