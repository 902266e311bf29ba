//! Which files of a run's output folder make one frame: the particles of `particles.pvd` and,
//! from the other series, the data set written at the same time (`polyhedra.pvd`, `walls.pvd`,
//! `contacts.pvd`, each only when the run wrote it).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use super::PictureError;
use crate::io::vtk_read::{read_pvd, read_vtp, PolyData, PvdEntry};

/// Which frames to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrameChoice {
    /// The frame with this index (0 is the first).
    Index(usize),
    #[default]
    Last,
    All,
}

impl FromStr for FrameChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "last" => Ok(FrameChoice::Last),
            "all" => Ok(FrameChoice::All),
            n => n
                .parse()
                .map(FrameChoice::Index)
                .map_err(|_| format!("unknown frame '{n}': use a frame number, last or all")),
        }
    }
}

/// The series of a run's output folder.
#[derive(Clone, Debug)]
pub struct RunFiles {
    dir: PathBuf,
    particles: Vec<PvdEntry>,
    polyhedra: Vec<PvdEntry>,
    walls: Vec<PvdEntry>,
    contacts: Vec<PvdEntry>,
    legend: Legend,
}

/// One frame: what each series holds at one time.
#[derive(Clone, Debug)]
pub struct Snapshot {
    pub time: f64,
    pub particles_file: PathBuf,
    pub particles: PolyData,
    pub polyhedra: Option<(PathBuf, PolyData)>,
    pub walls: Option<(PathBuf, PolyData)>,
    pub contacts: Option<(PathBuf, PolyData)>,
    /// Names of the material and shape numbers (`legend.csv`), empty when the run wrote none.
    pub legend: Legend,
}

/// What the `material` and `shape` numbers stand for: (kind, number) → name.
pub type Legend = HashMap<(String, u32), String>;

/// Reads `legend.csv` (`kind,number,name`, the name quoted when it holds a comma or quote);
/// an empty legend when there is no such file.
pub fn read_legend(path: &Path) -> Result<Legend, PictureError> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Legend::new()),
        Err(e) => return Err(PictureError::file(path, e.to_string())),
    };
    let mut legend = Legend::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let bad = || PictureError::file(path, format!("line {}: not kind,number,name", n + 1));
        let mut parts = line.splitn(3, ',');
        let (Some(kind), Some(number), Some(name)) = (parts.next(), parts.next(), parts.next())
        else {
            return Err(bad());
        };
        let number: u32 = number.trim().parse().map_err(|_| bad())?;
        let name = match name.strip_prefix('"').and_then(|n| n.strip_suffix('"')) {
            Some(inner) => inner.replace("\"\"", "\""),
            None => name.to_string(),
        };
        legend.insert((kind.trim().to_string(), number), name);
    }
    Ok(legend)
}

impl RunFiles {
    /// Reads the `.pvd` collections of `dir`; `particles.pvd` must be there.
    pub fn open(dir: &Path) -> Result<Self, PictureError> {
        let particles_pvd = dir.join("particles.pvd");
        if !particles_pvd.is_file() {
            return Err(PictureError::file(
                dir,
                "has no particles.pvd: give the output folder of `polydem run`",
            ));
        }
        let optional = |name: &str| -> Result<Vec<PvdEntry>, PictureError> {
            let path = dir.join(name);
            if path.is_file() {
                Ok(read_pvd(&path)?)
            } else {
                Ok(Vec::new())
            }
        };
        let particles = read_pvd(&particles_pvd)?;
        if particles.is_empty() {
            return Err(PictureError::file(particles_pvd, "lists no frame yet"));
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            particles,
            polyhedra: optional("polyhedra.pvd")?,
            walls: optional("walls.pvd")?,
            contacts: optional("contacts.pvd")?,
            legend: read_legend(&dir.join("legend.csv"))?,
        })
    }

    /// The run's name: the output folder's name, as `polydem run` names it after the scene.
    pub fn name(&self) -> String {
        let dir = std::fs::canonicalize(&self.dir).unwrap_or_else(|_| self.dir.clone());
        dir.file_name()
            .map_or_else(|| "run".to_string(), |n| n.to_string_lossy().into_owned())
    }

    pub fn frames(&self) -> usize {
        self.particles.len()
    }

    /// Whether the run wrote its force network.
    pub fn has_contacts(&self) -> bool {
        !self.contacts.is_empty()
    }

    /// The frame indices `choice` stands for, or an error naming the frames there are.
    pub fn select(&self, choice: FrameChoice) -> Result<Vec<usize>, PictureError> {
        let n = self.frames();
        match choice {
            FrameChoice::Last => Ok(vec![n - 1]),
            FrameChoice::All => Ok((0..n).collect()),
            FrameChoice::Index(i) if i < n => Ok(vec![i]),
            FrameChoice::Index(i) => Err(PictureError::Option(format!(
                "there is no frame {i}: {} has frames 0 to {}",
                self.dir.display(),
                n - 1
            ))),
        }
    }

    /// Reads frame `index`; the force network only when `contacts` is asked for.
    pub fn load(&self, index: usize, contacts: bool) -> Result<Snapshot, PictureError> {
        let entry = &self.particles[index];
        let particles = read_vtp(&entry.file)?;
        let partner = |series: &[PvdEntry]| -> Result<Option<(PathBuf, PolyData)>, PictureError> {
            match nearest(series, entry.time) {
                Some(e) => Ok(Some((e.file.clone(), read_vtp(&e.file)?))),
                None => Ok(None),
            }
        };
        Ok(Snapshot {
            time: particles.time.unwrap_or(entry.time),
            particles_file: entry.file.clone(),
            particles,
            polyhedra: partner(&self.polyhedra)?,
            walls: partner(&self.walls)?,
            contacts: if contacts {
                partner(&self.contacts)?
            } else {
                None
            },
            legend: self.legend.clone(),
        })
    }
}

/// The entry written at `time`: every series is written at the same output times, so the
/// nearest one is it (and a series that missed a frame still gives the closest state).
fn nearest(series: &[PvdEntry], time: f64) -> Option<&PvdEntry> {
    series
        .iter()
        .min_by(|a, b| (a.time - time).abs().total_cmp(&(b.time - time).abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_choices_parse() {
        assert_eq!("last".parse(), Ok(FrameChoice::Last));
        assert_eq!("all".parse(), Ok(FrameChoice::All));
        assert_eq!("12".parse(), Ok(FrameChoice::Index(12)));
        assert!("first"
            .parse::<FrameChoice>()
            .unwrap_err()
            .contains("first"));
    }

    #[test]
    fn the_legend_names_materials_and_shapes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("legend.csv");
        assert!(read_legend(&path).unwrap().is_empty());
        std::fs::write(
            &path,
            "kind,number,name\nmaterial,0,glass\nshape,1,\"a, \"\"b\"\"\"\n",
        )
        .unwrap();
        let legend = read_legend(&path).unwrap();
        assert_eq!(legend[&("material".to_string(), 0)], "glass");
        assert_eq!(legend[&("shape".to_string(), 1)], "a, \"b\"");
        std::fs::write(&path, "kind,number,name\nmaterial,x,glass\n").unwrap();
        let err = read_legend(&path).unwrap_err().to_string();
        assert!(
            err.contains("legend.csv") && err.contains("line 2"),
            "{err}"
        );
    }

    #[test]
    fn a_folder_without_particles_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let err = RunFiles::open(dir.path()).unwrap_err().to_string();
        assert!(err.contains("particles.pvd"), "{err}");
        assert!(err.contains(&dir.path().display().to_string()), "{err}");
    }
}
