//! Scene keys set from the command line (`--set simulation.duration=2`, `--duration 2`), as in
//! LIGGGHTS-style workflows where one scene file serves a parameter study. The file's text is
//! edited (with `toml_edit`, which keeps its layout, so line numbers in messages still point at
//! the file's lines) and then read and checked exactly like the file itself.

use std::fmt;
use std::str::FromStr;
use toml_edit::{DocumentMut, InlineTable, Item, TableLike, Value};

/// One `KEY=VALUE`: a dotted key path, with `[i]` for the i-th entry of an array of tables
/// (`material[0].friction`), and a TOML value (a bare word is taken as a string).
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    pub key: String,
    pub value: String,
}

impl FromStr for Override {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (key, value) = s.split_once('=').ok_or_else(|| {
            format!("'{s}' is not KEY=VALUE (for example simulation.duration=2.0)")
        })?;
        let (key, value) = (key.trim(), value.trim());
        if key.is_empty() || value.is_empty() {
            return Err(format!(
                "'{s}' is not KEY=VALUE (for example simulation.duration=2.0)"
            ));
        }
        Ok(Self {
            key: key.to_string(),
            value: value.to_string(),
        })
    }
}

impl fmt::Display for Override {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}={}", self.key, self.value)
    }
}

/// `source` with every override applied in order; an error names the override and what is wrong.
pub fn apply(source: &str, overrides: &[Override]) -> Result<String, String> {
    if overrides.is_empty() {
        return Ok(source.to_string());
    }
    let mut doc: DocumentMut = source
        .parse()
        .map_err(|e| format!("the scene is not valid TOML: {e}"))?;
    for o in overrides {
        set(&mut doc, o).map_err(|why| format!("--set {o}: {why}"))?;
    }
    Ok(doc.to_string())
}

/// One step of a key path: a key, and an index into the array it names.
fn segments(key: &str) -> Result<Vec<(&str, Option<usize>)>, String> {
    key.split('.')
        .map(|part| match part.split_once('[') {
            None if !part.is_empty() => Ok((part, None)),
            Some((name, rest)) if !name.is_empty() => {
                let index = rest
                    .strip_suffix(']')
                    .and_then(|i| i.parse().ok())
                    .ok_or_else(|| format!("'{part}': an index is written name[0]"))?;
                Ok((name, Some(index)))
            }
            _ => Err(format!("'{key}' has an empty part")),
        })
        .collect()
}

fn set(doc: &mut DocumentMut, o: &Override) -> Result<(), String> {
    let path = segments(&o.key)?;
    let value: Value = o
        .value
        .parse()
        .unwrap_or_else(|_| Value::from(o.value.as_str()));
    let (&(name, last_index), inner) = path.split_last().expect("split gives at least one part");
    if last_index.is_some() {
        return Err(format!(
            "`{}` is a table; set one of its keys ({}.KEY=VALUE)",
            o.key, o.key
        ));
    }
    let mut table: &mut dyn TableLike = doc.as_table_mut();
    let mut walked = String::new();
    for &(name, index) in inner {
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(name);
        if table.get(name).is_none() {
            if index.is_some() {
                return Err(format!("the scene has no `{walked}` entries"));
            }
            table.insert(name, Item::Value(Value::InlineTable(InlineTable::new())));
        }
        let item = table.get_mut(name).expect("present or just inserted");
        table = match index {
            None => item
                .as_table_like_mut()
                .ok_or_else(|| format!("`{walked}` is a value, not a table"))?,
            Some(i) => {
                walked.push_str(&format!("[{i}]"));
                entry(item, i).ok_or_else(|| format!("the scene has no `{walked}`"))?
            }
        };
    }
    if table.get(name).is_some_and(|item| item.is_table_like()) {
        return Err(format!("`{}` is a table; set one of its keys", o.key));
    }
    table.insert(name, Item::Value(value));
    Ok(())
}

/// The `i`-th table of an array of tables (`[[material]]`) or of an inline array of tables.
fn entry(item: &mut Item, i: usize) -> Option<&mut dyn TableLike> {
    match item {
        Item::ArrayOfTables(tables) => tables.get_mut(i).map(|t| t as &mut dyn TableLike),
        Item::Value(Value::Array(values)) => values
            .get_mut(i)
            .and_then(Value::as_inline_table_mut)
            .map(|t| t as &mut dyn TableLike),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "# a comment\n[simulation]\nduration = 1.0\n\n\
                         [[material]]\nname = \"a\"\nfriction = 0.5\n\n\
                         [[material]]\nname = \"b\"\nfriction = 0.4\n\n\
                         [[mesh_wall]]\nmotion = { rpm = 10.0, axis = [0.0, 0.0, 1.0] }\n";

    fn set(overrides: &[&str]) -> Result<String, String> {
        let o: Vec<Override> = overrides.iter().map(|s| s.parse().unwrap()).collect();
        apply(SCENE, &o)
    }

    #[test]
    fn values_are_set_in_place_keeping_the_layout() {
        let out = set(&[
            "simulation.duration=2.5",
            "material[1].friction=0.3",
            "mesh_wall[0].motion.rpm=60",
            "simulation.broad_phase=cell_grid",
        ])
        .unwrap();
        let value: toml::Table = out.parse().unwrap();
        assert_eq!(value["simulation"]["duration"].as_float(), Some(2.5));
        assert_eq!(
            value["simulation"]["broad_phase"].as_str(),
            Some("cell_grid")
        );
        assert_eq!(value["material"][1]["friction"].as_float(), Some(0.3));
        assert_eq!(value["material"][0]["friction"].as_float(), Some(0.5));
        assert_eq!(
            value["mesh_wall"][0]["motion"]["rpm"].as_integer(),
            Some(60)
        );
        // Untouched lines keep their place; the one new key (broad_phase) adds a line to its
        // table.
        assert_eq!(out.lines().next(), Some("# a comment"));
        assert_eq!(
            out.lines().position(|l| l.starts_with("[[material]]")),
            Some(5)
        );
    }

    #[test]
    fn a_new_key_goes_into_its_table() {
        let out = set(&["output.checkpoint_interval=0.1"]).unwrap();
        let value: toml::Table = out.parse().unwrap();
        assert_eq!(value["output"]["checkpoint_interval"].as_float(), Some(0.1));
    }

    #[test]
    fn bad_overrides_say_what_is_wrong() {
        assert!("simulation.duration".parse::<Override>().is_err());
        let e = set(&["material[2].friction=0.3"]).unwrap_err();
        assert!(
            e.contains("--set material[2].friction=0.3") && e.contains("no `material[2]`"),
            "{e}"
        );
        let e = set(&["simulation=3"]).unwrap_err();
        assert!(e.contains("is a table"), "{e}");
        let e = set(&["simulation.duration.x=3"]).unwrap_err();
        assert!(e.contains("is a value"), "{e}");
        let e = set(&["insert[0].count=3"]).unwrap_err();
        assert!(e.contains("no `insert` entries"), "{e}");
        let e = set(&["material[x].friction=3"]).unwrap_err();
        assert!(e.contains("index"), "{e}");
    }
}
