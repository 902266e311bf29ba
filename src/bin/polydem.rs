//! The `polydem` command: run or check a scene file, and make pictures of a run.

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use polydem::picture::camera::View;
use polydem::picture::cut::Cut;
use polydem::picture::render::RenderOptions;
use polydem::picture::run_files::FrameChoice;
use polydem::run::RunEvent;
use polydem::scene::{Prepared, Scene};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

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
        /// Output folder [default: output/<scene name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads, overriding the scene's `threads` (0: one per core).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Check a scene file and report what a run would do, without running it.
    Check {
        /// Scene file (TOML).
        scene: PathBuf,
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            scene,
            out,
            threads,
        } => run(&scene, out, threads),
        Command::Check { scene } => check(&scene),
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

fn prepare(scene: &Path, threads: Option<usize>) -> Result<Prepared, String> {
    let mut scene = Scene::load(scene).map_err(|e| e.to_string())?;
    if let Some(threads) = threads {
        scene.spec.simulation.threads = threads;
    }
    scene.build().map_err(|e| e.to_string())
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
    println!(
        "duration     {} s = {steps} steps, output every {} s",
        p.duration, p.output_interval
    );
    println!("threads      {}", w.threads());
    for note in &p.notes {
        println!("note         {note}");
    }
}

fn check(scene: &Path) -> Result<(), String> {
    let prepared = prepare(scene, None)?;
    describe(scene, &prepared);
    println!("scene is valid");
    Ok(())
}

fn run(scene: &Path, out: Option<PathBuf>, threads: Option<usize>) -> Result<(), String> {
    // Everything is validated before the output folder is created, so bad input never leaves a
    // half-written folder behind.
    let mut prepared = prepare(scene, threads)?;
    let out = out.unwrap_or_else(|| {
        let stem = scene.file_stem().unwrap_or_default();
        Path::new("output").join(stem)
    });
    describe(scene, &prepared);
    println!("output       {}", out.display());

    let steps = polydem::run::total_steps(&prepared);
    let duration = prepared.duration;
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {percent:>3}% t = {msg} | {per_sec} | ETA {eta}")
            .expect("the template is valid"),
    );
    let start = Instant::now();
    let result = polydem::run::run(&mut prepared, &out, |event| match event {
        RunEvent::Progress(w) => {
            bar.set_position(w.steps_done());
            bar.set_message(format!("{:.4} / {duration} s", w.time()));
        }
        RunEvent::Inserted(r) => {
            let line = format!(
                "t = {:.4} s: [[insert]] #{} added {} bodies",
                r.time,
                r.index + 1,
                r.inserted
            );
            match &r.shortfall {
                Some(why) => bar.println(format!("{line}; not all fitted: {why}")),
                None => bar.println(line),
            }
        }
    });
    bar.finish_and_clear();
    result.map_err(|e| match e {
        polydem::run::RunError::Output(e) => format!("writing output to '{}': {e}", out.display()),
        blow_up => format!("{}: {blow_up}", scene.display()),
    })?;
    let seconds = start.elapsed().as_secs_f64();
    let w = &prepared.world;
    println!(
        "done         {} steps in {seconds:.2} s: {:.3e} particle-steps/s",
        w.steps_done(),
        (w.steps_done() as f64 * w.bodies().len() as f64) / seconds.max(1e-9)
    );
    if w.bodies_removed() > 0 {
        println!(
            "             {} bodies left the domain and were removed",
            w.bodies_removed()
        );
    }
    Ok(())
}

fn bench_scene(
    scene: &Path,
    settle_steps: u64,
    steps: u64,
    window_start: u64,
    threads: Option<usize>,
) -> Result<(), String> {
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
