//! The `polydem` command: run or check a scene file, and make pictures of a run.

use clap::{Parser, Subcommand};
use polydem::checkpoint::SceneRecord;
use polydem::picture::camera::View;
use polydem::picture::cut::Cut;
use polydem::picture::render::RenderOptions;
use polydem::picture::run_files::FrameChoice;
use polydem::run::{Control, ResumeOptions, RunError};
use polydem::scene::{Prepared, Scene};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[path = "polydem/progress.rs"]
mod progress;
#[cfg(feature = "mpi")]
#[path = "polydem/ranks.rs"]
mod ranks;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

#[derive(Parser)]
#[command(
    version,
    about = "Discrete Element Method simulations of spheres and polyhedra"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene and write VTK (ParaView) and CSV output.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        #[command(flatten)]
        changes: SceneChanges,
        /// Output folder [default: output/<scene name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads, overriding the scene's `threads` (0: one per core).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Continue a run from the newest checkpoint in its output folder, into the same output
    /// series; the result is the same, bit for bit, as if the run had never stopped.
    Resume {
        /// The run's output folder (with its `checkpoints/`).
        dir: PathBuf,
        /// Continue with this scene file instead of the one stored in the checkpoint; it may
        /// differ only in the duration, output and checkpoint intervals and threads.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// A new end time [s], e.g. to run a finished run further.
        #[arg(long)]
        duration: Option<f64>,
        /// Continue with the scene stored in the checkpoint even if its file has changed since.
        #[arg(long, conflicts_with = "scene")]
        stored_scene: bool,
        /// Worker threads (0: one per core); results do not depend on them.
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Check a scene file and report what a run would do, without running it.
    Check {
        /// Scene file (TOML).
        scene: PathBuf,
        #[command(flatten)]
        changes: SceneChanges,
    },
    /// Draw frames of a run as shaded PNG pictures (particles, walls, colour bar), no ParaView
    /// needed.
    Render {
        /// Output folder of `polydem run`.
        dir: PathBuf,
        /// Frame number (0 is the first), last, or all (a numbered series).
        #[arg(long, default_value = "last")]
        frame: FrameChoice,
        /// Where the camera looks from: iso, front (from −y), top (from +z), side (from +x), or a
        /// direction x,y,z from the scene towards the viewer (e.g. 1,-2,1).
        #[arg(long, default_value = "iso", allow_hyphen_values = true)]
        view: View,
        /// Point data of particles_*.vtp to colour by (vectors by their length), e.g. speed,
        /// id, material, radius, angular_velocity; material and shape as categories.
        #[arg(long, default_value = "speed")]
        color: String,
        /// Colour range LOW:HIGH [default: the frame's range; a series' over all its frames].
        #[arg(long, value_parser = polydem::picture::render::parse_range, allow_hyphen_values = true)]
        range: Option<(f64, f64)>,
        /// Cut the walls away in a half-space, e.g. y<0 or x>0.1 (axis, < or >, metres); the
        /// rest of the walls is drawn opaque. May be given more than once.
        #[arg(long)]
        cut: Vec<Cut>,
        /// The cuts also remove the bodies whose centre lies in them (a section through a bed).
        #[arg(long)]
        cut_bodies: bool,
        /// Picture size in pixels.
        #[arg(long, default_value = "1200x900", value_parser = polydem::picture::render::parse_size)]
        size: (usize, usize),
        /// Draw the contacts as lines scaled by their normal force (needs a run with
        /// force_network = true).
        #[arg(long)]
        force_network: bool,
        /// A .png file, a folder for numbered files, or a .gif file for an animation of the
        /// frames [default: DIR/render_NNNNNN.png].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Frames per second of an animated GIF.
        #[arg(long, default_value_t = 10.0)]
        fps: f64,
    },
    /// Plot a run's time series (energy and ledger closure, contacts, flow, wall forces) as PNG.
    Plot {
        /// Output folder of `polydem run`.
        dir: PathBuf,
        /// Folder for the plots [default: DIR].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Measure speed; prints a Markdown table for docs/benchmarks.md.
    Bench {
        #[command(subcommand)]
        what: Bench,
    },
}

/// Scene keys set from the command line instead of the file.
#[derive(clap::Args)]
struct SceneChanges {
    /// Set a scene key, e.g. `--set simulation.duration=2` or `--set material[0].friction=0.3`
    /// (`[i]`: the i-th entry, from 0); repeatable. Checked like the file.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<polydem::scene::overrides::Override>,
    /// The simulated duration [s] (same as `--set simulation.duration=SECONDS`).
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
}

impl SceneChanges {
    fn overrides(&self) -> Vec<polydem::scene::overrides::Override> {
        let mut all = self.set.clone();
        if let Some(d) = self.duration {
            all.push(polydem::scene::overrides::Override {
                key: "simulation.duration".into(),
                value: format!("{d:?}"),
            });
        }
        all
    }
}

#[derive(Subcommand)]
enum Bench {
    /// Time per broad-phase update on a moving gas, a dense packing and a 1:20 bidisperse packing.
    BroadPhase {
        /// Body counts, comma separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "1000,10000,100000,1000000"
        )]
        sizes: Vec<usize>,
        /// Methods, comma separated (sweep_and_prune, cell_grid, brute_force).
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "sweep_and_prune,cell_grid,brute_force"
        )]
        methods: Vec<String>,
        /// Timed updates per case (after 3 untimed ones); the median is reported.
        #[arg(long, default_value_t = 20)]
        steps: usize,
        /// Brute force is skipped above this many bodies (it is O(n²)).
        #[arg(long, default_value_t = 20000)]
        brute_force_limit: usize,
    },
    /// Step a scene with no output and time a window of steps at the end (the settled bed); prints
    /// one machine-readable line, as used by scripts/bench_peers.sh.
    Scene {
        /// Scene file (TOML); its bodies must all be placed at the start.
        scene: PathBuf,
        /// Untimed steps first, after which every body is stopped: the state `bench initial
        /// --settle-steps` writes for the peer codes. The steps below count from there.
        #[arg(long, default_value_t = 0)]
        settle_steps: u64,
        /// Steps taken in all (the scene's duration is ignored).
        #[arg(long, default_value_t = 10000)]
        steps: u64,
        /// First step of the timed window, which runs to the last step.
        #[arg(long, default_value_t = 5000)]
        window_start: u64,
        /// Worker threads, overriding the scene's `threads` (0: one per core).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Write a scene's planes and bodies as they are at the start (one line each: spheres as
    /// centre and radius, polyhedra as their corners), for peer codes to start from the same state.
    Initial {
        /// Scene file (TOML).
        scene: PathBuf,
        /// File to write.
        #[arg(long)]
        out: PathBuf,
        /// Settle this many steps first and stop the bodies, as `bench scene --settle-steps`.
        #[arg(long, default_value_t = 0)]
        settle_steps: u64,
        /// Worker threads, overriding the scene's `threads` (0: one per core); the state written
        /// does not depend on it.
        #[arg(long)]
        threads: Option<usize>,
    },
}

/// Makes glibc's allocator map every block of 128 KiB or more on its own, and so give it back to
/// the system when it is freed. By default glibc raises that threshold to the largest block freed
/// so far, after which the contact store's arrays, which grow a little at each neighbour search,
/// are reallocated in the heap and leave holes it cannot give back: at 65,000 spheres that was
/// a quarter of the peak memory (164 MB against 129 MB; `docs/benchmarks.md`).
fn give_freed_arrays_back() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a tuning parameter of the allocator, before anything is
    // allocated on another thread.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}

/// Big arrays on 2 MiB pages where Linux gives them (`polydem::huge_pages`): the large worlds'
/// step waits less on address translation.
#[global_allocator]
static ALLOCATOR: polydem::huge_pages::HugePageAlloc = polydem::huge_pages::HugePageAlloc;

fn main() -> ExitCode {
    give_freed_arrays_back();
    let cli = Cli::parse();
    // Built with MPI, `run` and `resume` go on ranks.
    let simulates = !cfg!(feature = "mpi")
        && matches!(cli.command, Command::Run { .. } | Command::Resume { .. });
    let ranks = polydem::decomposition::launched_ranks();
    if simulates && ranks > 1 {
        // Every process would run the whole scene and write the same files over each other.
        eprintln!(
            "error: polydem was started by an MPI launcher as one of {ranks} processes, but \
             this build of it has no MPI, so it cannot run on several MPI ranks: each process \
             would run the whole scene and write the same files. Build it with \
             `cargo build --release --features mpi` (needs Open MPI: Debian libopenmpi-dev \
             libclang-dev), or run it without mpirun (or with -np 1) and give it the cores of \
             the machine with --threads N."
        );
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Run {
            scene,
            changes,
            out,
            threads,
        } => run(&scene, &changes, out, threads),
        Command::Resume {
            dir,
            scene,
            duration,
            stored_scene,
            threads,
        } => resume(
            &dir,
            ResumeOptions {
                scene,
                threads,
                duration,
                stored_scene,
            },
        ),
        Command::Check { scene, changes } => check(&scene, &changes),
        Command::Render {
            dir,
            frame,
            view,
            color,
            range,
            cut,
            cut_bodies,
            size,
            force_network,
            out,
            fps,
        } => {
            let options = RenderOptions {
                view,
                colour: color,
                range,
                cuts: cut,
                cut_bodies,
                width: size.0,
                height: size.1,
                force_network,
                fps,
                fit_box: None,
            };
            report_written(polydem::picture::render::render_run(
                &dir,
                frame,
                &options,
                out.as_deref(),
            ))
        }
        Command::Plot { dir, out } => report_written(polydem::picture::plot::plot_run(
            &dir,
            out.as_deref().unwrap_or(&dir),
        )),
        Command::Bench {
            what:
                Bench::BroadPhase {
                    sizes,
                    methods,
                    steps,
                    brute_force_limit,
                },
        } => bench_broad_phase(&sizes, &methods, steps, brute_force_limit),
        Command::Bench {
            what:
                Bench::Scene {
                    scene,
                    settle_steps,
                    steps,
                    window_start,
                    threads,
                },
        } => bench_scene(&scene, settle_steps, steps, window_start, threads),
        Command::Bench {
            what:
                Bench::Initial {
                    scene,
                    out,
                    settle_steps,
                    threads,
                },
        } => polydem::bench::scene::write_initial_bodies(&scene, settle_steps, threads, &out)
            .map(|n| println!("wrote {n} bodies to {}", out.display())),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Prints the files a picture command wrote.
fn report_written(
    result: Result<Vec<PathBuf>, polydem::picture::PictureError>,
) -> Result<(), String> {
    let written = result.map_err(|e| e.to_string())?;
    for path in &written {
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Exit code of a run stopped by SIGINT or SIGTERM, as shells report a process ended by SIGINT.
const EXIT_INTERRUPTED: u8 = 130;

fn load(scene: &Path, changes: &SceneChanges, threads: Option<usize>) -> Result<Scene, String> {
    let overrides = changes.overrides();
    // A message about a key set on the command line should say so.
    let note = |e: polydem::scene::SceneError| {
        let set: Vec<String> = overrides.iter().map(|o| o.to_string()).collect();
        if set.is_empty() || matches!(e, polydem::scene::SceneError::Override { .. }) {
            e.to_string()
        } else {
            format!(
                "{e}\n(the scene as changed by --set {})",
                set.join(" --set ")
            )
        }
    };
    let mut scene = Scene::load_with(scene, &overrides).map_err(note)?;
    if let Some(threads) = threads {
        scene.spec.simulation.threads = threads;
    }
    Ok(scene)
}

fn describe(scene: &Path, p: &Prepared) {
    let w = &p.world;
    let steps = polydem::run::total_steps(p);
    println!("scene        {}", scene.display());
    let moving = w
        .mesh_walls()
        .iter()
        .filter(|m| !m.motion.is_fixed())
        .count();
    println!(
        "bodies       {} ({} materials, {} plane walls, {} mesh walls of which {moving} move)",
        w.bodies().len(),
        w.materials().len(),
        w.planes().len(),
        w.mesh_walls().len()
    );
    let how = if p.automatic_time_step {
        "auto".to_string()
    } else {
        format!("given; stable estimate {:.4e} s", p.estimate.seconds)
    };
    println!("time step    {:.4e} s ({how})", w.time_step());
    println!("             estimate: {}", p.estimate.reason);
    if let Some(deep) = &p.estimate.deepest {
        println!(
            "overlap      at most {:.1}% of the radius, for {} (refused above {:.0}%)",
            100.0 * deep.ratio,
            deep.what,
            100.0 * polydem::scene::MAX_OVERLAP
        );
    }
    if p.output_interval == p.csv_interval {
        println!(
            "duration     {} s = {steps} steps, output every {} s",
            p.duration, p.output_interval
        );
    } else {
        println!(
            "duration     {} s = {steps} steps, VTK frames every {} s, CSV rows every {} s",
            p.duration, p.output_interval, p.csv_interval
        );
    }
    println!("threads      {}", w.threads());
    for s in &p.schedule {
        let (most, times) = polydem::run::bodies_to_come(s, p.duration);
        let what = s.spec.shape.as_deref().unwrap_or("sphere");
        let how_many = match (&s.spec.inlet, s.spec.count) {
            (Some(inlet), _) => format!(
                "'{what}' bodies through an inlet, {} per second at {} m/s,",
                inlet.rate, inlet.speed
            ),
            (None, Some(n)) => format!("{n} '{what}' bodies"),
            (None, None) => format!("'{what}' bodies to a volume fraction"),
        };
        let when = match s.spec.every {
            Some(every) => format!("every {every} s from {} s, {times} times", s.next_time),
            None => format!("at {} s", s.next_time),
        };
        let total = if most > 0 {
            format!(": up to {most} bodies")
        } else {
            String::new()
        };
        println!(
            "insert       [[insert]] #{}: {how_many} {when}{total}",
            s.index + 1
        );
    }
    for note in &p.notes {
        println!("note         {note}");
    }
}

fn check(scene: &Path, changes: &SceneChanges) -> Result<(), String> {
    let loaded = load(scene, changes, None)?;
    let prepared = loaded.build().map_err(|e| e.to_string())?;
    describe(scene, &prepared);
    println!("scene is valid");
    // A short trial on a world of its own (the trial moves it on).
    let mut trial_world = loaded.build().map_err(|e| e.to_string())?;
    let trial = polydem::run::Trial::run(&mut trial_world, 2.0);
    let steps = polydem::run::total_steps(&prepared);
    let to_come: u64 = prepared
        .schedule
        .iter()
        .map(|s| polydem::run::bodies_to_come(s, prepared.duration).0)
        .sum();
    // Bodies inserted during the run are there for part of it: count them for half.
    let bodies = prepared.world.bodies().len() as f64 + 0.5 * to_come as f64;
    let seconds = trial.estimate(steps, bodies);
    println!(
        "estimate     roughly {} for the run: its first {} steps took {:.2} s, and the rest \
         is taken at that pace, with the bodies still to come counted for half the run (a bed \
         that settles into many contacts runs slower; a full hopper holds fewer bodies than \
         its feed offers)",
        human_duration(seconds),
        trial.steps,
        trial.seconds
    );
    Ok(())
}

/// `seconds` as a person would say it: 45 s, 12 min, 3.5 h.
fn human_duration(seconds: f64) -> String {
    if seconds < 90.0 {
        format!("{seconds:.0} s")
    } else if seconds < 5400.0 {
        format!("{:.0} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
}

fn run(
    scene: &Path,
    changes: &SceneChanges,
    out: Option<PathBuf>,
    threads: Option<usize>,
) -> Result<(), String> {
    #[cfg(feature = "mpi")]
    if polydem::decomposition::launched_ranks() > 1 {
        return ranks::run_on_ranks(scene, changes, out, threads);
    }
    // Everything is validated before the output folder is created, so bad input never leaves a
    // half-written folder behind.
    let loaded = load(scene, changes, threads)?;
    let record = SceneRecord::new(loaded.file.clone(), loaded.source.clone())
        .with_overrides(&changes.overrides());
    let mut prepared = loaded.build().map_err(|e| e.to_string())?;
    let out = out.unwrap_or_else(|| {
        let stem = scene.file_stem().unwrap_or_default();
        Path::new("output").join(stem)
    });
    describe(scene, &prepared);
    println!("output       {}", out.display());
    let control = Control {
        scene: Some(record),
        stop: Some(stop_on_signal()),
    };
    let start = prepared.world.energy();
    let result = progress::show(|observe| {
        polydem::run::run_with(&mut prepared, &out, control, observe).map(|_| ())
    });
    let (_, summary) = result.map_err(|e| run_error(e, scene, &out))?;
    summary.report(&prepared, &start, &out);
    Ok(())
}

fn resume(dir: &Path, options: ResumeOptions) -> Result<(), String> {
    #[cfg(feature = "mpi")]
    if polydem::decomposition::launched_ranks() > 1 {
        return ranks::resume_on_ranks(dir, options);
    }
    let control = Control {
        scene: None,
        stop: Some(stop_on_signal()),
    };
    let result = progress::show(|observe| {
        polydem::run::resume(dir, &options, control, observe).map(|(prepared, _)| prepared)
    });
    let (prepared, summary) = result.map_err(|e| run_error(e, dir, dir))?;
    // The ledger at the run's start: the first row of its energy.csv.
    let start =
        progress::first_ledger(&dir.join("energy.csv")).unwrap_or_else(|| prepared.world.energy());
    summary.report(&prepared, &start, dir);
    Ok(())
}

/// A flag that Ctrl-C (SIGINT) and SIGTERM set, so the run stops at the next chunk of steps with
/// a checkpoint; a second signal ends the process at once.
fn stop_on_signal() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let installed = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            eprintln!("\nstopping now, without a checkpoint");
            std::process::exit(130);
        }
        eprintln!(
            "\nstopping after the steps under way, with a checkpoint (Ctrl-C again: stop at once)"
        );
    });
    if let Err(e) = installed {
        eprintln!("warning: Ctrl-C will stop the run without a checkpoint ({e})");
    }
    stop
}

/// The message of a run that failed; a run that was stopped by a signal ends the process here,
/// with its own exit code, after saying how to continue it.
fn run_error(e: RunError, scene: &Path, out: &Path) -> String {
    match e {
        RunError::Output(e) => format!("writing output to '{}': {e}", out.display()),
        RunError::Checkpoint(e) => e.to_string(),
        RunError::Interrupted { .. } => {
            eprintln!("{e}: polydem resume {}", out.display());
            std::process::exit(EXIT_INTERRUPTED.into());
        }
        e => format!("{}: {e}", scene.display()),
    }
}

fn bench_scene(
    scene: &Path,
    settle_steps: u64,
    steps: u64,
    window_start: u64,
    threads: Option<usize>,
) -> Result<(), String> {
    #[cfg(feature = "mpi")]
    if polydem::decomposition::launched_ranks() > 1 {
        return ranks::bench_scene_on_ranks(scene, settle_steps, steps, window_start, threads);
    }
    let timing =
        polydem::bench::scene::run(scene, settle_steps, steps, window_start, threads, |note| {
            eprintln!("{note}")
        })?;
    println!("{}", timing.line());
    Ok(())
}

fn bench_broad_phase(
    sizes: &[usize],
    methods: &[String],
    steps: usize,
    brute_force_limit: usize,
) -> Result<(), String> {
    use polydem::bench::broad_phase::{time, Scene};
    use polydem::broad_phase::Method;
    let methods: Vec<Method> = methods
        .iter()
        .map(|m| {
            Method::from_name(m).ok_or_else(|| {
                format!("unknown broad phase '{m}': use sweep_and_prune, cell_grid or brute_force")
            })
        })
        .collect::<Result<_, _>>()?;
    println!("| scene | bodies | method | ms per update | candidate pairs |");
    println!("| --- | ---: | --- | ---: | ---: |");
    for scene in [Scene::Gas, Scene::Packing, Scene::Bidisperse] {
        for &n in sizes {
            for &method in &methods {
                if method == Method::BruteForce && n > brute_force_limit {
                    continue;
                }
                let t = time(scene, n, method, 3, steps);
                println!(
                    "| {} | {} | {} | {:.3} | {:.0} |",
                    t.scene.name(),
                    t.bodies,
                    t.method,
                    t.seconds_per_step * 1e3,
                    t.pairs
                );
            }
        }
    }
    Ok(())
}
