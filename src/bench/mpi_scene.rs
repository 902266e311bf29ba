//! The whole-scene benchmark on MPI ranks (`mpirun -np N polydem bench scene …`): the scene
//! decomposed among the ranks ([`MpiRanks`]), stepped and timed over the same window as
//! [`super::scene::run`], the figures added up over the ranks.

use super::scene::{
    check_window, contact_counts, load, peak_rss_bytes, scene_name, settle, ContactCounts,
    SceneTiming,
};
use crate::decomposition::mpi_ranks::MpiRanks;
use crate::decomposition::RankTimes;
use mpi::traits::*;
use std::path::Path;
use std::time::Instant;

/// [`super::scene::run`] with the scene decomposed among the ranks of `communicator` (every rank
/// calls it together; every rank builds, and settles if asked, the whole scene the same way,
/// then keeps its share). The window's time is the slowest rank's; bodies, contacts and peak
/// memory are added up over the ranks.
pub fn run<C: Communicator>(
    file: &Path,
    settle_steps: u64,
    steps: u64,
    window_start: u64,
    threads: Option<usize>,
    communicator: &C,
    mut progress: impl FnMut(&str),
) -> Result<SceneTiming, String> {
    check_window(steps, window_start)?;
    let start = Instant::now();
    let mut world = load(file, threads)?;
    settle(&mut world, settle_steps);
    let threads = world.threads();
    let mut ranks = MpiRanks::new(world, communicator).map_err(|e| e.to_string())?;
    let owned = |r: &MpiRanks<C>| {
        let b = r.world().bodies();
        (0..b.len()).filter(|&i| !b.is_ghost(i)).count() as u64
    };
    progress(&format!(
        "built and drawn {} shares of {} bodies in {:.2} s; {threads} threads per rank",
        communicator.size(),
        ranks.total(owned(&ranks)),
        start.elapsed().as_secs_f64(),
    ));
    ranks.run_steps(window_start).map_err(|e| e.to_string())?;
    let seconds_before_window = start.elapsed().as_secs_f64();
    communicator.barrier();
    let rebuilds_before = ranks.world().pair_rebuilds();
    let times_before = ranks.times;
    let redraws_before = ranks.redraws;
    let window = Instant::now();
    ranks
        .run_steps(steps - window_start)
        .map_err(|e| e.to_string())?;
    communicator.barrier();
    let seconds = window.elapsed().as_secs_f64();
    let mine = ranks.times.since(times_before).to_array();
    let mut all = vec![0.0; RankTimes::LEN * communicator.size() as usize];
    communicator.all_gather_into(&mine[..], &mut all[..]);
    for (rank, times) in all.chunks_exact(RankTimes::LEN).enumerate() {
        let t = RankTimes::from_array(times.try_into().expect("a rank's times"));
        progress(&format!(
            "rank {rank} in the window: own step {:.2} s, agreeing {:.2} s, ghost exchange {:.2} \
             s, redraws {:.2} s",
            t.step, t.agree, t.exchange, t.redraw
        ));
    }
    let counts = contact_counts(ranks.world());
    let ghosts = {
        let b = ranks.world().bodies();
        (0..b.len()).filter(|&i| b.is_ghost(i)).count() as u64
    };
    progress(&format!(
        "step {steps}: {} redraws, {} cuts, {} bodies changed owner, {} ghosts (summed over \
         the ranks); in the window, candidate lists made {} times and shares redrawn {} times \
         (each share alike)",
        ranks.total(ranks.redraws),
        ranks.total(ranks.rebalances),
        ranks.total(ranks.migrations),
        ranks.total(ghosts),
        ranks.world().pair_rebuilds() - rebuilds_before,
        ranks.redraws - redraws_before,
    ));
    Ok(SceneTiming {
        name: scene_name(file),
        threads,
        ranks: communicator.size() as usize,
        bodies: ranks.total(owned(&ranks)) as usize,
        settle_steps,
        steps,
        window_start,
        seconds,
        seconds_before_window,
        contacts: ContactCounts {
            body_body: ranks.total(counts.body_body as u64) as usize,
            body_wall: ranks.total(counts.body_wall as u64) as usize,
        },
        // Every rank takes part in the sum, whether its system reports the figure or not.
        peak_rss_bytes: Some(ranks.total(peak_rss_bytes().unwrap_or(0))).filter(|&b| b > 0),
    })
}
