//! Resuming a run from the newest checkpoint in its output folder: the world is rebuilt from the
//! scene text stored in the checkpoint (or from a new scene that differs only where that makes
//! sense, see `checkpoint::ALLOWED_CHANGES`), given the checkpoint's state, and run on into the
//! same output series.

use super::stepwise::{Detached, SteppedRun};
use super::{templates, Control, RunError, RunEvent};
use crate::checkpoint::{self, SceneRecord, ALLOWED_CHANGES};
use crate::io::body_values::ShapeNames;
use crate::io::output::RunOutput;
use crate::scene::overrides::{self, Override};
use crate::scene::{Prepared, Scene};
use std::path::{Path, PathBuf};

/// What may differ from the run as it was started.
#[derive(Clone, Debug, Default)]
pub struct ResumeOptions {
    /// Continue with this scene file instead of the one stored in the checkpoint; it may differ
    /// only in the keys of [`ALLOWED_CHANGES`].
    pub scene: Option<PathBuf>,
    /// Worker threads (results do not depend on them).
    pub threads: Option<usize>,
    /// A new end time [s] (`simulation.duration`), to run a finished run further, say.
    pub duration: Option<f64>,
    /// Continue with the scene stored in the checkpoint even if its file has changed since.
    pub stored_scene: bool,
}

/// Continues the run in `out_dir` from its newest readable checkpoint to its end, as
/// [`super::run_with`] would have (bit for bit). `control.scene` is ignored: the resumed run's
/// checkpoints store the scene it continues with. Returns the prepared world at the end with
/// the output.
pub fn resume(
    out_dir: &Path,
    options: &ResumeOptions,
    control: Control,
    mut observe: impl FnMut(RunEvent),
) -> Result<(Prepared, RunOutput), RunError> {
    let mut run = SteppedRun::resume(out_dir, options, control, &mut observe)?;
    run.advance_to(u64::MAX, observe)?;
    Ok(run.into_parts())
}

impl SteppedRun {
    /// The run in `out_dir` as its newest readable checkpoint left it, ready to be driven on
    /// (see [`resume`]).
    pub fn resume(
        out_dir: &Path,
        options: &ResumeOptions,
        control: Control,
        mut observe: impl FnMut(RunEvent),
    ) -> Result<Self, RunError> {
        restore(out_dir, options, control, &mut observe)
    }
}

fn restore(
    out_dir: &Path,
    options: &ResumeOptions,
    control: Control,
    observe: &mut impl FnMut(RunEvent),
) -> Result<SteppedRun, RunError> {
    let latest = checkpoint::latest(out_dir)?;
    for skipped in &latest.skipped {
        observe(RunEvent::Note(format!(
            "{skipped}; resuming from the older '{}'",
            latest.path.display()
        )));
    }
    let saved = latest.checkpoint;
    let record = scene_to_continue_with(&saved.scene, options, observe)?;
    let mut scene = Scene::parse(&record.file, record.text.clone())
        .map_err(|e| RunError::Resume(e.to_string()))?;
    if let Some(threads) = options.threads {
        scene.spec.simulation.threads = threads;
    }
    if let Some(duration) = options.duration {
        scene.spec.simulation.duration = duration;
    }
    let mut prepared = scene.build().map_err(|e| RunError::Resume(e.to_string()))?;
    let templates = templates(&prepared);
    let fingerprint = super::fingerprint(&prepared, &templates);
    if fingerprint != saved.fingerprint {
        return Err(RunError::Resume(format!(
            "'{}' builds other shapes or walls than the run in '{}' was started with: a mesh or \
             shape file the scene names has changed since. Restore it, or start the run again",
            record.file.display(),
            out_dir.display()
        )));
    }
    prepared
        .world
        .restore(saved.world, &templates)
        .map_err(|e| RunError::Resume(format!("{}: {e}", latest.path.display())))?;
    let schedule = saved.progress.schedule;
    prepared
        .schedule
        .retain(|s| schedule.iter().any(|r| r.index == s.index));
    for s in &mut prepared.schedule {
        let r = schedule.iter().find(|r| r.index == s.index);
        if let Some(r) = r {
            s.next_time = r.next_time;
            s.done = r.done;
        }
    }
    let mut output = saved.progress.output;
    output.relocate(out_dir);
    output.set_shape_names(ShapeNames::new(prepared.shape_names.clone()));
    // Drop what the stopped run wrote after its checkpoint (a frame at an interrupt, rows).
    output.rewind()?;
    let watch = super::EnergyWatch::new(&prepared.world);
    let sides = super::WallSides::new(&prepared.world);
    let rest = Detached {
        watch,
        warned: false,
        sides,
        warned_sides: false,
        output,
        control: Control {
            scene: Some(record),
            ..control
        },
        templates,
        fingerprint,
    };
    Ok(SteppedRun {
        prepared,
        rest: Some(rest),
    })
}

/// The scene to continue with: the one stored in the checkpoint, unless the file it came from has
/// changed since (then the user must say which: `scene` for the changed file, which may differ
/// only where allowed, or `stored_scene`), or another file is asked for. The run's command-line
/// overrides apply to a new file as they did to the old one.
fn scene_to_continue_with(
    saved: &SceneRecord,
    options: &ResumeOptions,
    observe: &mut impl FnMut(RunEvent),
) -> Result<SceneRecord, RunError> {
    let overrides: Vec<Override> = saved
        .overrides
        .iter()
        .filter_map(|o| o.parse().ok())
        .collect();
    let read = |file: &Path| -> Result<String, String> {
        let text = std::fs::read_to_string(file).map_err(|e| e.to_string())?;
        overrides::apply(&text, &overrides)
    };
    let Some(file) = &options.scene else {
        if options.stored_scene {
            return Ok(saved.clone());
        }
        let now = match read(&saved.file) {
            Ok(now) => now,
            Err(e) => {
                observe(RunEvent::Note(format!(
                    "cannot read the scene file '{}' ({e}): continuing with the scene stored in \
                     the checkpoint",
                    saved.file.display()
                )));
                return Ok(saved.clone());
            }
        };
        let changed = checkpoint::changed_keys(&saved.text, &now).unwrap_or_default();
        if changed.is_empty() {
            return Ok(saved.clone());
        }
        return Err(RunError::Resume(format!(
            "'{}' has changed since the run was started (in {}). To continue with the changed \
             file: `polydem resume DIR --scene {}` (only {} may change); to continue as the run \
             was started: `polydem resume DIR --stored-scene`",
            saved.file.display(),
            changed.join(", "),
            saved.file.display(),
            ALLOWED_CHANGES.join(", ")
        )));
    };
    let text = read(file).map_err(|e| RunError::Resume(format!("'{}': {e}", file.display())))?;
    let changed = checkpoint::changed_keys(&saved.text, &text)
        .map_err(|e| RunError::Resume(format!("'{}': {e}", file.display())))?;
    let refused: Vec<&str> = changed
        .iter()
        .filter(|k| !checkpoint::change_allowed(k))
        .map(String::as_str)
        .collect();
    if !refused.is_empty() {
        return Err(RunError::Resume(format!(
            "'{}' differs from the scene the run was started with ('{}') in {}: a resumed run \
             continues from bodies and contacts computed with the old values, so only {} may \
             change (`[]`: any index). Start a new run for the other changes",
            file.display(),
            saved.file.display(),
            refused.join(", "),
            ALLOWED_CHANGES.join(", ")
        )));
    }
    Ok(SceneRecord::new(file.clone(), text).with_overrides(&saved.overrides))
}
