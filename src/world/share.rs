//! A world as one share of a decomposed world (`decomposition`): the bodies it owns and steps
//! for good, and ghosts, copies of bodies other shares own that its owned bodies may touch before
//! the shares are redrawn. A share is a whole world: it steps its ghosts too (so its owned bodies
//! see them move), and after each step the ghosts are overwritten with their owners' state; what
//! adds up over bodies or contacts (the ledger, meters, wall loads, outputs) leaves ghosts to their
//! owners (`Bodies::ghost`). Nothing here books energy: bodies and contacts change hands, they do
//! not come or go.

use super::World;
use crate::body::{BodyMotionState, BodyRecord};
use crate::contact::{EntryRecord, UnplacedContact};
use crate::math::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;

impl World {
    /// Each body's index by global id.
    pub fn index_by_id(&self) -> HashMap<u64, usize> {
        (0..self.bodies.len())
            .map(|i| (self.bodies.id[i], i))
            .collect()
    }

    /// Keeps the bodies whose `keep` flag is set, with their contacts; the others are another
    /// share's now (no energy is booked). The forces stay those of the last evaluation.
    pub fn keep_share(&mut self, keep: &[bool]) {
        let mut new_index = Vec::with_capacity(keep.len());
        let mut next = 0u32;
        for &k in keep {
            new_index.push(if k { next } else { u32::MAX });
            next += k as u32;
        }
        if next as usize == keep.len() {
            return;
        }
        self.contacts.renumber(&new_index, |_| false);
        self.bodies.retain(keep);
        self.search.invalidate();
    }

    /// Adds the body `record` describes, bit for bit, as a ghost. Its shape id names an entry of
    /// this world's shape table, which every share of a decomposed world has the same.
    pub fn hold_ghost(&mut self, record: &BodyRecord) {
        assert!(
            (record.shape as usize) < self.shapes.len(),
            "body {} has shape {} of {}: the shares' shape tables differ",
            record.id,
            record.shape,
            self.shapes.len()
        );
        self.bodies.push_record(record, true);
        self.search.invalidate();
    }

    /// Marks which bodies are ghosts (see `Bodies::ghost`).
    pub fn set_ghosts(&mut self, ghost: &[bool]) {
        self.bodies.set_ghosts(ghost);
    }

    /// Makes body `i`'s motion `state`, bit for bit: a ghost takes its owner's after each step.
    pub fn set_motion_state(&mut self, i: usize, state: &BodyMotionState) {
        self.bodies.set_motion_state(i, state);
    }

    /// Makes the candidate list again now if it may have gone stale (after bodies changed
    /// hands), carrying every continuing contact's history and last response over.
    pub fn refresh_candidates(&mut self) {
        self.update_candidates();
    }

    /// Body `i`'s every contact entry, keyed by global ids.
    pub fn contact_records(&self, i: usize) -> Vec<EntryRecord> {
        self.contacts.records_of(&self.bodies, i)
    }

    /// Makes body `i`'s contact entries those of `records`, taken from the share that owned it
    /// (see `ContactStore::adopt`); `index` is [`World::index_by_id`]. The candidate list must
    /// be current ([`World::refresh_candidates`]).
    pub fn adopt_contacts(
        &mut self,
        i: usize,
        index: &HashMap<u64, usize>,
        records: &[EntryRecord],
    ) -> Result<(), UnplacedContact> {
        self.contacts.adopt(i, index, records)
    }

    /// How far the body that will have moved farthest from `from` (a place per body) will be
    /// after the next step's drift, predicted from the forces of the last evaluation. Shares are
    /// redrawn, all at once, before it would reach the distance their ghost layer allows.
    pub fn predicted_largest_move(&self, from: &[DVec3]) -> f64 {
        let (b, h, dt) = (&self.bodies, 0.5 * self.time_step, self.time_step);
        assert_eq!(from.len(), b.len(), "a place per body");
        let g = self.gravity;
        (0..b.len())
            .into_par_iter()
            .map(|i| {
                let v = b.velocity[i] + (b.force[i] * b.inv_mass[i] + g) * h;
                (b.position[i] + v * dt - from[i]).length()
            })
            .reduce(|| 0.0, f64::max)
    }

    /// Makes this share's running totals (energy dissipated, inserted and removed, the work of
    /// gravity changes and of moving walls, the walls' impulses, the meters' counts) its part of
    /// the decomposed world's: the whole of them if `first`, none otherwise; and the walls'
    /// power, from which the next step's work goes on, that of its own contacts.
    pub fn take_share_of_totals(&mut self, first: bool) {
        if !first {
            self.dissipated = 0.0;
            self.energy_inserted = 0.0;
            self.energy_removed = 0.0;
            self.bodies_removed = 0;
            self.gravity_work = 0.0;
            self.kick_excess = 0.0;
            let loads = &mut self.wall_loads;
            loads.impulse.iter_mut().for_each(|i| *i = DVec3::ZERO);
            loads
                .angular_impulse
                .iter_mut()
                .for_each(|i| *i = DVec3::ZERO);
            loads.work = 0.0;
            for meter in &mut self.flow_meters {
                meter.mass = 0.0;
                meter.bodies = 0;
            }
        }
        self.book_wall_loads(0.0);
    }
}
