//! Which changes of the scene a resumed run accepts: those that do not contradict the state it
//! continues from. Run longer or shorter, write frames or checkpoints at another interval, use
//! other threads, move a wall at another speed from now on — yes. Another material, shape, wall
//! or insertion — no: the bodies and contacts in the checkpoint were computed with the old ones.
//! (A wall's new motion must also put the wall where the run had it at the checkpoint's time:
//! `World::restore` checks that.)

/// The keys whose values may differ between a checkpoint's scene and the scene it is resumed with
/// (`[]` stands for any index).
pub const ALLOWED_CHANGES: &[&str] = &[
    "simulation.duration",
    "simulation.output_interval",
    "simulation.threads",
    "simulation.watchdog",
    "output.checkpoint_interval",
    "output.vtk_interval",
    "output.csv_interval",
    "mesh_wall[].motion",
];

/// Whether a changed key (as [`changed_keys`] names it) is one a resumed run accepts.
pub fn change_allowed(key: &str) -> bool {
    // `mesh_wall[2].motion.rpm` → `mesh_wall[].motion.rpm`.
    let mut general = String::with_capacity(key.len());
    let mut in_index = false;
    for c in key.chars() {
        match c {
            '[' => in_index = true,
            ']' => in_index = false,
            _ if in_index => continue,
            _ => {}
        }
        general.push(c);
    }
    ALLOWED_CHANGES
        .iter()
        .any(|a| general == *a || general.starts_with(&format!("{a}.")))
}

/// The keys (as `table.key`, `array[i].key`) whose values differ between two scene files, or an
/// error naming the file that does not parse as TOML.
pub fn changed_keys(old: &str, new: &str) -> Result<Vec<String>, String> {
    let parse = |text: &str, which: &str| {
        text.parse::<toml::Table>()
            .map_err(|e| format!("the {which} scene is not valid TOML: {e}"))
    };
    let (old, new) = (parse(old, "checkpoint's")?, parse(new, "new")?);
    let mut changed = Vec::new();
    compare_tables(&old, &new, "", &mut changed);
    Ok(changed)
}

fn compare_tables(old: &toml::Table, new: &toml::Table, prefix: &str, out: &mut Vec<String>) {
    let mut keys: Vec<&String> = old.keys().chain(new.keys()).collect();
    keys.sort();
    keys.dedup();
    for key in keys {
        let path = if prefix.is_empty() {
            key.clone()
        } else {
            format!("{prefix}.{key}")
        };
        match (old.get(key), new.get(key)) {
            (Some(a), Some(b)) => compare_values(a, b, &path, out),
            _ => out.push(path),
        }
    }
}

fn compare_values(old: &toml::Value, new: &toml::Value, path: &str, out: &mut Vec<String>) {
    use toml::Value;
    match (old, new) {
        (Value::Table(a), Value::Table(b)) => compare_tables(a, b, path, out),
        // Arrays of tables ([[material]], [[insert]], …) item by item, so the message names the
        // item; other arrays (vectors, tables of numbers) as a whole.
        (Value::Array(a), Value::Array(b))
            if a.len() == b.len() && a.iter().chain(b).all(Value::is_table) =>
        {
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                compare_values(x, y, &format!("{path}[{k}]"), out);
            }
        }
        _ if old == new => {}
        // 1 and 1.0 are the same number to the scene reader.
        (Value::Integer(i), Value::Float(f)) | (Value::Float(f), Value::Integer(i))
            if *i as f64 == *f => {}
        _ => out.push(path.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_values_that_differ_are_named_with_their_place() {
        let old = "[simulation]\nduration = 1\ngravity = [0, 0, -9.81]\n\
                   [[material]]\nname = \"a\"\ndensity = 2500\n\
                   [[material]]\nname = \"b\"\ndensity = 1000\n";
        let new = "# a comment, and other spacing\n[simulation]\nduration = 2.0\n\
                   gravity = [0, 0, -9.81]\n\
                   [[material]]\nname = \"a\"\ndensity = 2500.0\n\
                   [[material]]\nname = \"b\"\ndensity = 1200\nfriction = 0.3\n";
        assert_eq!(
            changed_keys(old, new).unwrap(),
            [
                "material[1].density",
                "material[1].friction",
                "simulation.duration"
            ]
        );
        assert!(changed_keys(old, old).unwrap().is_empty());
    }

    #[test]
    fn wall_motions_may_change_but_not_walls() {
        assert!(change_allowed("mesh_wall[3].motion.rpm_table"));
        assert!(change_allowed("mesh_wall[0].motion"));
        assert!(change_allowed("simulation.duration"));
        assert!(!change_allowed("mesh_wall[0].generator.radius"));
        assert!(!change_allowed("mesh_wall"));
        assert!(!change_allowed("simulation.durationx"));
        assert!(!change_allowed("material[0].friction"));
    }

    #[test]
    fn a_different_number_of_items_is_one_change() {
        let old = "[[insert]]\ncount = 1\n";
        let new = "[[insert]]\ncount = 1\n[[insert]]\ncount = 2\n";
        assert_eq!(changed_keys(old, new).unwrap(), ["insert"]);
    }

    #[test]
    fn a_new_scene_that_is_not_toml_is_an_error() {
        assert!(changed_keys("a = 1", "a = ")
            .unwrap_err()
            .contains("new scene"));
    }
}
