//! Reading back what `vtk` writes: `.pvd` collections and `.vtp` PolyData files with one
//! `<AppendedData encoding="raw">` block (UInt64 block headers, little endian), for `polydem
//! render`.
//!
//! This is a reader for our own output, not for VTK files in general: compressed, base64 or
//! big-endian files are refused with a message saying so. Everything read from the file is checked
//! (array lengths against the piece's counts, block bounds, cell indices), so a truncated or
//! hand-edited file gives an error naming the file and what is wrong, never a panic.

use std::path::{Path, PathBuf};

use glam::DVec3;

/// What went wrong, and in which file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct VtkReadError {
    pub path: PathBuf,
    pub message: String,
}

fn error(path: &Path, message: impl Into<String>) -> VtkReadError {
    VtkReadError {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// One data set of a `.pvd` collection.
#[derive(Debug, Clone, PartialEq)]
pub struct PvdEntry {
    pub time: f64,
    /// The file, resolved against the `.pvd`'s folder.
    pub file: PathBuf,
}

/// Reads a `.pvd` collection: its data sets in file order.
pub fn read_pvd(path: &Path) -> Result<Vec<PvdEntry>, VtkReadError> {
    let text = std::fs::read_to_string(path).map_err(|e| error(path, e.to_string()))?;
    let doc = roxmltree::Document::parse(&text)
        .map_err(|e| error(path, format!("not a well-formed .pvd collection: {e}")))?;
    let root = doc.root_element();
    if root.attribute("type") != Some("Collection") {
        return Err(error(
            path,
            "not a .pvd collection (VTKFile type is not \"Collection\")",
        ));
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut entries = Vec::new();
    for node in root.descendants().filter(|n| n.has_tag_name("DataSet")) {
        let line = doc.text_pos_at(node.range().start).row;
        let (Some(time), Some(file)) = (node.attribute("timestep"), node.attribute("file")) else {
            return Err(error(
                path,
                format!("line {line}: DataSet without timestep or file"),
            ));
        };
        let time: f64 = time.parse().map_err(|_| {
            error(
                path,
                format!("line {line}: timestep \"{time}\" is not a number"),
            )
        })?;
        entries.push(PvdEntry {
            time,
            file: folder.join(file),
        });
    }
    Ok(entries)
}

/// A named array of point or cell data, every component widened to `f64` (ids and material
/// indices are far below 2^53, so they come back exact).
#[derive(Debug, Clone, PartialEq)]
pub struct DataArray {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
}

impl DataArray {
    /// Number of tuples (points or cells).
    pub fn len(&self) -> usize {
        self.values.len() / self.components.max(1)
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The components of tuple `i`.
    pub fn tuple(&self, i: usize) -> &[f64] {
        &self.values[i * self.components..(i + 1) * self.components]
    }

    /// One number per tuple: the value of a scalar, the length of a vector.
    pub fn magnitudes(&self) -> Vec<f64> {
        if self.components == 1 {
            return self.values.clone();
        }
        self.values
            .chunks_exact(self.components.max(1))
            .map(|c| c.iter().map(|x| x * x).sum::<f64>().sqrt())
            .collect()
    }
}

/// Cells of one kind (lines or polygons) as end offsets into a connectivity list.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellList {
    pub connectivity: Vec<u32>,
    /// End of each cell in `connectivity`.
    pub offsets: Vec<usize>,
}

impl CellList {
    pub fn len(&self) -> usize {
        self.offsets.len()
    }

    pub fn is_empty(&self) -> bool {
        self.offsets.is_empty()
    }

    /// The point indices of each cell, in order.
    pub fn iter(&self) -> impl Iterator<Item = &[u32]> {
        let starts = std::iter::once(0).chain(self.offsets.iter().copied());
        starts
            .zip(&self.offsets)
            .map(|(start, &end)| &self.connectivity[start..end])
    }
}

/// The contents of one `.vtp` file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PolyData {
    /// Field data `TIME`, when present.
    pub time: Option<f64>,
    /// Field data string [`crate::io::vtk::FRAME_STATE`] of a frame off the output times (the
    /// state at a blow-up or an interrupt), when present.
    pub state: Option<String>,
    pub points: Vec<DVec3>,
    pub point_data: Vec<DataArray>,
    /// One tuple per cell, vertex cells first, then lines, then polygons (VTK's order).
    pub cell_data: Vec<DataArray>,
    pub num_verts: usize,
    pub lines: CellList,
    pub polys: CellList,
}

impl PolyData {
    pub fn point_array(&self, name: &str) -> Option<&DataArray> {
        self.point_data.iter().find(|a| a.name == name)
    }

    pub fn cell_array(&self, name: &str) -> Option<&DataArray> {
        self.cell_data.iter().find(|a| a.name == name)
    }

    /// The names of the point data arrays, for messages listing what there is.
    pub fn point_array_names(&self) -> Vec<&str> {
        self.point_data.iter().map(|a| a.name.as_str()).collect()
    }
}

/// Reads a `.vtp` file written by `vtk::write_particles`, `write_polygons` or
/// `write_force_network`.
pub fn read_vtp(path: &Path) -> Result<PolyData, VtkReadError> {
    let bytes = std::fs::read(path).map_err(|e| error(path, e.to_string()))?;
    parse_vtp(&bytes).map_err(|message| error(path, message))
}

/// The header is XML but the appended block is raw bytes, so the two are split at the block's
/// `_` marker: the XML before it (closed by hand) goes to the parser, the bytes after it are the
/// data whose offsets the header names.
fn parse_vtp(bytes: &[u8]) -> Result<PolyData, String> {
    const TAG: &[u8] = b"<AppendedData";
    let tag_start = find(bytes, TAG)
        .ok_or("no <AppendedData> block: not a .vtp file written by polydem (or cut short)")?;
    let tag_end = tag_start
        + find(&bytes[tag_start..], b">").ok_or("the <AppendedData> tag is not closed")?;
    let tag = String::from_utf8_lossy(&bytes[tag_start..tag_end]);
    if !tag.contains(r#"encoding="raw""#) {
        return Err(format!(
            "only raw appended data can be read, found {tag}>; write the file with polydem"
        ));
    }
    let marker = tag_end
        + find(&bytes[tag_end..], b"_").ok_or("the appended data has no '_' start marker")?;
    let data = &bytes[marker + 1..];
    let header = std::str::from_utf8(&bytes[..tag_start])
        .map_err(|_| "the XML header is not UTF-8 text".to_string())?;
    let xml = format!("{header}</VTKFile>");
    let doc = roxmltree::Document::parse(&xml)
        .map_err(|e| format!("the XML header is not well-formed: {e}"))?;
    let root = doc.root_element();
    let expect = |name: &str, want: &str| match root.attribute(name) {
        Some(v) if v == want => Ok(()),
        Some(v) => Err(format!(
            "VTKFile {name}=\"{v}\" but only {name}=\"{want}\" can be read"
        )),
        None => Err(format!("VTKFile has no {name} attribute")),
    };
    expect("type", "PolyData")?;
    expect("byte_order", "LittleEndian")?;
    expect("header_type", "UInt64")?;
    if let Some(c) = root.attribute("compressor") {
        return Err(format!("compressed files ({c}) cannot be read"));
    }

    let piece = root
        .descendants()
        .find(|n| n.has_tag_name("Piece"))
        .ok_or("no <Piece> element")?;
    let count = |name: &str| -> Result<usize, String> {
        piece.attribute(name).map_or(Ok(0), |v| {
            v.parse()
                .map_err(|_| format!("Piece {name}=\"{v}\" is not a count"))
        })
    };
    let num_points = count("NumberOfPoints")?;
    let num_verts = count("NumberOfVerts")?;
    let num_lines = count("NumberOfLines")?;
    let num_strips = count("NumberOfStrips")?;
    let num_polys = count("NumberOfPolys")?;
    if num_strips > 0 {
        return Err("triangle strips cannot be read".into());
    }
    let num_cells = num_verts
        .checked_add(num_lines)
        .and_then(|n| n.checked_add(num_polys))
        .ok_or("the piece's cell counts are too large")?;

    let section = |name: &str| piece.children().find(|n| n.has_tag_name(name));
    let arrays_in =
        |node: Option<roxmltree::Node>, tuples: usize| -> Result<Vec<DataArray>, String> {
            let Some(node) = node else {
                return Ok(Vec::new());
            };
            node.children()
                .filter(|n| n.has_tag_name("DataArray"))
                .map(|n| read_array(n, data, Some(tuples)))
                .collect()
        };
    let mut data_set = PolyData {
        point_data: arrays_in(section("PointData"), num_points)?,
        cell_data: arrays_in(section("CellData"), num_cells)?,
        num_verts,
        ..PolyData::default()
    };

    let points = arrays_in(section("Points"), num_points)?;
    match points.first() {
        Some(p) if p.components == 3 => {
            data_set.points = p
                .values
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]))
                .collect();
        }
        Some(p) => return Err(format!("Points have {} components, not 3", p.components)),
        None if num_points == 0 => {}
        None => return Err("no Points array".into()),
    }
    // Read (and so checked) although a vertex cell per point tells nothing more.
    read_cells(section("Verts"), data, "Verts", num_verts, num_points)?;
    data_set.lines = read_cells(section("Lines"), data, "Lines", num_lines, num_points)?;
    data_set.polys = read_cells(section("Polys"), data, "Polys", num_polys, num_points)?;

    if let Some(field) = root
        .descendants()
        .find(|n| n.has_tag_name("FieldData"))
        .and_then(|f| {
            f.children()
                .find(|n| n.has_tag_name("DataArray") && n.attribute("Name") == Some("TIME"))
        })
    {
        let time = read_array(field, data, None)?;
        data_set.time = time.values.first().copied();
    }
    if let Some(field) = root
        .descendants()
        .find(|n| n.has_tag_name("FieldData"))
        .and_then(|f| {
            f.children().find(|n| {
                n.has_tag_name("DataArray")
                    && n.attribute("Name") == Some(crate::io::vtk::FRAME_STATE)
            })
        })
    {
        data_set.state = Some(read_text(field, data)?);
    }
    Ok(data_set)
}

/// Reads an appended `String` array of one tuple (its bytes, ended by a 0).
fn read_text(node: roxmltree::Node, data: &[u8]) -> Result<String, String> {
    let name = node.attribute("Name").unwrap_or("(unnamed)");
    if node.attribute("type") != Some("String") || node.attribute("format") != Some("appended") {
        return Err(format!(
            "field data \"{name}\" is not an appended String array"
        ));
    }
    let offset: usize = node
        .attribute("offset")
        .and_then(|o| o.parse().ok())
        .ok_or_else(|| format!("DataArray \"{name}\" has a bad offset"))?;
    let cut_short =
        || format!("the data of array \"{name}\" runs past the end of the file (file cut short?)");
    let length_end = offset.checked_add(8).ok_or_else(cut_short)?;
    let length = data.get(offset..length_end).ok_or_else(cut_short)?;
    let length = u64::from_le_bytes(length.try_into().expect("8 bytes")) as usize;
    let end = length_end.checked_add(length).ok_or_else(cut_short)?;
    let block = data.get(length_end..end).ok_or_else(cut_short)?;
    let text = block.strip_suffix(&[0]).unwrap_or(block);
    String::from_utf8(text.to_vec()).map_err(|_| format!("string \"{name}\" is not UTF-8"))
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// Reads one appended DataArray; `tuples` is the count the piece promises (None for field data).
fn read_array(
    node: roxmltree::Node,
    data: &[u8],
    tuples: Option<usize>,
) -> Result<DataArray, String> {
    let name = node.attribute("Name").unwrap_or("(unnamed)").to_string();
    let attribute = |key: &str| {
        node.attribute(key)
            .ok_or_else(|| format!("DataArray \"{name}\" has no {key} attribute"))
    };
    if attribute("format")? != "appended" {
        return Err(format!(
            "DataArray \"{name}\" is not in the appended block (format=\"{}\")",
            attribute("format")?
        ));
    }
    let components: usize = match node.attribute("NumberOfComponents") {
        None => 1,
        Some(c) => c
            .parse()
            .ok()
            .filter(|&c| c > 0)
            .ok_or_else(|| format!("DataArray \"{name}\" has NumberOfComponents=\"{c}\""))?,
    };
    let offset: usize = attribute("offset")?
        .parse()
        .map_err(|_| format!("DataArray \"{name}\" has a bad offset"))?;
    let ty = attribute("type")?;
    let size = match ty {
        "Float64" | "Int64" | "UInt64" => 8,
        "Float32" | "Int32" | "UInt32" => 4,
        "Int16" | "UInt16" => 2,
        "Int8" | "UInt8" => 1,
        other => return Err(format!("DataArray \"{name}\" has unknown type {other}")),
    };
    let cut_short =
        || format!("the data of array \"{name}\" runs past the end of the file (file cut short?)");
    let length_end = offset.checked_add(8).ok_or_else(cut_short)?;
    let length = data.get(offset..length_end).ok_or_else(cut_short)?;
    let length = u64::from_le_bytes(length.try_into().expect("8 bytes")) as usize;
    let end = length_end.checked_add(length).ok_or_else(cut_short)?;
    let block = data.get(length_end..end).ok_or_else(cut_short)?;
    if !length.is_multiple_of(size) {
        return Err(format!(
            "array \"{name}\" has {length} bytes, not a whole number of {ty} values"
        ));
    }
    let values: Vec<f64> = block
        .chunks_exact(size)
        .map(|c| match ty {
            "Float64" => f64::from_le_bytes(c.try_into().expect("8 bytes")),
            "Int64" => i64::from_le_bytes(c.try_into().expect("8 bytes")) as f64,
            "UInt64" => u64::from_le_bytes(c.try_into().expect("8 bytes")) as f64,
            "Float32" => f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes"))),
            "Int32" => f64::from(i32::from_le_bytes(c.try_into().expect("4 bytes"))),
            "UInt32" => f64::from(u32::from_le_bytes(c.try_into().expect("4 bytes"))),
            "Int16" => f64::from(i16::from_le_bytes(c.try_into().expect("2 bytes"))),
            "UInt16" => f64::from(u16::from_le_bytes(c.try_into().expect("2 bytes"))),
            "Int8" => f64::from(c[0] as i8),
            _ => f64::from(c[0]),
        })
        .collect();
    if let Some(tuples) = tuples {
        if Some(values.len()) != tuples.checked_mul(components) {
            return Err(format!(
                "array \"{name}\" has {} values but the piece needs {tuples} × {components}",
                values.len()
            ));
        }
    }
    Ok(DataArray {
        name,
        components,
        values,
    })
}

/// Reads a cell section (`Lines`, `Polys`): connectivity and end offsets, checked.
fn read_cells(
    node: Option<roxmltree::Node>,
    data: &[u8],
    tag: &str,
    count: usize,
    num_points: usize,
) -> Result<CellList, String> {
    let Some(node) = node else {
        return if count == 0 {
            Ok(CellList::default())
        } else {
            Err(format!(
                "the piece has {count} {tag} but no <{tag}> section"
            ))
        };
    };
    let array = |name: &str| {
        node.children()
            .find(|n| n.has_tag_name("DataArray") && n.attribute("Name") == Some(name))
            .ok_or_else(|| format!("<{tag}> has no {name} array"))
            .and_then(|n| read_array(n, data, None))
    };
    let connectivity = array("connectivity")?.values;
    let offsets = array("offsets")?.values;
    if offsets.len() != count {
        return Err(format!(
            "<{tag}> has {} offsets but the piece has {count} cells",
            offsets.len()
        ));
    }
    let mut previous = 0usize;
    let mut ends = Vec::with_capacity(count);
    for &end in &offsets {
        let end_index = end as usize;
        if end < 0.0 || end_index < previous || end_index > connectivity.len() {
            return Err(format!(
                "<{tag}> offsets are not increasing within the connectivity"
            ));
        }
        ends.push(end_index);
        previous = end_index;
    }
    let mut points = Vec::with_capacity(connectivity.len());
    for &p in &connectivity {
        if p < 0.0 || p as usize >= num_points {
            return Err(format!(
                "<{tag}> refers to point {p} but the piece has {num_points} points"
            ));
        }
        points.push(p as u32);
    }
    Ok(CellList {
        connectivity: points,
        offsets: ends,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::vtk::{write_force_network, BodyFields, ForceNetwork};
    use crate::io::{write_particles, write_polygons, ParticleFrame, PolygonMesh, PvdSeries};
    use glam::DQuat;

    fn particles(path: &Path) {
        let frame = ParticleFrame {
            ids: &[7, 9],
            positions: &[DVec3::new(1.0, 2.0, 3.0), DVec3::new(-1.0, 0.5, 0.0)],
            radii: &[0.5, 0.25],
            orientations: &[DQuat::IDENTITY, DQuat::from_rotation_z(1.0)],
            fields: BodyFields {
                velocities: &[DVec3::new(3.0, 4.0, 0.0), DVec3::ZERO],
                speeds: &[5.0, 0.0],
                angular_velocities: &[DVec3::ZERO, DVec3::X],
                forces: &[DVec3::ZERO, DVec3::Z],
                torques: &[DVec3::ZERO; 2],
                coordination: &[2, 0],
                wall_contacts: &[0, 1],
                materials: &[1, 0],
                shapes: &[0, 3],
            },
        };
        write_particles(path, &frame, 0.125).unwrap();
    }

    #[test]
    fn particles_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.vtp");
        particles(&path);
        let data = read_vtp(&path).unwrap();
        assert_eq!(data.time, Some(0.125));
        assert_eq!(data.points[0], DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(data.num_verts, 2);
        assert_eq!(data.point_array("id").unwrap().values, [7.0, 9.0]);
        assert_eq!(data.point_array("radius").unwrap().values, [0.5, 0.25]);
        let v = data.point_array("velocity").unwrap();
        assert_eq!(v.components, 3);
        assert_eq!(v.magnitudes(), [5.0, 0.0]);
        assert_eq!(data.point_array("material").unwrap().values, [1.0, 0.0]);
        let q = data.point_array("orientation").unwrap();
        assert_eq!(q.tuple(0), [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(
            data.point_array_names()[..4],
            ["id", "radius", "orientation", "velocity"]
        );
    }

    #[test]
    fn polygons_and_lines_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = PolygonMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ONE],
            polygons: vec![vec![0, 1, 2], vec![1, 3, 2, 0]],
            cell_ids: vec![4, 5],
        };
        let path = dir.path().join("w.vtp");
        write_polygons(&path, &mesh, "wall", 2.0).unwrap();
        let data = read_vtp(&path).unwrap();
        let polys: Vec<&[u32]> = data.polys.iter().collect();
        assert_eq!(polys, [&[0, 1, 2][..], &[1, 3, 2, 0][..]]);
        assert_eq!(data.cell_array("wall").unwrap().values, [4.0, 5.0]);

        let network = ForceNetwork {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            lines: vec![vec![0, 1], vec![1, 2, 0]],
            normal_force: vec![1.5, 2.5],
            force: vec![DVec3::X, DVec3::Y],
            wall_contact: vec![0, 1],
        };
        let path = dir.path().join("c.vtp");
        write_force_network(&path, &network, 2.0).unwrap();
        let data = read_vtp(&path).unwrap();
        let lines: Vec<&[u32]> = data.lines.iter().collect();
        assert_eq!(lines, [&[0, 1][..], &[1, 2, 0][..]]);
        assert_eq!(data.cell_array("normal_force").unwrap().values, [1.5, 2.5]);
    }

    #[test]
    fn pvd_entries_resolve_against_its_folder() {
        let dir = tempfile::tempdir().unwrap();
        let mut series = PvdSeries::new(dir.path().join("s.pvd"));
        series.add(0.0, "a_0.vtp", 0).unwrap();
        series.add(0.5, "a_1.vtp", 0).unwrap();
        let entries = read_pvd(series.path()).unwrap();
        assert_eq!(entries.len(), 2);
        assert_eq!(entries[1].time, 0.5);
        assert_eq!(entries[1].file, dir.path().join("a_1.vtp"));
    }

    /// Every way of breaking a good file gives an error naming it, never a panic.
    #[test]
    fn broken_files_give_errors_naming_them() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.vtp");
        particles(&good);
        let bytes = std::fs::read(&good).unwrap();
        let text = String::from_utf8_lossy(&bytes).to_string();
        let header_end = text.find("<AppendedData").unwrap();
        let mut cases: Vec<(&str, Vec<u8>)> = vec![
            ("empty", Vec::new()),
            ("cut short", bytes[..bytes.len() - 60].to_vec()),
            ("header only", bytes[..header_end].to_vec()),
            (
                "not xml",
                b"hello <AppendedData encoding=\"raw\">_".to_vec(),
            ),
        ];
        let replace = |from: &str, to: &str| {
            let at = find(&bytes, from.as_bytes()).unwrap();
            let mut b = bytes[..at].to_vec();
            b.extend_from_slice(to.as_bytes());
            b.extend_from_slice(&bytes[at + from.len()..]);
            b
        };
        cases.push(("big endian", replace("LittleEndian", "BigEndian")));
        cases.push((
            "wrong count",
            replace("NumberOfPoints=\"2\"", "NumberOfPoints=\"3\""),
        ));
        cases.push(("bad offset", replace("offset=\"0\"", "offset=\"99999\"")));
        cases.push(("bad type", replace("type=\"Float64\"", "type=\"Float99\"")));
        // Prefixes of the file (the classic truncation of a killed copy) that end before the
        // data does.
        for cut in (0..bytes.len() - 40).step_by(97) {
            cases.push(("prefix", bytes[..cut].to_vec()));
        }
        for (what, content) in cases {
            let path = dir.path().join("broken.vtp");
            std::fs::write(&path, &content).unwrap();
            let err = read_vtp(&path).expect_err(what);
            assert_eq!(err.path, path, "{what}");
            assert!(err.to_string().contains("broken.vtp"), "{what}: {err}");
        }
        // Any single byte of the header changed to any of a few troublesome ones: an error or
        // a file that still reads, never a panic.
        for at in 0..header_end {
            for byte in [b'9', b'0', b'"', b'<', b'_', 0xff] {
                let mut b = bytes.clone();
                b[at] = byte;
                let _ = parse_vtp(&b);
            }
        }
        let err = read_vtp(&dir.path().join("missing.vtp")).unwrap_err();
        assert!(err.to_string().contains("missing.vtp"), "{err}");
        let pvd = dir.path().join("broken.pvd");
        std::fs::write(
            &pvd,
            "<VTKFile type=\"Collection\"><Collection><DataSet timestep=\"x\" file=\"a\"/>",
        )
        .unwrap();
        let err = read_pvd(&pvd).unwrap_err();
        assert!(err.to_string().contains("broken.pvd"), "{err}");
    }
}
