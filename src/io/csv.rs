//! Scalar time series (energies, forces on walls, …) as CSV.
//!
//! The file is created atomically with its header and first row, then grows by whole lines
//! appended in one write each and synced to disk, so a long run's cost per row stays constant
//! and a reader never sees a row half written by a run that is still going. The rows are also
//! kept in memory (a few numbers per output interval) so that a checkpoint carries them: a
//! resumed run writes the file whole once from them, dropping rows the stopped run wrote after
//! its checkpoint, then appends again.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::{atomic::write_atomic, format_f64, invalid_input};

/// A CSV file with a fixed header, grown one row at a time.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct CsvSeries {
    path: PathBuf,
    columns: Vec<String>,
    rows: Vec<Vec<f64>>,
    /// How many of `rows` the file holds; 0 after a checkpoint is read, so that the file is
    /// then written whole.
    #[serde(skip)]
    on_disk: usize,
}

impl CsvSeries {
    /// Starts an empty series; nothing is written until the first push, so
    /// creating a series never fails.
    pub fn new<S: AsRef<str>>(path: PathBuf, columns: &[S]) -> Self {
        Self {
            path,
            columns: columns.iter().map(|c| c.as_ref().to_string()).collect(),
            rows: Vec::new(),
            on_disk: 0,
        }
    }

    /// The same series, written into `dir` under the same file name.
    pub fn relocate(&mut self, dir: &Path) {
        if let Some(name) = self.path.file_name() {
            self.path = dir.join(name);
        }
    }

    /// Records `row` and writes it: the first time (and after a checkpoint was read) the whole
    /// file atomically, then by appending the rows the file lacks.
    ///
    /// Returns `InvalidInput` if `row` does not have one value per column; the
    /// row is then not recorded. If writing fails, the row stays recorded and
    /// is written by the next successful push.
    pub fn push(&mut self, row: &[f64]) -> io::Result<()> {
        if row.len() != self.columns.len() {
            return Err(invalid_input(format!(
                "CSV row has {} values but {} has {} columns",
                row.len(),
                self.path.display(),
                self.columns.len()
            )));
        }
        self.rows.push(row.to_vec());
        if self.on_disk == 0 {
            write_atomic(&self.path, |w| self.write_to(w))?;
        } else {
            let mut lines = String::new();
            for row in &self.rows[self.on_disk..] {
                lines.push_str(&line(row));
            }
            let append = || -> io::Result<()> {
                let mut file = std::fs::OpenOptions::new().append(true).open(&self.path)?;
                // One write of whole lines, then to disk before the run goes on.
                file.write_all(lines.as_bytes())?;
                file.sync_data()
            };
            append().map_err(|e| super::atomic::naming(&self.path, e))?;
        }
        self.on_disk = self.rows.len();
        Ok(())
    }

    /// Writes the file whole from the rows recorded (a resumed run: the file may hold rows
    /// written after the checkpoint), or removes it when there are none.
    pub fn rewrite(&mut self) -> io::Result<()> {
        if self.rows.is_empty() {
            self.on_disk = 0;
            return match std::fs::remove_file(&self.path) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => {
                    Err(super::atomic::naming(&self.path, e))
                }
                _ => Ok(()),
            };
        }
        write_atomic(&self.path, |w| self.write_to(w))?;
        self.on_disk = self.rows.len();
        Ok(())
    }

    /// Where the file is written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The column names, in order.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// All rows pushed so far.
    pub fn rows(&self) -> &[Vec<f64>] {
        &self.rows
    }

    fn write_to(&self, w: &mut dyn Write) -> io::Result<()> {
        let header: Vec<String> = self.columns.iter().map(|c| quote(c)).collect();
        writeln!(w, "{}", header.join(","))?;
        for row in &self.rows {
            w.write_all(line(row).as_bytes())?;
        }
        Ok(())
    }
}

/// One row as a line of the file, exact (see `format_f64`).
fn line(row: &[f64]) -> String {
    let fields: Vec<String> = row.iter().map(|&x| format_f64(x)).collect();
    format!("{}\n", fields.join(","))
}

/// RFC 4180 quoting, so a column name containing a comma cannot shift columns.
fn quote(field: &str) -> String {
    if field.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
        let mut lines = text.lines();
        let header = lines
            .next()
            .unwrap()
            .split(',')
            .map(str::to_string)
            .collect();
        let rows = lines
            .map(|l| l.split(',').map(|f| f.parse::<f64>().unwrap()).collect())
            .collect();
        (header, rows)
    }

    #[test]
    fn rows_round_trip_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("energy.csv");
        let mut series = CsvSeries::new(path.clone(), &["time", "kinetic", "count"]);
        let rows = [
            [0.0, 0.0, 3.0],
            [1e-6, 1.234_567_890_123_456_7e-12, 1000.0],
            [0.1 + 0.2, -7.25e300, f64::MIN_POSITIVE],
        ];
        for (i, row) in rows.iter().enumerate() {
            series.push(row).unwrap();
            let (header, parsed) = parse(&std::fs::read_to_string(&path).unwrap());
            assert_eq!(header, ["time", "kinetic", "count"]);
            assert_eq!(parsed.len(), i + 1, "file holds all rows so far");
            for (got, want) in parsed.iter().zip(&rows) {
                let got_bits: Vec<u64> = got.iter().map(|x| x.to_bits()).collect();
                let want_bits: Vec<u64> = want.iter().map(|x| x.to_bits()).collect();
                assert_eq!(got_bits, want_bits);
            }
        }
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("time,kinetic,count\n0,0,3\n"), "{text}");
        assert!(text.ends_with('\n'));
        assert_eq!(series.rows().len(), 3);
    }

    #[test]
    fn wrong_row_length_is_invalid_input_and_not_recorded() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        let mut series = CsvSeries::new(path.clone(), &["a", "b"]);
        let err = series.push(&[1.0]).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        let err = series.push(&[1.0, 2.0, 3.0]).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(series.rows().is_empty());
        assert!(!path.exists());
        series.push(&[1.0, 2.0]).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n1,2\n");
    }

    #[test]
    fn awkward_column_names_are_quoted() {
        assert_eq!(quote("force,x"), "\"force,x\"");
        assert_eq!(quote("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(quote("plain"), "plain");
    }

    /// Rows after the first are appended, not rewritten: the file's first bytes are not touched
    /// again (a rewrite would replace the file, giving it a new inode).
    #[cfg(unix)]
    #[test]
    fn rows_are_appended_and_a_resumed_series_is_written_whole_once() {
        use std::os::unix::fs::MetadataExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        let mut series = CsvSeries::new(path.clone(), &["a"]);
        series.push(&[1.0]).unwrap();
        let inode = std::fs::metadata(&path).unwrap().ino();
        series.push(&[2.0]).unwrap();
        series.push(&[3.0]).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().ino(), inode);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a\n1\n2\n3\n");

        // As from a checkpoint taken after two rows, the stopped run having written a third.
        let mut resumed = series.clone();
        resumed.rows.truncate(2);
        resumed.on_disk = 0;
        resumed.push(&[4.0]).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a\n1\n2\n4\n");
        resumed.push(&[5.0]).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a\n1\n2\n4\n5\n");
    }

    #[test]
    fn write_failure_is_an_error_and_row_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing_dir").join("s.csv");
        let mut series = CsvSeries::new(path, &["a"]);
        assert!(series.push(&[1.0]).is_err());
        assert_eq!(series.rows().len(), 1);
    }
}
