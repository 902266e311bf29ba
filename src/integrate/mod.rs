//! Time stepping: velocity Verlet for translation, a symplectic splitting for rotation.
//!
//! One step is kick(dt/2) → drift(dt) → [new forces] → kick(dt/2) (Verlet 1967; Swope et al.
//! 1982). Rotation uses the same pattern on the world-frame angular momentum L: the torque kicks L,
//! and the torque-free drift turns the orientation by the splitting of [`rotation`] while L stays
//! fixed (Dullweber, Leimkuhler & McLachlan 1997). Both parts are time-reversible and symplectic,
//! so a free body keeps its energy and angular momentum over long runs.

pub mod rotation;

use crate::body::Bodies;
use crate::math::DVec3;
use rayon::prelude::*;

/// Bodies per parallel work item: per-body work is a few dozen flops, so smaller items would
/// cost more in scheduling than they save.
const MIN_BODIES_PER_TASK: usize = 1024;

/// v += (F/m + g) h and L += τ h, then refreshes ω from L. Used with h = dt/2.
pub fn kick(bodies: &mut Bodies, gravity: DVec3, h: f64) {
    let Bodies {
        velocity,
        angular_momentum,
        angular_velocity,
        orientation,
        inv_mass,
        inv_inertia,
        force,
        torque,
        ..
    } = bodies;
    velocity
        .par_iter_mut()
        .zip(force.par_iter())
        .zip(inv_mass.par_iter())
        .with_min_len(MIN_BODIES_PER_TASK)
        .for_each(|((v, f), inv_m)| *v += (*f * *inv_m + gravity) * h);
    angular_momentum
        .par_iter_mut()
        .zip(angular_velocity.par_iter_mut())
        .zip(torque.par_iter())
        .zip(orientation.par_iter())
        .zip(inv_inertia.par_iter())
        .with_min_len(MIN_BODIES_PER_TASK)
        .for_each(|((((l, w), t), q), inv_i)| {
            *l += *t * h;
            *w = rotation::angular_velocity(*q, *l, *inv_i);
        });
}

/// x += v dt, and the torque-free rotation of each body over dt.
pub fn drift(bodies: &mut Bodies, dt: f64) {
    let Bodies {
        position,
        velocity,
        orientation,
        angular_momentum,
        inv_inertia,
        angular_velocity,
        ..
    } = bodies;
    position
        .par_iter_mut()
        .zip(velocity.par_iter())
        .with_min_len(MIN_BODIES_PER_TASK)
        .for_each(|(x, v)| *x += *v * dt);
    orientation
        .par_iter_mut()
        .zip(angular_momentum.par_iter())
        .zip(inv_inertia.par_iter())
        .zip(angular_velocity.par_iter_mut())
        .with_min_len(MIN_BODIES_PER_TASK)
        .for_each(|(((q, l), inv_i), w)| {
            *q = rotation::drift(*q, *l, *inv_i, dt);
            // The body frame turned, so the world-frame ω of a non-spherical body changed.
            *w = rotation::angular_velocity(*q, *l, *inv_i);
        });
}
