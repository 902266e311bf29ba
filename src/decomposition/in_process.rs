//! The decomposed step run in one process: each rank's share of the world is a [`World`] of its
//! own, and what MPI ranks would send each other is copied between them. It is the reference the
//! MPI run is held to, and it tests the design in an ordinary `cargo test`: a decomposed run gives
//! every body the bits a single world gives it (`tests/decomposed_run.rs`).
//!
//! The design (`docs/mpi-plan.md`):
//! - **Shares.** Space is cut among the ranks by recursive coordinate bisection by body count
//!   ([`Decomposition`]); a rank owns the bodies in its region and holds as ghosts every body
//!   within the ghost layer of it: twice the largest bounding radius (the reach of a contact) and
//!   two skins (how far two bodies may move towards each other before the shares are redrawn,
//!   with a margin).
//! - **Every step**, each share steps all its bodies; then each ghost takes its owner's state
//!   (position, orientation, velocities, forces): the owner summed every contact of the body, the
//!   ghost's holder only some.
//! - **Redrawing.** Before any body would move half a skin from where the shares were drawn
//!   ([`World::predicted_search_move`], a maximum over the ranks), the cuts are made again from
//!   the bodies' places (so the counts stay balanced as they drift), bodies change hands, ghosts
//!   come and go, and each share makes its candidate list again. A body that changes owner brings
//!   its contacts' histories from its old owner ([`World::contact_records`]): the new owner held
//!   it as a ghost, but a ghost's contacts with other ghosts were not the exact ones.
//! - **Order.** Pairs are seen from the body of smaller id, and each body sums its contacts by
//!   its partners' ids (`contact::ContactKey::order`), so the share's numbering changes no bit.

use super::{Decomposition, LocalBodies};
use crate::body::BodyRecord;
use crate::contact::{EntryRecord, UnplacedContact};
use crate::energy::EnergyReport;
use crate::math::DVec3;
use crate::world::World;
use std::collections::HashMap;

/// Shares are redrawn when a body would come this far (in skins) from where they were drawn:
/// under the half skin the ghost layer allows for, so that round-off in the prediction does not
/// matter.
const REDRAW_AT: f64 = 0.45;

/// A world decomposed among ranks, all in this process.
pub struct InProcessRanks {
    shares: Vec<World>,
    /// Thickness of the ghost layer [m].
    layer: f64,
    /// Where each body is: its owner's rank and index there, by id.
    owners: HashMap<u64, (usize, usize)>,
    /// Each share's body count when `owners` was made (a body leaving the domain changes it).
    counts: Vec<usize>,
    /// Times the shares were drawn, and bodies that changed owner.
    pub redraws: u64,
    pub migrations: u64,
}

/// What a share receives when the shares are redrawn: bodies to hold, and histories of bodies it
/// takes over.
#[derive(Default)]
struct Delivery {
    bodies: Vec<BodyRecord>,
    contacts: Vec<(u64, Vec<EntryRecord>)>,
}

impl InProcessRanks {
    /// Splits a world among `ranks` shares. `build` makes the world (every share starts as a
    /// whole copy of it and keeps its share); it must give the same world every time.
    pub fn new(ranks: usize, build: impl Fn() -> World) -> Result<Self, UnplacedContact> {
        let mut shares: Vec<World> = (0..ranks).map(|_| build()).collect();
        for w in &mut shares {
            // The forces of the start, found with every body present, as a single world finds
            // them.
            w.update_contacts();
            w.set_sort_interval(0);
        }
        let w = &shares[0];
        let b = w.bodies();
        let largest = b.bounding_radius.iter().fold(0.0, |m: f64, &r| m.max(r));
        let layer = 2.0 * largest + 2.0 * w.skin();
        // Every share holds every body: the first drawing makes the shares with rank 0 as every
        // body's owner to copy from.
        let owners = (0..b.len()).map(|i| (b.id[i], (0, i))).collect();
        let mut world = InProcessRanks {
            shares,
            layer,
            owners,
            counts: Vec::new(),
            redraws: 0,
            migrations: 0,
        };
        world.redraw(true)?;
        for (r, w) in world.shares.iter_mut().enumerate() {
            w.take_share_of_totals(r == 0);
        }
        Ok(world)
    }

    pub fn shares(&self) -> &[World] {
        &self.shares
    }

    /// Advances every share by one step, gives the ghosts their owners' state, and redraws the
    /// shares if a body would otherwise move too far before the next step.
    pub fn step(&mut self) -> Result<(), UnplacedContact> {
        for w in &mut self.shares {
            w.step();
            // Bodies that left the domain: the forces are found again now, as a single world
            // finds them before its next step, so that the ghosts can take their owners'.
            w.update_contacts();
        }
        self.exchange();
        let moved = self
            .shares
            .iter()
            .map(World::predicted_search_move)
            .fold(0.0, f64::max);
        if moved > REDRAW_AT * self.shares[0].skin() {
            self.redraw(false)?;
        }
        Ok(())
    }

    /// The energy ledger of the whole: the shares' ledgers added up.
    pub fn energy(&self) -> EnergyReport {
        let mut total = EnergyReport::default();
        for w in &self.shares {
            let e = w.energy();
            total.kinetic_translational += e.kinetic_translational;
            total.kinetic_rotational += e.kinetic_rotational;
            total.potential += e.potential;
            total.elastic += e.elastic;
            total.dissipated += e.dissipated;
            total.removed += e.removed;
            total.inserted += e.inserted;
            total.wall_work += e.wall_work;
            total.gravity_work += e.gravity_work;
            total.contacts += e.contacts;
        }
        total
    }

    /// Each ghost takes its owner's state.
    fn exchange(&mut self) {
        self.index_owners();
        for r in 0..self.shares.len() {
            let ghosts: Vec<(usize, BodyRecordSource)> = {
                let b = self.shares[r].bodies();
                (0..b.len())
                    .filter(|&i| b.is_ghost(i))
                    .map(|i| (i, self.owners[&b.id[i]]))
                    .collect()
            };
            for (i, (owner, at)) in ghosts {
                let state = self.shares[owner].bodies().motion_state(at);
                self.shares[r].set_motion_state(i, &state);
            }
        }
    }

    /// Makes `owners` again if a share's bodies changed (after bodies left the domain).
    fn index_owners(&mut self) {
        let counts: Vec<usize> = self.shares.iter().map(|w| w.bodies().len()).collect();
        if counts == self.counts {
            return;
        }
        self.owners.clear();
        for (r, w) in self.shares.iter().enumerate() {
            let b = w.bodies();
            for i in (0..b.len()).filter(|&i| !b.is_ghost(i)) {
                self.owners.insert(b.id[i], (r, i));
            }
        }
        self.counts = counts;
    }

    /// Draws the shares again from the owned bodies' places (see the module's notes). `first`:
    /// every share holds every body, and rank 0's copies are the ones to take.
    fn redraw(&mut self, first: bool) -> Result<(), UnplacedContact> {
        let ranks = self.shares.len();
        // Every body once, from its owner: id, place, old owner and index there.
        let mut all: Vec<(u64, DVec3, usize, usize)> = self
            .owners
            .iter()
            .map(|(&id, &(r, i))| (id, self.shares[r].bodies().position[i], r, i))
            .collect();
        all.sort_unstable_by_key(|b| b.0);
        let places: Vec<DVec3> = all.iter().map(|b| b.1).collect();
        let cuts = Decomposition::new(ranks, &mut LocalBodies(&places));
        let mut new_owner: HashMap<u64, usize> = HashMap::with_capacity(all.len());
        let mut holders: Vec<Vec<u64>> = vec![Vec::new(); ranks];
        let mut deliveries: Vec<Delivery> = (0..ranks).map(|_| Delivery::default()).collect();
        for &(id, x, old, i) in &all {
            let owner = cuts.owner(x);
            new_owner.insert(id, owner);
            for r in cuts.ranks_near(x, self.layer) {
                holders[r].push(id);
            }
            if owner != old && !first {
                self.migrations += 1;
                let records = self.shares[old].contact_records(i);
                deliveries[owner].contacts.push((id, records));
            }
        }
        for (r, held) in holders.iter().enumerate() {
            let present: std::collections::HashSet<u64> =
                self.shares[r].bodies().id.iter().copied().collect();
            for &id in held.iter().filter(|id| !present.contains(id)) {
                let (old, i) = self.owners[&id];
                deliveries[r]
                    .bodies
                    .push(self.shares[old].bodies().record(i));
            }
        }
        for (r, delivery) in deliveries.into_iter().enumerate() {
            let held: std::collections::HashSet<u64> = holders[r].iter().copied().collect();
            let w = &mut self.shares[r];
            let keep: Vec<bool> = w.bodies().id.iter().map(|id| held.contains(id)).collect();
            w.keep_share(&keep);
            for record in &delivery.bodies {
                w.hold_ghost(record);
            }
            let ghost: Vec<bool> = w.bodies().id.iter().map(|id| new_owner[id] != r).collect();
            w.set_ghosts(&ghost);
            w.refresh_candidates();
            let index = w.index_by_id();
            for (id, records) in &delivery.contacts {
                w.adopt_contacts(index[id], &index, records)?;
            }
        }
        self.counts.clear();
        self.index_owners();
        self.redraws += 1;
        Ok(())
    }
}

/// Where a ghost's owner keeps the body: rank and index.
type BodyRecordSource = (usize, usize);
