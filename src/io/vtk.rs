//! VTK XML PolyData (`.vtp`) snapshots and `.pvd` time-series collections,
//! the formats ParaView opens directly.
//!
//! Data goes into one `<AppendedData encoding="raw">` block after the XML
//! header: binary Float64 keeps positions bit-exact (restart-quality) and is
//! far smaller and faster than ASCII. Each array block is a little-endian
//! UInt64 byte count followed by the little-endian values, which is what
//! `header_type="UInt64" byte_order="LittleEndian"` promises the reader. Bytes
//! are encoded explicitly with `to_le_bytes`, so output is identical on any
//! host. Arrays are streamed from the caller's slices into the buffered file
//! rather than assembled in memory first.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use glam::{DQuat, DVec3};

use super::{atomic::write_atomic, format_f64, invalid_input};

/// The name of the field-data string of a frame that is not one of the regular output times:
/// `"blow-up: …"` (the state at which the watchdog stopped the run, with its reason) or
/// `"interrupted: …"` (the state at which Ctrl-C or SIGTERM stopped it). Regular frames have no
/// such array. ParaView shows it in the Information panel's data arrays and in the spreadsheet
/// view's field data.
pub const FRAME_STATE: &str = "polydem_state";

/// What is written of every body, particle points and polyhedra faces alike, as parallel slices
/// (one entry per point or face), borrowed so that writing never copies the simulation state.
#[derive(Debug, Clone, Copy)]
pub struct BodyFields<'a> {
    pub velocities: &'a [DVec3],
    pub speeds: &'a [f64],
    pub angular_velocities: &'a [DVec3],
    /// Sum of the contact forces on the body [N] (gravity not included).
    pub forces: &'a [DVec3],
    /// Sum of the contact torques about the body's centre [N m].
    pub torques: &'a [DVec3],
    /// Other bodies touching it (a body touching in several places counts once).
    pub coordination: &'a [u32],
    /// Walls (planes and mesh walls) touching it.
    pub wall_contacts: &'a [u32],
    /// Material indices, for colouring by material (names in `legend.csv`).
    pub materials: &'a [u32],
    /// Shape indices (names in `legend.csv`).
    pub shapes: &'a [u32],
}

impl<'a> BodyFields<'a> {
    fn lengths(&self) -> [(&'static str, usize); 9] {
        [
            ("velocities", self.velocities.len()),
            ("speeds", self.speeds.len()),
            ("angular_velocities", self.angular_velocities.len()),
            ("forces", self.forces.len()),
            ("torques", self.torques.len()),
            ("coordination", self.coordination.len()),
            ("wall_contacts", self.wall_contacts.len()),
            ("materials", self.materials.len()),
            ("shapes", self.shapes.len()),
        ]
    }

    fn arrays(&self) -> Vec<Array<'a>> {
        vec![
            Array::new("velocity", Values::Vec3(self.velocities)),
            Array::new("speed", Values::F64(self.speeds)),
            Array::new("angular_velocity", Values::Vec3(self.angular_velocities)),
            Array::new("force", Values::Vec3(self.forces)),
            Array::new("torque", Values::Vec3(self.torques)),
            Array::new("coordination", Values::U32(self.coordination)),
            Array::new("wall_contacts", Values::U32(self.wall_contacts)),
            Array::new("material", Values::U32(self.materials)),
            Array::new("shape", Values::U32(self.shapes)),
        ]
    }
}

/// Every slice of `lengths` has `n` entries, else `InvalidInput` naming the first that differs.
fn check_lengths(what: &str, n: usize, lengths: &[(&str, usize)]) -> io::Result<()> {
    match lengths.iter().find(|(_, len)| *len != n) {
        Some((name, len)) => Err(invalid_input(format!(
            "{what} has {n} entries but {len} {name}"
        ))),
        None => Ok(()),
    }
}

/// One snapshot of the bodies as points (one per body, spheres and polyhedra alike).
#[derive(Debug, Clone, Copy)]
pub struct ParticleFrame<'a> {
    /// Stable body identities, to follow a body across frames.
    pub ids: &'a [u64],
    pub positions: &'a [DVec3],
    /// Bounding radius (a sphere's radius).
    pub radii: &'a [f64],
    /// Written as 4 components in the order w, x, y, z.
    pub orientations: &'a [DQuat],
    pub fields: BodyFields<'a>,
}

impl ParticleFrame<'_> {
    /// Number of particles, after checking that all slices agree on it.
    fn checked_len(&self) -> io::Result<usize> {
        let n = self.ids.len();
        let own = [
            ("positions", self.positions.len()),
            ("radii", self.radii.len()),
            ("orientations", self.orientations.len()),
        ];
        check_lengths("particle frame", n, &own)?;
        check_lengths("particle frame", n, &self.fields.lengths())?;
        Ok(n)
    }
}

/// Writes particles as a `.vtp` file: one point per particle, one vertex cell
/// per point (so ParaView renders them without a filter).
///
/// The point data names `radius` as active scalars and `velocity` as active
/// vectors, so ParaView's Glyph filter (Sphere, Scale Array = radius, Scale
/// Factor 2 because its unit sphere has radius 0.5) draws the true particle
/// sizes. The simulation `time` is stored as field data array `TIME`.
///
/// Returns `InvalidInput` if the frame's slices differ in length.
pub fn write_particles(path: &Path, frame: &ParticleFrame, time: f64) -> io::Result<()> {
    write_particles_marked(path, frame, time, None)
}

/// [`write_particles`], with field data [`FRAME_STATE`] saying what is special about the frame.
pub fn write_particles_marked(
    path: &Path,
    frame: &ParticleFrame,
    time: f64,
    state: Option<&str>,
) -> io::Result<()> {
    let n = frame.checked_len()?;
    let mut point_data = vec![
        Array::new("id", Values::U64(frame.ids)),
        Array::new("radius", Values::F64(frame.radii)),
        Array::new("orientation", Values::Quat(frame.orientations))
            .with_component_names(&["w", "x", "y", "z"]),
    ];
    point_data.extend(frame.fields.arrays());
    let file = PolyDataFile {
        time,
        num_points: n,
        points: Values::Vec3(frame.positions),
        point_data,
        point_attributes: r#" Scalars="radius" Vectors="velocity""#,
        cells: Cells::Verts(n),
        cell_data: Vec::new(),
        state,
    };
    write_atomic(path, |w| file.write_to(w))
}

/// Writes the faces of polyhedral bodies as a `.vtp` file of polygon cells, each with its body's
/// `id` and `fields` as cell data (so faces can be coloured by speed, force, … directly).
///
/// Returns `InvalidInput` if `fields` and `body_ids` do not have one entry per polygon or a
/// polygon refers to a vertex that does not exist.
pub fn write_body_surfaces(
    path: &Path,
    mesh: &PolygonMesh,
    fields: &BodyFields,
    time: f64,
) -> io::Result<()> {
    write_body_surfaces_marked(path, mesh, fields, time, None)
}

/// [`write_body_surfaces`], with field data [`FRAME_STATE`].
pub fn write_body_surfaces_marked(
    path: &Path,
    mesh: &PolygonMesh,
    fields: &BodyFields,
    time: f64,
    state: Option<&str>,
) -> io::Result<()> {
    check_lengths("body surface", mesh.polygons.len(), &fields.lengths())?;
    check_polygons(mesh)?;
    let mut cell_data = vec![Array::new("id", Values::U32(&mesh.cell_ids))];
    cell_data.extend(fields.arrays());
    let file = PolyDataFile {
        time,
        num_points: mesh.vertices.len(),
        points: Values::Vec3(&mesh.vertices),
        point_data: Vec::new(),
        point_attributes: "",
        cells: Cells::Polys(&mesh.polygons),
        cell_data,
        state,
    };
    write_atomic(path, |w| file.write_to(w))
}

/// A surface made of polygons, each with any number of vertices — walls now,
/// polyhedral particle surfaces later.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PolygonMesh {
    /// Written as the file's points.
    pub vertices: Vec<DVec3>,
    /// Indices into `vertices`, in the polygon's winding order.
    pub polygons: Vec<Vec<u32>>,
    /// One per polygon; written as cell data `wall` so ParaView can colour
    /// or threshold by the wall (or particle) each face belongs to.
    pub cell_ids: Vec<u32>,
}

/// Writes `mesh` as a `.vtp` file of polygon cells with cell data `wall`
/// (UInt32) and the simulation `time` as field data `TIME`.
///
/// Returns `InvalidInput` if `cell_ids` and `polygons` differ in length or a
/// polygon refers to a vertex that does not exist.
pub fn write_polygons(
    path: &Path,
    mesh: &PolygonMesh,
    id_name: &'static str,
    time: f64,
) -> io::Result<()> {
    write_polygons_marked(path, mesh, id_name, time, None)
}

/// [`write_polygons`], with field data [`FRAME_STATE`].
pub fn write_polygons_marked(
    path: &Path,
    mesh: &PolygonMesh,
    id_name: &'static str,
    time: f64,
    state: Option<&str>,
) -> io::Result<()> {
    check_polygons(mesh)?;
    let num_vertices = mesh.vertices.len();
    let file = PolyDataFile {
        time,
        num_points: num_vertices,
        points: Values::Vec3(&mesh.vertices),
        point_data: Vec::new(),
        point_attributes: "",
        cells: Cells::Polys(&mesh.polygons),
        cell_data: vec![Array::new(id_name, Values::U32(&mesh.cell_ids))],
        state,
    };
    write_atomic(path, |w| file.write_to(w))
}

/// One cell id per polygon, and every polygon's vertices in the mesh.
fn check_polygons(mesh: &PolygonMesh) -> io::Result<()> {
    if mesh.cell_ids.len() != mesh.polygons.len() {
        return Err(invalid_input(format!(
            "polygon mesh has {} polygons but {} cell ids",
            mesh.polygons.len(),
            mesh.cell_ids.len()
        )));
    }
    let num_vertices = mesh.vertices.len();
    for (p, polygon) in mesh.polygons.iter().enumerate() {
        if let Some(&bad) = polygon.iter().find(|&&v| v as usize >= num_vertices) {
            return Err(invalid_input(format!(
                "polygon {p} refers to vertex {bad} but the mesh has {num_vertices} vertices"
            )));
        }
    }
    Ok(())
}

/// Contact forces as lines between the centres of the bodies in contact (a body–wall contact
/// runs from the body's centre to the contact point), for ParaView's force-network views.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ForceNetwork {
    pub points: Vec<DVec3>,
    /// Indices into `points` per line: two (centre to centre, or to a wall's contact point), or
    /// three for one region of a pair that touches in several (centre, contact point, centre).
    pub lines: Vec<Vec<u32>>,
    /// Per line: normal force magnitude [N] (cell data `normal_force`).
    pub normal_force: Vec<f64>,
    /// Per line: total contact force on the first body [N] (cell data `force`).
    pub force: Vec<DVec3>,
    /// Per line: 0 for body–body, 1 for body–wall (cell data `wall_contact`).
    pub wall_contact: Vec<u32>,
}

/// Writes a force network as a `.vtp` file of line cells.
pub fn write_force_network(path: &Path, network: &ForceNetwork, time: f64) -> io::Result<()> {
    write_force_network_marked(path, network, time, None)
}

/// [`write_force_network`], with field data [`FRAME_STATE`].
pub fn write_force_network_marked(
    path: &Path,
    network: &ForceNetwork,
    time: f64,
    state: Option<&str>,
) -> io::Result<()> {
    let n = network.lines.len();
    if network.normal_force.len() != n
        || network.force.len() != n
        || network.wall_contact.len() != n
    {
        return Err(invalid_input("force network arrays differ in length"));
    }
    if let Some(bad) = network
        .lines
        .iter()
        .flatten()
        .find(|&&v| v as usize >= network.points.len())
    {
        return Err(invalid_input(format!(
            "force network line refers to point {bad} of {}",
            network.points.len()
        )));
    }
    let file = PolyDataFile {
        time,
        num_points: network.points.len(),
        points: Values::Vec3(&network.points),
        point_data: Vec::new(),
        point_attributes: "",
        cells: Cells::Lines(&network.lines),
        cell_data: vec![
            Array::new("normal_force", Values::F64(&network.normal_force)),
            Array::new("force", Values::Vec3(&network.force)),
            Array::new("wall_contact", Values::U32(&network.wall_contact)),
        ],
        state,
    };
    write_atomic(path, |w| file.write_to(w))
}

/// A `.pvd` collection indexing a time series of `.vtp` files, so ParaView
/// opens the whole run as one animated data set with true simulation times.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<PvdEntry>,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
struct PvdEntry {
    time: f64,
    file: String,
    part: u32,
    /// Written as an XML comment before the entry: what is special about this data set (the
    /// state at a blow-up, at an interrupt). Regular frames have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    note: Option<String>,
}

impl PvdSeries {
    /// Starts an empty collection; nothing is written until the first add.
    pub fn new(path: PathBuf) -> Self {
        Self {
            path,
            entries: Vec::new(),
        }
    }

    /// The same series, written into `dir` under the same file name.
    pub fn relocate(&mut self, dir: &Path) {
        if let Some(name) = self.path.file_name() {
            self.path = dir.join(name);
        }
    }

    /// Records that `file` (relative to the `.pvd`'s folder) holds `part` of
    /// the data at `time`, then rewrites the whole collection atomically so
    /// the series on disk is valid even if the run is killed right after.
    ///
    /// Returns `InvalidInput` for a non-finite time (it is not recorded). If
    /// writing fails the entry stays recorded and the next add writes it.
    pub fn add(&mut self, time: f64, file: &str, part: u32) -> io::Result<()> {
        self.add_noted(time, file, part, None)
    }

    /// [`PvdSeries::add`], with `note` written as an XML comment before the entry (ParaView
    /// ignores it; a reader of the file sees why the data set is there).
    pub fn add_noted(
        &mut self,
        time: f64,
        file: &str,
        part: u32,
        note: Option<&str>,
    ) -> io::Result<()> {
        if !time.is_finite() {
            return Err(invalid_input(format!(
                "pvd time step must be finite, got {time}"
            )));
        }
        self.entries.push(PvdEntry {
            time,
            file: file.to_string(),
            part,
            note: note.map(str::to_string),
        });
        write_atomic(&self.path, |w| self.write_to(w))
    }

    /// Writes the collection as recorded (a resumed run: the file may list data sets written
    /// after the checkpoint), or removes the file when nothing is recorded.
    pub fn rewrite(&self) -> io::Result<()> {
        if self.entries.is_empty() {
            return match std::fs::remove_file(&self.path) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => {
                    Err(super::atomic::naming(&self.path, e))
                }
                _ => Ok(()),
            };
        }
        write_atomic(&self.path, |w| self.write_to(w))
    }

    /// Where the collection is written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Number of data sets recorded so far.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing has been recorded yet.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    fn write_to(&self, w: &mut dyn Write) -> io::Result<()> {
        writeln!(w, r#"<?xml version="1.0"?>"#)?;
        writeln!(
            w,
            r#"<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">"#
        )?;
        writeln!(w, "  <Collection>")?;
        for e in &self.entries {
            if let Some(note) = &e.note {
                // "--" may not appear in an XML comment.
                writeln!(w, "    <!-- {} -->", note.replace("--", "- -"))?;
            }
            writeln!(
                w,
                r#"    <DataSet timestep="{}" group="" part="{}" file="{}"/>"#,
                format_f64(e.time),
                e.part,
                escape_xml(&e.file)
            )?;
        }
        writeln!(w, "  </Collection>")?;
        writeln!(w, "</VTKFile>")
    }
}

/// File names are user-controlled; `&`, `<` or quotes must not break the XML.
fn escape_xml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// The borrowed contents of one DataArray; knows its VTK type, component
/// count and how to stream itself as little-endian bytes.
#[derive(Debug, Clone, Copy)]
enum Values<'a> {
    U64(&'a [u64]),
    U32(&'a [u32]),
    F64(&'a [f64]),
    Vec3(&'a [DVec3]),
    Quat(&'a [DQuat]),
    /// Vertex cells `0..n`, one point each.
    VertConnectivity(usize),
    /// End offsets `1..=n` of the vertex cells.
    VertOffsets(usize),
    PolyConnectivity(&'a [Vec<u32>]),
    /// End offset of each polygon in the connectivity array.
    PolyOffsets(&'a [Vec<u32>]),
    /// One string (a VTK `String` array of one tuple: its bytes and a terminating 0).
    Text(&'a str),
}

impl Values<'_> {
    fn vtk_type(&self) -> &'static str {
        match self {
            Values::U64(_) => "UInt64",
            Values::U32(_) => "UInt32",
            Values::F64(_) | Values::Vec3(_) | Values::Quat(_) => "Float64",
            Values::Text(_) => "String",
            // vtkIdType is 64-bit in current VTK builds.
            Values::VertConnectivity(_)
            | Values::VertOffsets(_)
            | Values::PolyConnectivity(_)
            | Values::PolyOffsets(_) => "Int64",
        }
    }

    fn components(&self) -> usize {
        match self {
            Values::Vec3(_) => 3,
            Values::Quat(_) => 4,
            _ => 1,
        }
    }

    fn byte_len(&self) -> u64 {
        let count = match self {
            Values::U32(v) => return 4 * v.len() as u64,
            Values::Text(t) => return t.len() as u64 + 1,
            Values::U64(v) => v.len(),
            Values::F64(v) => v.len(),
            Values::Vec3(v) => 3 * v.len(),
            Values::Quat(v) => 4 * v.len(),
            Values::VertConnectivity(n) | Values::VertOffsets(n) => *n,
            Values::PolyConnectivity(p) => p.iter().map(Vec::len).sum(),
            Values::PolyOffsets(p) => p.len(),
        };
        8 * count as u64
    }

    /// Writes the block: UInt64 byte count, then the values.
    fn write_block(&self, w: &mut dyn Write) -> io::Result<()> {
        w.write_all(&self.byte_len().to_le_bytes())?;
        match *self {
            Values::U64(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::U32(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::Text(t) => {
                w.write_all(t.as_bytes())?;
                w.write_all(&[0])
            }
            Values::F64(v) => write_f64s(w, v.iter().copied()),
            Values::Vec3(v) => write_f64s(w, v.iter().flat_map(|p| p.to_array())),
            Values::Quat(v) => write_f64s(w, v.iter().flat_map(|q| [q.w, q.x, q.y, q.z])),
            Values::VertConnectivity(n) => write_i64s(w, (0..n).map(|i| i as i64)),
            Values::VertOffsets(n) => write_i64s(w, (1..=n).map(|i| i as i64)),
            Values::PolyConnectivity(p) => write_i64s(w, p.iter().flatten().map(|&i| i64::from(i))),
            Values::PolyOffsets(p) => write_i64s(
                w,
                p.iter().scan(0i64, |end, poly| {
                    *end += poly.len() as i64;
                    Some(*end)
                }),
            ),
        }
    }
}

fn write_f64s(w: &mut dyn Write, values: impl Iterator<Item = f64>) -> io::Result<()> {
    values
        .into_iter()
        .try_for_each(|x| w.write_all(&x.to_le_bytes()))
}

fn write_i64s(w: &mut dyn Write, values: impl Iterator<Item = i64>) -> io::Result<()> {
    values
        .into_iter()
        .try_for_each(|x| w.write_all(&x.to_le_bytes()))
}

/// A named DataArray.
struct Array<'a> {
    name: &'static str,
    values: Values<'a>,
    component_names: &'static [&'static str],
}

impl<'a> Array<'a> {
    fn new(name: &'static str, values: Values<'a>) -> Self {
        Self {
            name,
            values,
            component_names: &[],
        }
    }

    /// Labels shown in ParaView instead of "0", "1", … (e.g. quaternion w x y z).
    fn with_component_names(mut self, names: &'static [&'static str]) -> Self {
        self.component_names = names;
        self
    }
}

/// The cell topology of a piece.
enum Cells<'a> {
    Verts(usize),
    Lines(&'a [Vec<u32>]),
    Polys(&'a [Vec<u32>]),
}

/// Everything a single-piece `.vtp` file holds, borrowed from the caller.
struct PolyDataFile<'a> {
    time: f64,
    num_points: usize,
    points: Values<'a>,
    point_data: Vec<Array<'a>>,
    /// Extra attributes of `<PointData>` naming the active arrays.
    point_attributes: &'static str,
    cells: Cells<'a>,
    cell_data: Vec<Array<'a>>,
    /// What is special about this frame (see [`FRAME_STATE`]), if anything.
    state: Option<&'a str>,
}

impl PolyDataFile<'_> {
    fn write_to(&self, w: &mut dyn Write) -> io::Result<()> {
        let time = [self.time];
        let time_array = Array::new("TIME", Values::F64(&time));
        let points = Array::new("Points", self.points);
        let (tag, num_verts, num_lines, num_polys, connectivity, offsets) = match self.cells {
            Cells::Verts(n) => (
                "Verts",
                n,
                0,
                0,
                Values::VertConnectivity(n),
                Values::VertOffsets(n),
            ),
            Cells::Lines(l) => (
                "Lines",
                0,
                l.len(),
                0,
                Values::PolyConnectivity(l),
                Values::PolyOffsets(l),
            ),
            Cells::Polys(p) => (
                "Polys",
                0,
                0,
                p.len(),
                Values::PolyConnectivity(p),
                Values::PolyOffsets(p),
            ),
        };
        let connectivity = Array::new("connectivity", connectivity);
        let offsets = Array::new("offsets", offsets);

        // The appended blocks must follow the order of the DataArrays in the
        // header, since each header entry names its block's byte offset.
        let mut header = HeaderWriter {
            w: &mut *w,
            offset: 0,
            blocks: Vec::new(),
        };
        header.line(r#"<?xml version="1.0"?>"#)?;
        header.line(
            r#"<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#,
        )?;
        header.line("  <PolyData>")?;
        header.line("    <FieldData>")?;
        // Field data has no piece to take its length from.
        header.array("      ", &time_array, Some(1))?;
        if let Some(state) = self.state {
            let state = Array::new(FRAME_STATE, Values::Text(state));
            header.array("      ", &state, Some(1))?;
        }
        header.line("    </FieldData>")?;
        header.line(&format!(
            r#"    <Piece NumberOfPoints="{}" NumberOfVerts="{num_verts}" NumberOfLines="{num_lines}" NumberOfStrips="0" NumberOfPolys="{num_polys}">"#,
            self.num_points
        ))?;
        header.line(&format!("      <PointData{}>", self.point_attributes))?;
        for array in &self.point_data {
            header.array("        ", array, None)?;
        }
        header.line("      </PointData>")?;
        header.line("      <CellData>")?;
        for array in &self.cell_data {
            header.array("        ", array, None)?;
        }
        header.line("      </CellData>")?;
        header.line("      <Points>")?;
        header.array("        ", &points, None)?;
        header.line("      </Points>")?;
        header.line(&format!("      <{tag}>"))?;
        header.array("        ", &connectivity, None)?;
        header.array("        ", &offsets, None)?;
        header.line(&format!("      </{tag}>"))?;
        header.line("    </Piece>")?;
        header.line("  </PolyData>")?;
        let blocks = header.blocks;
        // The underscore marks the start of the raw bytes (offset 0).
        w.write_all(b"  <AppendedData encoding=\"raw\">\n   _")?;
        for values in blocks {
            values.write_block(w)?;
        }
        w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
    }
}

/// Writes the XML header while assigning each DataArray its offset into the
/// appended data, remembering the blocks to write afterwards in that order.
struct HeaderWriter<'w, 'a> {
    w: &'w mut dyn Write,
    offset: u64,
    blocks: Vec<Values<'a>>,
}

impl<'a> HeaderWriter<'_, 'a> {
    fn line(&mut self, text: &str) -> io::Result<()> {
        writeln!(self.w, "{text}")
    }

    fn array(&mut self, indent: &str, array: &Array<'a>, tuples: Option<usize>) -> io::Result<()> {
        let values = array.values;
        write!(
            self.w,
            r#"{indent}<DataArray type="{}" Name="{}""#,
            values.vtk_type(),
            array.name
        )?;
        if values.components() > 1 {
            write!(self.w, r#" NumberOfComponents="{}""#, values.components())?;
        }
        for (i, name) in array.component_names.iter().enumerate() {
            write!(self.w, r#" ComponentName{i}="{name}""#)?;
        }
        if let Some(tuples) = tuples {
            write!(self.w, r#" NumberOfTuples="{tuples}""#)?;
        }
        writeln!(self.w, r#" format="appended" offset="{}"/>"#, self.offset)?;
        self.offset += 8 + values.byte_len();
        self.blocks.push(values);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    //! Output is checked with an independent reader (an XML parser plus a
    //! decoder for the appended blocks written from the VTK file-format
    //! spec), not by comparing with stored bytes. The `vtkio` crate was tried
    //! first but cannot read `encoding="raw"` appended data.

    use super::*;
    use std::collections::HashMap;

    /// A decoded DataArray.
    #[derive(Debug, Clone, PartialEq)]
    enum Decoded {
        F64(Vec<f64>),
        U64(Vec<u64>),
        U32(Vec<u32>),
        I64(Vec<i64>),
    }

    #[derive(Debug)]
    struct ReadArray {
        components: usize,
        attributes: HashMap<String, String>,
        data: Decoded,
    }

    /// What the reader found, keyed by "Section/Name", e.g. "PointData/radius".
    #[derive(Debug)]
    struct ReadVtp {
        root: HashMap<String, String>,
        piece: HashMap<String, String>,
        point_data: HashMap<String, String>,
        arrays: HashMap<String, ReadArray>,
    }

    impl ReadVtp {
        fn f64s(&self, key: &str) -> &[f64] {
            match &self.arrays[key].data {
                Decoded::F64(v) => v,
                other => panic!("{key} is not Float64: {other:?}"),
            }
        }
        fn i64s(&self, key: &str) -> &[i64] {
            match &self.arrays[key].data {
                Decoded::I64(v) => v,
                other => panic!("{key} is not Int64: {other:?}"),
            }
        }
        fn u64s(&self, key: &str) -> &[u64] {
            match &self.arrays[key].data {
                Decoded::U64(v) => v,
                other => panic!("{key} is not UInt64: {other:?}"),
            }
        }
        fn u32s(&self, key: &str) -> &[u32] {
            match &self.arrays[key].data {
                Decoded::U32(v) => v,
                other => panic!("{key} is not UInt32: {other:?}"),
            }
        }
    }

    fn attrs(node: roxmltree::Node) -> HashMap<String, String> {
        node.attributes()
            .map(|a| (a.name().to_string(), a.value().to_string()))
            .collect()
    }

    fn find_subslice(haystack: &[u8], needle: &[u8]) -> usize {
        haystack
            .windows(needle.len())
            .position(|w| w == needle)
            .unwrap_or_else(|| panic!("{:?} not found", String::from_utf8_lossy(needle)))
    }

    /// Reads a `.vtp` with raw appended data and a UInt64 header, checking
    /// along the way that the blocks tile the appended section exactly and
    /// that the whole file (with the raw bytes cut out) is well-formed XML.
    fn read_vtp(path: &Path) -> ReadVtp {
        let bytes = std::fs::read(path).unwrap();
        let tag = b"<AppendedData encoding=\"raw\">";
        let appended_tag = find_subslice(&bytes, tag);
        let underscore = appended_tag + find_subslice(&bytes[appended_tag..], b"_");
        assert!(bytes[appended_tag + tag.len()..underscore]
            .iter()
            .all(u8::is_ascii_whitespace));
        let data = &bytes[underscore + 1..];

        let head = std::str::from_utf8(&bytes[..appended_tag]).unwrap();
        let head = format!("{head}</VTKFile>");
        let head_doc = roxmltree::Document::parse(&head).unwrap();
        let root = head_doc.root_element();

        // First pass: byte ranges of all blocks, to find the end of the data.
        let mut ranges = Vec::new();
        for node in root.descendants().filter(|n| n.has_tag_name("DataArray")) {
            assert_eq!(node.attribute("format"), Some("appended"));
            let offset: usize = node.attribute("offset").unwrap().parse().unwrap();
            let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
            ranges.push((offset, offset + 8 + len));
        }
        ranges.sort();
        let mut end = 0;
        for (start, stop) in &ranges {
            assert_eq!(*start, end, "appended blocks must be contiguous");
            end = *stop;
        }
        let mut full = bytes[..underscore + 1].to_vec();
        full.extend_from_slice(&data[end..]);
        let full = String::from_utf8(full).unwrap();
        roxmltree::Document::parse(&full).expect("file is well-formed XML");

        let mut arrays = HashMap::new();
        for node in root.descendants().filter(|n| n.has_tag_name("DataArray")) {
            let a = attrs(node);
            let offset: usize = a["offset"].parse().unwrap();
            let len = u64::from_le_bytes(data[offset..offset + 8].try_into().unwrap()) as usize;
            let block = &data[offset + 8..offset + 8 + len];
            let decoded = match a["type"].as_str() {
                "Float64" => Decoded::F64(
                    block
                        .chunks_exact(8)
                        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                        .collect(),
                ),
                "UInt64" => Decoded::U64(
                    block
                        .chunks_exact(8)
                        .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
                        .collect(),
                ),
                "Int64" => Decoded::I64(
                    block
                        .chunks_exact(8)
                        .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
                        .collect(),
                ),
                "UInt32" => Decoded::U32(
                    block
                        .chunks_exact(4)
                        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
                        .collect(),
                ),
                other => panic!("unexpected type {other}"),
            };
            let element = if a["type"] == "UInt32" { 4 } else { 8 };
            assert_eq!(len % element, 0);
            let components = a
                .get("NumberOfComponents")
                .map_or(1, |c| c.parse().unwrap());
            let section = node.parent_element().unwrap().tag_name().name();
            let key = format!("{section}/{}", a["Name"]);
            let array = ReadArray {
                components,
                attributes: a,
                data: decoded,
            };
            assert!(arrays.insert(key, array).is_none(), "duplicate array");
        }
        let piece = root
            .descendants()
            .find(|n| n.has_tag_name("Piece"))
            .unwrap();
        let point_data = piece
            .children()
            .find(|n| n.has_tag_name("PointData"))
            .unwrap();
        ReadVtp {
            root: attrs(root),
            piece: attrs(piece),
            point_data: attrs(point_data),
            arrays,
        }
    }

    fn flat3(v: &[DVec3]) -> Vec<f64> {
        v.iter().flat_map(|p| p.to_array()).collect()
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// Values chosen to expose any precision loss or byte-order mistake.
    fn awkward(i: usize) -> f64 {
        let i = i as f64;
        (0.1 + i) * std::f64::consts::PI * 10f64.powi((i as i32 % 7) - 3) - 1e-300
    }

    #[test]
    fn particles_round_trip_exactly() {
        let n = 5;
        let ids: Vec<u64> = (0..n as u64)
            .map(|i| i * 1_000_000_007 + u64::MAX / 3)
            .collect();
        let positions: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(awkward(i), -awkward(i + 1), awkward(i + 2)))
            .collect();
        let radii: Vec<f64> = (0..n).map(|i| 1e-3 * awkward(i).abs()).collect();
        let velocities: Vec<DVec3> = (0..n).map(|i| DVec3::splat(awkward(i + 3))).collect();
        let angular: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(0.0, -0.0, awkward(i + 4)))
            .collect();
        let materials: Vec<u32> = (0..n as u32).map(|i| u32::MAX - 100 + i * 7).collect();
        let orientations: Vec<DQuat> = (0..n)
            .map(|i| DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), awkward(i)))
            .collect();
        let speeds: Vec<f64> = velocities.iter().map(|v| v.length()).collect();
        let forces: Vec<DVec3> = (0..n).map(|i| DVec3::splat(-awkward(i + 5))).collect();
        let torques: Vec<DVec3> = (0..n).map(|i| DVec3::splat(awkward(i + 6))).collect();
        let coordination: Vec<u32> = (0..n as u32).collect();
        let wall_contacts: Vec<u32> = (0..n as u32).map(|i| i % 2).collect();
        let shapes: Vec<u32> = (0..n as u32).map(|i| 3 * i).collect();
        let frame = ParticleFrame {
            ids: &ids,
            positions: &positions,
            radii: &radii,
            orientations: &orientations,
            fields: BodyFields {
                velocities: &velocities,
                speeds: &speeds,
                angular_velocities: &angular,
                forces: &forces,
                torques: &torques,
                coordination: &coordination,
                wall_contacts: &wall_contacts,
                materials: &materials,
                shapes: &shapes,
            },
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("particles.vtp");
        let time = 0.1 + 0.2;
        write_particles(&path, &frame, time).unwrap();

        let vtp = read_vtp(&path);
        assert_eq!(vtp.root["type"], "PolyData");
        assert_eq!(vtp.root["byte_order"], "LittleEndian");
        assert_eq!(vtp.root["header_type"], "UInt64");
        assert_eq!(vtp.piece["NumberOfPoints"], n.to_string());
        assert_eq!(vtp.piece["NumberOfVerts"], n.to_string());
        assert_eq!(vtp.piece["NumberOfPolys"], "0");
        assert_eq!(vtp.point_data["Scalars"], "radius");
        assert_eq!(vtp.point_data["Vectors"], "velocity");

        assert_eq!(vtp.arrays["Points/Points"].components, 3);
        assert_eq!(bits(vtp.f64s("Points/Points")), bits(&flat3(&positions)));
        assert_eq!(bits(vtp.f64s("PointData/radius")), bits(&radii));
        assert_eq!(vtp.arrays["PointData/velocity"].components, 3);
        assert_eq!(
            bits(vtp.f64s("PointData/velocity")),
            bits(&flat3(&velocities))
        );
        assert_eq!(vtp.arrays["PointData/angular_velocity"].components, 3);
        assert_eq!(
            bits(vtp.f64s("PointData/angular_velocity")),
            bits(&flat3(&angular))
        );
        assert_eq!(vtp.u64s("PointData/id"), ids);
        assert_eq!(vtp.u32s("PointData/material"), materials);
        assert_eq!(bits(vtp.f64s("PointData/speed")), bits(&speeds));
        assert_eq!(bits(vtp.f64s("PointData/force")), bits(&flat3(&forces)));
        assert_eq!(bits(vtp.f64s("PointData/torque")), bits(&flat3(&torques)));
        assert_eq!(vtp.u32s("PointData/coordination"), coordination);
        assert_eq!(vtp.u32s("PointData/wall_contacts"), wall_contacts);
        assert_eq!(vtp.u32s("PointData/shape"), shapes);
        let orientation = &vtp.arrays["PointData/orientation"];
        assert_eq!(orientation.components, 4);
        assert_eq!(orientation.attributes["ComponentName0"], "w");
        let wxyz: Vec<f64> = orientations
            .iter()
            .flat_map(|q| [q.w, q.x, q.y, q.z])
            .collect();
        assert_eq!(bits(vtp.f64s("PointData/orientation")), bits(&wxyz));

        let expected: Vec<i64> = (0..n as i64).collect();
        assert_eq!(vtp.i64s("Verts/connectivity"), expected);
        let expected: Vec<i64> = (1..=n as i64).collect();
        assert_eq!(vtp.i64s("Verts/offsets"), expected);

        let time_array = &vtp.arrays["FieldData/TIME"];
        assert_eq!(time_array.attributes["NumberOfTuples"], "1");
        assert_eq!(bits(vtp.f64s("FieldData/TIME")), bits(&[time]));
    }

    #[test]
    fn zero_particles_give_a_valid_empty_file() {
        let frame = ParticleFrame {
            ids: &[],
            positions: &[],
            radii: &[],
            orientations: &[],
            fields: BodyFields {
                velocities: &[],
                speeds: &[],
                angular_velocities: &[],
                forces: &[],
                torques: &[],
                coordination: &[],
                wall_contacts: &[],
                materials: &[],
                shapes: &[],
            },
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("empty.vtp");
        write_particles(&path, &frame, 2.5).unwrap();
        let vtp = read_vtp(&path);
        assert_eq!(vtp.piece["NumberOfPoints"], "0");
        assert_eq!(vtp.piece["NumberOfVerts"], "0");
        assert!(vtp.f64s("Points/Points").is_empty());
        assert!(vtp.u64s("PointData/id").is_empty());
        assert!(vtp.i64s("Verts/offsets").is_empty());
        assert_eq!(vtp.f64s("FieldData/TIME"), [2.5]);
    }

    #[test]
    fn mismatched_particle_slices_are_invalid_input() {
        let one = [DVec3::ONE];
        let two = [DVec3::ONE, DVec3::ZERO];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.vtp");
        let fields = BodyFields {
            velocities: &one,
            speeds: &[1.0],
            angular_velocities: &one,
            forces: &one,
            torques: &one,
            coordination: &[0],
            wall_contacts: &[0],
            materials: &[0],
            shapes: &[0],
        };
        let good = ParticleFrame {
            ids: &[1],
            positions: &one,
            radii: &[1.0],
            orientations: &[DQuat::IDENTITY],
            fields,
        };
        let variants = [
            ParticleFrame {
                ids: &[1, 2],
                ..good
            },
            ParticleFrame {
                positions: &two,
                ..good
            },
            ParticleFrame { radii: &[], ..good },
            ParticleFrame {
                fields: BodyFields {
                    velocities: &two,
                    ..fields
                },
                ..good
            },
            ParticleFrame {
                fields: BodyFields {
                    angular_velocities: &[],
                    ..fields
                },
                ..good
            },
            ParticleFrame {
                fields: BodyFields {
                    materials: &[0, 0],
                    ..fields
                },
                ..good
            },
            ParticleFrame {
                fields: BodyFields {
                    coordination: &[],
                    ..fields
                },
                ..good
            },
            ParticleFrame {
                orientations: &[],
                ..good
            },
        ];
        for frame in variants {
            let err = write_particles(&path, &frame, 0.0).unwrap_err();
            assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
            assert!(!path.exists());
        }
        write_particles(&path, &good, 0.0).unwrap();
        assert!(path.exists());
    }

    fn wall_mesh() -> PolygonMesh {
        PolygonMesh {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.5, 0.5, 1.0 / 3.0),
                DVec3::new(2.0, 0.5, -0.1),
            ],
            polygons: vec![
                vec![0, 1, 4],
                vec![0, 1, 2, 3],
                vec![1, 5, 2, 4, 3],
                vec![2, 3, 4],
            ],
            cell_ids: vec![0, 0, 7, u32::MAX],
        }
    }

    #[test]
    fn polygons_round_trip() {
        let mesh = wall_mesh();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("walls.vtp");
        write_polygons(&path, &mesh, "wall", 1e-7).unwrap();
        let vtp = read_vtp(&path);
        assert_eq!(vtp.piece["NumberOfPoints"], "6");
        assert_eq!(vtp.piece["NumberOfPolys"], "4");
        assert_eq!(vtp.piece["NumberOfVerts"], "0");
        assert_eq!(
            bits(vtp.f64s("Points/Points")),
            bits(&flat3(&mesh.vertices))
        );

        // Rebuild the polygons from connectivity + end offsets.
        let connectivity = vtp.i64s("Polys/connectivity");
        let mut start = 0;
        let mut polygons: Vec<Vec<u32>> = Vec::new();
        for &end in vtp.i64s("Polys/offsets") {
            let end = end as usize;
            polygons.push(connectivity[start..end].iter().map(|&i| i as u32).collect());
            start = end;
        }
        assert_eq!(start, connectivity.len());
        assert_eq!(polygons, mesh.polygons);
        assert_eq!(vtp.u32s("CellData/wall"), mesh.cell_ids);
        assert_eq!(vtp.f64s("FieldData/TIME"), [1e-7]);
    }

    #[test]
    fn force_network_round_trip() {
        let network = ForceNetwork {
            points: vec![DVec3::ZERO, DVec3::X, DVec3::new(0.0, 2.0, 0.0)],
            lines: vec![vec![0, 1], vec![1, 2]],
            normal_force: vec![3.5, 0.25],
            force: vec![DVec3::new(3.5, 0.1, 0.0), DVec3::new(0.0, -0.25, 0.0)],
            wall_contact: vec![0, 1],
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("forces.vtp");
        write_force_network(&path, &network, 0.5).unwrap();
        let vtp = read_vtp(&path);
        assert_eq!(vtp.piece["NumberOfLines"], "2");
        assert_eq!(vtp.piece["NumberOfPolys"], "0");
        assert_eq!(vtp.i64s("Lines/connectivity"), [0, 1, 1, 2]);
        assert_eq!(vtp.i64s("Lines/offsets"), [2, 4]);
        assert_eq!(vtp.f64s("CellData/normal_force"), network.normal_force);
        assert_eq!(
            bits(vtp.f64s("CellData/force")),
            bits(&flat3(&network.force))
        );
        assert_eq!(vtp.u32s("CellData/wall_contact"), network.wall_contact);
        let mut broken = network.clone();
        broken.lines[1][1] = 7;
        assert!(write_force_network(&path, &broken, 0.5).is_err());
    }

    #[test]
    fn empty_mesh_is_valid() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("none.vtp");
        write_polygons(&path, &PolygonMesh::default(), "wall", 0.0).unwrap();
        let vtp = read_vtp(&path);
        assert_eq!(vtp.piece["NumberOfPolys"], "0");
        assert!(vtp.u32s("CellData/wall").is_empty());
    }

    #[test]
    fn bad_meshes_are_invalid_input() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.vtp");
        let mut mesh = wall_mesh();
        mesh.cell_ids.pop();
        let err = write_polygons(&path, &mesh, "wall", 0.0).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);

        let mut mesh = wall_mesh();
        mesh.polygons[2][1] = 6;
        let err = write_polygons(&path, &mesh, "wall", 0.0).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(!path.exists());
    }

    #[test]
    fn pvd_lists_every_entry_and_is_well_formed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("series.pvd");
        let mut series = PvdSeries::new(path.clone());
        assert!(series.is_empty());
        let entries = [
            (0.0, "particles_0.vtp", 0),
            (0.0, "walls_0.vtp", 1),
            (1e-4 / 3.0, "particles_1.vtp", 0),
            (0.1 + 0.2, "odd & <name> \"q\".vtp", 0),
            (12345.678, "sub/particles_3.vtp", 0),
        ];
        for (i, (time, file, part)) in entries.iter().enumerate() {
            series.add(*time, file, *part).unwrap();
            let text = std::fs::read_to_string(&path).unwrap();
            let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
            let root = doc.root_element();
            assert_eq!(root.attribute("type"), Some("Collection"));
            let collection = root
                .children()
                .find(|n| n.has_tag_name("Collection"))
                .unwrap();
            let datasets: Vec<_> = collection
                .children()
                .filter(|n| n.has_tag_name("DataSet"))
                .collect();
            assert_eq!(datasets.len(), i + 1);
            for (node, (time, file, part)) in datasets.iter().zip(&entries) {
                let t: f64 = node.attribute("timestep").unwrap().parse().unwrap();
                assert_eq!(t.to_bits(), time.to_bits());
                assert_eq!(node.attribute("file"), Some(*file));
                assert_eq!(node.attribute("part"), Some(part.to_string().as_str()));
                assert_eq!(node.attribute("group"), Some(""));
            }
        }
        assert_eq!(series.len(), entries.len());
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "no temporaries left behind");
    }

    #[test]
    fn pvd_rejects_non_finite_time() {
        let dir = tempfile::tempdir().unwrap();
        let mut series = PvdSeries::new(dir.path().join("s.pvd"));
        let err = series.add(f64::NAN, "a.vtp", 0).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(series.is_empty());
    }
}
