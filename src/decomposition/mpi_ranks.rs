//! The decomposed step on MPI ranks: this process's [`Share`], with what it sends the other ranks
//! moving through MPI collectives. Everything else is the in-process run's
//! ([`super::InProcessRanks`]), so the two give the same bits (`tests/mpi_decomposition.rs`
//! holds `mpirun -np 2` and `-np 3` to a single world).
//!
//! Per step: one `MPI_Allreduce` (did bodies leave the domain?), the ghosts' states (an
//! `MPI_Alltoallv` of 22 numbers per ghost: each rank knows how many it receives from whom), and
//! one `MPI_Allgather` of three numbers a rank (the largest predicted move beyond the slack, and
//! the two largest predicted moves since the neighbour lists were made: then every share remakes
//! its list at the same step). When the shares are redrawn: the owned counts
//! (one reduction; the cuts are made again, with a reduction per bisection probe, only when they
//! drifted apart), and the deliveries as MessagePack bytes (`MPI_Alltoall` of the sizes, then
//! `MPI_Alltoallv`). Every rank sends every other rank something, possibly nothing: fine for the
//! rank counts of one machine; neighbour-only messages are for later (`docs/mpi-plan.md`).

use super::mpi_count::DistributedBodies;
use super::share::{imbalance, Delivery, Share, REBALANCE_AT};
use super::{Decomposition, LocalBodies, RankTimes};
use crate::body::BodyMotionState;
use crate::energy::EnergyReport;
use crate::shape::Shape;
use crate::step::timing::Stopwatch;
use crate::world::{ShareOutlook, SharePart, World, WorldState};
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::traits::*;

/// Why a decomposed run cannot go on.
#[derive(Debug, thiserror::Error)]
pub enum MpiRunError {
    #[error(transparent)]
    Unplaced(#[from] crate::contact::UnplacedContact),
    #[error("the whole world sent to every rank does not fit this rank's scene: {0}")]
    Restore(String),
    #[error("rank {rank} could not read what rank {from} sent: {why}")]
    Garbled {
        rank: usize,
        from: usize,
        why: String,
    },
}

/// The ranks handed to the pool's thread for [`MpiRanks::run_steps`].
struct OnPoolThread<'r, 'c, C: Communicator>(&'r mut MpiRanks<'c, C>);

// SAFETY: the communicator (a handle MPI gives) is what keeps `MpiRanks` from being `Send`. It is
// used on the pool's thread only while the thread that handed it over waits in `install`, so no
// two threads call MPI at once, which MPI allows at the `Serialized` level `run_steps` checks for.
unsafe impl<C: Communicator> Send for OnPoolThread<'_, '_, C> {}

/// This process's share of a world decomposed among the ranks of `communicator`.
pub struct MpiRanks<'c, C: Communicator> {
    share: Share,
    communicator: &'c C,
    cuts: Decomposition,
    /// Times the shares were drawn, times the cuts were made, and bodies that changed owner
    /// (this rank's; see [`MpiRanks::total`]).
    pub redraws: u64,
    pub rebalances: u64,
    pub migrations: u64,
    /// Where this rank's time went (see [`RankTimes`]).
    pub times: RankTimes,
    /// The per-step exchange's buffers, kept from step to step.
    outgoing: Vec<f64>,
    incoming: Vec<f64>,
}

impl<'c, C: Communicator> MpiRanks<'c, C> {
    /// This rank's share of `world`, which every rank built the same (the whole scene).
    pub fn new(world: World, communicator: &'c C) -> Result<Self, MpiRunError> {
        let (rank, ranks) = (communicator.rank() as usize, communicator.size() as usize);
        // Every rank holds every body: the cuts need no communication yet.
        let cuts = Decomposition::new(ranks, &mut LocalBodies(&world.bodies().position));
        let share = Share::new(world, rank, &cuts);
        let mut run = MpiRanks {
            share,
            communicator,
            cuts,
            redraws: 0,
            rebalances: 1,
            migrations: 0,
            times: RankTimes::default(),
            outgoing: Vec::new(),
            incoming: Vec::new(),
        };
        run.redraw(false)?;
        run.share.take_share_of_totals();
        Ok(run)
    }

    /// Starts the shares again from the whole world `state`, which every rank receives alike
    /// (every rank calls it together): after bodies were inserted into the whole, or to resume
    /// a run. `templates` name its polyhedral shapes (`World::restore`).
    pub fn restart(&mut self, state: WorldState, templates: &[Shape]) -> Result<(), MpiRunError> {
        let ranks = self.communicator.size() as usize;
        self.cuts = Decomposition::new(ranks, &mut LocalBodies(&state.bodies.position));
        self.rebalances += 1;
        self.share
            .restart(state, templates, &self.cuts)
            .map_err(|e| MpiRunError::Restore(e.to_string()))?;
        self.redraw(false)?;
        self.share.take_share_of_totals();
        Ok(())
    }

    /// This rank's share.
    pub fn world(&self) -> &World {
        self.share.world()
    }

    /// One step of the whole (every rank calls it together).
    pub fn step(&mut self) -> Result<(), MpiRunError> {
        let mut watch = Stopwatch::start();
        let left = self.share.step();
        watch.lap(&mut self.times.step);
        if self.any(left) {
            watch.lap(&mut self.times.agree);
            let redrawn = self.redraw(true);
            watch.lap(&mut self.times.redraw);
            return redrawn;
        }
        watch.lap(&mut self.times.agree);
        self.exchange();
        watch.lap(&mut self.times.exchange);
        // One gathering for two questions: how far an owned body will have moved from where the
        // shares were drawn (beyond its slack), and how far from where the neighbour searches
        // made their lists (the two largest over all the bodies, which no reduction of MPI's
        // gives). Then every share remakes its list at the same step: a rank that remade its
        // list alone would hold the others up at the next exchange.
        let mine = self.share.outlook().to_array();
        let mut all = vec![0.0; 3 * self.communicator.size() as usize];
        self.communicator.all_gather_into(&mine[..], &mut all[..]);
        let merged = all
            .chunks_exact(3)
            .map(|o| ShareOutlook::from_array([o[0], o[1], o[2]]))
            .reduce(ShareOutlook::merge)
            .expect("a communicator has a rank");
        watch.lap(&mut self.times.agree);
        if self.share.must_redraw(merged.excess_move) {
            self.redraw(false)?;
            watch.lap(&mut self.times.redraw);
        } else {
            self.share.follow_search_outlook(&merged);
        }
        Ok(())
    }

    /// `n` steps of the whole (every rank calls it together), run on the world's own thread
    /// pool, MPI calls included, where MPI allows calls from any one thread at a time
    /// ([`mpi::Threading::Serialized`]; `polydem` asks for it). Stepped from the thread that
    /// started the rank, each step would hand its work to the pool and sleep until it is done:
    /// two wake-ups a step, and a rank's thread woken on the core where the other rank works
    /// (perf of two ranks: the starting thread 2.7 % of the samples, context switches 0.5 %).
    pub fn run_steps(&mut self, n: u64) -> Result<(), MpiRunError> {
        if mpi::environment::threading_support() < mpi::Threading::Serialized {
            return (0..n).try_for_each(|_| self.step());
        }
        let pool = self.share.world().thread_pool();
        let ranks = OnPoolThread(self);
        pool.install(move || {
            let ranks = ranks;
            (0..n).try_for_each(|_| ranks.0.step())
        })
    }

    /// The energy ledger of the whole, on every rank.
    pub fn energy(&self) -> EnergyReport {
        let mine = self.share.world().energy().to_array();
        let mut all = [0.0; 10];
        self.communicator
            .all_reduce_into(&mine[..], &mut all[..], SystemOperation::sum());
        EnergyReport::from_array(all)
    }

    /// The run's checks over every rank's share (every rank calls it together): a state no
    /// longer finite, a body faster than `speed_limit`, and the energy ledger of the whole.
    pub fn check(&self, speed_limit: f64) -> crate::run::SharedCheck {
        let w = self.share.world();
        let not_finite = crate::run::blow_up(w).is_some();
        let too_fast = crate::run::too_fast(w, speed_limit).is_some();
        crate::run::SharedCheck {
            not_finite: self.any(not_finite),
            too_fast: self.any(too_fast),
            energy: self.energy(),
        }
    }

    /// Makes `whole` (on rank 0; `None` on the others) the whole world, from every rank's part
    /// (see `World::assemble`; every rank calls it together): the parts go to rank 0 as
    /// MessagePack bytes.
    pub fn gather(&self, whole: Option<&mut World>) -> Result<(), MpiRunError> {
        let rank = self.communicator.rank() as usize;
        let root = self.communicator.process_at_rank(0);
        let bytes = rmp_serde::to_vec(&self.share.world().share_part()).expect("a part encodes");
        let size = bytes.len() as i32;
        let Some(whole) = whole else {
            root.gather_into(&size);
            root.gather_varcount_into(&bytes[..]);
            return Ok(());
        };
        let mut sizes = vec![0i32; self.communicator.size() as usize];
        root.gather_into_root(&size, &mut sizes[..]);
        let starts = starts(&sizes);
        let mut all = vec![0u8; sizes.iter().sum::<i32>() as usize];
        root.gather_varcount_into_root(
            &bytes[..],
            &mut PartitionMut::new(&mut all[..], &sizes[..], &starts[..]),
        );
        let parts = sizes
            .iter()
            .zip(&starts)
            .enumerate()
            .map(|(from, (&n, &start))| {
                let piece = &all[start as usize..(start + n) as usize];
                rmp_serde::from_slice(piece).map_err(|e| MpiRunError::Garbled {
                    rank,
                    from,
                    why: e.to_string(),
                })
            })
            .collect::<Result<Vec<SharePart>, _>>()?;
        whole.assemble(self.share.world(), &parts)?;
        Ok(())
    }

    /// The sum of `value` over the ranks, on every rank.
    pub fn total(&self, value: u64) -> u64 {
        let mut sum = 0u64;
        self.communicator
            .all_reduce_into(&value, &mut sum, SystemOperation::sum());
        sum
    }

    fn any(&self, flag: bool) -> bool {
        self.total(flag as u64) > 0
    }

    /// Each ghost takes its owner's state (through buffers kept from step to step).
    fn exchange(&mut self) {
        let ranks = self.communicator.size() as usize;
        const N: usize = BodyMotionState::LEN;
        let mut outgoing = std::mem::take(&mut self.outgoing);
        outgoing.clear();
        let mut send_counts = Vec::with_capacity(ranks);
        for to in 0..ranks {
            let before = outgoing.len();
            self.share.put_states_for(to, &mut outgoing);
            send_counts.push((outgoing.len() - before) as i32);
        }
        let receive_counts: Vec<i32> = (0..ranks)
            .map(|from| (self.share.ghosts_from(from) * N) as i32)
            .collect();
        let mut incoming = std::mem::take(&mut self.incoming);
        self.all_to_all_into(&outgoing, &send_counts, &receive_counts, &mut incoming);
        let mut at = 0;
        for (from, &count) in receive_counts.iter().enumerate() {
            let count = count as usize;
            self.share.take_states(from, &incoming[at..at + count]);
            at += count;
        }
        (self.outgoing, self.incoming) = (outgoing, incoming);
    }

    /// Draws the shares again (see [`super::share`]).
    fn redraw(&mut self, stale: bool) -> Result<(), MpiRunError> {
        let ranks = self.communicator.size() as usize;
        let rank = self.communicator.rank() as usize;
        let places = self.share.owned_places();
        let mut mine = vec![0u64; ranks];
        for &x in &places {
            mine[self.cuts.owner(x)] += 1;
        }
        let mut owned = vec![0u64; ranks];
        self.communicator
            .all_reduce_into(&mine[..], &mut owned[..], SystemOperation::sum());
        if imbalance(&owned) > REBALANCE_AT {
            self.cuts = Decomposition::new(
                ranks,
                &mut DistributedBodies {
                    local: LocalBodies(&places),
                    communicator: self.communicator,
                },
            );
            self.rebalances += 1;
        }
        let (mut out, migrations) = self.share.deliveries(&self.cuts, stale);
        self.migrations += migrations;
        // What this rank delivers itself (every body it keeps: most of what it sends) stays in
        // memory; the others' deliveries travel as bytes.
        let own = std::mem::take(&mut out[rank]);
        let mut outgoing = Vec::new();
        let mut send_counts = Vec::with_capacity(ranks);
        for (to, delivery) in out.iter().enumerate() {
            let bytes = if to == rank {
                Vec::new()
            } else {
                rmp_serde::to_vec(delivery).expect("a delivery encodes")
            };
            send_counts.push(bytes.len() as i32);
            outgoing.extend_from_slice(&bytes);
        }
        let mut receive_counts = vec![0i32; ranks];
        self.communicator
            .all_to_all_into(&send_counts[..], &mut receive_counts[..]);
        let incoming = self.all_to_all(&outgoing, &send_counts, &receive_counts);
        let mut deliveries = Vec::with_capacity(ranks);
        let mut own = Some(own);
        let mut at = 0;
        for (from, &count) in receive_counts.iter().enumerate() {
            if from == rank {
                deliveries.extend(own.take());
                continue;
            }
            let bytes = &incoming[at..at + count as usize];
            let delivery: Delivery =
                rmp_serde::from_slice(bytes).map_err(|e| MpiRunError::Garbled {
                    rank,
                    from,
                    why: e.to_string(),
                })?;
            deliveries.push(delivery);
            at += count as usize;
        }
        self.share.receive(&self.cuts, deliveries)?;
        self.redraws += 1;
        Ok(())
    }

    /// `MPI_Alltoallv`: `outgoing` holds, rank after rank, `send_counts[r]` items for rank `r`;
    /// returns, rank after rank, the `receive_counts[r]` items rank `r` sent this one.
    fn all_to_all<T: Equivalence + Default + Clone>(
        &self,
        outgoing: &[T],
        send_counts: &[i32],
        receive_counts: &[i32],
    ) -> Vec<T> {
        let mut incoming = Vec::new();
        self.all_to_all_into(outgoing, send_counts, receive_counts, &mut incoming);
        incoming
    }

    /// [`MpiRanks::all_to_all`] into `incoming` (whose room is kept).
    fn all_to_all_into<T: Equivalence + Default + Clone>(
        &self,
        outgoing: &[T],
        send_counts: &[i32],
        receive_counts: &[i32],
        incoming: &mut Vec<T>,
    ) {
        let (send_starts, receive_starts) = (starts(send_counts), starts(receive_counts));
        let total: i32 = receive_counts.iter().sum();
        incoming.clear();
        incoming.resize(total as usize, T::default());
        self.communicator.all_to_all_varcount_into(
            &Partition::new(outgoing, send_counts, &send_starts[..]),
            &mut PartitionMut::new(&mut incoming[..], receive_counts, &receive_starts[..]),
        );
    }
}

/// Where each rank's items start in a buffer that holds `counts[r]` items of rank `r`, rank
/// after rank (the displacements of the `MPI_*v` collectives).
fn starts(counts: &[i32]) -> Vec<i32> {
    counts
        .iter()
        .scan(0, |at, &c| {
            let start = *at;
            *at += c;
            Some(start)
        })
        .collect()
}
