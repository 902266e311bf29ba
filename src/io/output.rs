//! The files a run writes: a VTK time series for ParaView and a CSV energy time series.
//!
//! Layout of the output folder:
//! - `particles.pvd` → `particles_NNNNNN.vtp`: one point per body with its data;
//! - `walls.pvd` → `walls_NNNNNN.vtp`: plane walls drawn as squares around the particles;
//! - `polyhedra.pvd` → `polyhedra_NNNNNN.vtp`: the faces of every polyhedral body at its current
//!   pose, with the body's `id` per face (only when the scene has polyhedra);
//! - `energy.csv`: the energy ledger and contact count at each output time.
//!
//! Every file is replaced atomically, so a crash at any moment leaves valid files behind.

use super::{write_particles, write_polygons, CsvSeries, ParticleFrame, PolygonMesh, PvdSeries};
use crate::math::{Aabb, DVec3};
use crate::shape::Shape;
use crate::world::World;
use std::io;
use std::path::{Path, PathBuf};

pub const ENERGY_COLUMNS: [&str; 11] = [
    "time",
    "kinetic_translational",
    "kinetic_rotational",
    "potential_gravity",
    "elastic",
    "dissipated",
    "removed",
    "inserted",
    "total",
    "contacts",
    "bodies",
];

pub struct RunOutput {
    dir: PathBuf,
    particles: PvdSeries,
    walls: PvdSeries,
    polyhedra: PvdSeries,
    energy: CsvSeries,
    frame: usize,
    /// Where and how large to draw the infinite plane walls, fixed at the start.
    wall_centre: DVec3,
    wall_half_size: f64,
}

impl RunOutput {
    /// Creates the output folder (and its parents) for a run of `world`.
    pub fn create(dir: &Path, world: &World) -> io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        let b = &world.bodies;
        let bounds = (0..b.len())
            .map(|i| Aabb::around_sphere(b.position[i], b.bounding_radius[i]))
            .reduce(|a, c| a.union(&c))
            .unwrap_or(Aabb::new(DVec3::ZERO, DVec3::ZERO));
        Ok(Self {
            dir: dir.to_path_buf(),
            particles: PvdSeries::new(dir.join("particles.pvd")),
            walls: PvdSeries::new(dir.join("walls.pvd")),
            polyhedra: PvdSeries::new(dir.join("polyhedra.pvd")),
            energy: CsvSeries::new(dir.join("energy.csv"), &ENERGY_COLUMNS),
            frame: 0,
            wall_centre: 0.5 * (bounds.min + bounds.max),
            wall_half_size: bounds.extent().max_element().max(f64::MIN_POSITIVE),
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes one frame of every series.
    pub fn write(&mut self, world: &World) -> io::Result<()> {
        let b = &world.bodies;
        let name = format!("particles_{:06}.vtp", self.frame);
        write_particles(
            &self.dir.join(&name),
            &ParticleFrame {
                ids: &b.id,
                positions: &b.position,
                radii: &b.bounding_radius,
                velocities: &b.velocity,
                angular_velocities: &b.angular_velocity,
                materials: &b.material,
                orientations: &b.orientation,
            },
            world.time,
        )?;
        self.particles.add(world.time, &name, 0)?;

        let name = format!("walls_{:06}.vtp", self.frame);
        write_polygons(
            &self.dir.join(&name),
            &self.wall_mesh(world),
            "wall",
            world.time,
        )?;
        self.walls.add(world.time, &name, 0)?;

        if world.shapes.iter().any(|s| matches!(s, Shape::Convex(_))) {
            let name = format!("polyhedra_{:06}.vtp", self.frame);
            write_polygons(
                &self.dir.join(&name),
                &polyhedra_mesh(world),
                "id",
                world.time,
            )?;
            self.polyhedra.add(world.time, &name, 0)?;
        }

        let e = world.energy();
        self.energy.push(&[
            world.time,
            e.kinetic_translational,
            e.kinetic_rotational,
            e.potential,
            e.elastic,
            e.dissipated,
            e.removed,
            e.inserted,
            e.total(),
            e.contacts as f64,
            b.len() as f64,
        ])?;
        self.frame += 1;
        Ok(())
    }

    fn wall_mesh(&self, world: &World) -> PolygonMesh {
        let mut mesh = PolygonMesh::default();
        for (n, plane) in world.planes.iter().enumerate() {
            let first = mesh.vertices.len() as u32;
            mesh.vertices
                .extend(plane.patch(self.wall_centre, self.wall_half_size));
            mesh.polygons.push((first..first + 4).collect());
            mesh.cell_ids.push(n as u32);
        }
        mesh
    }
}

/// Faces of every polyhedral body, in world coordinates.
fn polyhedra_mesh(world: &World) -> PolygonMesh {
    let b = &world.bodies;
    let mut mesh = PolygonMesh::default();
    for i in 0..b.len() {
        let Shape::Convex(p) = &world.shapes[b.shape[i] as usize] else {
            continue;
        };
        let first = mesh.vertices.len() as u32;
        mesh.vertices.extend(
            p.vertices()
                .iter()
                .map(|&v| b.position[i] + b.orientation[i] * v),
        );
        for face in p.faces() {
            mesh.polygons
                .push(face.vertices.iter().map(|&v| first + v as u32).collect());
            mesh.cell_ids.push(b.id[i] as u32);
        }
    }
    mesh
}
