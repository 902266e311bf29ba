//! The stages of a time step's contact pipeline, each a function with explicit inputs and outputs:
//!
//! 1. [`candidates`] — the neighbour search: which bodies and partners may touch (made again only
//!    when something has moved more than half the skin);
//! 2. [`detect`] — the narrow phase: the contact geometry of every candidate, into the contact
//!    store (polyhedral pairs that may touch in several places first; spheres on mesh walls at
//!    the start of each chunk of stage 3, then the rest);
//! 3. [`forces::evaluate`] — the contact laws: force, moment and energy of every contact, and
//!    each body's sum of its own contacts' loads (in a world that outgrows the last-level cache,
//!    completed there with the contacts whose partner each body is, as soon as the chunks
//!    writing them are done: `complete_sums`);
//! 4. [`forces::accumulate`] — the sums completed with the contacts whose partner each body is
//!    (unless stage 3 did), and the closing half kick (in a share of a decomposed world, with the
//!    [`lookahead`] at the bodies' next move); [`wall_loads`] the reactions on the walls.
//!
//! Stages 2 and 3 run chunk by chunk over the store ([`detect_and_evaluate`]; a chunk holds the
//! entries of whole bodies), so that a chunk's entries are still in cache when the laws read what
//! the narrow phase wrote, and its loads when they are added up.
//! `World::update_forces` (src/world.rs) runs the stages in order.

#[macro_use]
mod four_wide;
pub mod candidates;
pub mod detect;
pub mod forces;
pub mod lookahead;
pub mod margins;
pub mod mesh_lanes;
pub mod plane_lanes;
pub(crate) mod prefetch;
mod rolling_lanes;
pub mod space_order;
pub mod sphere_lanes;
pub mod spheres;
pub mod timing;
pub mod wall_loads;

pub use candidates::{NeighbourSearch, SearchState};
pub use detect::{detect_regions, RegionOutput, Scene};
pub use forces::{accumulate, IncomingSums, LawInputs};
pub use lookahead::{Lookahead, Moves};
pub use timing::{StageTimes, Stopwatch};
pub use wall_loads::{WallLoads, WallsNow};

pub use forces::OwnSums;

use crate::contact::{finish, Chunks, ContactStore, StorePass};
use crate::math::DVec3;
use std::ops::Range;

/// The narrow phase of the single-contact pairs, then the contact laws of every entry, over the
/// step `dt`, chunk by chunk in parallel (regional pairs' geometry comes from
/// [`detect_regions`], run before). Each chunk holds the entries of whole bodies, and leaves in
/// `own` (every body's) the sums of its bodies' own contacts, for [`accumulate`] to complete.
/// Returns the energy the contacts dissipated over the step: each chunk's sum, then the chunks'
/// in order, so the same figure for any thread count (`partial` is working memory kept from step
/// to step).
pub fn detect_and_evaluate(
    laws: LawInputs,
    store: &mut ContactStore,
    own: OwnSums,
    dt: f64,
    partial: &mut Vec<f64>,
) -> f64 {
    let (pass, chunks) = store.pass_mut();
    partial.clear();
    partial.resize(chunks.len(), 0.0);
    if chunks.len() == 0 {
        // No index lists yet, so no entries: no contact sums either.
        own.force.fill(DVec3::ZERO);
        own.torque.fill(DVec3::ZERO);
        store.set_sums_completed(false);
        return 0.0;
    }
    let completes_sums = chunks.completes_sums();
    debug_assert_eq!(chunks.bodies.last().copied(), Some(own.force.len() as u32));
    let range = ChunkRange {
        chunks: 0..chunks.len(),
        id: 0,
    };
    evaluate_chunks(&laws, pass, own, chunks, range, partial, dt);
    store.set_sums_completed(completes_sums);
    partial.iter().sum()
}

/// A range of the contact loop's chunks and its number in the loop's halving (see
/// `contact::store::finish`).
struct ChunkRange {
    chunks: Range<usize>,
    id: usize,
}

/// [`forces::evaluate`] of the chunks of `range` (whose entries are `pass`, whose bodies' sums
/// are `own`, and whose dissipated energies go to `partial`), halved until one chunk is left, the
/// halves in parallel; then, where the loop completes the sums, those of the bodies whose last
/// loads the range wrote ([`complete_sums`]).
fn evaluate_chunks(
    laws: &LawInputs,
    mut pass: StorePass,
    mut own: OwnSums,
    chunks: Chunks,
    range: ChunkRange,
    partial: &mut [f64],
    dt: f64,
) {
    let first = range.chunks.start;
    if range.chunks.len() == 1 {
        let (pass, own) = (pass.reborrow(), own.reborrow());
        partial[0] = forces::evaluate(*laws, pass, own, (chunks, first), dt);
    } else {
        let mid = finish::split_point(&range.chunks);
        let (left, right) = finish::halves(range.id, &range.chunks, mid);
        let entries = chunks.first_entry(mid) - chunks.first_entry(first);
        let bodies = (chunks.bodies[mid] - chunks.bodies[first]) as usize;
        let (pass, pass_rest) = pass.reborrow().split_at(entries);
        let (own, own_rest) = own.reborrow().split_at(bodies);
        let (partial, partial_rest) = partial.split_at_mut(mid - first);
        let (left, right) = (
            ChunkRange {
                chunks: first..mid,
                id: left,
            },
            ChunkRange {
                chunks: mid..range.chunks.end,
                id: right,
            },
        );
        rayon::join(
            || evaluate_chunks(laws, pass, own, chunks, left, partial, dt),
            || evaluate_chunks(laws, pass_rest, own_rest, chunks, right, partial_rest, dt),
        );
    }
    complete_sums(&pass, &mut own, chunks, &range);
}

/// Completes the force and moment sums of the bodies whose last loads the chunks of `range`
/// wrote (`pass` their entries, `own` their bodies' sums of their own contacts): each adds the
/// loads of the entries whose partner it is, in the order of its incoming list (its partners'
/// ids), so the same bits for any thread count and numbering, and as `IncomingSums` would. Here
/// rather than in the pass over the bodies in a world that outgrows the last-level cache: the
/// loads were written moments ago and are still in cache (in the 65,000-sphere bed, that pass
/// waited on a miss per incoming load for a sixth of the step). In a smaller world the pass
/// over the bodies finds them in cache anyway, and is the faster (docs/benchmarks.md).
fn complete_sums(pass: &StorePass, own: &mut OwnSums, chunks: Chunks, range: &ChunkRange) {
    let first_entry = chunks.first_entry(range.chunks.start);
    let first_body = chunks.bodies[range.chunks.start] as usize;
    for &b in chunks.finishing(range.id) {
        let i = b as usize - first_body;
        let incoming = chunks.incoming(b as usize).iter();
        let loads = incoming.map(|&e| &pass.load[e as usize - first_entry]);
        (own.force[i], own.torque[i]) = forces::add_incoming((own.force[i], own.torque[i]), loads);
    }
}
