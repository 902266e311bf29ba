//! One rank's share of a decomposed world, and the rank's own half of every exchange: what it
//! sends each other rank and what it does with what it receives. How the bytes travel is the
//! transport's: [`super::InProcessRanks`] copies them between shares in one process, MPI ranks
//! send them (`mpi_run`). So the MPI run is the in-process run with another transport.
//!
//! The design (`docs/mpi-plan.md`):
//! - **Shares.** Space is cut among the ranks by recursive coordinate bisection by body count
//!   ([`Decomposition`]); a rank owns the bodies in its region and holds as ghosts every body
//!   within the ghost layer of it: twice the largest bounding radius (the reach of a contact) and
//!   two skins (how far two bodies may move towards each other before the shares are redrawn,
//!   with a margin), and keeps those it held within a skin more.
//! - **Every step**, each share steps all its bodies; then each ghost takes its owner's state
//!   (position, orientation, velocities, forces: [`Share::put_states_for`]): the owner summed
//!   every contact of the body, the ghost's holder only some.
//! - **Redrawing** ([`Share::deliveries`], [`Share::receive`]). Before any body would move
//!   [`REDRAW_AT`] skins (more if it lies deep in its owner's region) from where the shares were
//!   drawn ([`World::share_outlook`], a maximum over the ranks), or when bodies left the domain,
//!   bodies change hands, ghosts come and go, and each share makes its candidate list again. A
//!   body that changes owner brings its contacts' histories from its old owner
//!   ([`World::contact_records`]): the new owner held it as a ghost, but a ghost's contacts with
//!   other ghosts are not the exact ones.
//! - **Order.** Pairs are seen from the body of smaller id, and each body sums its contacts by
//!   its partners' ids (`contact::ContactKey::order`), so the share's numbering changes no bit.

use super::Decomposition;
use crate::body::{Bodies, BodyMotionState, BodyRecord};
use crate::contact::{EntryRecord, UnplacedContact};
use crate::math::DVec3;
use crate::step::prefetch::prefetch;
use crate::step::space_order::{SORT_INTERVAL, SORT_MIN_BODIES};
use crate::world::{ShareOutlook, World};
use std::collections::{HashMap, HashSet};

/// Shares are redrawn when a body would come this far (in skins) from where they were drawn. Two
/// bodies that touch are within twice the largest bounding radius of each other; an owned body is
/// then at most this far out of its owner's region, its partner at most this far from where it
/// was drawn: within the ghost layer of two radii and twice this and a tenth skins, with a fifth
/// of a skin to spare for round-off in the prediction.
///
/// Two skins rather than one: a redraw makes every share's candidate list from scratch, and on
/// the 65,000-sphere bed, settled, shares redrawn at 0.9 skins were redrawn 12 times in 1,000
/// steps, at 1.9 skins 5 times (2.9: 4) for 16 % more ghosts, which cost little: pairs of two
/// ghosts are no candidates (`step::candidates`), so a ghost beyond reach of the owned bodies
/// is stepped and sent, no more.
///
/// A body whose drawn place lies deeper in its owner's region than the layer and a skin (by
/// [`Decomposition::depth`], the distance along an axis to the region's nearest cut) may go as
/// much farther as it lies deeper: its slack. It then stays over a layer deep in that region, so
/// it is no rank's ghost (no rank's region is within a layer of it) and, when its owner's, it
/// keeps away from every body its owner does not hold (those were over a layer outside the
/// region when drawn, and come no closer to it than they would without slack). So only bodies
/// near a cut call for a redraw: in a settling bed, not every body that still bounces.
pub const REDRAW_AT: f64 = 1.9;

/// What one share sends another when the shares are redrawn: the bodies the receiver is to hold
/// (of those the sender owned), and the contacts of those the receiver takes over.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Delivery {
    /// Bodies the receiver holds already, in the state the sender has: by id.
    pub held: Vec<u64>,
    /// Bodies the receiver is to hold anew, in full.
    pub bodies: Vec<BodyRecord>,
    /// Bodies the receiver is to own, each with the ranks that are to hold it (its owner too),
    /// to whom it sends the body's state after every step.
    pub owned: Vec<(u64, Vec<u32>)>,
    /// The contact entries of the bodies the receiver takes over from the sender.
    pub contacts: Vec<(u64, Vec<EntryRecord>)>,
}

/// One rank's share of a decomposed world.
pub struct Share {
    world: World,
    rank: usize,
    /// Thickness of the ghost layer [m] (the same on every rank).
    layer: f64,
    /// Per rank: the owned bodies it holds as ghosts, by local index, in order of id.
    send: Vec<Vec<u32>>,
    /// Per rank: the ghosts it owns, by local index, in order of id.
    receive: Vec<Vec<u32>>,
    /// The body count after the last exchange (bodies leaving the domain change it).
    count: usize,
    /// The step at which the share last put its bodies in space order (see
    /// [`Share::sort_in_space_if_due`]).
    sorted_at: Option<u64>,
}

impl Share {
    /// Rank `rank`'s share of `world`, a whole copy of the world every rank starts from (built
    /// the same way on every rank, forces found), with the cuts `cuts`: it owns the bodies in its
    /// region. The shares must then be drawn ([`Share::deliveries`], [`Share::receive`]).
    pub fn new(world: World, rank: usize, cuts: &Decomposition) -> Self {
        let mut share = Share {
            world,
            rank,
            layer: 0.0,
            send: Vec::new(),
            receive: Vec::new(),
            count: 0,
            sorted_at: None,
        };
        share.start_from_whole(cuts);
        share
    }

    /// Makes this share's world the whole `state` (a snapshot of the whole world, which every
    /// rank receives alike: after bodies were inserted into it), to be drawn again as after
    /// [`Share::new`]. `templates` name its polyhedral shapes (`World::restore`).
    pub fn restart(
        &mut self,
        state: crate::world::WorldState,
        templates: &[crate::shape::Shape],
        cuts: &Decomposition,
    ) -> Result<(), crate::world::RestoreError> {
        self.world.restore(state, templates)?;
        self.start_from_whole(cuts);
        Ok(())
    }

    /// The share's world holds every body: finds the forces, marks the bodies outside the
    /// share's region as ghosts, and forgets the last drawing.
    fn start_from_whole(&mut self, cuts: &Decomposition) {
        let world = &mut self.world;
        // The ghost layer and the look-ahead at the bodies' next move assume half a skin for
        // every body, and the two largest moves' rule.
        world.set_uniform_margins();
        world.update_contacts();
        // The share's numbering is its own business; bodies keep the order they came in.
        world.set_sort_interval(0);
        let b = world.bodies();
        let largest = b.bounding_radius.iter().fold(0.0, |m: f64, &r| m.max(r));
        self.layer = 2.0 * largest + 2.0 * (REDRAW_AT + 0.1) * world.skin();
        let rank = self.rank;
        let ghost: Vec<bool> = b.position.iter().map(|&x| cuts.owner(x) != rank).collect();
        world.set_ghosts(&ghost);
        self.count = world.bodies().len();
        self.send = vec![Vec::new(); cuts.ranks()];
        self.receive = vec![Vec::new(); cuts.ranks()];
    }

    pub fn world(&self) -> &World {
        &self.world
    }

    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The places of the bodies this share owns.
    pub fn owned_places(&self) -> Vec<DVec3> {
        let b = self.world.bodies();
        (0..b.len())
            .filter(|&i| !b.is_ghost(i))
            .map(|i| b.position[i])
            .collect()
    }

    /// One step of every body the share holds, and the forces found again if bodies left the
    /// domain (as a single world finds them before its next step). Returns whether bodies left:
    /// the shares must then be redrawn, not merely exchanged.
    pub fn step(&mut self) -> bool {
        self.world.step();
        self.world.update_contacts();
        self.world.bodies().len() != self.count
    }

    /// What the shares must agree on before the next step, as this share sees it (merged over
    /// the shares with [`ShareOutlook::merge`]): how far an owned body will have gone, after the
    /// next step's drift, beyond its slack from where it was when the shares were drawn, and
    /// how far from where the neighbour search made its list (see [`World::share_outlook`]).
    pub fn outlook(&self) -> ShareOutlook {
        self.world.share_outlook()
    }

    /// Makes this share's neighbour list again at the next step if the bodies' moves `merged`
    /// over the shares call for it (another share's bodies may: then every share does, at the
    /// same step, as a single world of all the bodies would); otherwise the next step does not
    /// look at the moves again.
    pub fn follow_search_outlook(&mut self, merged: &ShareOutlook) {
        self.world.follow_search_outlook(merged.list_moves);
    }

    /// Whether the shares must be redrawn before the next step, given the largest
    /// [`ShareOutlook::excess_move`] over the ranks.
    pub fn must_redraw(&self, largest_excess: f64) -> bool {
        largest_excess > REDRAW_AT * self.world.skin()
    }

    /// Appends to `out` the state of the bodies rank `to` holds as ghosts of this share's, in
    /// order of id, as numbers ([`BodyMotionState::to_array`], [`BodyMotionState::LEN`] a body):
    /// what is sent after every step, written straight from the bodies' arrays.
    pub fn put_states_for(&self, to: usize, out: &mut Vec<f64>) {
        let b = self.world.bodies();
        let send = &self.send[to];
        out.reserve(send.len() * BodyMotionState::LEN);
        for (k, &i) in send.iter().enumerate() {
            if let Some(&ahead) = send.get(k + STATES_AHEAD) {
                prefetch_motion_state(b, ahead as usize);
            }
            out.extend_from_slice(&b.motion_state(i as usize).to_array());
        }
    }

    /// The number of this share's ghosts that rank `from` owns (the states it sends each step).
    pub fn ghosts_from(&self, from: usize) -> usize {
        self.receive[from].len()
    }

    /// Gives the ghosts rank `from` owns the states it sent ([`Share::put_states_for`]).
    pub fn take_states(&mut self, from: usize, numbers: &[f64]) {
        const N: usize = BodyMotionState::LEN;
        assert_eq!(
            numbers.len(),
            self.receive[from].len() * N,
            "rank {from} sent {} numbers for {} ghosts of rank {}",
            numbers.len(),
            self.receive[from].len(),
            self.rank
        );
        let receive = &self.receive[from];
        for (k, (&i, state)) in receive.iter().zip(numbers.chunks_exact(N)).enumerate() {
            if let Some(&ahead) = receive.get(k + STATES_AHEAD) {
                prefetch_motion_state(self.world.bodies(), ahead as usize);
            }
            let state = BodyMotionState::from_slice(state);
            self.world.set_motion_state(i as usize, &state);
        }
    }

    /// What this share sends each rank (itself included) when the shares are redrawn with the
    /// cuts `cuts`: each owned body to every rank that is to hold it, and its contacts to its new
    /// owner if that is another rank. A rank holds the bodies within the ghost layer of its
    /// region, and keeps those it held within a skin more (so that bodies near the layer's edge
    /// do not come and go at every redraw). Bodies a rank holds already go by id, unless
    /// `stale` (bodies left the domain since the last exchange, which was then not made: the
    /// receiver's copies are a step old). Returns the deliveries, by receiver, with the number of
    /// bodies changing owner.
    pub fn deliveries(&self, cuts: &Decomposition, stale: bool) -> (Vec<Delivery>, u64) {
        let b = self.world.bodies();
        let mut out: Vec<Delivery> = vec![Delivery::default(); cuts.ranks()];
        // Which other ranks hold each owned body now (valid unless bodies left: then none), as
        // (body, rank) pairs sorted by body.
        let mut holders: Vec<(u32, u32)> = Vec::new();
        if !stale {
            for (r, list) in self.send.iter().enumerate() {
                holders.extend(list.iter().map(|&i| (i, r as u32)));
            }
        }
        holders.sort_unstable();
        let skin = self.world.skin();
        let mut migrations = 0;
        let (mut near, mut reach) = (Vec::new(), Vec::new());
        let mut from = 0;
        for i in (0..b.len()).filter(|&i| !b.is_ghost(i)) {
            // The ranks holding body i: a run of `holders`, which is sorted by body.
            while from < holders.len() && (holders[from].0 as usize) < i {
                from += 1;
            }
            let end = from + holders[from..].partition_point(|h| h.0 as usize == i);
            let held_by = |r: usize| holders[from..end].iter().any(|h| h.1 as usize == r);
            let x = b.position[i];
            cuts.ranks_near_into(x, self.layer, &mut near);
            cuts.ranks_near_into(x, self.layer + skin, &mut reach);
            reach.retain(|r| near.contains(r) || held_by(*r));
            for &r in &reach {
                if r == self.rank || held_by(r) {
                    out[r].held.push(b.id[i]);
                } else {
                    out[r].bodies.push(b.record(i));
                }
            }
            let owner = cuts.owner(x);
            out[owner]
                .owned
                .push((b.id[i], reach.iter().map(|&r| r as u32).collect()));
            if owner != self.rank {
                migrations += 1;
                let contacts = self.world.contact_records(i);
                out[owner].contacts.push((b.id[i], contacts));
            }
        }
        (out, migrations)
    }

    /// Takes what every rank sent ([`Share::deliveries`], by sender) when the shares were drawn
    /// with `cuts`: holds the bodies sent, in the state sent, drops the others, marks the ghosts,
    /// makes the candidate list again, takes over the contacts of the bodies it now owns, and
    /// makes the lists of the per-step exchange.
    pub fn receive(
        &mut self,
        cuts: &Decomposition,
        deliveries: Vec<Delivery>,
    ) -> Result<(), UnplacedContact> {
        let sent: HashMap<u64, &BodyRecord> = deliveries
            .iter()
            .flat_map(|d| &d.bodies)
            .map(|r| (r.id, r))
            .collect();
        let held: HashSet<u64> = deliveries.iter().flat_map(|d| &d.held).copied().collect();
        let keep: Vec<bool> = self
            .world
            .bodies()
            .id
            .iter()
            .map(|id| held.contains(id) || sent.contains_key(id))
            .collect();
        self.world.keep_share(&keep);
        let index = self.world.index_by_id();
        let mut new: Vec<&BodyRecord> = Vec::new();
        for (id, record) in &sent {
            match index.get(id) {
                Some(&i) => self.world.set_motion_state(i, &record.motion),
                None => new.push(record),
            }
        }
        // In order of id, so that every transport builds the same share.
        new.sort_unstable_by_key(|r| r.id);
        for record in new {
            self.world.hold_ghost(record);
        }
        self.sort_in_space_if_due();
        let b = self.world.bodies();
        let owner: Vec<usize> = b.position.iter().map(|&x| cuts.owner(x)).collect();
        let ghost: Vec<bool> = owner.iter().map(|&o| o != self.rank).collect();
        self.world.set_ghosts(&ghost);
        self.world.refresh_candidates();
        let index = self.world.index_by_id();
        for (id, records) in deliveries.iter().flat_map(|d| &d.contacts) {
            self.world.adopt_contacts(index[id], &index, records)?;
        }
        let owned = deliveries.iter().flat_map(|d| &d.owned);
        self.index_exchange(&index, owned, &owner);
        // A body deep in its owner's region may go farther before any rank's ghosts could miss
        // it: see [`REDRAW_AT`].
        let beyond = self.layer + self.world.skin();
        let drawn_at = self.world.bodies().position.clone();
        let slack = drawn_at
            .iter()
            .map(|&x| (cuts.depth(x) - beyond).max(0.0))
            .collect();
        self.world.set_drawing(drawn_at, slack);
        Ok(())
    }

    /// Renumbers the share's bodies along a space-filling curve, as a single world does every
    /// [`SORT_INTERVAL`] steps (`World::sort_bodies_in_space`), if that many steps have passed
    /// since the share last did: between redraws the share keeps its numbering (the exchange's
    /// lists name bodies by index), and a redraw makes its candidate list anew anyway. The
    /// results do not change by a bit (pairs and sums go by global ids).
    fn sort_in_space_if_due(&mut self) {
        let steps = self.world.steps_done();
        let due = self.sorted_at.is_none_or(|at| steps >= at + SORT_INTERVAL);
        if due && self.world.bodies().len() >= SORT_MIN_BODIES {
            self.world.sort_bodies_in_space();
            self.sorted_at = Some(steps);
        }
    }

    /// The lists of the per-step exchange: which owned bodies go to which rank (`owned`: each
    /// body this share owns with the ranks that hold it), which ghosts come from which (`owner`,
    /// by local index), both in order of id, so that sender and receiver agree on the order.
    fn index_exchange<'a>(
        &mut self,
        index: &HashMap<u64, usize>,
        owned: impl Iterator<Item = &'a (u64, Vec<u32>)>,
        owner: &[usize],
    ) {
        for list in self.send.iter_mut().chain(self.receive.iter_mut()) {
            list.clear();
        }
        for (id, holders) in owned {
            for &r in holders.iter().filter(|&&r| r as usize != self.rank) {
                self.send[r as usize].push(index[id] as u32);
            }
        }
        for (i, &owner) in owner.iter().enumerate() {
            if owner != self.rank {
                self.receive[owner].push(i as u32);
            }
        }
        let id = &self.world.bodies().id;
        for list in self.send.iter_mut().chain(self.receive.iter_mut()) {
            list.sort_unstable_by_key(|&i| id[i as usize]);
        }
        self.count = self.world.bodies().len();
    }

    /// Makes this share's running totals its part of the whole's (see
    /// [`World::take_share_of_totals`]): rank 0 keeps them, the others start from zero.
    pub fn take_share_of_totals(&mut self) {
        self.world.take_share_of_totals(self.rank == 0);
    }
}

/// The number of bodies each rank owns, over the ranks: the largest over the mean (1: balanced).
pub fn imbalance(owned: &[u64]) -> f64 {
    let total: u64 = owned.iter().sum();
    let largest = owned.iter().copied().max().unwrap_or(0);
    if total == 0 {
        return 1.0;
    }
    largest as f64 * owned.len() as f64 / total as f64
}

/// Recompute the cuts when the ranks' body counts drift this far apart (max over mean).
pub const REBALANCE_AT: f64 = 1.10;

/// How many bodies ahead the ghosts' exchange asks for a body's motion state.
const STATES_AHEAD: usize = 8;

/// Asks for the lines of body `i`'s motion state (seven arrays: see [`BodyMotionState`]). The
/// bodies a share sends and receives after every step lie scattered over its arrays, and reading
/// or writing their states waited for a miss per array and body (1 % of a rank's window in
/// `perf record` of two ranks on the 65,000-sphere bed): asked for some bodies ahead, the misses
/// overlap.
fn prefetch_motion_state(b: &Bodies, i: usize) {
    prefetch(&b.position[i]);
    prefetch(&b.orientation[i]);
    prefetch(&b.velocity[i]);
    prefetch(&b.angular_momentum[i]);
    prefetch(&b.angular_velocity[i]);
    prefetch(&b.force[i]);
    prefetch(&b.torque[i]);
}
