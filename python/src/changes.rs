//! Changes a script makes between steps — what a loading protocol needs: wall motion, gravity,
//! bodies inserted, removed and set moving. Each goes through the library's own door (the
//! `World` methods that keep the energy ledger closing), so the run's outputs stay consistent.

use crate::errors::value_error;
use polydem::body::BodyInit;
use polydem::math::{DQuat, DVec3};
use polydem::run::SteppedRun;
use polydem::shape::{Shape, Sphere};
use pyo3::prelude::*;

/// A mesh wall named by its number among the mesh walls (from 0) or by its name in
/// `wall_forces.csv`.
pub fn mesh_wall_index(run: &SteppedRun, wall: &Bound<'_, PyAny>) -> PyResult<usize> {
    let world = run.world();
    let count = world.mesh_walls().len();
    if let Ok(index) = wall.extract::<usize>() {
        if index < count {
            return Ok(index);
        }
        return Err(value_error(format!(
            "there is no mesh wall {index}: the scene has {count} (numbered from 0)"
        )));
    }
    let name: String = wall
        .extract()
        .map_err(|_| value_error("a wall is given by its number or its name"))?;
    let names = &run.prepared().output.wall_names;
    let planes = world.planes().len();
    names
        .iter()
        .skip(planes)
        .position(|n| *n == name)
        .ok_or_else(|| {
            value_error(format!(
                "no mesh wall is called {name:?}; the mesh walls are {:?}",
                &names[planes.min(names.len())..]
            ))
        })
}

/// When a change made now is complete: after `ramp` seconds, by default one time step (the
/// shortest change the run can follow; the same as a scene table with rows one step apart).
fn change_window(run: &SteppedRun, ramp: Option<f64>) -> PyResult<(f64, f64)> {
    let world = run.world();
    let ramp = ramp.unwrap_or(world.time_step());
    if !(ramp.is_finite() && ramp > 0.0) {
        return Err(value_error(format!("ramp: {ramp} s; give a time > 0")));
    }
    Ok((world.time(), world.time() + ramp))
}

pub fn set_wall_velocity(
    run: &mut SteppedRun,
    wall: usize,
    velocity: DVec3,
    ramp: Option<f64>,
) -> PyResult<()> {
    let (from, until) = change_window(run, ramp)?;
    let world = &mut run.prepared_mut().world;
    let motion = world.mesh_walls()[wall]
        .motion
        .clone()
        .with_velocity_changed_at(from, until, velocity)
        .map_err(|e| value_error(format!("mesh wall {wall}: {e}")))?;
    world
        .set_wall_motion(wall, motion)
        .map_err(|e| value_error(e.to_string()))
}

pub fn set_wall_rpm(
    run: &mut SteppedRun,
    wall: usize,
    rpm: f64,
    axis: Option<(DVec3, DVec3)>,
    ramp: Option<f64>,
) -> PyResult<()> {
    let (from, until) = change_window(run, ramp)?;
    let world = &mut run.prepared_mut().world;
    let motion = world.mesh_walls()[wall]
        .motion
        .clone()
        .with_rpm_changed_at(from, until, rpm, axis)
        .map_err(|e| value_error(format!("mesh wall {wall}: {e}")))?;
    world
        .set_wall_motion(wall, motion)
        .map_err(|e| value_error(e.to_string()))
}

/// Where each of `ids` is in the body arrays now.
pub fn indices_of(run: &SteppedRun, ids: &[u64]) -> PyResult<Vec<usize>> {
    let b = run.world().bodies();
    let mut index = std::collections::HashMap::with_capacity(b.len());
    for (i, &id) in b.id.iter().enumerate() {
        index.insert(id, i);
    }
    ids.iter()
        .map(|id| {
            index
                .get(id)
                .copied()
                .ok_or_else(|| value_error(format!("there is no body with id {id} (now)")))
        })
        .collect()
}

pub fn set_velocities(
    run: &mut SteppedRun,
    ids: &[u64],
    velocities: &[DVec3],
    angular_velocities: Option<&[DVec3]>,
) -> PyResult<()> {
    let indices = indices_of(run, ids)?;
    if velocities.len() != ids.len() || angular_velocities.is_some_and(|w| w.len() != ids.len()) {
        return Err(value_error(
            "give one velocity (and angular velocity) per id",
        ));
    }
    let world = &mut run.prepared_mut().world;
    for (k, &i) in indices.iter().enumerate() {
        let spin = angular_velocities.map_or(world.bodies().angular_velocity[i], |w| w[k]);
        world.set_velocity(i, velocities[k], spin);
    }
    Ok(())
}

pub fn remove(run: &mut SteppedRun, ids: &[u64]) -> PyResult<()> {
    let indices = indices_of(run, ids)?;
    let world = &mut run.prepared_mut().world;
    let mut keep = vec![true; world.bodies().len()];
    for i in indices {
        keep[i] = false;
    }
    world.remove_bodies(&keep);
    // Contacts and energies read before the next step see the bodies as they are now.
    world.update_contacts();
    Ok(())
}

/// What `Simulation.insert` was given.
pub struct NewBody<'a> {
    pub position: DVec3,
    pub radius: Option<f64>,
    pub shape: Option<&'a str>,
    pub material: &'a str,
    pub velocity: DVec3,
    pub angular_velocity: DVec3,
    /// (w, x, y, z) of the shape's principal frame.
    pub orientation: [f64; 4],
}

/// Inserts one body; returns its id.
pub fn insert(run: &mut SteppedRun, new: NewBody<'_>) -> PyResult<u64> {
    let prepared = run.prepared();
    let materials = prepared.world.materials();
    let material = materials
        .iter()
        .position(|m| m.name == new.material)
        .ok_or_else(|| {
            let known: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
            value_error(format!(
                "no material named {:?}; the scene defines {known:?}",
                new.material
            ))
        })? as u32;
    let shape = match (new.radius, new.shape) {
        (Some(r), None) if r.is_finite() && r > 0.0 => Shape::Sphere(Sphere::new(r)),
        (None, Some(name)) => prepared
            .shape_names
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, s)| s.clone())
            .ok_or_else(|| {
                let known: Vec<&str> = prepared
                    .shape_names
                    .iter()
                    .map(|(n, _)| n.as_str())
                    .collect();
                value_error(format!(
                    "no shape named {name:?}; the scene defines {known:?}"
                ))
            })?,
        _ => {
            return Err(value_error(
                "give exactly one of radius (> 0, a sphere) and shape (a [shape.NAME])",
            ))
        }
    };
    let [w, x, y, z] = new.orientation;
    let orientation = DQuat::from_xyzw(x, y, z, w);
    if !(orientation.is_finite() && orientation.length() > 0.0) {
        return Err(value_error(
            "orientation: give a non-zero quaternion (w, x, y, z)",
        ));
    }
    let index = run
        .insert_body(BodyInit {
            shape,
            material,
            position: new.position,
            orientation: orientation.normalize(),
            velocity: new.velocity,
            angular_velocity: new.angular_velocity,
        })
        .map_err(value_error)?;
    // Contacts and energies read before the next step include the new body's.
    run.prepared_mut().world.update_contacts();
    Ok(run.world().bodies().id[index])
}
