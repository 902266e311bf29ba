//! A run on MPI ranks (`mpirun -np N polydem run SCENE`): every rank builds the scene and keeps
//! its share ([`MpiRanks`]); rank 0 runs the run loop (`run::run_shared`) as a [`Leader`] and
//! writes everything, and the other ranks [`follow`] its orders. An order is one broadcast of
//! two numbers per chunk of steps, check or gather, so every rank enters the same collective
//! calls in the same order; the outputs come from the whole world assembled on rank 0 at each
//! output time (`World::assemble`). Bodies are inserted into that whole on rank 0, which then
//! sends it to every rank to start the shares again from (`MpiRanks::restart`); a resumed run
//! starts its shares the same way.

use super::mpi_ranks::{MpiRanks, MpiRunError};
use crate::run::{RunError, SharedCheck, SharedSteps};
use crate::shape::Shape;
use crate::world::{World, WorldState};
use mpi::traits::*;

/// What rank 0 tells the others to do next: a code and its argument.
const STEPS: u64 = 1;
const CHECK: u64 = 2;
const GATHER: u64 = 3;
const FINISH: u64 = 4;
const SCATTER: u64 = 5;

/// Rank 0's side: the run loop's world, stepped as shares, every call an order to the others.
pub struct Leader<'r, 'c, C: Communicator> {
    ranks: &'r mut MpiRanks<'c, C>,
    communicator: &'c C,
}

impl<'r, 'c, C: Communicator> Leader<'r, 'c, C> {
    pub fn new(ranks: &'r mut MpiRanks<'c, C>, communicator: &'c C) -> Self {
        Leader {
            ranks,
            communicator,
        }
    }

    /// Tells the other ranks that the run is over (whether it ended or stopped).
    pub fn finish(self) {
        order(self.communicator, FINISH, 0);
    }
}

fn order<C: Communicator>(communicator: &C, code: u64, argument: u64) -> [u64; 2] {
    let mut message = [code, argument];
    communicator
        .process_at_rank(0)
        .broadcast_into(&mut message[..]);
    message
}

fn ranks_error(e: MpiRunError) -> RunError {
    RunError::Ranks(format!("the run on several MPI ranks cannot go on: {e}"))
}

impl<C: Communicator> SharedSteps for Leader<'_, '_, C> {
    fn steps(&mut self, n: u64) -> Result<(f64, u64), RunError> {
        order(self.communicator, STEPS, n);
        self.ranks.run_steps(n).map_err(ranks_error)?;
        let w = self.ranks.world();
        Ok((w.time(), w.steps_done()))
    }

    fn check(&mut self, speed_limit: f64) -> Result<SharedCheck, RunError> {
        order(self.communicator, CHECK, speed_limit.to_bits());
        Ok(self.ranks.check(speed_limit))
    }

    fn gather(&mut self, whole: &mut World) -> Result<(), RunError> {
        order(self.communicator, GATHER, 0);
        self.ranks.gather(Some(whole)).map_err(ranks_error)
    }

    fn scatter(&mut self, whole: &World, templates: &[Shape]) -> Result<(), RunError> {
        let state = whole
            .snapshot(templates)
            .map_err(|e| ranks_error(MpiRunError::Restore(e.to_string())))?;
        let mut bytes = rmp_serde::to_vec(&state).expect("a world state encodes");
        order(self.communicator, SCATTER, bytes.len() as u64);
        self.communicator
            .process_at_rank(0)
            .broadcast_into(&mut bytes[..]);
        self.ranks.restart(state, templates).map_err(ranks_error)
    }
}

/// The other ranks' side: does what rank 0 orders until it says the run is over. `templates` are
/// the polyhedral shapes of this rank's build of the scene (`run::templates`), in rank 0's order.
pub fn follow<C: Communicator>(
    ranks: &mut MpiRanks<'_, C>,
    communicator: &C,
    templates: &[Shape],
) -> Result<(), MpiRunError> {
    loop {
        match order(communicator, 0, 0) {
            [STEPS, n] => ranks.run_steps(n)?,
            [CHECK, limit] => {
                ranks.check(f64::from_bits(limit));
            }
            [GATHER, _] => ranks.gather(None)?,
            [SCATTER, size] => {
                let mut bytes = vec![0u8; size as usize];
                communicator
                    .process_at_rank(0)
                    .broadcast_into(&mut bytes[..]);
                let state: WorldState =
                    rmp_serde::from_slice(&bytes).map_err(|e| MpiRunError::Garbled {
                        rank: communicator.rank() as usize,
                        from: 0,
                        why: e.to_string(),
                    })?;
                ranks.restart(state, templates)?;
            }
            _ => return Ok(()),
        }
    }
}
