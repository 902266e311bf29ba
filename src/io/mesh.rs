//! Reading triangle meshes from STL (ASCII and binary, via `stl_io`) and Wavefront OBJ (via `tobj`,
//! polygons triangulated as fans) into one indexed triangle list, with near-duplicate vertices
//! welded and the coordinates scaled.
//!
//! Files written by CAD tools repeat every corner for each triangle that uses it (STL always does),
//! and single-precision coordinates mean that copies of one corner need not be bit-identical.
//! Vertices closer than [`WELD_TOLERANCE`] × the diagonal of the mesh's bounding box are therefore
//! merged into the first of them (in file order, so the result is deterministic), and triangles
//! that collapse to fewer than three distinct corners are dropped (`geometry::weld`). [`MeshInfo`]
//! says how much of that happened.
//!
//! What the mesh is used for (a convex particle, a wall) is decided elsewhere: this module only
//! reads geometry and refuses files that cannot be read, cannot be parsed, or hold coordinates
//! that are not finite numbers.

use crate::geometry::weld::{weld, WELD_TOLERANCE};
use crate::math::DVec3;
use std::fmt;
use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A mesh file format, chosen by the file's extension (case-insensitive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// `.stl`, ASCII or binary (told apart by the content).
    Stl,
    /// `.obj`, Wavefront.
    Obj,
}

impl MeshFormat {
    /// The format a file's extension names, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "stl" => Some(MeshFormat::Stl),
            "obj" => Some(MeshFormat::Obj),
            _ => None,
        }
    }
}

impl fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Stl => "STL",
            MeshFormat::Obj => "OBJ",
        })
    }
}

/// What reading a mesh did to it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshInfo {
    pub format: MeshFormat,
    /// Vertex records in the file that triangles use: three per STL facet; for OBJ the `v`
    /// positions referenced by faces (counted once per `o`/`g` group that uses them).
    pub file_vertices: usize,
    /// Distinct vertices after welding.
    pub vertices: usize,
    /// Vertex records merged into an earlier one: `file_vertices − vertices`.
    pub welded: usize,
    /// Of the welded records, those that were not bit-identical to the one kept (they were merged
    /// only because they lay within the weld tolerance).
    pub near_duplicates: usize,
    /// Triangles in the file (after triangulating OBJ polygons).
    pub file_triangles: usize,
    /// Triangles dropped because welding left them with fewer than three distinct corners.
    pub degenerate_triangles: usize,
}

/// An indexed triangle mesh read from a file, welded and scaled.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedMesh {
    pub vertices: Vec<DVec3>,
    /// Indices into `vertices`, in the file's winding order.
    pub triangles: Vec<[usize; 3]>,
    pub info: MeshInfo,
}

/// Why a mesh file could not be read. Every message names the file.
#[derive(Debug, Error)]
pub enum MeshError {
    #[error(
        "cannot read mesh file '{}': {source}",
        path.display()
    )]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "mesh file '{}' has an unknown extension: use .stl (ASCII or binary) or .obj",
        path.display()
    )]
    UnknownFormat { path: PathBuf },
    #[error("mesh file '{}' is not a valid {format} file: {message}", path.display())]
    Parse {
        path: PathBuf,
        format: MeshFormat,
        message: String,
    },
    #[error("mesh file '{}' holds no triangles", path.display())]
    Empty { path: PathBuf },
    #[error(
        "mesh file '{}': vertex {index} is [{}, {}, {}]: every coordinate must be a finite number",
        path.display(), point.x, point.y, point.z
    )]
    NonFinite {
        path: PathBuf,
        index: usize,
        point: DVec3,
    },
    #[error("scale = {scale} is not allowed: must be a finite number > 0")]
    Scale { scale: f64 },
}

/// Reads the mesh in `path` (format by extension), welds near-duplicate vertices and multiplies
/// every coordinate by `scale`.
pub fn read_mesh(path: &Path, scale: f64) -> Result<ImportedMesh, MeshError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(MeshError::Scale { scale });
    }
    let format = MeshFormat::from_path(path).ok_or_else(|| MeshError::UnknownFormat {
        path: path.to_path_buf(),
    })?;
    let bytes = std::fs::read(path).map_err(|source| MeshError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_mesh(&bytes, format, path, scale)
}

/// As [`read_mesh`], from the bytes of a file; `path` only names it in messages.
pub fn parse_mesh(
    bytes: &[u8],
    format: MeshFormat,
    path: &Path,
    scale: f64,
) -> Result<ImportedMesh, MeshError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(MeshError::Scale { scale });
    }
    let parse_error = |message: String| MeshError::Parse {
        path: path.to_path_buf(),
        format,
        message,
    };
    let soup = match format {
        MeshFormat::Stl => parse_stl(bytes).map_err(parse_error)?,
        MeshFormat::Obj => parse_obj(bytes).map_err(parse_error)?,
    };
    if soup.triangles.is_empty() {
        return Err(MeshError::Empty {
            path: path.to_path_buf(),
        });
    }
    if let Some((index, &point)) = soup
        .vertices
        .iter()
        .enumerate()
        .find(|(_, p)| !p.is_finite())
    {
        return Err(MeshError::NonFinite {
            path: path.to_path_buf(),
            index,
            point,
        });
    }
    let welded = weld(&soup.vertices, &soup.triangles, WELD_TOLERANCE);
    let info = MeshInfo {
        format,
        file_vertices: soup.vertices.len(),
        vertices: welded.vertices.len(),
        welded: soup.vertices.len() - welded.vertices.len(),
        near_duplicates: welded.near_duplicates,
        file_triangles: soup.triangles.len(),
        degenerate_triangles: soup.triangles.len() - welded.triangles.len(),
    };
    Ok(ImportedMesh {
        vertices: welded.vertices.iter().map(|&v| v * scale).collect(),
        triangles: welded.triangles,
        info,
    })
}

/// Vertices and triangles as the file has them, before welding.
struct Soup {
    vertices: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
}

fn parse_stl(bytes: &[u8]) -> Result<Soup, String> {
    // `stl_io` takes a file for ASCII when it starts with "solid ". Some exporters begin binary
    // files with "solid" too, and some ASCII files have "solid" alone on the first line; a file
    // whose size is exactly that of the binary layout its triangle count announces is binary.
    let binary_size = |b: &[u8]| {
        b.len() >= 84 && {
            let count = u32::from_le_bytes([b[80], b[81], b[82], b[83]]) as u64;
            b.len() as u64 == 84 + 50 * count
        }
    };
    let mut data = bytes.to_vec();
    if binary_size(bytes) {
        if data.starts_with(b"solid") {
            data[..5].copy_from_slice(b"SOLID"); // the 80-byte header is free text
        }
    } else if data.starts_with(b"solid") && matches!(data.get(5), Some(b'\n' | b'\r') | None) {
        data.insert(5, b' ');
    } else if !data.starts_with(b"solid ") {
        return Err(if data.len() < 84 {
            format!(
                "{} bytes: too short for a binary STL (84 bytes of header and count) and not \
                 ASCII (which starts with \"solid \")",
                data.len()
            )
        } else {
            let count = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
            format!(
                "not ASCII (which starts with \"solid \"), and as binary its header announces \
                 {count} triangles, which take {} bytes, but the file has {}",
                84 + 50 * count,
                data.len()
            )
        });
    }
    let mut cursor = Cursor::new(data);
    let reader = stl_io::create_stl_reader(&mut cursor).map_err(|e| e.to_string())?;
    let mut soup = Soup {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    for (n, triangle) in reader.enumerate() {
        let triangle = triangle.map_err(|e| format!("facet {}: {e}", n + 1))?;
        let first = soup.vertices.len();
        soup.vertices.extend(
            triangle
                .vertices
                .iter()
                .map(|v| DVec3::new(v.0[0].into(), v.0[1].into(), v.0[2].into())),
        );
        soup.triangles.push([first, first + 1, first + 2]);
    }
    Ok(soup)
}

fn parse_obj(bytes: &[u8]) -> Result<Soup, String> {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = BufReader::new(bytes);
    // Materials are of no use to a particle: material libraries are not opened.
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| e.to_string())?;
    let mut soup = Soup {
        vertices: Vec::new(),
        triangles: Vec::new(),
    };
    for model in &models {
        let mesh = &model.mesh;
        let first = soup.vertices.len();
        soup.vertices.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| DVec3::new(p[0], p[1], p[2])),
        );
        for t in mesh.indices.chunks_exact(3) {
            soup.triangles
                .push([0, 1, 2].map(|k| first + t[k] as usize));
        }
    }
    Ok(soup)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ascii_tetrahedron(first_line: &str) -> String {
        let p = ["0 0 0", "1 0 0", "0 1 0", "0 0 1"];
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let mut s = format!("{first_line}\n");
        for f in faces {
            s += "facet normal 0 0 0\nouter loop\n";
            for i in f {
                s += &format!("vertex {}\n", p[i]);
            }
            s += "endloop\nendfacet\n";
        }
        s + "endsolid t\n"
    }

    #[test]
    fn extension_picks_the_format_case_insensitively() {
        assert_eq!(
            MeshFormat::from_path(Path::new("a/b.STL")),
            Some(MeshFormat::Stl)
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("b.Obj")),
            Some(MeshFormat::Obj)
        );
        assert_eq!(MeshFormat::from_path(Path::new("b.ply")), None);
        assert_eq!(MeshFormat::from_path(Path::new("stl")), None);
    }

    #[test]
    fn ascii_stl_with_bare_solid_line_is_read() {
        for first in ["solid t", "solid"] {
            let m = parse_mesh(
                ascii_tetrahedron(first).as_bytes(),
                MeshFormat::Stl,
                Path::new("t.stl"),
                2.0,
            )
            .unwrap();
            assert_eq!(m.vertices.len(), 4);
            assert_eq!(m.triangles.len(), 4);
            assert_eq!(m.info.file_vertices, 12);
            assert_eq!(m.info.welded, 8);
            assert_eq!(m.info.near_duplicates, 0);
            assert!(m.vertices.contains(&DVec3::new(0.0, 0.0, 2.0)));
        }
    }

    #[test]
    fn binary_stl_whose_header_starts_with_solid_is_read() {
        let text = ascii_tetrahedron("solid t");
        let ascii = parse_mesh(text.as_bytes(), MeshFormat::Stl, Path::new("t.stl"), 1.0).unwrap();
        let mut bytes = b"solid exported by a CAD tool".to_vec();
        bytes.resize(80, b' ');
        bytes.extend_from_slice(&(ascii.triangles.len() as u32).to_le_bytes());
        for t in &ascii.triangles {
            bytes.extend_from_slice(&[0u8; 12]);
            for &i in t {
                for c in ascii.vertices[i].to_array() {
                    bytes.extend_from_slice(&(c as f32).to_le_bytes());
                }
            }
            bytes.extend_from_slice(&[0, 0]);
        }
        let binary = parse_mesh(&bytes, MeshFormat::Stl, Path::new("t.stl"), 1.0).unwrap();
        assert_eq!(binary.vertices, ascii.vertices);
        assert_eq!(binary.triangles, ascii.triangles);
    }

    #[test]
    fn non_finite_and_bad_scale_are_refused() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n";
        let e = parse_mesh(obj.as_bytes(), MeshFormat::Obj, Path::new("m.obj"), 1.0).unwrap_err();
        assert!(matches!(e, MeshError::NonFinite { .. }), "{e}");
        assert!(e.to_string().contains("m.obj"), "{e}");
        let e = parse_mesh(obj.as_bytes(), MeshFormat::Obj, Path::new("m.obj"), 0.0).unwrap_err();
        assert!(e.to_string().contains("scale = 0"), "{e}");
        let e = parse_mesh(b"", MeshFormat::Obj, Path::new("m.obj"), 1.0).unwrap_err();
        assert!(matches!(e, MeshError::Empty { .. }), "{e}");
    }
}
