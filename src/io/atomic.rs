//! Crash-safe file replacement.
//!
//! Output files are written to a temporary sibling and renamed over the target
//! only once complete and synced to disk. A rename within one directory is
//! atomic on POSIX file systems (and replaces the target on Windows), so a
//! crash, kill or full disk at any moment leaves either the old complete file
//! or the new complete file at `path` — never a truncated one that would make
//! ParaView or a post-processing script choke at the end of a long run.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Distinguishes temporaries of concurrent writes from the same process.
static NEXT_TEMP_ID: AtomicU64 = AtomicU64::new(0);

/// Writes a file atomically: `write` fills a buffered temporary file in the
/// same directory as `path` (named `.{filename}.tmp-{pid}-{n}`), which is then
/// flushed, fsynced and renamed over `path`.
///
/// On any error — from `write`, the file system or the rename — the temporary
/// is removed and the error returned, naming `path` (a full disk must say which
/// file it stopped); `path` is left untouched. The temporary is also removed if
/// `write` panics.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    write_atomic_unnamed(path, |file| write(file)).map_err(|e| naming(path, e))
}

/// As [`write_atomic`], but `write` is given the buffered temporary file itself, in which it may
/// seek: for a format whose header says what only the end of the writing knows (a length, a
/// checksum), written without holding the whole file in memory.
pub fn write_atomic_file(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    write_atomic_unnamed(path, write).map_err(|e| naming(path, e))
}

/// `e` with the file it happened to in its message (unless it is there already).
pub(crate) fn naming(path: &Path, e: io::Error) -> io::Error {
    let shown = path.display().to_string();
    if e.to_string().contains(&shown) {
        return e;
    }
    io::Error::new(e.kind(), format!("'{shown}': {e}"))
}

fn write_atomic_unnamed(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    let temp = temp_path(path)?;
    // `create_new` never clobbers a file we did not create; the guard is only
    // armed once the temporary exists, so a failure here removes nothing.
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp)?;
    let mut guard = RemoveOnDrop(Some(temp.clone()));

    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(io::IntoInnerError::into_error)?;
    // Data must be on disk before the rename makes it visible, otherwise a
    // power loss could leave a renamed but empty file.
    file.sync_all()?;
    drop(file);

    fs::rename(&temp, path)?;
    guard.0 = None;
    sync_parent_dir(path);
    Ok(())
}

/// Writes `bytes` to `path` atomically; see [`write_atomic`].
pub fn write_atomic_bytes(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic(path, |w| w.write_all(bytes))
}

/// The temporary lives in the target's directory because a rename across file
/// systems is not atomic (and fails). The leading dot hides it from listings.
fn temp_path(path: &Path) -> io::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| super::invalid_input(format!("not a file path: {}", path.display())))?;
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        NEXT_TEMP_ID.fetch_add(1, Ordering::Relaxed)
    ));
    Ok(path.with_file_name(temp_name))
}

/// Makes the rename itself durable. Best effort: some file systems refuse to
/// fsync directories, and the file content is already safe at this point.
fn sync_parent_dir(path: &Path) {
    #[cfg(unix)]
    {
        let dir = match path.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir,
            _ => Path::new("."),
        };
        if let Ok(dir) = File::open(dir) {
            let _ = dir.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

/// Deletes the temporary file unless disarmed by taking the path out.
struct RemoveOnDrop(Option<PathBuf>);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        if let Some(path) = self.0.take() {
            let _ = fs::remove_file(path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn content_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic(&path, |w| {
            w.write_all(b"hello ")?;
            write!(w, "world {}", 42)
        })
        .unwrap();
        assert_eq!(fs::read_to_string(&path).unwrap(), "hello world 42");
        assert_eq!(entries(dir.path()), ["out.txt"]);
    }

    #[test]
    fn bytes_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("data.bin");
        let bytes: Vec<u8> = (0..=255).collect();
        write_atomic_bytes(&path, &bytes).unwrap();
        assert_eq!(fs::read(&path).unwrap(), bytes);
    }

    #[test]
    fn failing_writer_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let err = write_atomic(&path, |w| {
            w.write_all(b"partial content")?;
            Err(io::Error::other("simulated failure"))
        })
        .unwrap_err();
        // The error names the file it stopped (a full disk must say which).
        assert_eq!(
            err.to_string(),
            format!("'{}': simulated failure", path.display())
        );
        assert!(!path.exists());
        assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
    }

    #[test]
    fn failing_writer_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic_bytes(&path, b"old complete content").unwrap();
        let result = write_atomic(&path, |w| {
            w.write_all(b"new but trunc")?;
            Err(io::Error::other("disk full"))
        });
        assert!(result.is_err());
        assert_eq!(fs::read(&path).unwrap(), b"old complete content");
        assert_eq!(entries(dir.path()), ["out.txt"]);
    }

    #[test]
    fn panicking_writer_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        let result = std::panic::catch_unwind(|| {
            let _ = write_atomic(&path, |_| panic!("writer panicked"));
        });
        assert!(result.is_err());
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn overwrites_an_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        write_atomic_bytes(&path, b"a much longer first version of the file").unwrap();
        write_atomic_bytes(&path, b"short").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"short");
        assert_eq!(entries(dir.path()), ["out.txt"]);
    }

    #[test]
    fn missing_directory_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no_such_dir").join("out.txt");
        let err = write_atomic_bytes(&path, b"x").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
    }

    #[test]
    fn path_without_file_name_is_invalid_input() {
        let err = write_atomic_bytes(Path::new("/"), b"x").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }
}
