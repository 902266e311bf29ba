//! The stages of a time step's contact pipeline, each a function with explicit inputs and outputs:
//!
//! 1. [`candidates`] — the neighbour search: which bodies and partners may touch (made again only
//!    when something has moved more than half the skin);
//! 2. [`detect`] — the narrow phase: the contact geometry of every candidate, into the contact
//!    store (pairs that may touch in several places first, then the rest);
//! 3. [`forces::evaluate`] — the contact laws: force, moment and energy of every contact;
//! 4. [`forces::accumulate`] — the sums onto the bodies; [`wall_loads`] the reactions on the walls.
//!
//! Stages 2 and 3 run chunk by chunk over the store ([`detect_and_evaluate`]), so that a chunk's
//! entries are still in cache when the laws read what the narrow phase wrote.
//! `World::update_forces` (src/world.rs) runs the stages in order.

#[macro_use]
mod four_wide;
pub mod candidates;
pub mod detect;
pub mod forces;
pub mod plane_lanes;
mod prefetch;
pub mod space_order;
pub mod sphere_lanes;
pub mod spheres;
pub mod timing;
pub mod wall_loads;

pub use candidates::{NeighbourSearch, SearchState};
pub use detect::{detect_regions, RegionOutput, Scene};
pub use forces::{accumulate, LawInputs};
pub use timing::{StageTimes, Stopwatch};
pub use wall_loads::{WallLoads, WallsNow};

use crate::contact::{ContactStore, EntryIds, EntryState};
use rayon::iter::Either;
use rayon::prelude::*;

/// Entries per parallel work item: small enough to stay in the L1/L2 cache between the narrow
/// phase and the laws, large enough to make the scheduling cost negligible.
const CHUNK: usize = 256;

/// The narrow phase of the single-contact pairs, then the contact laws of every entry, over the
/// step `dt`, chunk by chunk in parallel (regional pairs' geometry comes from
/// [`detect_regions`], run before). Returns the energy the contacts dissipated over the step:
/// each chunk's sum, then the chunks' in order, so the same figure for any thread count
/// (`partial` is working memory kept from step to step).
pub fn detect_and_evaluate(
    laws: LawInputs,
    store: &mut ContactStore,
    dt: f64,
    partial: &mut Vec<f64>,
) -> f64 {
    let (ids, state) = store.pass_mut();
    // A world of spheres and planes keeps no geometry, one without polyhedra no volumes, one
    // without rolling friction and polyhedra no spin histories: each chunk then gets an empty
    // slice.
    let chunks = ids.key.len().div_ceil(CHUNK);
    let geometry = side_array_chunks(state.geometry, chunks);
    let volume = side_array_chunks(state.volume, chunks);
    let spin = side_array_chunks(state.spin, chunks);
    ids.key
        .par_chunks(CHUNK)
        .zip(ids.kind.par_chunks(CHUNK))
        .zip(state.touching.par_chunks_mut(CHUNK))
        .zip(geometry)
        .zip(volume)
        .zip(state.history.par_chunks_mut(CHUNK))
        .zip(spin)
        .zip(state.load.par_chunks_mut(CHUNK))
        .zip(state.report.par_chunks_mut(CHUNK))
        .map(
            |((((((((key, kind), touching), geometry), volume), history), spin), load), report)| {
                let ids = EntryIds { key, kind };
                let mut state = EntryState {
                    touching,
                    geometry,
                    volume,
                    history,
                    spin,
                    load,
                    report,
                };
                forces::evaluate(laws, &ids, &mut state, dt)
            },
        )
        .collect_into_vec(partial);
    partial.iter().sum()
}

/// The chunks of a side array that a world may not keep: its chunks, or `chunks` empty slices.
fn side_array_chunks<T: Send>(
    values: &mut [T],
    chunks: usize,
) -> impl IndexedParallelIterator<Item = &mut [T]> {
    if values.is_empty() {
        Either::Right((0..chunks).into_par_iter().map(|_| <&mut [T]>::default()))
    } else {
        Either::Left(values.par_chunks_mut(CHUNK))
    }
}
