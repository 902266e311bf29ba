//! Reading back the CSV series that `csv` writes (a header line of column names, then rows of
//! numbers), for `polydem plot`. Errors name the file and the line.

use std::path::{Path, PathBuf};

/// A CSV file's columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub path: PathBuf,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// The values of column `name`, in row order.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }
}

/// Reads a CSV file of numbers with one header line. A message on error says which file and
/// line is wrong.
pub fn read_table(path: &Path) -> Result<Table, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    // A run that is still going appends whole lines; a last line without its line break is
    // one being written, and is left out rather than refused.
    let complete = match text.rfind('\n') {
        Some(end) if !text.ends_with('\n') => &text[..=end],
        _ => &text[..],
    };
    let mut lines = complete.lines().enumerate();
    let columns: Vec<String> = match lines.next() {
        Some((_, header)) if !header.trim().is_empty() => header_fields(header),
        _ => return Err(format!("{}: empty file, no header line", path.display())),
    };
    let mut rows = Vec::new();
    for (n, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let row: Vec<f64> = line
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("{}: line {}: not a row of numbers", path.display(), n + 1))?;
        if row.len() != columns.len() {
            return Err(format!(
                "{}: line {}: {} values for {} columns",
                path.display(),
                n + 1,
                row.len(),
                columns.len()
            ));
        }
        rows.push(row);
    }
    Ok(Table {
        path: path.to_path_buf(),
        columns,
        rows,
    })
}

/// The column names of a header line, unquoted as RFC 4180 says (a name holding a comma, such
/// as a flow meter's, is written in double quotes, a quote inside doubled).
fn header_fields(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field).trim().to_string()),
            (c, _) => field.push(c),
        }
    }
    fields.push(field.trim().to_string());
    fields
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::CsvSeries;

    #[test]
    fn a_series_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let mut series = CsvSeries::new(dir.path().join("e.csv"), &["time", "kinetic"]);
        series.push(&[0.0, 1.5]).unwrap();
        series.push(&[0.1, 1e-300]).unwrap();
        let table = read_table(series.path()).unwrap();
        assert_eq!(table.columns, ["time", "kinetic"]);
        assert_eq!(table.column("kinetic"), Some(vec![1.5, 1e-300]));
        assert_eq!(table.column("nothing"), None);
    }

    #[test]
    fn quoted_names_and_a_line_being_written() {
        let dir = tempfile::tempdir().unwrap();
        let mut series = CsvSeries::new(
            dir.path().join("f.csv"),
            &["time", "out, left_mass", "say \"hi\""],
        );
        series.push(&[0.0, 1.0, 2.0]).unwrap();
        let mut text = std::fs::read_to_string(series.path()).unwrap();
        text.push_str("0.1,2");
        std::fs::write(series.path(), text).unwrap();
        let table = read_table(series.path()).unwrap();
        assert_eq!(table.columns, ["time", "out, left_mass", "say \"hi\""]);
        assert_eq!(table.rows, [vec![0.0, 1.0, 2.0]]);
    }

    #[test]
    fn broken_tables_name_the_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.csv");
        for (content, needle) in [
            ("", "empty"),
            ("time,a\n0,1\n0.1,x\n", "line 3"),
            ("time,a\n0,1,2\n", "line 2"),
        ] {
            std::fs::write(&path, content).unwrap();
            let err = read_table(&path).unwrap_err();
            assert!(err.contains("bad.csv") && err.contains(needle), "{err}");
        }
    }
}
