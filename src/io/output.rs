//! The files a run writes: a VTK time series for ParaView and a CSV energy time series.
//!
//! Layout of the output folder:
//! - `particles.pvd` → `particles_NNNNNN.vtp`: one point per body with its data (`BodyFields`:
//!   velocity, speed, angular velocity, contact force and torque, coordination number, walls
//!   touching, material, shape);
//! - `legend.csv`: the names of the material and shape numbers;
//! - `walls.pvd` → `walls_NNNNNN.vtp`: plane walls drawn where they cut the scene's extent, mesh
//!   walls where they are;
//! - `polyhedra.pvd` → `polyhedra_NNNNNN.vtp`: the faces of every polyhedral body at its current
//!   pose (the triangles of a non-convex one), with the body's `id` and fields per face (when the
//!   scene has polyhedral shapes: from the first frame on, empty until the first one arrives);
//! - `contacts.pvd` → `contacts_NNNNNN.vtp`: the force network, one line per contact with its
//!   forces (only when asked for); a pair touching in several regions has one line per region,
//!   bent at the region's contact point;
//! - `energy.csv`: the energy ledger and contact count at each output time, and the packing
//!   fraction of a region when one is given;
//! - `wall_forces.csv` (when the scene has walls): for each wall (`wall` id as in `walls.pvd`:
//!   planes first, then mesh walls) the mean force on it and mean torque about its reference
//!   point over the interval that ends at the row's time;
//! - `flow.csv` (when flow meters are defined): for each meter the net mass and number of bodies
//!   passed since the start and the mean mass flow rate over the interval.
//!
//! Every file is replaced atomically, so a crash at any moment leaves valid files behind.

use super::body_values::{BodyValues, FaceValues, ShapeNames};
use super::vtk::{
    write_body_surfaces_marked, write_force_network_marked, write_particles_marked,
    write_polygons_marked, ForceNetwork,
};
use super::{CsvSeries, ParticleFrame, PolygonMesh, PvdSeries};
use crate::math::{Aabb, DVec3};
use crate::shape::Shape;
use crate::world::World;
use std::io;
use std::path::{Path, PathBuf};

pub const ENERGY_COLUMNS: [&str; 13] = [
    "time",
    "kinetic_translational",
    "kinetic_rotational",
    "potential_gravity",
    "elastic",
    "dissipated",
    "removed",
    "inserted",
    "wall_work",
    "gravity_work",
    "total",
    "contacts",
    "bodies",
];

/// What a run writes beyond the defaults.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OutputOptions {
    /// Write the force network at every frame.
    pub force_network: bool,
    /// Report the packing fraction of this box in `energy.csv`.
    pub packing_region: Option<Aabb>,
    /// Where the scene happens (bodies, insertion regions, walls; see `Scene::extent`): plane
    /// walls are drawn as far as it reaches. `None`: around the bodies at the start.
    pub extent: Option<Aabb>,
    /// Names of the walls in `wall_forces.csv`, planes first, then mesh walls; a wall without
    /// one is `wallN` (its number in `walls.pvd`).
    pub wall_names: Vec<String>,
}

/// The files of one run and what they have recorded so far. Plain data, so that a checkpoint can
/// carry it and a resumed run continues the same series (see [`RunOutput::relocate`]).
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct RunOutput {
    dir: PathBuf,
    particles: PvdSeries,
    walls: PvdSeries,
    polyhedra: PvdSeries,
    contacts: PvdSeries,
    energy: CsvSeries,
    wall_forces: CsvSeries,
    flow: CsvSeries,
    options: OutputOptions,
    /// Time, wall impulses and meter totals at the last frame, for the interval means.
    last_time: f64,
    last_impulse: Vec<(DVec3, DVec3)>,
    last_flow_mass: Vec<f64>,
    frame: usize,
    /// Whether frames include `polyhedra_NNNNNN.vtp` (the scene has polyhedral shapes).
    polyhedra_series: bool,
    /// The names of shape numbers (set again by a resumed run: shapes are not stored).
    #[serde(skip)]
    names: ShapeNames,
    /// How far to draw the infinite plane walls, fixed at the start.
    wall_bounds: Aabb,
}

impl RunOutput {
    /// Creates the output folder (and its parents) for a run of `world` whose named shapes are
    /// `names`, and writes `legend.csv` there.
    pub fn create(
        dir: &Path,
        world: &World,
        options: &OutputOptions,
        names: ShapeNames,
    ) -> io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        write_legend(&dir.join("legend.csv"), world, &names)?;
        let polyhedra_series = names.has_polyhedra()
            || world
                .shapes()
                .iter()
                .any(|s| !matches!(s, Shape::Sphere(_)));
        let mut columns = ENERGY_COLUMNS.to_vec();
        if options.packing_region.is_some() {
            columns.push("packing_fraction");
        }
        let b = world.bodies();
        let bounds = options.extent.unwrap_or_else(|| {
            (0..b.len())
                .map(|i| Aabb::around_sphere(b.position[i], b.bounding_radius[i]))
                .reduce(|a, c| a.union(&c))
                .unwrap_or(Aabb::new(DVec3::ZERO, DVec3::ZERO))
        });
        // A margin, so that walls reach a little beyond the bodies at the scene's edge.
        let bounds = bounds.enlarged(0.05 * bounds.extent().max_element());
        Ok(Self {
            dir: dir.to_path_buf(),
            particles: PvdSeries::new(dir.join("particles.pvd")),
            walls: PvdSeries::new(dir.join("walls.pvd")),
            polyhedra: PvdSeries::new(dir.join("polyhedra.pvd")),
            contacts: PvdSeries::new(dir.join("contacts.pvd")),
            energy: CsvSeries::new(dir.join("energy.csv"), &columns),
            wall_forces: CsvSeries::new(
                dir.join("wall_forces.csv"),
                &wall_force_columns(world, &options.wall_names),
            ),
            flow: CsvSeries::new(dir.join("flow.csv"), &flow_columns(world)),
            options: options.clone(),
            last_time: world.time(),
            last_impulse: wall_impulses(world),
            last_flow_mass: world.flow_meters().iter().map(|m| m.mass).collect(),
            frame: 0,
            polyhedra_series,
            names,
            wall_bounds: bounds,
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The names of shape numbers, for a run resumed from a checkpoint (which does not store
    /// shapes).
    pub fn set_shape_names(&mut self, names: ShapeNames) {
        self.names = names;
    }

    /// Makes the series write into `dir` (a resumed run's output folder, which may have moved
    /// since the checkpoint was written).
    pub fn relocate(&mut self, dir: &Path) {
        self.dir = dir.to_path_buf();
        for series in [
            &mut self.particles,
            &mut self.walls,
            &mut self.polyhedra,
            &mut self.contacts,
        ] {
            series.relocate(dir);
        }
        for series in [&mut self.energy, &mut self.wall_forces, &mut self.flow] {
            series.relocate(dir);
        }
    }

    /// Writes one frame of every VTK series and a row of every CSV series.
    pub fn write(&mut self, world: &World) -> io::Result<()> {
        self.write_frame(world)?;
        self.write_rows(world)
    }

    /// Writes one frame of every VTK series.
    pub fn write_frame(&mut self, world: &World) -> io::Result<()> {
        self.write_frame_marked(world, None)
    }

    /// Writes a frame of every VTK series (unless `frame` is false: one was written at this
    /// step) and a row of every CSV series (unless `rows` is false) at a step off the output
    /// times, marked as such: `state` (e.g. "blow-up: …") is stored in each `.vtp` as the field
    /// data string [`super::vtk::FRAME_STATE`], and `note` as a comment before the entries of
    /// the `.pvd` files. Returns the particles file of the frame (written now or before).
    pub fn write_marked(
        &mut self,
        world: &World,
        state: &str,
        note: &str,
        frame: bool,
        rows: bool,
    ) -> io::Result<PathBuf> {
        if frame {
            self.write_frame_marked(world, Some((state, note)))?;
        }
        if rows {
            self.write_rows(world)?;
        }
        Ok(self
            .dir
            .join(format!("particles_{:06}.vtp", self.frame.saturating_sub(1))))
    }

    /// Makes the files agree with what is recorded here, as a checkpoint stored it: a run
    /// stopped after its checkpoint may have written frames, series entries and rows since
    /// (the frame at an interrupt, say), which the resumed run writes again or, for a frame off
    /// the output times, not at all. Rewrites the `.pvd` and CSV files and removes the frames
    /// numbered from the next one on, so that the resumed series equals an uninterrupted one.
    pub fn rewind(&mut self) -> io::Result<()> {
        for series in [
            &self.particles,
            &self.walls,
            &self.polyhedra,
            &self.contacts,
        ] {
            series.rewrite()?;
        }
        for series in [&mut self.energy, &mut self.wall_forces, &mut self.flow] {
            series.rewrite()?;
        }
        let Ok(entries) = std::fs::read_dir(&self.dir) else {
            return Ok(());
        };
        for entry in entries {
            let entry = entry?;
            let name = entry.file_name();
            let Some(name) = name.to_str() else { continue };
            let later = SERIES
                .iter()
                .any(|s| frame_number(name, s).is_some_and(|n| n >= self.frame));
            if later && entry.file_type()?.is_file() {
                std::fs::remove_file(entry.path())
                    .map_err(|e| super::atomic::naming(&entry.path(), e))?;
            }
        }
        Ok(())
    }

    fn write_frame_marked(&mut self, world: &World, mark: Option<(&str, &str)>) -> io::Result<()> {
        let (state, note) = (mark.map(|m| m.0), mark.map(|m| m.1));
        let b = world.bodies();
        let values = BodyValues::of(world, &self.names);
        let fields = values.fields(world);
        let name = format!("particles_{:06}.vtp", self.frame);
        write_particles_marked(
            &self.dir.join(&name),
            &ParticleFrame {
                ids: &b.id,
                positions: &b.position,
                radii: &b.bounding_radius,
                orientations: &b.orientation,
                fields,
            },
            world.time(),
            state,
        )?;
        self.particles.add_noted(world.time(), &name, 0, note)?;

        let name = format!("walls_{:06}.vtp", self.frame);
        write_polygons_marked(
            &self.dir.join(&name),
            &self.wall_mesh(world),
            "wall",
            world.time(),
            state,
        )?;
        self.walls.add_noted(world.time(), &name, 0, note)?;

        if self.polyhedra_series {
            let name = format!("polyhedra_{:06}.vtp", self.frame);
            let (mesh, of_body) = polyhedra_mesh(world);
            let faces = FaceValues::gather(&fields, &of_body);
            write_body_surfaces_marked(
                &self.dir.join(&name),
                &mesh,
                &faces.fields(),
                world.time(),
                state,
            )?;
            self.polyhedra.add_noted(world.time(), &name, 0, note)?;
        }

        if self.options.force_network {
            let name = format!("contacts_{:06}.vtp", self.frame);
            write_force_network_marked(
                &self.dir.join(&name),
                &force_network(world),
                world.time(),
                state,
            )?;
            self.contacts.add_noted(world.time(), &name, 0, note)?;
        }
        self.frame += 1;
        Ok(())
    }

    /// Writes a row of every CSV series: the energy ledger now, wall forces and flow over the
    /// interval since the last row.
    pub fn write_rows(&mut self, world: &World) -> io::Result<()> {
        let b = world.bodies();
        let e = world.energy();
        let mut row = vec![
            world.time(),
            e.kinetic_translational,
            e.kinetic_rotational,
            e.potential,
            e.elastic,
            e.dissipated,
            e.removed,
            e.inserted,
            e.wall_work,
            e.gravity_work,
            e.total(),
            e.contacts as f64,
            b.len() as f64,
        ];
        if let Some(region) = self.options.packing_region {
            row.push(packing_fraction(world, &region));
        }
        self.energy.push(&row)?;
        self.write_interval_means(world)
    }

    /// Rows of `wall_forces.csv` and `flow.csv` for the interval since the last row.
    fn write_interval_means(&mut self, world: &World) -> io::Result<()> {
        let interval = world.time() - self.last_time;
        if interval <= 0.0 {
            return Ok(());
        }
        let impulses = wall_impulses(world);
        if !impulses.is_empty() {
            let mut row = vec![world.time()];
            for ((j, h), (j0, h0)) in impulses.iter().zip(&self.last_impulse) {
                let (f, t) = ((*j - *j0) / interval, (*h - *h0) / interval);
                row.extend([f.x, f.y, f.z, t.x, t.y, t.z]);
            }
            self.wall_forces.push(&row)?;
        }
        if !world.flow_meters().is_empty() {
            let mut row = vec![world.time()];
            for (m, m0) in world.flow_meters().iter().zip(&self.last_flow_mass) {
                row.extend([m.mass, m.bodies as f64, (m.mass - m0) / interval]);
            }
            self.flow.push(&row)?;
        }
        self.last_time = world.time();
        self.last_impulse = impulses;
        self.last_flow_mass = world.flow_meters().iter().map(|m| m.mass).collect();
        Ok(())
    }

    fn wall_mesh(&self, world: &World) -> PolygonMesh {
        let mut mesh = PolygonMesh::default();
        for (n, plane) in world.planes().iter().enumerate() {
            let first = mesh.vertices.len() as u32;
            let mut section = plane.section(&self.wall_bounds);
            if section.is_empty() {
                // A plane outside the scene touches nothing; drawn nearby all the same.
                let b = &self.wall_bounds;
                let half = 0.5 * b.extent().max_element().max(f64::MIN_POSITIVE);
                section = plane.patch(0.5 * (b.min + b.max), half).to_vec();
            }
            let corners = section.len() as u32;
            mesh.vertices.extend(section);
            mesh.polygons.push((first..first + corners).collect());
            mesh.cell_ids.push(n as u32);
        }
        // Mesh walls follow the planes in the `wall` numbering.
        for (n, wall) in world.mesh_walls().iter().enumerate() {
            let first = mesh.vertices.len() as u32;
            mesh.vertices.extend(wall.current_vertices());
            for t in wall.triangles() {
                mesh.polygons.push(t.iter().map(|&v| first + v).collect());
                mesh.cell_ids.push((world.planes().len() + n) as u32);
            }
        }
        mesh
    }
}

/// The VTK series of a run, by the names of their files.
const SERIES: [&str; 4] = ["particles", "walls", "polyhedra", "contacts"];

/// The number of a frame file `SERIES_NNNNNN.vtp` of `series`.
fn frame_number(name: &str, series: &str) -> Option<usize> {
    let n = name
        .strip_prefix(series)?
        .strip_prefix('_')?
        .strip_suffix(".vtp")?;
    (n.len() == 6 && n.bytes().all(|b| b.is_ascii_digit()))
        .then(|| n.parse().ok())
        .flatten()
}

/// Removes what an earlier run left in `dir`: its series (`.pvd`, numbered `.vtp` frames, the
/// CSV files), its checkpoints, and temporaries of writes that were killed. A new run into a
/// used folder must not leave frames of the old one beside its own (ParaView would show them),
/// nor checkpoints that `resume` would take for its own. Other files are left alone. Returns how
/// many files were removed.
pub fn clear_previous_run(dir: &Path) -> io::Result<usize> {
    let ours = |name: &str| {
        let temporary = name.starts_with('.') && name.contains(".tmp-");
        SERIES
            .iter()
            .any(|s| frame_number(name, s).is_some() || name == format!("{s}.pvd"))
            || ["energy.csv", "wall_forces.csv", "flow.csv", "legend.csv"].contains(&name)
            || temporary
    };
    let checkpoint = |name: &str| {
        (name.starts_with("step_") && name.ends_with(".ckpt"))
            || (name.starts_with(".step_") && name.contains(".ckpt.tmp-"))
    };
    let mut removed = 0;
    for (folder, keep) in [
        (dir.to_path_buf(), &ours as &dyn Fn(&str) -> bool),
        (dir.join("checkpoints"), &checkpoint),
    ] {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        for entry in entries {
            let entry = entry?;
            let name = entry.file_name();
            if entry.file_type()?.is_file() && name.to_str().is_some_and(keep) {
                std::fs::remove_file(entry.path())?;
                removed += 1;
            }
        }
    }
    Ok(removed)
}

/// Cumulative (impulse, angular impulse) of every wall, zero where no contact has happened yet.
fn wall_impulses(world: &World) -> Vec<(DVec3, DVec3)> {
    let walls = world.planes().len() + world.mesh_walls().len();
    (0..walls)
        .map(|w| {
            let j = world
                .wall_loads()
                .impulse
                .get(w)
                .copied()
                .unwrap_or(DVec3::ZERO);
            let h = world
                .wall_loads()
                .angular_impulse
                .get(w)
                .copied()
                .unwrap_or(DVec3::ZERO);
            (j, h)
        })
        .collect()
}

fn wall_force_columns(world: &World, names: &[String]) -> Vec<String> {
    let walls = world.planes().len() + world.mesh_walls().len();
    let mut columns = vec!["time".to_string()];
    for w in 0..walls {
        let name = names.get(w).cloned().unwrap_or_else(|| format!("wall{w}"));
        for c in ["fx", "fy", "fz", "tx", "ty", "tz"] {
            columns.push(format!("{name}_{c}"));
        }
    }
    columns
}

fn flow_columns(world: &World) -> Vec<String> {
    let mut columns = vec!["time".to_string()];
    for m in world.flow_meters() {
        for c in ["mass", "bodies", "rate"] {
            columns.push(format!("{}_{c}", m.name));
        }
    }
    columns
}

/// Faces of every polyhedral body, in world coordinates, and each face's body.
fn polyhedra_mesh(world: &World) -> (PolygonMesh, Vec<usize>) {
    let b = world.bodies();
    let mut mesh = PolygonMesh::default();
    let mut of_body = Vec::new();
    for i in 0..b.len() {
        let first = mesh.vertices.len() as u32;
        let place = |v: &DVec3| b.position[i] + b.orientation[i] * *v;
        match &world.shapes()[b.shape[i] as usize] {
            Shape::Sphere(_) => continue,
            Shape::Convex(p) => {
                mesh.vertices.extend(p.vertices().iter().map(place));
                for face in p.faces() {
                    mesh.polygons
                        .push(face.vertices.iter().map(|&v| first + v as u32).collect());
                    mesh.cell_ids.push(b.id[i] as u32);
                    of_body.push(i);
                }
            }
            Shape::NonConvex(p) => {
                mesh.vertices.extend(p.vertices().iter().map(place));
                for t in p.triangles() {
                    mesh.polygons
                        .push(t.iter().map(|&v| first + v as u32).collect());
                    mesh.cell_ids.push(b.id[i] as u32);
                    of_body.push(i);
                }
            }
        }
    }
    (mesh, of_body)
}

/// `legend.csv`: what the `material` and `shape` numbers of the VTK files stand for.
fn write_legend(path: &Path, world: &World, names: &ShapeNames) -> io::Result<()> {
    super::write_atomic(path, |w| {
        writeln!(w, "kind,number,name")?;
        for (k, m) in world.materials().iter().enumerate() {
            writeln!(w, "material,{k},{}", csv_field(&m.name))?;
        }
        for (k, name) in names.names().enumerate() {
            writeln!(w, "shape,{k},{}", csv_field(name))?;
        }
        Ok(())
    })
}

/// A name as one CSV field (quoted when it holds a comma, quote or line break).
fn csv_field(name: &str) -> String {
    if name.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_string()
    }
}

/// One line per contact: body centre to body centre, or body centre to the contact point on a
/// wall. A pair that can touch in several places (a non-convex body) gets one line per contact
/// region, bent at its contact point: centre, contact point, centre.
fn force_network(world: &World) -> ForceNetwork {
    let b = world.bodies();
    let mut network = ForceNetwork::default();
    let mut line = |points: &[DVec3], c: &crate::contact::ContactRef, wall: u32| {
        let first = network.points.len() as u32;
        network.points.extend_from_slice(points);
        network
            .lines
            .push((first..first + points.len() as u32).collect());
        network.normal_force.push(c.report.normal_force);
        network.force.push(c.load.force);
        network.wall_contact.push(wall);
    };
    for c in world.contacts().iter() {
        let i = c.key.a as usize;
        match c.key.partner.body() {
            Some(j) => {
                let j = j as usize;
                let regional = |k: usize| world.shapes()[b.shape[k] as usize].has_regions();
                if regional(i) || regional(j) {
                    line(&[b.position[i], c.geometry.point, b.position[j]], &c, 0);
                } else {
                    line(&[b.position[i], b.position[j]], &c, 0);
                }
            }
            None => line(&[b.position[i], c.geometry.point], &c, 1),
        }
    }
    network
}

/// Volume of the bodies whose centre lies in `region`, over the region's volume. Counting by
/// centre is exact on average for a region many bodies wide (the parts of bodies sticking out
/// balance those sticking in); keep the region a few body sizes away from walls and the free
/// surface.
pub fn packing_fraction(world: &World, region: &Aabb) -> f64 {
    let b = world.bodies();
    let solid: f64 = (0..b.len())
        .filter(|&i| b.position[i].cmpge(region.min).all() && b.position[i].cmple(region.max).all())
        .map(|i| {
            world.shapes()[b.shape[i] as usize]
                .unit_mass_properties()
                .volume
        })
        .sum();
    solid / region.extent().element_product()
}
