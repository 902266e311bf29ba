//! The stages of a time step's contact pipeline, each a function with explicit inputs and outputs:
//!
//! 1. [`candidates`] — the neighbour search: which bodies and partners may touch (made again only
//!    when something has moved more than half the skin);
//! 2. [`detect`] — the narrow phase: the contact geometry of every candidate, into the contact
//!    store (polyhedral pairs that may touch in several places first; spheres on mesh walls at
//!    the start of each chunk of stage 3, then the rest);
//! 3. [`forces::evaluate`] — the contact laws: force, moment and energy of every contact, and
//!    each body's sum of its own contacts' loads;
//! 4. [`forces::accumulate`] — the sums completed with the contacts whose partner each body is,
//!    and the closing half kick (in a share of a decomposed world, with the [`lookahead`] at the
//!    bodies' next move); [`wall_loads`] the reactions on the walls.
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

use crate::contact::{Chunks, ContactStore, StorePass};
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
        return 0.0;
    }
    debug_assert_eq!(chunks.bodies.last().copied(), Some(own.force.len() as u32));
    evaluate_chunks(&laws, pass, own, chunks, 0..chunks.len(), partial, dt);
    partial.iter().sum()
}

/// [`forces::evaluate`] of the chunks `range` (whose entries are `pass`, whose bodies' sums are
/// `own`, and whose dissipated energies go to `partial`), halved until one chunk is left, the
/// halves in parallel.
fn evaluate_chunks(
    laws: &LawInputs,
    pass: StorePass,
    own: OwnSums,
    chunks: Chunks,
    range: Range<usize>,
    partial: &mut [f64],
    dt: f64,
) {
    if range.len() == 1 {
        partial[0] = forces::evaluate(*laws, pass, own, (chunks, range.start), dt);
        return;
    }
    let mid = range.start + range.len() / 2;
    let entries = chunks.first_entry(mid) - chunks.first_entry(range.start);
    let bodies = (chunks.bodies[mid] - chunks.bodies[range.start]) as usize;
    let (pass, pass_rest) = pass.split_at(entries);
    let (own, own_rest) = own.split_at(bodies);
    let (partial, partial_rest) = partial.split_at_mut(mid - range.start);
    rayon::join(
        || evaluate_chunks(laws, pass, own, chunks, range.start..mid, partial, dt),
        || {
            evaluate_chunks(
                laws,
                pass_rest,
                own_rest,
                chunks,
                mid..range.end,
                partial_rest,
                dt,
            )
        },
    );
}
