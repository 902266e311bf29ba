//! The size of the processor's last-level cache: whether a world's step fits in it decides how
//! the kick-drift writes the packed motion ([`super::motion::streams_motion`]) and where the
//! bodies' force sums are completed (`contact::ContactStore::completes_sums`).

use std::path::Path;
use std::sync::OnceLock;

/// Where Linux describes the first processor's caches, one `index*` folder per cache.
const SYSFS_CACHES: &str = "/sys/devices/system/cpu/cpu0/cache";

/// Assumed where the size cannot be read (no Linux sysfs): 32 MiB, the level-3 cache of one
/// chiplet of a current server processor, the cache on which streaming stores were measured to
/// pay (docs/benchmarks.md).
const ASSUMED_BYTES: usize = 32 << 20;

/// A step's working set in bytes per body: the bodies' arrays, their packed motion and the
/// contact store's entries come to about a kilobyte a sphere in a settled bed (peak memory, with
/// the program and the candidate list, is some 1.6 kB a sphere at 65,000).
const STEP_BYTES_PER_BODY: usize = 1024;

/// Whether the step of a world of `bodies` bodies does not fit the last-level cache: what a
/// step wrote has then left the cache by the time the next reads it.
pub fn outgrown_by(bodies: usize) -> bool {
    bodies.saturating_mul(STEP_BYTES_PER_BODY) >= bytes()
}

/// The size in bytes of the largest-level data or unified cache, read once per process.
pub fn bytes() -> usize {
    static BYTES: OnceLock<usize> = OnceLock::new();
    *BYTES.get_or_init(|| read(Path::new(SYSFS_CACHES)).unwrap_or(ASSUMED_BYTES))
}

/// The size of the highest-level cache that holds data among `dir`'s `index*` folders, each with
/// the files `level`, `type` and `size` (Linux's `cpu/cpuN/cache` layout); `None` if there is
/// none or one of them cannot be read.
fn read(dir: &Path) -> Option<usize> {
    let text = |cache: &Path, file: &str| std::fs::read_to_string(cache.join(file)).ok();
    let mut largest: Option<(u32, usize)> = None;
    for entry in std::fs::read_dir(dir).ok()? {
        let cache = entry.ok()?.path();
        let is_cache = cache.file_name()?.to_str()?.starts_with("index");
        if !is_cache || text(&cache, "type")?.trim() == "Instruction" {
            continue;
        }
        let level: u32 = text(&cache, "level")?.trim().parse().ok()?;
        let size = parse_size(&text(&cache, "size")?)?;
        if largest.is_none_or(|(highest, _)| level > highest) {
            largest = Some((level, size));
        }
    }
    largest.map(|(_, size)| size)
}

/// Bytes in a sysfs cache size: a count with an optional binary suffix, as in `491520K`.
fn parse_size(text: &str) -> Option<usize> {
    let text = text.trim();
    let digits = text
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(text.len());
    let (count, unit) = text.split_at(digits);
    let scale = match unit {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return None,
    };
    count.parse::<usize>().ok()?.checked_mul(scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_with_their_suffix() {
        assert_eq!(parse_size("491520K\n"), Some(491_520 << 10));
        assert_eq!(parse_size("32M"), Some(32 << 20));
        assert_eq!(parse_size("4096"), Some(4096));
        assert_eq!(parse_size(""), None);
        assert_eq!(parse_size("12X"), None);
        assert_eq!(parse_size("K"), None);
    }

    /// A folder laid out as Linux's `cpu0/cache`: levels 1 to 3, the instruction cache ignored.
    fn caches(list: &[(&str, &str, &str)]) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("uevent"), "").unwrap();
        for (k, (level, kind, size)) in list.iter().enumerate() {
            let cache = dir.path().join(format!("index{k}"));
            std::fs::create_dir(&cache).unwrap();
            std::fs::write(cache.join("level"), format!("{level}\n")).unwrap();
            std::fs::write(cache.join("type"), format!("{kind}\n")).unwrap();
            std::fs::write(cache.join("size"), format!("{size}\n")).unwrap();
        }
        dir
    }

    #[test]
    fn the_highest_level_data_cache_is_the_last_level() {
        let dir = caches(&[
            ("3", "Unified", "32768K"),
            ("1", "Data", "48K"),
            ("1", "Instruction", "64K"),
            ("2", "Unified", "2048K"),
        ]);
        assert_eq!(read(dir.path()), Some(32 << 20));
        let instructions_higher = caches(&[("4", "Instruction", "64K"), ("2", "Data", "1M")]);
        assert_eq!(read(instructions_higher.path()), Some(1 << 20));
    }

    #[test]
    fn no_caches_or_an_unreadable_one_gives_none() {
        assert_eq!(read(caches(&[]).path()), None);
        assert_eq!(read(caches(&[("x", "Data", "48K")]).path()), None);
        assert_eq!(read(Path::new("/no/such/folder")), None);
        assert!(bytes() > 0);
    }
}
