//! The decomposed step run in one process: each rank's [`Share`] is a world of its own, and what
//! MPI ranks would send each other is handed from share to share. It is the reference the MPI run
//! is held to, and it tests the design in an ordinary `cargo test`: a decomposed run gives every
//! body the bits a single world gives it (`tests/decomposed_run.rs`). The design is in
//! [`super::share`].

use super::share::{imbalance, Delivery, Share, REBALANCE_AT};
use super::{Decomposition, LocalBodies};
use crate::contact::UnplacedContact;
use crate::energy::EnergyReport;
use crate::math::DVec3;
use crate::world::{ShareOutlook, World};

/// A world decomposed among ranks, all in this process.
pub struct InProcessRanks {
    shares: Vec<Share>,
    cuts: Decomposition,
    /// Times the shares were drawn, times the cuts were made, and bodies that changed owner.
    pub redraws: u64,
    pub rebalances: u64,
    pub migrations: u64,
}

impl InProcessRanks {
    /// Splits a world among `ranks` shares. `build` makes the world (every share starts as a
    /// whole copy of it and keeps its share); it must give the same world every time.
    pub fn new(ranks: usize, build: impl Fn() -> World) -> Result<Self, UnplacedContact> {
        let first = build();
        let cuts = Decomposition::new(ranks, &mut LocalBodies(&first.bodies().position));
        let mut shares = vec![Share::new(first, 0, &cuts)];
        shares.extend((1..ranks).map(|r| Share::new(build(), r, &cuts)));
        let mut world = InProcessRanks {
            shares,
            cuts,
            redraws: 0,
            rebalances: 1,
            migrations: 0,
        };
        world.redraw(false)?;
        for share in &mut world.shares {
            share.take_share_of_totals();
        }
        Ok(world)
    }

    /// Each rank's share.
    pub fn shares(&self) -> impl Iterator<Item = &World> + '_ {
        self.shares.iter().map(Share::world)
    }

    /// Advances every share by one step, gives the ghosts their owners' state, and redraws the
    /// shares if a body would otherwise move too far before the next step, or bodies left.
    pub fn step(&mut self) -> Result<(), UnplacedContact> {
        let mut left = false;
        for share in &mut self.shares {
            left |= share.step();
        }
        if left {
            return self.redraw(true);
        }
        let mut states = Vec::new();
        for from in 0..self.shares.len() {
            for to in 0..self.shares.len() {
                states.clear();
                self.shares[from].put_states_for(to, &mut states);
                self.shares[to].take_states(from, &states);
            }
        }
        // As on MPI ranks: the shares' outlooks merged, so every share remakes its neighbour
        // list at the same step.
        let merged = self
            .shares
            .iter()
            .map(Share::outlook)
            .reduce(ShareOutlook::merge);
        let Some(merged) = merged else {
            return Ok(());
        };
        if self.shares[0].must_redraw(merged.excess_move) {
            self.redraw(false)?;
        } else {
            for share in &mut self.shares {
                share.follow_search_outlook(&merged);
            }
        }
        Ok(())
    }

    /// The energy ledger of the whole: the shares' ledgers added up.
    pub fn energy(&self) -> EnergyReport {
        self.shares().map(World::energy).sum()
    }

    /// Draws the shares again: new cuts if the counts drifted apart, then every share's
    /// deliveries to every other.
    fn redraw(&mut self, stale: bool) -> Result<(), UnplacedContact> {
        let places: Vec<Vec<DVec3>> = self.shares.iter().map(Share::owned_places).collect();
        let owned: Vec<u64> = (0..self.shares.len())
            .map(|r| {
                places
                    .iter()
                    .flatten()
                    .filter(|&&x| self.cuts.owner(x) == r)
                    .count() as u64
            })
            .collect();
        if imbalance(&owned) > REBALANCE_AT {
            let all: Vec<DVec3> = places.concat();
            self.cuts = Decomposition::new(self.shares.len(), &mut LocalBodies(&all));
            self.rebalances += 1;
        }
        let ranks = self.shares.len();
        let mut inbox: Vec<Vec<Delivery>> = (0..ranks).map(|_| Vec::new()).collect();
        for share in &self.shares {
            let (out, migrations) = share.deliveries(&self.cuts, stale);
            self.migrations += migrations;
            for (to, delivery) in out.into_iter().enumerate() {
                inbox[to].push(delivery);
            }
        }
        for (share, deliveries) in self.shares.iter_mut().zip(inbox) {
            share.receive(&self.cuts, deliveries)?;
        }
        self.redraws += 1;
        Ok(())
    }
}
