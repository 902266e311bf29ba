//! Scene errors that say which file, which line and key, and what is allowed.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in the scene file a value is: a table (`simulation`, or an array of tables such as
/// `material` with its index) and a key inside it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyPath {
    pub table: String,
    pub index: Option<usize>,
    pub key: Option<String>,
}

impl KeyPath {
    pub fn table(table: &str) -> Self {
        Self {
            table: table.into(),
            index: None,
            key: None,
        }
    }

    pub fn entry(table: &str, index: usize) -> Self {
        Self {
            table: table.into(),
            index: Some(index),
            key: None,
        }
    }

    pub fn key(mut self, key: &str) -> Self {
        self.key = Some(key.into());
        self
    }
}

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self.index {
            // Users count array-of-tables entries from 1, as they appear in the file.
            Some(i) => write!(f, "[[{}]] #{}", self.table, i + 1)?,
            None => write!(f, "[{}]", self.table)?,
        }
        if let Some(key) = &self.key {
            write!(f, " {key}")?;
        }
        Ok(())
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file '{}': {source}", file.display())]
    Read {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{}:{line}:{column}: {message}\n    {text}", file.display())]
    Syntax {
        file: PathBuf,
        line: usize,
        column: usize,
        text: String,
        message: String,
    },
    #[error("{}: {message}", file.display())]
    Override { file: PathBuf, message: String },
    #[error("{}{}: {key}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        file: PathBuf,
        line: Option<usize>,
        key: KeyPath,
        message: String,
    },
}

impl SceneError {
    /// A TOML or schema error from the parser, located by its byte span.
    pub fn from_toml(file: &Path, source: &str, error: &toml::de::Error) -> Self {
        let (line, column) = error
            .span()
            .map(|span| line_and_column(source, span.start))
            .unwrap_or((1, 1));
        SceneError::Syntax {
            file: file.to_path_buf(),
            line,
            column,
            text: source
                .lines()
                .nth(line - 1)
                .unwrap_or("")
                .trim_end()
                .to_string(),
            message: error.message().trim_end().to_string(),
        }
    }

    /// A file that is not UTF-8 text, located at its first bad byte.
    pub fn not_utf8(file: &Path, error: &std::string::FromUtf8Error) -> Self {
        let bytes = error.as_bytes();
        let offset = error.utf8_error().valid_up_to();
        let before = &bytes[..offset];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        let column = String::from_utf8_lossy(&bytes[line_start..offset])
            .chars()
            .count()
            + 1;
        let line_end = bytes[offset..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| offset + p);
        SceneError::Syntax {
            file: file.to_path_buf(),
            line,
            column,
            text: String::from_utf8_lossy(&bytes[line_start..line_end])
                .trim_end()
                .to_string(),
            message: format!(
                "byte 0x{:02x} is not UTF-8 text: save the file as UTF-8 (a name with an accent \
                 typed in another encoding, say)",
                bytes[offset]
            ),
        }
    }

    /// A value that parsed but is not allowed; the line is looked up from the key's position.
    pub fn invalid(file: &Path, source: &str, key: KeyPath, message: impl Into<String>) -> Self {
        SceneError::Invalid {
            file: file.to_path_buf(),
            line: locate(source, &key),
            key,
            message: message.into(),
        }
    }
}

fn line_and_column(source: &str, offset: usize) -> (usize, usize) {
    let before = &source[..offset.min(source.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |p| p + 1) + 1;
    (line, column)
}

/// Finds the line of a key in the usual layout of a scene file (`[table]` or `[[table]]` headers,
/// one `key = value` per line). Returns `None` for layouts it does not follow (inline tables,
/// dotted keys); the error still names the key.
fn locate(source: &str, path: &KeyPath) -> Option<usize> {
    let header = match path.index {
        Some(_) => format!("[[{}]]", path.table),
        None => format!("[{}]", path.table),
    };
    let wanted = path.index.unwrap_or(0);
    let mut seen = 0;
    let mut inside = false;
    let mut header_line = None;
    for (n, raw) in source.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.starts_with('[') {
            if inside {
                break;
            }
            if line.replace(' ', "") == header {
                if seen == wanted {
                    inside = true;
                    header_line = Some(n + 1);
                }
                seen += 1;
            }
            continue;
        }
        if inside {
            if let Some(key) = &path.key {
                let first = key.split('.').next().unwrap_or(key);
                if let Some((k, _)) = line.split_once('=') {
                    if k.trim() == first {
                        return Some(n + 1);
                    }
                }
            }
        }
    }
    header_line
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "[simulation]\nduration = 1\n\n[[material]]\nname = \"a\"\n\n[[material]]\n# second\nname = \"b\"\ndensity = -1\n";

    #[test]
    fn finds_keys_in_arrays_of_tables() {
        let key = KeyPath::entry("material", 1).key("density");
        assert_eq!(locate(SCENE, &key), Some(10));
        assert_eq!(
            locate(SCENE, &KeyPath::table("simulation").key("duration")),
            Some(2)
        );
        // A key that is absent points at its table's header.
        assert_eq!(
            locate(SCENE, &KeyPath::entry("material", 0).key("density")),
            Some(4)
        );
        assert_eq!(
            locate(SCENE, &KeyPath::table("contact").key("normal")),
            None
        );
    }

    #[test]
    fn message_names_file_line_and_key() {
        let e = SceneError::invalid(
            Path::new("s.toml"),
            SCENE,
            KeyPath::entry("material", 1).key("density"),
            "must be positive",
        );
        assert_eq!(
            e.to_string(),
            "s.toml:10: [[material]] #2 density: must be positive"
        );
    }
}
