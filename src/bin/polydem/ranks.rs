//! The commands under an MPI launcher (`mpirun -np N polydem ...`, the `mpi` feature): `run`,
//! `resume` and `bench scene` on ranks.

use super::*;

/// MPI, initialised for calls from one thread at a time, not only the one that started it: a
/// rank steps on its world's thread pool (`MpiRanks::run_steps`; with a library that cannot, it
/// steps from this thread).
fn initialize_mpi() -> Result<mpi::environment::Universe, String> {
    mpi::initialize_with_threading(mpi::Threading::Serialized)
        .map(|(universe, _)| universe)
        .ok_or_else(|| "MPI could not be initialised".to_string())
}

/// `run` under an MPI launcher: every rank builds the scene and keeps its share; rank 0 runs the
/// run loop, says what happens and writes every file (`decomposition::mpi_run`).
pub(super) fn run_on_ranks(
    scene: &Path,
    changes: &SceneChanges,
    out: Option<PathBuf>,
    threads: Option<usize>,
) -> Result<(), String> {
    use mpi::traits::*;
    use polydem::decomposition::mpi_ranks::MpiRanks;
    use polydem::decomposition::mpi_run::{follow, Leader};
    let universe = initialize_mpi()?;
    let communicator = universe.world();
    let first = communicator.rank() == 0;
    // Every rank reads the same scene and fails the same way: rank 0 says why (the others end
    // quietly, so that the launcher does not end rank 0 before it has).
    let loaded = load(scene, changes, threads).and_then(|loaded| {
        let record = SceneRecord::new(loaded.file.clone(), loaded.source.clone())
            .with_overrides(&changes.overrides());
        Ok((record, loaded.build().map_err(|e| e.to_string())?))
    });
    let (record, mut prepared) = match loaded {
        Ok(loaded) => loaded,
        Err(e) if first => return Err(e),
        Err(_) => return Ok(()),
    };
    // Ctrl-C reaches every rank: rank 0 stops the run, the others wait for its word.
    let stop = stop_on_signal();
    let abort = |e: String| -> ! {
        eprintln!("error (rank {}): {e}", communicator.rank());
        // The other ranks may wait in a collective call: end them all.
        communicator.abort(1)
    };
    if !first {
        let templates = polydem::run::templates(&prepared);
        let mut ranks =
            MpiRanks::new(prepared.world, &communicator).unwrap_or_else(|e| abort(e.to_string()));
        return follow(&mut ranks, &communicator, &templates).map_err(|e| abort(e.to_string()));
    }
    // Rank 0 keeps the whole world for its outputs, and builds it again for its share.
    let share = load(scene, changes, threads)
        .and_then(|l| l.build().map_err(|e| e.to_string()))
        .unwrap_or_else(|e| abort(e))
        .world;
    let mut ranks = MpiRanks::new(share, &communicator).unwrap_or_else(|e| abort(e.to_string()));
    let out = out.unwrap_or_else(|| {
        let stem = scene.file_stem().unwrap_or_default();
        Path::new("output").join(stem)
    });
    describe(scene, &prepared);
    println!("ranks        {} (MPI), rank 0 writes", communicator.size());
    println!("output       {}", out.display());
    let control = Control {
        scene: Some(record),
        stop: Some(stop),
    };
    let start = prepared.world.energy();
    let mut leader = Leader::new(&mut ranks, &communicator);
    let result = progress::show(|observe| {
        polydem::run::run_shared(&mut prepared, &out, control, &mut leader, observe).map(|_| ())
    });
    if let Err(RunError::Ranks(why)) = &result {
        abort(why.clone());
    }
    leader.finish();
    let (_, summary) = result.map_err(|e| run_error(e, scene, &out))?;
    summary.report(&prepared, &start, &out);
    Ok(())
}

/// `resume` under an MPI launcher: rank 0 reads the checkpoint and sends the scene the run goes
/// on with to the other ranks, which build it; the shares start from the checkpoint's whole world
/// (`SteppedRun::advance_shared`), and rank 0 runs the loop and writes as in [`run_on_ranks`].
pub(super) fn resume_on_ranks(dir: &Path, options: ResumeOptions) -> Result<(), String> {
    use mpi::traits::*;
    use polydem::checkpoint::SceneRecord;
    use polydem::decomposition::mpi_ranks::MpiRanks;
    use polydem::decomposition::mpi_run::{follow, Leader};
    use polydem::run::SteppedRun;
    let universe = initialize_mpi()?;
    let communicator = universe.world();
    let root = communicator.process_at_rank(0);
    let abort = |e: String| -> ! {
        eprintln!("error (rank {}): {e}", communicator.rank());
        communicator.abort(1)
    };
    // The scene the run goes on with, as MessagePack bytes from rank 0 (none: it could not
    // resume, and says why).
    let share_scene = |record: Option<&SceneRecord>| -> Option<SceneRecord> {
        let mut bytes = record.map_or_else(Vec::new, |r| {
            rmp_serde::to_vec(r).expect("a scene record encodes")
        });
        let mut size = bytes.len() as u64;
        root.broadcast_into(&mut size);
        if size == 0 {
            return None;
        }
        bytes.resize(size as usize, 0);
        root.broadcast_into(&mut bytes[..]);
        Some(rmp_serde::from_slice(&bytes).unwrap_or_else(|e| abort(format!("scene record: {e}"))))
    };
    let build = |record: &SceneRecord| -> polydem::scene::Prepared {
        let mut scene = polydem::scene::Scene::parse(&record.file, record.text.clone())
            .unwrap_or_else(|e| abort(e.to_string()));
        if let Some(threads) = options.threads {
            scene.spec.simulation.threads = threads;
        }
        scene.build().unwrap_or_else(|e| abort(e.to_string()))
    };
    let stop = stop_on_signal();
    if communicator.rank() != 0 {
        let Some(record) = share_scene(None) else {
            return Ok(()); // rank 0 says why the run cannot resume
        };
        let prepared = build(&record);
        let templates = polydem::run::templates(&prepared);
        let mut ranks =
            MpiRanks::new(prepared.world, &communicator).unwrap_or_else(|e| abort(e.to_string()));
        return follow(&mut ranks, &communicator, &templates).map_err(|e| abort(e.to_string()));
    }
    let control = Control {
        scene: None,
        stop: Some(stop),
    };
    let result = progress::show(|observe| {
        let run = SteppedRun::resume(dir, &options, control, &mut *observe);
        let mut run = match run {
            Ok(run) => run,
            Err(e) => {
                share_scene(None);
                return Err(e);
            }
        };
        let record = run
            .scene_record()
            .cloned()
            .expect("a resumed run writes checkpoints");
        share_scene(Some(&record));
        let share = build(&record).world;
        let mut ranks =
            MpiRanks::new(share, &communicator).unwrap_or_else(|e| abort(e.to_string()));
        let mut leader = Leader::new(&mut ranks, &communicator);
        let driven = run.advance_shared(u64::MAX, &mut leader, &mut *observe);
        if let Err(RunError::Ranks(why)) = &driven {
            abort(why.clone());
        }
        leader.finish();
        driven.map(|_| run.into_parts().0)
    });
    let (prepared, summary) = result.map_err(|e| run_error(e, dir, dir))?;
    let start =
        progress::first_ledger(&dir.join("energy.csv")).unwrap_or_else(|| prepared.world.energy());
    summary.report(&prepared, &start, dir);
    Ok(())
}

/// `bench scene` under an MPI launcher: the scene decomposed among the ranks; rank 0 prints.
pub(super) fn bench_scene_on_ranks(
    scene: &Path,
    settle_steps: u64,
    steps: u64,
    window_start: u64,
    threads: Option<usize>,
) -> Result<(), String> {
    use mpi::traits::*;
    let universe = initialize_mpi()?;
    let world = universe.world();
    let first = world.rank() == 0;
    let say = |note: &str| {
        if first {
            eprintln!("{note}")
        }
    };
    let timing = polydem::bench::mpi_scene::run(
        scene,
        settle_steps,
        steps,
        window_start,
        threads,
        &world,
        say,
    );
    match timing {
        Ok(timing) if first => println!("{}", timing.line()),
        Ok(_) => {}
        Err(e) => {
            eprintln!("error (rank {}): {e}", world.rank());
            // The other ranks may wait in a collective call: end them all.
            world.abort(1)
        }
    }
    Ok(())
}
