//! Built-in triangle meshes for walls: a subdivided rectangle, a box, a cylinder or tube, a cone
//! frustum (hopper with outlet) and a helical screw flight with its shaft and an optional tube.
//!
//! Every generator returns a welded [`TriMesh`] whose triangles are counter-clockwise seen from
//! the side bodies live on ([`Facing`]): `Inward` for a container (box, drum, tube, hopper),
//! `Outward` for an obstacle (a box in the flow, the screw).

use super::mesh::{MeshWall, MeshWallError};
use crate::material::MaterialId;
use crate::math::{is_finite_vec, DQuat, DVec3};
use std::collections::HashMap;
use std::f64::consts::TAU;
use thiserror::Error;

/// Relative tolerance for merging the shared corners of generated pieces.
const WELD: f64 = 1e-9;

/// A generator's parameters were not allowed.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{0}")]
pub struct GeneratorError(pub String);

fn require(ok: bool, message: impl FnOnce() -> String) -> Result<(), GeneratorError> {
    if ok {
        Ok(())
    } else {
        Err(GeneratorError(message()))
    }
}

fn positive(name: &str, value: f64) -> Result<(), GeneratorError> {
    require(value.is_finite() && value > 0.0, || {
        format!("{name} = {value} is not allowed: must be a finite number > 0")
    })
}

fn at_least_one(name: &str, value: usize) -> Result<(), GeneratorError> {
    require(value >= 1, || {
        format!("{name} = {value} is not allowed: must be at least 1")
    })
}

/// Which side of a generated surface bodies live on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Bodies inside (a container).
    Inward,
    /// Bodies outside (an obstacle).
    Outward,
}

/// Whether a cylinder or frustum has flat end caps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ends {
    Open,
    Closed,
}

/// Handedness of a screw's helix: a right-handed flight advances along +z while turning
/// counter-clockwise seen from +z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hand {
    Right,
    Left,
}

/// An indexed triangle mesh (counter-clockwise seen from the side bodies live on).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Total area of the triangles.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Signed volume enclosed (positive for a closed mesh with outward normals).
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// How many triangles use each undirected edge (smaller vertex index first).
    pub fn edge_uses(&self) -> HashMap<[u32; 2], usize> {
        let mut uses = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (i, j) = (t[k], t[(k + 1) % 3]);
                *uses.entry([i.min(j), i.max(j)]).or_insert(0) += 1;
            }
        }
        uses
    }

    /// Edges used by one triangle only.
    pub fn boundary_edges(&self) -> Vec<[u32; 2]> {
        let mut b: Vec<_> = self
            .edge_uses()
            .into_iter()
            .filter(|&(_, n)| n == 1)
            .map(|(e, _)| e)
            .collect();
        b.sort_unstable();
        b
    }

    /// True when every edge is shared by exactly two triangles that traverse it in opposite
    /// directions (closed and consistently oriented).
    pub fn is_closed(&self) -> bool {
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        directed
            .iter()
            .all(|(&(i, j), &n)| n == 1 && directed.get(&(j, i)) == Some(&1))
    }

    /// The same surface facing the other way.
    pub fn flipped(mut self) -> Self {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
        self
    }

    /// The mesh facing `facing`, given that it was built facing outward.
    fn facing(self, facing: Facing) -> Self {
        match facing {
            Facing::Outward => self,
            Facing::Inward => self.flipped(),
        }
    }

    /// Adds another mesh's triangles (its vertices are not merged with ours; see `welded`).
    pub fn append(&mut self, other: &TriMesh) {
        let offset = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + offset)));
    }

    /// The mesh with coincident vertices merged (within 1e-9 of the bounding-box diagonal).
    pub fn welded(&self) -> Self {
        let triangles: Vec<[usize; 3]> = self
            .triangles
            .iter()
            .map(|t| t.map(|i| i as usize))
            .collect();
        let w = crate::geometry::weld::weld(&self.vertices, &triangles, WELD);
        Self {
            vertices: w.vertices,
            triangles: w.triangles.iter().map(|t| t.map(|i| i as u32)).collect(),
        }
    }

    /// Every vertex x moved to `rotation * (scale * x) + translation`.
    pub fn transformed(&self, scale: f64, rotation: DQuat, translation: DVec3) -> Self {
        Self {
            vertices: self
                .vertices
                .iter()
                .map(|&v| rotation * (scale * v) + translation)
                .collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// A wall of this mesh.
    pub fn into_wall(self, material: MaterialId) -> Result<MeshWall, MeshWallError> {
        MeshWall::new(self.vertices, self.triangles, material)
    }
}

/// The parallelogram `origin + s u + t v`, s, t ∈ [0, 1], as `nu × nv` cells of two triangles;
/// its normal is along u × v.
pub fn rectangle(
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    nu: usize,
    nv: usize,
) -> Result<TriMesh, GeneratorError> {
    at_least_one("divisions along u", nu)?;
    at_least_one("divisions along v", nv)?;
    require(
        is_finite_vec(origin) && is_finite_vec(u) && is_finite_vec(v),
        || "a rectangle's corner and sides must be finite".into(),
    )?;
    require(
        u.cross(v).length() > 1e-12 * u.length_squared().max(v.length_squared()),
        || "a rectangle's sides must not be parallel or zero".into(),
    )?;
    let mut m = TriMesh::default();
    for j in 0..=nv {
        for i in 0..=nu {
            m.vertices
                .push(origin + u * (i as f64 / nu as f64) + v * (j as f64 / nv as f64));
        }
    }
    let row = nu as u32 + 1;
    for j in 0..nv as u32 {
        for i in 0..nu as u32 {
            let a = j * row + i;
            let (b, c, d) = (a + 1, a + row + 1, a + row);
            m.triangles.push([a, b, c]);
            m.triangles.push([a, c, d]);
        }
    }
    Ok(m)
}

/// The closed box between corners `min` and `max`, each face split into `divisions` ×
/// `divisions` squares of two triangles (12 divisions² triangles).
pub fn box_mesh(
    min: DVec3,
    max: DVec3,
    divisions: usize,
    facing: Facing,
) -> Result<TriMesh, GeneratorError> {
    at_least_one("divisions", divisions)?;
    require(
        is_finite_vec(min) && is_finite_vec(max) && min.cmplt(max).all(),
        || "a box's max corner must be above its min corner along every axis".into(),
    )?;
    let e = max - min;
    let (ex, ey, ez) = (DVec3::X * e.x, DVec3::Y * e.y, DVec3::Z * e.z);
    // (corner, u, v) with u × v outward.
    let faces = [
        (min, ey, ex),      // z = min, −z
        (min + ez, ex, ey), // z = max, +z
        (min, ex, ez),      // y = min, −y
        (min + ey, ez, ex), // y = max, +y
        (min, ez, ey),      // x = min, −x
        (min + ex, ey, ez), // x = max, +x
    ];
    let mut m = TriMesh::default();
    for (o, u, v) in faces {
        m.append(&rectangle(o, u, v, divisions, divisions)?);
    }
    Ok(m.welded().facing(facing))
}

/// A cone frustum around the z axis from radius `bottom_radius` at z = 0 to `top_radius` at
/// z = `height`: `segments` around, `rings` along the axis, with or without flat ends. An inward
/// frustum open at both ends is a hopper whose outlet is the smaller end.
pub fn frustum(
    bottom_radius: f64,
    top_radius: f64,
    height: f64,
    segments: usize,
    rings: usize,
    ends: Ends,
    facing: Facing,
) -> Result<TriMesh, GeneratorError> {
    positive("bottom radius", bottom_radius)?;
    positive("top radius", top_radius)?;
    positive("height", height)?;
    require(segments >= 3, || {
        format!("segments = {segments} is not allowed: must be at least 3")
    })?;
    at_least_one("rings", rings)?;
    let n = segments as u32;
    let mut m = TriMesh::default();
    for k in 0..=rings {
        let s = k as f64 / rings as f64;
        let r = bottom_radius + (top_radius - bottom_radius) * s;
        for i in 0..segments {
            let a = TAU * i as f64 / segments as f64;
            m.vertices
                .push(DVec3::new(r * a.cos(), r * a.sin(), height * s));
        }
    }
    for k in 0..rings as u32 {
        for i in 0..n {
            let a = k * n + i;
            let b = k * n + (i + 1) % n;
            let (c, d) = (b + n, a + n);
            m.triangles.push([a, b, c]);
            m.triangles.push([a, c, d]);
        }
    }
    if ends == Ends::Closed {
        let bottom = m.vertices.len() as u32;
        m.vertices.push(DVec3::ZERO);
        m.vertices.push(DVec3::new(0.0, 0.0, height));
        let top_ring = rings as u32 * n;
        for i in 0..n {
            m.triangles.push([bottom, (i + 1) % n, i]);
            m.triangles
                .push([bottom + 1, top_ring + i, top_ring + (i + 1) % n]);
        }
    }
    Ok(m.facing(facing))
}

/// A cylinder of `radius` around the z axis from z = 0 to `height` (an inward one open at both
/// ends is a tube; closed, a drum).
pub fn cylinder(
    radius: f64,
    height: f64,
    segments: usize,
    rings: usize,
    ends: Ends,
    facing: Facing,
) -> Result<TriMesh, GeneratorError> {
    frustum(radius, radius, height, segments, rings, ends, facing)
}

/// A helical screw along the z axis, starting at z = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screw {
    pub shaft_radius: f64,
    /// Outer radius of the flight.
    pub flight_radius: f64,
    /// Axial advance per turn.
    pub pitch: f64,
    pub turns: f64,
    /// Axial thickness of the flight.
    pub thickness: f64,
    pub hand: Hand,
    /// Facets per turn around the axis (also the shaft's facets around).
    pub segments_per_turn: usize,
    /// Facets across the flight, from shaft to outer radius.
    pub radial_segments: usize,
    /// Include the shaft (a closed cylinder from the bottom to the top of the flight).
    pub shaft: bool,
    /// The casing around the flight, if any.
    pub casing: Casing,
    /// Which of screw and casing go into the mesh.
    pub part: ScrewPart,
}

/// What surrounds a screw's flight (open at both ends, facing the screw).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Casing {
    None,
    /// A tube of radius flight radius + `clearance`.
    Tube {
        clearance: f64,
    },
    /// A U-shaped trough open towards +y: the half of a tube of radius flight radius +
    /// `clearance` at y ≤ 0, continued by two flat sides (x = ± that radius) up to y = `height`.
    Trough {
        clearance: f64,
        height: f64,
    },
}

/// Which parts of a screw a generated mesh holds. A turning screw and its fixed casing are two
/// walls with the same parameters: one `Screw`, one `Casing`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScrewPart {
    /// Flight and shaft and casing.
    All,
    /// Flight and shaft.
    Screw,
    /// The casing only.
    Casing,
}

impl Screw {
    /// Axial range [lowest, highest] of the flight.
    pub fn z_range(&self) -> (f64, f64) {
        let h = 0.5 * self.thickness;
        (-h, self.pitch * self.turns + h)
    }
}

/// The screw's flight: a closed-solid helical strip of axial thickness `thickness` from the
/// shaft radius to the flight radius — top and bottom helicoids z = p θ / 2π ± t/2, the outer rim
/// and the two end faces — open only along its root, which lies on the shaft's facets (they share
/// the angular division). With `shaft`, a closed cylinder; with a casing, an inward tube or
/// trough. Facing outward (the casing inward).
pub fn screw(s: &Screw) -> Result<TriMesh, GeneratorError> {
    positive("shaft radius", s.shaft_radius)?;
    positive("pitch", s.pitch)?;
    positive("turns", s.turns)?;
    positive("thickness", s.thickness)?;
    require(
        s.flight_radius.is_finite() && s.flight_radius > s.shaft_radius,
        || {
            format!(
                "flight radius = {} is not allowed: must exceed the shaft radius {}",
                s.flight_radius, s.shaft_radius
            )
        },
    )?;
    require(s.thickness < s.pitch, || {
        format!(
            "flight thickness = {} is not allowed: must be less than the pitch {}",
            s.thickness, s.pitch
        )
    })?;
    require(s.segments_per_turn >= 3, || {
        format!(
            "segments per turn = {} is not allowed: must be at least 3",
            s.segments_per_turn
        )
    })?;
    at_least_one("radial segments", s.radial_segments)?;
    match s.casing {
        Casing::None => require(s.part != ScrewPart::Casing, || {
            "a screw's casing was asked for but it has none: give a tube or trough clearance".into()
        })?,
        Casing::Tube { clearance } => positive("tube clearance", clearance)?,
        Casing::Trough { clearance, height } => {
            positive("trough clearance", clearance)?;
            require(height.is_finite() && height >= 0.0, || {
                format!(
                    "trough height = {height} is not allowed: must be a finite number ≥ 0 \
                     (the sides' height above the axis)"
                )
            })?;
        }
    }

    let mut mesh = TriMesh::default();
    if s.part != ScrewPart::Casing {
        mesh = flight_and_shaft(s)?;
        if s.hand == Hand::Left {
            // A mirror image turns the other way; mirroring also reverses the winding.
            for v in &mut mesh.vertices {
                v.y = -v.y;
            }
            mesh = mesh.flipped();
        }
    }
    if s.part != ScrewPart::Screw {
        mesh.append(&casing(s)?);
    }
    Ok(mesh)
}

/// The flight, and the shaft when asked for (facing outward).
fn flight_and_shaft(s: &Screw) -> Result<TriMesh, GeneratorError> {
    let total = TAU * s.turns;
    let steps = (s.turns * s.segments_per_turn as f64 - 1e-9)
        .ceil()
        .max(1.0) as usize;
    let lead = s.pitch / TAU;
    let half = 0.5 * s.thickness;
    let m_r = s.radial_segments;
    let cols = m_r as u32 + 1;
    let mut f = TriMesh::default();
    // Vertex (i, j, side): angle step i, radius step j, side 0 bottom / 1 top.
    for side in 0..2 {
        let dz = if side == 0 { -half } else { half };
        for i in 0..=steps {
            let theta = (TAU * i as f64 / s.segments_per_turn as f64).min(total);
            for j in 0..=m_r {
                let r = s.shaft_radius + (s.flight_radius - s.shaft_radius) * j as f64 / m_r as f64;
                f.vertices.push(DVec3::new(
                    r * theta.cos(),
                    r * theta.sin(),
                    lead * theta + dz,
                ));
            }
        }
    }
    let per_side = (steps as u32 + 1) * cols;
    let id = |i: u32, j: u32, side: u32| side * per_side + i * cols + j;
    for i in 0..steps as u32 {
        for j in 0..m_r as u32 {
            // Top: radial × angular is upward.
            let (a, b, c, d) = (
                id(i, j, 1),
                id(i, j + 1, 1),
                id(i + 1, j + 1, 1),
                id(i + 1, j, 1),
            );
            f.triangles.push([a, b, c]);
            f.triangles.push([a, c, d]);
            let (a, b, c, d) = (
                id(i, j, 0),
                id(i, j + 1, 0),
                id(i + 1, j + 1, 0),
                id(i + 1, j, 0),
            );
            f.triangles.push([a, c, b]);
            f.triangles.push([a, d, c]);
        }
        // Outer rim: angular × axial is radially outward.
        let o = m_r as u32;
        let (a, b, c, d) = (id(i, o, 0), id(i + 1, o, 0), id(i + 1, o, 1), id(i, o, 1));
        f.triangles.push([a, b, c]);
        f.triangles.push([a, c, d]);
    }
    let last = steps as u32;
    for j in 0..m_r as u32 {
        // Start face: radial × axial = −tangential (outward at θ = 0).
        let (a, b, c, d) = (id(0, j, 0), id(0, j + 1, 0), id(0, j + 1, 1), id(0, j, 1));
        f.triangles.push([a, b, c]);
        f.triangles.push([a, c, d]);
        let (a, b, c, d) = (
            id(last, j, 0),
            id(last, j + 1, 0),
            id(last, j + 1, 1),
            id(last, j, 1),
        );
        f.triangles.push([a, c, b]);
        f.triangles.push([a, d, c]);
    }
    let mut mesh = f;
    let (z0, z1) = s.z_range();
    if s.shaft {
        let shaft = cylinder(
            s.shaft_radius,
            z1 - z0,
            s.segments_per_turn,
            (s.turns.ceil() as usize).max(1),
            Ends::Closed,
            Facing::Outward,
        )?
        .transformed(1.0, DQuat::IDENTITY, DVec3::new(0.0, 0.0, z0));
        mesh.append(&shaft);
    }
    Ok(mesh)
}

/// The casing over the flight's axial range (facing inward; empty without one).
fn casing(s: &Screw) -> Result<TriMesh, GeneratorError> {
    let (z0, z1) = s.z_range();
    let rings = (s.turns.ceil() as usize).max(1);
    let mesh = match s.casing {
        Casing::None => TriMesh::default(),
        Casing::Tube { clearance } => cylinder(
            s.flight_radius + clearance,
            z1 - z0,
            s.segments_per_turn,
            rings,
            Ends::Open,
            Facing::Inward,
        )?,
        Casing::Trough { clearance, height } => {
            let radius = s.flight_radius + clearance;
            // Cross-section from the top of the side at −x, round the bottom, to the top at +x.
            let arc = s.segments_per_turn.div_ceil(2);
            let mut section = Vec::with_capacity(arc + 3);
            if height > 0.0 {
                section.push((-radius, height));
            }
            for i in 0..=arc {
                let a = std::f64::consts::PI * (1.0 + i as f64 / arc as f64);
                section.push((radius * a.cos(), radius * a.sin()));
            }
            if height > 0.0 {
                section.push((radius, height));
            }
            extrusion(&section, z1 - z0, rings).facing(Facing::Inward)
        }
    };
    Ok(mesh.transformed(1.0, DQuat::IDENTITY, DVec3::new(0.0, 0.0, z0)))
}

/// The open polyline `section` in the xy plane swept along z from 0 to `length` in `rings`
/// steps; facing outward means facing the right of the polyline's direction seen from +z.
fn extrusion(section: &[(f64, f64)], length: f64, rings: usize) -> TriMesh {
    let mut m = TriMesh::default();
    for k in 0..=rings {
        let z = length * k as f64 / rings as f64;
        m.vertices
            .extend(section.iter().map(|&(x, y)| DVec3::new(x, y, z)));
    }
    let n = section.len() as u32;
    for k in 0..rings as u32 {
        for i in 0..n - 1 {
            let (a, b) = (k * n + i, k * n + i + 1);
            let (c, d) = (b + n, a + n);
            m.triangles.push([a, b, c]);
            m.triangles.push([a, c, d]);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn normal(m: &TriMesh, t: usize) -> DVec3 {
        let [a, b, c] = m.triangles[t].map(|i| m.vertices[i as usize]);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn rectangle_counts_and_area() {
        let m = rectangle(DVec3::ZERO, DVec3::X * 2.0, DVec3::Y * 3.0, 10, 10).unwrap();
        assert_eq!(m.vertices.len(), 121);
        assert_eq!(m.triangles.len(), 200);
        assert!((m.area() - 6.0).abs() < 1e-12);
        assert!((normal(&m, 17) - DVec3::Z).length() < 1e-12);
        assert_eq!(m.boundary_edges().len(), 40);
        assert!(rectangle(DVec3::ZERO, DVec3::X, DVec3::X, 1, 1).is_err());
    }

    #[test]
    fn box_is_closed_and_faces_the_right_way() {
        for d in [1, 4] {
            let min = DVec3::new(-1.0, 0.0, 2.0);
            let max = DVec3::new(1.0, 3.0, 2.5);
            let out = box_mesh(min, max, d, Facing::Outward).unwrap();
            assert_eq!(out.triangles.len(), 12 * d * d);
            assert_eq!(out.vertices.len(), 6 * d * d + 2); // Euler: V − E + F = 2
            assert!(out.is_closed());
            assert!((out.area() - 2.0 * (6.0 + 1.0 + 1.5)).abs() < 1e-12);
            assert!((out.signed_volume() - 3.0).abs() < 1e-12);
            let inward = box_mesh(min, max, d, Facing::Inward).unwrap();
            assert!(inward.is_closed());
            assert!((inward.signed_volume() + 3.0).abs() < 1e-12);
            let wall = inward.into_wall(0).unwrap();
            assert!(wall.is_closed());
        }
        assert!(box_mesh(DVec3::ONE, DVec3::ZERO, 1, Facing::Inward).is_err());
    }

    #[test]
    fn cylinder_and_frustum() {
        let (r, h, n) = (0.5, 2.0, 48);
        let open = cylinder(r, h, n, 3, Ends::Open, Facing::Inward).unwrap();
        assert_eq!(open.vertices.len(), 4 * n);
        assert_eq!(open.triangles.len(), 6 * n);
        assert!(!open.is_closed());
        assert_eq!(open.boundary_edges().len(), 2 * n);
        // The polygon's perimeter 2nr sin(π/n) against 2πr.
        let exact = 2.0 * n as f64 * r * (PI / n as f64).sin() * h;
        assert!((open.area() - exact).abs() < 1e-12);
        assert!((open.area() / (TAU * r * h) - 1.0).abs() < 0.003);
        // Inward: the normal of a side facet points to the axis.
        let t = 0;
        let [a, ..] = open.triangles[t].map(|i| open.vertices[i as usize]);
        assert!(normal(&open, t).dot(DVec3::new(a.x, a.y, 0.0)) < 0.0);

        let drum = cylinder(r, h, n, 1, Ends::Closed, Facing::Inward).unwrap();
        assert!(drum.is_closed());
        assert_eq!(drum.triangles.len(), 4 * n);
        let polygon = 0.5 * n as f64 * r * r * (TAU / n as f64).sin();
        assert!((drum.signed_volume() + polygon * h).abs() < 1e-12);
        assert!((drum.area() - exact - 2.0 * polygon).abs() < 1e-12);

        // Hopper: r 0.1 at the outlet to 1.0 at the top, height 1.
        let hopper = frustum(0.1, 1.0, 1.0, 64, 4, Ends::Open, Facing::Inward).unwrap();
        let slant = (0.9f64 * 0.9 + 1.0).sqrt();
        let analytic = PI * (0.1 + 1.0) * slant;
        assert!((hopper.area() / analytic - 1.0).abs() < 0.002);
        let closed = frustum(0.1, 1.0, 1.0, 64, 4, Ends::Closed, Facing::Outward).unwrap();
        assert!(closed.is_closed());
        let cone_volume = PI / 3.0 * (0.01 + 0.1 + 1.0);
        assert!((closed.signed_volume() / cone_volume - 1.0).abs() < 0.003);
        assert!(cylinder(0.0, 1.0, 8, 1, Ends::Open, Facing::Inward).is_err());
        assert!(cylinder(1.0, 1.0, 2, 1, Ends::Open, Facing::Inward).is_err());
    }

    fn helicoid_area(a: f64, b: f64, c: f64, angle: f64) -> f64 {
        let f = |r: f64| {
            let s = (r * r + c * c).sqrt();
            r * s + c * c * (r + s).ln()
        };
        0.5 * angle * (f(b) - f(a))
    }

    fn flight(hand: Hand) -> Screw {
        Screw {
            shaft_radius: 0.02,
            flight_radius: 0.05,
            pitch: 0.06,
            turns: 2.5,
            thickness: 0.004,
            hand,
            segments_per_turn: 72,
            radial_segments: 3,
            shaft: false,
            casing: Casing::None,
            part: ScrewPart::All,
        }
    }

    #[test]
    fn screw_flight_counts_area_and_closedness() {
        let s = flight(Hand::Right);
        let m = screw(&s).unwrap();
        let steps = 180;
        assert_eq!(m.vertices.len(), 2 * (steps + 1) * 4);
        assert_eq!(m.triangles.len(), steps * (4 * 3 + 2) + 4 * 3);
        // Consistent orientation everywhere; open only along the root, at the shaft radius.
        let uses = m.edge_uses();
        assert!(uses.values().all(|&n| n <= 2));
        let boundary = m.boundary_edges();
        assert_eq!(boundary.len(), 2 * steps + 2);
        for e in &boundary {
            for &v in e {
                let p = m.vertices[v as usize];
                assert!((p.truncate().length() - s.shaft_radius).abs() < 1e-12);
            }
        }
        let angle = TAU * s.turns;
        let c = s.pitch / TAU;
        let analytic = 2.0 * helicoid_area(s.shaft_radius, s.flight_radius, c, angle)
            + angle * s.flight_radius * s.thickness
            + 2.0 * (s.flight_radius - s.shaft_radius) * s.thickness;
        assert!(
            (m.area() / analytic - 1.0).abs() < 2e-3,
            "{} vs {analytic}",
            m.area()
        );
        // Volume of the flight: thickness × annulus × turns (closed by the shaft's facets).
        let top = m
            .triangles
            .iter()
            .enumerate()
            .find(|(t, _)| normal(&m, *t).z > 0.5);
        assert!(top.is_some());
    }

    #[test]
    fn screw_handedness_and_parts() {
        let right = screw(&flight(Hand::Right)).unwrap();
        let left = screw(&flight(Hand::Left)).unwrap();
        assert!((right.area() - left.area()).abs() < 1e-12);
        // A right-handed flight at a quarter turn is a quarter pitch up at +y; left-handed at −y.
        let quarter = |m: &TriMesh, y: f64| {
            m.vertices
                .iter()
                .filter(|v| v.x.abs() < 1e-12 && (v.y - y).abs() < 1e-12 && v.z > 0.0 && v.z < 0.03)
                .count()
        };
        assert!(quarter(&right, 0.05) > 0);
        assert_eq!(quarter(&right, -0.05), 0);
        assert!(quarter(&left, -0.05) > 0);
        assert_eq!(quarter(&left, 0.05), 0);
        // Top faces still face up after mirroring.
        let up = |m: &TriMesh| {
            (0..m.triangles.len())
                .filter(|&t| normal(m, t).z > 0.5)
                .count()
        };
        assert_eq!(up(&right), up(&left));

        let mut full = flight(Hand::Left);
        full.shaft = true;
        full.casing = Casing::Tube { clearance: 0.005 };
        let m = screw(&full).unwrap();
        let n = 72;
        assert_eq!(
            m.triangles.len(),
            right.triangles.len() + (2 * 3 * n + 2 * n) + 2 * 3 * n
        );
        let wall = m.into_wall(1).unwrap();
        assert_eq!(wall.material, 1);
        let mut bad = flight(Hand::Right);
        bad.thickness = 0.1;
        assert!(screw(&bad).is_err());
        bad = flight(Hand::Right);
        bad.flight_radius = 0.01;
        assert!(screw(&bad)
            .unwrap_err()
            .to_string()
            .contains("flight radius"));
    }

    #[test]
    fn screw_trough_and_parts() {
        let (clearance, height) = (0.004, 0.03);
        let mut s = flight(Hand::Left);
        s.shaft = true;
        s.casing = Casing::Trough { clearance, height };
        let all = screw(&s).unwrap();
        s.part = ScrewPart::Screw;
        let screw_only = screw(&s).unwrap();
        s.part = ScrewPart::Casing;
        let trough = screw(&s).unwrap();
        assert_eq!(
            all.triangles.len(),
            screw_only.triangles.len() + trough.triangles.len()
        );
        // Half a 72-gon of radius R plus two sides of `height`, over the flight's length.
        let radius = s.flight_radius + clearance;
        let (z0, z1) = s.z_range();
        let arc = 36.0 * 2.0 * radius * (PI / 72.0).sin();
        assert!((trough.area() - (arc + 2.0 * height) * (z1 - z0)).abs() < 1e-12);
        assert_eq!(trough.triangles.len(), 2 * (36 + 2) * 3);
        // Open towards +y even for a left-handed screw, and facing the axis: every facet's
        // normal points into the U (towards the axis on the arc, inwards on the sides).
        for t in 0..trough.triangles.len() {
            let [a, b, c] = trough.triangles[t].map(|i| trough.vertices[i as usize]);
            let centre = (a + b + c) / 3.0;
            assert!(centre.y < height + 1e-12 && centre.z > z0 - 1e-12 && centre.z < z1 + 1e-12);
            let inward = if centre.y > 0.0 {
                DVec3::new(-centre.x.signum(), 0.0, 0.0)
            } else {
                -DVec3::new(centre.x, centre.y, 0.0).normalize()
            };
            assert!(normal(&trough, t).dot(inward) > 0.99, "facet {t}");
        }
        // Open ends and an open top: the boundary is the two end sections and the two top edges.
        assert_eq!(trough.boundary_edges().len(), 2 * (36 + 2) + 2 * 3);

        s.casing = Casing::None;
        assert!(screw(&s).unwrap_err().to_string().contains("casing"));
        s.casing = Casing::Trough {
            clearance,
            height: -1.0,
        };
        assert!(screw(&s).unwrap_err().to_string().contains("trough height"));
    }
}
