//! What a run shows while it goes: a progress bar with the simulated time and the rate in
//! particle-steps per second, the run's events as lines (insertions, checkpoints, notes), and the
//! summary at the end.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use polydem::energy::EnergyReport;
use polydem::run::{RunError, RunEvent};
use polydem::scene::Prepared;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// Insertions of one `[[insert]]` during the run.
#[derive(Default)]
struct Inserted {
    times: u64,
    bodies: u64,
    short: u64,
}

/// An `[[insert]]` that repeats is reported line by line this many times, then summed up at the
/// end (a flood feed inserts every few milliseconds: hundreds of lines otherwise).
const INSERTIONS_SHOWN: u64 = 3;

/// What the run did, counted as it went.
pub struct Summary {
    start: Instant,
    first_step: u64,
    /// Σ bodies × steps over the run (bodies come and go: the end count would misstate it).
    particle_steps: f64,
    inserted: BTreeMap<usize, Inserted>,
}

impl Summary {
    /// The closing lines: steps, time, throughput, contacts, the ledger's closure since `start`
    /// (the ledger when the run, or this resumed part of it, began), the files in `out`, bodies
    /// removed and insertions.
    pub fn report(&self, prepared: &Prepared, start: &EnergyReport, out: &Path) {
        let seconds = self.start.elapsed().as_secs_f64();
        let w = &prepared.world;
        println!(
            "done         {} steps in {seconds:.2} s: {:.3e} particle-steps/s (t = {:.6} s, \
             {} bodies, {} contacts)",
            w.steps_done() - self.first_step,
            self.particle_steps / seconds.max(1e-9),
            w.time(),
            w.bodies().len(),
            w.contacts()
                .iter()
                .filter(|c| c.report.normal_force > 0.0)
                .count()
        );
        let end = w.energy();
        let moved = energy_moved(start, &end);
        if moved > 0.0 {
            println!(
                "energy       the ledger closes to {:.3} % of the energy moved ({moved:.3e} J: \
                 kinetic, elastic, potential released, dissipated, brought in and out)",
                100.0 * (end.total() - start.total()).abs() / moved
            );
        }
        println!("files        {}", files_written(out));
        if w.bodies_removed() > 0 {
            println!(
                "             {} bodies left the domain and were removed",
                w.bodies_removed()
            );
        }
        for (index, s) in self
            .inserted
            .iter()
            .filter(|(_, s)| s.times > INSERTIONS_SHOWN)
        {
            println!(
                "inserted     [[insert]] #{}: {} bodies in {} insertions, {} of which fell short",
                index + 1,
                s.bodies,
                s.times,
                s.short
            );
        }
    }
}

/// Runs `go` with a progress bar on stderr fed by the run's events; returns its result and the
/// summary.
pub fn show<T>(
    go: impl FnOnce(&mut dyn FnMut(RunEvent)) -> Result<T, RunError>,
) -> Result<(T, Summary), RunError> {
    let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {percent:>3}% {msg} | ETA {eta}")
            .expect("the template is valid"),
    );
    bar.set_message("starting");
    let mut summary = Summary {
        start: Instant::now(),
        first_step: 0,
        particle_steps: 0.0,
        inserted: BTreeMap::new(),
    };
    let mut last_step = 0;
    // indicatif draws nothing when stderr is not a terminal (a log file, CI): say it plainly then.
    let say = |line: String| {
        if bar.is_hidden() {
            eprintln!("{line}")
        } else {
            bar.println(line)
        }
    };
    let mut observe = |event: RunEvent| match event {
        RunEvent::Start { from, to } => {
            summary.first_step = from;
            last_step = from;
            bar.set_length(to);
            bar.set_position(from);
            bar.reset_eta();
        }
        RunEvent::Progress(w) => {
            let steps = w.steps_done() - last_step;
            last_step = w.steps_done();
            summary.particle_steps += steps as f64 * w.bodies().len() as f64;
            let rate = summary.particle_steps / summary.start.elapsed().as_secs_f64().max(1e-9);
            bar.set_position(w.steps_done());
            bar.set_message(format!(
                "t = {:.4} s | {} bodies | {rate:.2e} particle-steps/s",
                w.time(),
                w.bodies().len()
            ));
        }
        RunEvent::Inserted(r) => {
            let counts = summary.inserted.entry(r.index).or_default();
            counts.times += 1;
            counts.bodies += r.inserted as u64;
            counts.short += u64::from(r.shortfall.is_some());
            let line = format!(
                "t = {:.4} s: [[insert]] #{} added {} bodies",
                r.time,
                r.index + 1,
                r.inserted
            );
            // The reason for a shortfall once per [[insert]]; after a few lines, a sum at the end.
            match &r.shortfall {
                Some(why) if counts.short == 1 => say(format!("{line}; not all fitted: {why}")),
                _ if counts.times <= INSERTIONS_SHOWN => say(line),
                _ => {}
            }
            if counts.times == INSERTIONS_SHOWN {
                say(format!(
                    "             (further insertions of [[insert]] #{} are summed up at the end)",
                    r.index + 1
                ));
            }
        }
        RunEvent::Checkpoint(path) => say(format!("checkpoint   {}", path.display())),
        RunEvent::Note(note) => say(format!("note         {note}")),
    };
    let result = go(&mut observe);
    bar.finish_and_clear();
    result.map(|r| (r, summary))
}

/// The energy a run moved between the ledgers `s` and `e`: the scale its closure is judged on.
fn energy_moved(s: &EnergyReport, e: &EnergyReport) -> f64 {
    s.kinetic_translational
        + s.kinetic_rotational
        + s.elastic
        + e.kinetic_translational
        + e.kinetic_rotational
        + e.elastic
        + (e.potential - s.potential).abs()
        + (e.dissipated - s.dissipated).abs()
        + (e.inserted - s.inserted).abs()
        + (e.removed - s.removed).abs()
        + (e.wall_work - s.wall_work).abs()
        + (e.gravity_work - s.gravity_work).abs()
}

/// What the output folder holds, counted by kind: `"41 frames (particles.pvd, walls.pvd),
/// energy.csv, wall_forces.csv, 2 checkpoints in output/x"`.
fn files_written(out: &Path) -> String {
    let names = |dir: &Path| -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .filter_map(|e| e.ok())
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        names.sort();
        names
    };
    let all = names(out);
    let with = |ext: &str| -> Vec<&String> { all.iter().filter(|n| n.ends_with(ext)).collect() };
    let series: Vec<&str> = with(".pvd").iter().map(|s| s.as_str()).collect();
    let frames = all.iter().filter(|n| n.ends_with(".vtp")).count();
    let csv: Vec<&str> = with(".csv").iter().map(|s| s.as_str()).collect();
    let checkpoints = names(&out.join("checkpoints"))
        .iter()
        .filter(|n| n.ends_with(".ckpt"))
        .count();
    format!(
        "{frames} VTK files in {} series ({}), {}, {checkpoints} checkpoint{}, in {}",
        series.len(),
        series.join(", "),
        if csv.is_empty() {
            "no CSV".to_string()
        } else {
            csv.join(", ")
        },
        if checkpoints == 1 { "" } else { "s" },
        out.display()
    )
}

/// The ledger of the first row of a run's `energy.csv` (its start), if it can be read.
pub fn first_ledger(path: &Path) -> Option<EnergyReport> {
    let table = polydem::io::csv_read::read_table(path).ok()?;
    let value = |name: &str| table.column(name).and_then(|c| c.first().copied());
    Some(EnergyReport {
        kinetic_translational: value("kinetic_translational")?,
        kinetic_rotational: value("kinetic_rotational")?,
        potential: value("potential_gravity")?,
        elastic: value("elastic")?,
        dissipated: value("dissipated")?,
        removed: value("removed")?,
        inserted: value("inserted")?,
        wall_work: value("wall_work")?,
        gravity_work: value("gravity_work")?,
        contacts: value("contacts")? as usize,
    })
}
