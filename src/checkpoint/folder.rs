//! Where a run's checkpoints live (`checkpoints/` in its output folder, one file per checkpoint
//! named by its step) and which are kept: the last two, so that a machine that fails while one
//! is written still leaves a complete one besides the atomic write.

use super::{file, Checkpoint, CheckpointError};
use std::path::{Path, PathBuf};

/// The folder of `out_dir`'s checkpoints.
pub fn folder(out_dir: &Path) -> PathBuf {
    out_dir.join("checkpoints")
}

/// The checkpoint of step `step` in `out_dir`.
pub fn checkpoint_path(out_dir: &Path, step: u64) -> PathBuf {
    folder(out_dir).join(format!("step_{step:012}.ckpt"))
}

/// The checkpoints in `out_dir`, oldest first, with their steps.
pub fn checkpoints_in(out_dir: &Path) -> Vec<(u64, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(folder(out_dir)) else {
        return Vec::new();
    };
    let mut found: Vec<(u64, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            let step = name.strip_prefix("step_")?.strip_suffix(".ckpt")?;
            Some((step.parse().ok()?, e.path()))
        })
        .collect();
    found.sort();
    found
}

/// Writes `checkpoint` as step `step`'s in `out_dir`, then removes all but the two newest (and
/// temporaries a killed write left behind). Returns the file written.
pub fn write_keeping_two(
    out_dir: &Path,
    step: u64,
    checkpoint: &Checkpoint<impl serde::Serialize>,
) -> Result<PathBuf, CheckpointError> {
    let path = checkpoint_path(out_dir, step);
    std::fs::create_dir_all(folder(out_dir)).map_err(|source| CheckpointError::Write {
        path: path.clone(),
        source,
    })?;
    file::write(&path, checkpoint)?;
    let all = checkpoints_in(out_dir);
    for (_, old) in all.iter().take(all.len().saturating_sub(2)) {
        // A checkpoint that cannot be removed is only disk space: not worth stopping the run.
        let _ = std::fs::remove_file(old);
    }
    if let Ok(entries) = std::fs::read_dir(folder(out_dir)) {
        for e in entries.filter_map(Result::ok) {
            let name = e.file_name();
            let name = name.to_string_lossy();
            // Our own temporaries (see io::atomic) from a write that was killed; this process's
            // own are gone by now, the write above having finished.
            if name.starts_with(".step_") && name.contains(".ckpt.tmp-") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    Ok(path)
}

/// The newest checkpoint of `out_dir` that can be read.
pub struct Latest {
    pub checkpoint: Checkpoint,
    pub path: PathBuf,
    /// Newer checkpoints that could not be read, and why (the user should know).
    pub skipped: Vec<CheckpointError>,
}

/// Reads the newest readable checkpoint of `out_dir`. An error when there is none: the message
/// names the folder, or the newest file and why it cannot be read.
pub fn latest(out_dir: &Path) -> Result<Latest, CheckpointError> {
    let all = checkpoints_in(out_dir);
    if all.is_empty() {
        return Err(CheckpointError::Read {
            path: folder(out_dir),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "no checkpoint here (step_*.ckpt): was the run started in this folder, and did \
                 it get as far as its first checkpoint? Runs write one at the end, when \
                 interrupted (Ctrl-C, SIGTERM) and every `[output] checkpoint_interval`",
            ),
        });
    }
    let mut skipped = Vec::new();
    for (_, path) in all.iter().rev() {
        match file::read(path) {
            Ok(checkpoint) => {
                return Ok(Latest {
                    checkpoint,
                    path: path.clone(),
                    skipped,
                })
            }
            Err(e) => skipped.push(e),
        }
    }
    Err(skipped.swap_remove(0))
}
