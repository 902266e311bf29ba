//! What a Python-driven run does with the run loop's events while the GIL is released: an
//! optional progress bar, the notes kept for `Simulation.notes`, and a look for Ctrl-C now and
//! then (the interpreter only sees signals while it holds the GIL: a pending KeyboardInterrupt
//! sets the run's stop flag, and the run stops at the next chunk with a checkpoint).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use polydem::run::RunEvent;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often the interpreter is asked for signals during a run.
const SIGNAL_CHECK: Duration = Duration::from_millis(100);

pub struct Observer {
    bar: Option<ProgressBar>,
    stop: Arc<AtomicBool>,
    last_check: Instant,
    /// Notes of the run (an earlier run's files removed, a checkpoint passed over).
    pub notes: Vec<String>,
    /// The Ctrl-C caught, raised again when the run has stopped.
    pub interrupt: Option<PyErr>,
}

impl Observer {
    pub fn new(progress: bool, stop: Arc<AtomicBool>) -> Self {
        let bar = progress.then(|| {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  t = {msg} s  {per_sec}  ETA {eta}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar
        });
        Self {
            bar,
            stop,
            last_check: Instant::now(),
            notes: Vec::new(),
            interrupt: None,
        }
    }

    pub fn observe(&mut self, event: RunEvent) {
        match event {
            RunEvent::Start { from, to } => {
                if let Some(bar) = &self.bar {
                    bar.set_length(to);
                    bar.set_position(from);
                }
            }
            RunEvent::Progress(world) => {
                if let Some(bar) = &self.bar {
                    bar.set_position(world.steps_done());
                    bar.set_message(format!("{:.4}", world.time()));
                }
                if self.last_check.elapsed() >= SIGNAL_CHECK {
                    self.last_check = Instant::now();
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        self.stop.store(true, Ordering::Relaxed);
                        self.interrupt = Some(e);
                    }
                }
            }
            RunEvent::Note(note) => self.notes.push(note),
            RunEvent::Inserted(_) | RunEvent::Checkpoint(_) => {}
        }
    }

    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
