//! Files stay small enough to read (issue #18): no file of `src/` has more than 800 lines of
//! production code (the lines before its `#[cfg(test)]`), and `world.rs`, which keeps the world's
//! state and lifecycle only, stays under 400. A file that grows past this holds more than one
//! idea: split it by idea (as `scene/build.rs` and `scene/prepared.rs` were from `scene/mod.rs`).

use std::path::{Path, PathBuf};

const MOST_LINES: usize = 800;
const MOST_WORLD_LINES: usize = 400;

fn rust_files(dir: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "rs") {
            found.push(path);
        }
    }
}

/// The lines of `text` before its first `#[cfg(test)]` at the start of a line.
fn production_lines(text: &str) -> usize {
    text.lines()
        .take_while(|line| !line.starts_with("#[cfg(test)]"))
        .count()
}

#[test]
fn production_lines_are_counted_up_to_the_tests() {
    assert_eq!(production_lines("a\nb\n#[cfg(test)]\nmod tests {}\n"), 2);
    assert_eq!(production_lines("a\n    #[cfg(test)]\nb\n"), 3);
    assert_eq!(production_lines(""), 0);
}

#[test]
fn no_source_file_is_over_800_production_lines() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.len() > 50, "found only {} files", files.len());
    let mut too_long = Vec::new();
    for file in &files {
        let lines = production_lines(&std::fs::read_to_string(file).unwrap());
        let name = file.strip_prefix(&src).unwrap().display().to_string();
        let most = if name == "world.rs" {
            MOST_WORLD_LINES
        } else {
            MOST_LINES
        };
        if lines > most {
            too_long.push(format!(
                "src/{name}: {lines} production lines (at most {most})"
            ));
        }
    }
    assert!(too_long.is_empty(), "{}", too_long.join("\n"));
}
