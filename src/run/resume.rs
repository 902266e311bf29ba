//! Resuming a run from the newest checkpoint in its output folder: the world is rebuilt from the
//! scene text stored in the checkpoint (or from a new scene that differs only where that makes
//! sense, see `checkpoint::ALLOWED_CHANGES`), given the checkpoint's state, and run on into the
//! same output series.

use super::{templates, Control, RunError, RunEvent, Session};
use crate::checkpoint::{self, SceneRecord, ALLOWED_CHANGES};
use crate::io::output::RunOutput;
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
    let latest = checkpoint::latest(out_dir)?;
    for skipped in &latest.skipped {
        observe(RunEvent::Note(format!(
            "{skipped}; resuming from the older '{}'",
            latest.path.display()
        )));
    }
    let saved = latest.checkpoint;
    let record = scene_to_continue_with(&saved.scene, options)?;
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
    let fingerprint = checkpoint::fingerprint(&prepared.world, &templates);
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
    let mut session = Session {
        prepared: &mut prepared,
        output,
        control: Control {
            scene: Some(record),
            ..control
        },
        templates,
        fingerprint,
    };
    session.drive(observe)?;
    let output = session.output;
    Ok((prepared, output))
}

/// The scene stored in the checkpoint, or the new one if it differs only where allowed.
fn scene_to_continue_with(
    saved: &SceneRecord,
    options: &ResumeOptions,
) -> Result<SceneRecord, RunError> {
    let Some(file) = &options.scene else {
        return Ok(saved.clone());
    };
    let text = std::fs::read_to_string(file)
        .map_err(|e| RunError::Resume(format!("cannot read '{}': {e}", file.display())))?;
    let changed = checkpoint::changed_keys(&saved.text, &text)
        .map_err(|e| RunError::Resume(format!("'{}': {e}", file.display())))?;
    let refused: Vec<&String> = changed
        .iter()
        .filter(|k| !checkpoint::change_allowed(k))
        .collect();
    if !refused.is_empty() {
        let list: Vec<&str> = refused.iter().map(|k| k.as_str()).collect();
        return Err(RunError::Resume(format!(
            "'{}' differs from the scene the run was started with ('{}') in {}: a resumed run \
             continues from bodies and contacts computed with the old values, so only {} may \
             change (`[]`: any index). Start a new run for the other changes",
            file.display(),
            saved.file.display(),
            list.join(", "),
            ALLOWED_CHANGES.join(", ")
        )));
    }
    Ok(SceneRecord::new(file.clone(), text))
}
