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
use crate::step::candidates::bodies_moved_too_far;
use crate::step::lookahead::largest_two_of;
use crate::step::{Lookahead, Moves, NeighbourSearch};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// A share's running totals (see [`World::take_share_of_totals`]): what adds up over the shares
/// of a decomposed world to the whole's.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunningTotals {
    pub dissipated: f64,
    pub energy_inserted: f64,
    pub energy_removed: f64,
    pub bodies_removed: u64,
    pub gravity_work: f64,
    pub kick_excess: f64,
    pub wall_impulse: Vec<DVec3>,
    pub wall_angular_impulse: Vec<DVec3>,
    pub wall_work: f64,
    pub meter_mass: Vec<f64>,
    pub meter_bodies: Vec<i64>,
}

impl RunningTotals {
    /// Adds `other`'s totals to these (which must be of a world with the same walls and meters,
    /// or empty).
    fn add(&mut self, other: &RunningTotals) {
        fn add_all<T: Copy + std::ops::AddAssign + Default>(sum: &mut Vec<T>, part: &[T]) {
            sum.resize(part.len(), T::default());
            sum.iter_mut().zip(part).for_each(|(s, &p)| *s += p);
        }
        self.dissipated += other.dissipated;
        self.energy_inserted += other.energy_inserted;
        self.energy_removed += other.energy_removed;
        self.bodies_removed += other.bodies_removed;
        self.gravity_work += other.gravity_work;
        self.kick_excess += other.kick_excess;
        add_all(&mut self.wall_impulse, &other.wall_impulse);
        add_all(&mut self.wall_angular_impulse, &other.wall_angular_impulse);
        self.wall_work += other.wall_work;
        add_all(&mut self.meter_mass, &other.meter_mass);
        add_all(&mut self.meter_bodies, &other.meter_bodies);
    }
}

/// What [`World::share_outlook`] finds, for the shares of a decomposed world to agree on before
/// the next step (the shares' outlooks merged by [`ShareOutlook::merge`]: every body is some
/// share's own).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShareOutlook {
    /// The largest distance an owned body will be, after the next step's drift, from where the
    /// shares were drawn, beyond its slack (0 if none goes beyond it): the shares are redrawn
    /// before it would reach the bound their ghost layer allows.
    pub excess_move: f64,
    /// The two largest distances an owned body will be, after the next step's drift, from where
    /// the neighbour search made its list, largest first (infinite if it makes a new one
    /// anyway): every share makes its list again when they call for it
    /// ([`World::follow_search_outlook`]), as a single world of all the bodies would.
    pub list_moves: [f64; 2],
}

impl ShareOutlook {
    /// The outlook of the bodies of both.
    pub fn merge(self, other: ShareOutlook) -> ShareOutlook {
        ShareOutlook {
            excess_move: self.excess_move.max(other.excess_move),
            list_moves: largest_two_of(self.list_moves, other.list_moves),
        }
    }

    /// As numbers, for a transport to carry ([`ShareOutlook::from_array`] reads them).
    pub fn to_array(self) -> [f64; 3] {
        [self.excess_move, self.list_moves[0], self.list_moves[1]]
    }

    pub fn from_array([excess_move, first, second]: [f64; 3]) -> Self {
        ShareOutlook {
            excess_move,
            list_moves: [first, second],
        }
    }
}

/// Where the bodies of a share were when the shares were drawn, how much farther each may go,
/// and what the last step's force sums found of their next move (see `step::lookahead`).
#[derive(Clone, Debug, Default)]
pub(super) struct Drawing {
    drawn_at: Vec<DVec3>,
    slack: Vec<f64>,
    /// `None` when the forces were found again since (then [`World::share_outlook`] calls for a
    /// redraw).
    pub(super) next: Option<Moves>,
}

impl Drawing {
    /// What `step::accumulate` reads to find the next move of a world's `bodies` bodies, whose
    /// neighbour search is `search`; `None` when they changed since the shares were drawn.
    pub(super) fn lookahead<'a>(
        &'a self,
        search: &'a NeighbourSearch,
        bodies: usize,
        dt: f64,
    ) -> Option<Lookahead<'a>> {
        (self.drawn_at.len() == bodies).then(|| Lookahead {
            drawn_at: &self.drawn_at,
            slack: &self.slack,
            listed: search.reference_positions().filter(|x| x.len() == bodies),
            dt,
        })
    }
}

/// What one share of a decomposed world gives towards the whole: its owned bodies, their
/// contacts as `a` (so each contact of the whole once) and its running totals.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SharePart {
    pub bodies: Vec<BodyRecord>,
    pub contacts: Vec<EntryRecord>,
    pub totals: RunningTotals,
}

impl World {
    /// This world's part of the whole, when it is a share of a decomposed world.
    pub fn share_part(&self) -> SharePart {
        let b = &self.bodies;
        let owned = (0..b.len()).filter(|&i| !b.is_ghost(i));
        SharePart {
            bodies: owned.clone().map(|i| b.record(i)).collect(),
            contacts: owned
                .flat_map(|i| self.contacts.own_records(b, i))
                .collect(),
            totals: self.running_totals(),
        }
    }

    /// This world's running totals.
    pub fn running_totals(&self) -> RunningTotals {
        RunningTotals {
            dissipated: self.dissipated,
            energy_inserted: self.energy_inserted,
            energy_removed: self.energy_removed,
            bodies_removed: self.bodies_removed,
            gravity_work: self.gravity_work,
            kick_excess: self.kick_excess,
            wall_impulse: self.wall_loads.impulse.clone(),
            wall_angular_impulse: self.wall_loads.angular_impulse.clone(),
            wall_work: self.wall_loads.work,
            meter_mass: self.flow_meters.iter().map(|m| m.mass).collect(),
            meter_bodies: self.flow_meters.iter().map(|m| m.bodies).collect(),
        }
    }

    /// Makes this world, built from the same scene as the shares of a decomposed world, the
    /// whole of it: `share` (any of them) gives the clock, the walls' and gravity's state, and
    /// every share's part (`parts`, in rank order) its bodies, contacts and totals. The whole then
    /// steps on as its shares would, bit for bit: bodies are copied exactly, contacts with their
    /// histories and last loads, and the totals add up. Bodies come in the order of the parts.
    ///
    /// A state that is no longer finite (a blow-up) is assembled without its contacts: a
    /// neighbour search of it would mean nothing.
    pub fn assemble(&mut self, share: &World, parts: &[SharePart]) -> Result<(), UnplacedContact> {
        assert_eq!(
            self.shapes.len(),
            share.shapes.len(),
            "the whole and its shares are built from one scene"
        );
        self.time = share.time;
        self.steps_done = share.steps_done;
        self.gravity = share.gravity;
        self.move_walls_to(share.wall_time);
        self.wall_states.clone_from(&share.wall_states);
        self.next_id = share.next_id;
        self.forces_current = share.forces_current;
        self.bodies = Default::default();
        self.drawing = None;
        for record in parts.iter().flat_map(|p| &p.bodies) {
            self.bodies.push_record(record, false);
        }
        self.contacts = Default::default();
        self.search.invalidate();
        let finite = self.bodies.position.iter().all(|x| x.is_finite());
        if finite {
            self.update_candidates();
            let index = self.index_by_id();
            let records: Vec<EntryRecord> = parts
                .iter()
                .flat_map(|p| p.contacts.iter().copied())
                .collect();
            self.contacts.adopt_all(&index, &records)?;
        }
        let mut totals = RunningTotals::default();
        for part in parts {
            totals.add(&part.totals);
        }
        self.dissipated = totals.dissipated;
        self.energy_inserted = totals.energy_inserted;
        self.energy_removed = totals.energy_removed;
        self.bodies_removed = totals.bodies_removed;
        self.gravity_work = totals.gravity_work;
        self.kick_excess = totals.kick_excess;
        self.wall_loads.impulse = totals.wall_impulse;
        self.wall_loads.angular_impulse = totals.wall_angular_impulse;
        self.wall_loads.work = totals.wall_work;
        for (m, (&mass, &bodies)) in self
            .flow_meters
            .iter_mut()
            .zip(totals.meter_mass.iter().zip(&totals.meter_bodies))
        {
            m.mass = mass;
            m.bodies = bodies;
        }
        if finite {
            self.book_wall_loads(0.0);
        }
        Ok(())
    }

    /// Sets the clock alone: for the view of a decomposed world that its run keeps between two
    /// assemblies (`run::SharedSteps`), whose bodies are those of the last.
    pub(crate) fn set_clock(&mut self, time: f64, steps_done: u64) {
        self.time = time;
        self.steps_done = steps_done;
    }

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
        self.contacts.renumber(&new_index);
        self.bodies.retain(keep);
        self.search.renumber(&new_index);
        self.drawing = None;
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
        self.search.append(1);
        self.drawing = None;
    }

    /// Marks which bodies are ghosts (see `Bodies::ghost`).
    pub fn set_ghosts(&mut self, ghost: &[bool]) {
        let had = (0..self.bodies.len()).map(|i| self.bodies.is_ghost(i));
        if !had.eq(ghost.iter().copied()) {
            // The candidate list leaves out pairs of two ghosts (`step::candidates`): a ghost
            // that became owned needs its pairs with ghosts back.
            self.search.expire();
        }
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

    /// Gives every body half the skin for margin, and makes the list again when the two largest
    /// moves add up to a skin (`step::margins::Margins::Uniform`): what a share of a decomposed
    /// world's ghost layer and look-ahead assume ([`ShareOutlook`]).
    pub fn set_uniform_margins(&mut self) {
        self.search
            .set_margins(crate::step::margins::Margins::Uniform);
    }

    /// Makes `drawn_at` the places of this share's bodies when the shares were drawn, and
    /// `slack[i]` how much farther than the shares' common bound body `i` may go from there.
    pub fn set_drawing(&mut self, drawn_at: Vec<DVec3>, slack: Vec<f64>) {
        assert_eq!(drawn_at.len(), self.bodies.len(), "a place per body");
        assert_eq!(slack.len(), self.bodies.len(), "a slack per body");
        self.drawing = Some(Drawing {
            drawn_at,
            slack,
            next: None,
        });
    }

    /// What a decomposed world asks of each share after every step (see [`ShareOutlook`]):
    /// each owned body's place after the next step's drift, predicted from the forces of the
    /// last evaluation, against where the shares were drawn ([`World::set_drawing`]) and
    /// against where the neighbour search made its list, as the last step's force sums found
    /// it (`step::lookahead`). If they found none (the forces were found again since, or the
    /// bodies changed since the drawing), the outlook calls for a redraw, which is always safe.
    pub fn share_outlook(&self) -> ShareOutlook {
        let listed = self
            .search
            .reference_positions()
            .is_some_and(|x| x.len() == self.bodies.len());
        match self.drawing.as_ref().and_then(|d| d.next) {
            Some(moves) => ShareOutlook {
                excess_move: moves.excess.max(0.0),
                list_moves: match listed {
                    true => moves.listed_squared.map(f64::sqrt),
                    false => [f64::INFINITY; 2],
                },
            },
            None => ShareOutlook {
                excess_move: f64::INFINITY,
                list_moves: [f64::INFINITY; 2],
            },
        }
    }

    /// Makes the neighbour search's list again at the next step if the bodies' two largest
    /// moves since it was made, after the next step's drift, call for it (`list_moves`, merged
    /// over the shares of a decomposed world: see [`ShareOutlook`]); otherwise the next step
    /// takes them as checked (the mesh walls' moves it checks itself).
    pub fn follow_search_outlook(&mut self, list_moves: [f64; 2]) {
        if bodies_moved_too_far(list_moves, self.skin(), !self.mesh_walls.is_empty()) {
            self.search.expire();
        } else {
            self.search.moves_checked_elsewhere();
        }
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
