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
    let mut lines = text.lines().enumerate();
    let columns: Vec<String> = match lines.next() {
        Some((_, header)) if !header.trim().is_empty() => {
            header.split(',').map(|c| c.trim().to_string()).collect()
        }
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
