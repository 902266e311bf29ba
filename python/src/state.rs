//! The state of a run as NumPy arrays and plain Python values (see `arrays.rs` for why copies):
//! bodies, contacts, the energy ledger, wall loads and flow meters.

use crate::arrays::{quaternions, vectors};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use polydem::contact::Partner;
use polydem::io::output::ENERGY_COLUMNS;
use polydem::math::DVec3;
use polydem::World;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// One per-body quantity, as the Simulation properties name them.
#[derive(Clone, Copy)]
pub enum BodyArray {
    Positions,
    Velocities,
    AngularVelocities,
    Forces,
    Torques,
}

pub fn body_vectors<'py>(
    py: Python<'py>,
    world: &World,
    which: BodyArray,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let b = world.bodies();
    let values = match which {
        BodyArray::Positions => &b.position,
        BodyArray::Velocities => &b.velocity,
        BodyArray::AngularVelocities => &b.angular_velocity,
        BodyArray::Forces => &b.force,
        BodyArray::Torques => &b.torque,
    };
    vectors(py, values)
}

pub fn orientations<'py>(py: Python<'py>, world: &World) -> PyResult<Bound<'py, PyArray2<f64>>> {
    quaternions(py, &world.bodies().orientation)
}

/// The contacts that touch, as arrays: `bodies` (M, 2) body ids (the second −1 for a wall),
/// `wall` (M,) the wall's number as in `wall_forces.csv` (planes first, then mesh walls; −1
/// between bodies), `points`, `normals` (from the partner towards the first body), `forces` (on
/// the first body) (M, 3), `normal_force` and `overlap` (M,).
pub fn contacts<'py>(py: Python<'py>, world: &World) -> PyResult<Bound<'py, PyDict>> {
    let b = world.bodies();
    let planes = world.planes().len() as i64;
    let (mut pairs, mut wall) = (Vec::new(), Vec::new());
    let (mut points, mut normals, mut forces) = (Vec::new(), Vec::new(), Vec::new());
    let (mut normal_force, mut overlap) = (Vec::new(), Vec::new());
    for c in world.contacts().iter() {
        let a = b.id[c.key.a as usize] as i64;
        let (partner, w) = match c.key.partner {
            Partner::Body(j) => (b.id[j as usize] as i64, -1),
            Partner::Plane(p) => (-1, p as i64),
            Partner::Mesh(m) => (-1, planes + m as i64),
        };
        pairs.extend([a, partner]);
        wall.push(w);
        points.push(c.geometry.point);
        normals.push(c.geometry.normal);
        forces.push(c.load.force);
        normal_force.push(c.report.normal_force);
        overlap.push(c.geometry.overlap);
    }
    let d = PyDict::new(py);
    let m = wall.len();
    d.set_item("bodies", PyArray1::from_vec(py, pairs).reshape([m, 2])?)?;
    d.set_item("wall", PyArray1::from_vec(py, wall))?;
    d.set_item("points", vectors(py, &points)?)?;
    d.set_item("normals", vectors(py, &normals)?)?;
    d.set_item("forces", vectors(py, &forces)?)?;
    d.set_item("normal_force", PyArray1::from_vec(py, normal_force))?;
    d.set_item("overlap", PyArray1::from_vec(py, overlap))?;
    Ok(d)
}

/// The energy ledger now, under the column names of `energy.csv`.
pub fn energy<'py>(py: Python<'py>, world: &World) -> PyResult<Bound<'py, PyDict>> {
    let e = world.energy();
    let values = [
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
        world.bodies().len() as f64,
    ];
    let d = PyDict::new(py);
    for (name, value) in ENERGY_COLUMNS.iter().zip(values) {
        d.set_item(name, value)?;
    }
    Ok(d)
}

/// The loads on the walls (planes first, then mesh walls, as in `wall_forces.csv`): `names`,
/// `force` (W, 3) the force the bodies put on each wall now, and since the start of the run
/// `impulse` and `angular_impulse` (W, 3) (the CSV's means are their changes over an interval
/// divided by it) and `work` (of the moving walls on the bodies, J).
pub fn wall_loads<'py>(
    py: Python<'py>,
    world: &World,
    names: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    let planes = world.planes().len();
    let walls = planes + world.mesh_walls().len();
    let mut force = vec![DVec3::ZERO; walls];
    for c in world.contacts().iter() {
        let w = match c.key.partner {
            Partner::Body(_) => continue,
            Partner::Plane(p) => p as usize,
            Partner::Mesh(m) => planes + m as usize,
        };
        force[w] -= c.load.force;
    }
    let loads = world.wall_loads();
    let cumulative = |values: &[DVec3]| {
        let mut all = values.to_vec();
        all.resize(walls, DVec3::ZERO);
        all
    };
    let d = PyDict::new(py);
    d.set_item("names", names.to_vec())?;
    d.set_item("force", vectors(py, &force)?)?;
    d.set_item("impulse", vectors(py, &cumulative(&loads.impulse))?)?;
    d.set_item(
        "angular_impulse",
        vectors(py, &cumulative(&loads.angular_impulse))?,
    )?;
    d.set_item("work", loads.work)?;
    Ok(d)
}

/// Each flow meter by name: the net mass [kg] and number of bodies that have passed it.
pub fn flow<'py>(py: Python<'py>, world: &World) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for m in world.flow_meters() {
        let meter = PyDict::new(py);
        meter.set_item("mass", m.mass)?;
        meter.set_item("bodies", m.bodies)?;
        d.set_item(&m.name, meter)?;
    }
    Ok(d)
}
