//! Time stepping: velocity Verlet for translation, a symplectic splitting for rotation.
//!
//! One step is kick(dt/2) → drift(dt) → [new forces] → kick(dt/2) (Verlet 1967; Swope et al.
//! 1982). Rotation uses the same pattern on the world-frame angular momentum L: the torque kicks L,
//! and the torque-free drift turns the orientation by the splitting of [`rotation`] while L stays
//! fixed (Dullweber, Leimkuhler & McLachlan 1997). Both parts are time-reversible and symplectic,
//! so a free body keeps its energy and angular momentum over long runs.
//!
//! The step touches every body twice, not five times: [`kick_drift`] does the first half kick and
//! the drift and packs the motion the contact loops read ([`BodyMotion`]) in the same pass, and
//! the closing half kick ([`Kick::apply`]) runs in the pass that sums each body's contact forces
//! (`step::accumulate`), while they are in registers.

pub mod motion;
pub mod rotation;

pub use motion::BodyMotion;

use crate::body::Bodies;
use crate::math::{DQuat, DVec3};
use rayon::prelude::*;

/// Bodies per parallel work item: per-body work is a few dozen flops, so smaller items would
/// cost more in scheduling than they save.
const BODIES_PER_TASK: usize = 1024;

/// A half kick: v += (F/m + g) h and L += τ h, with ω refreshed from L.
#[derive(Clone, Copy, Debug)]
pub struct Kick {
    pub gravity: DVec3,
    pub h: f64,
}

/// One body's velocities and what the kick reads of it.
pub struct KickedBody<'a> {
    pub velocity: &'a mut DVec3,
    pub angular_momentum: &'a mut DVec3,
    pub angular_velocity: &'a mut DVec3,
    pub orientation: DQuat,
    pub inv_mass: f64,
    pub inv_inertia: DVec3,
}

impl Kick {
    #[inline(always)]
    pub fn apply(&self, body: KickedBody, force: DVec3, torque: DVec3) {
        *body.velocity += (force * body.inv_mass + self.gravity) * self.h;
        *body.angular_momentum += torque * self.h;
        *body.angular_velocity =
            rotation::angular_velocity(body.orientation, *body.angular_momentum, body.inv_inertia);
    }
}

/// The first half of a step for every body: the half kick with the forces of the last
/// evaluation (still in `bodies.force` and `bodies.torque`), the drift over `dt`, and the motion
/// the contact loops read, with the velocities at the end of the step predicted from the same
/// forces (see [`BodyMotion::predict`]).
pub fn kick_drift(bodies: &mut Bodies, gravity: DVec3, dt: f64, motion: &mut Vec<BodyMotion>) {
    let h = 0.5 * dt;
    let kick = Kick { gravity, h };
    motion.resize(bodies.len(), BodyMotion::default());
    let Bodies {
        position,
        velocity,
        orientation,
        angular_momentum,
        angular_velocity,
        inv_mass,
        inv_inertia,
        force,
        torque,
        bounding_radius,
        ..
    } = bodies;
    let (inv_mass, inv_inertia, force, torque) = (&*inv_mass, &*inv_inertia, &*force, &*torque);
    let bounding_radius = &*bounding_radius;
    position
        .par_chunks_mut(BODIES_PER_TASK)
        .zip(velocity.par_chunks_mut(BODIES_PER_TASK))
        .zip(orientation.par_chunks_mut(BODIES_PER_TASK))
        .zip(angular_momentum.par_chunks_mut(BODIES_PER_TASK))
        .zip(angular_velocity.par_chunks_mut(BODIES_PER_TASK))
        .zip(motion.par_chunks_mut(BODIES_PER_TASK))
        .enumerate()
        .for_each(|(c, (((((x, v), q), l), w), m))| {
            let first = c * BODIES_PER_TASK;
            for k in 0..x.len() {
                let i = first + k;
                let (f, t, inv_i) = (force[i], torque[i], inv_inertia[i]);
                if rotation::is_isotropic(inv_i) {
                    // A sphere (or a cube, a regular polyhedron): the general path below, with
                    // the steps its isotropic branches take and nothing else; ω = L/I is the
                    // same before and after the drift.
                    let acceleration = f * inv_mass[i] + gravity;
                    v[k] += acceleration * h;
                    l[k] += t * h;
                    w[k] = l[k] * inv_i.x;
                    x[k] += v[k] * dt;
                    q[k] = rotation::drift_isotropic(q[k], l[k], inv_i, dt);
                    m[k] = BodyMotion {
                        position: x[k],
                        velocity: v[k],
                        angular_velocity: w[k],
                        velocity_end: v[k] + acceleration * h,
                        angular_velocity_end: (l[k] + t * h) * inv_i.x,
                        radius: bounding_radius[i],
                    };
                    continue;
                }
                let body = KickedBody {
                    velocity: &mut v[k],
                    angular_momentum: &mut l[k],
                    angular_velocity: &mut w[k],
                    orientation: q[k],
                    inv_mass: inv_mass[i],
                    inv_inertia: inv_i,
                };
                kick.apply(body, f, t);
                x[k] += v[k] * dt;
                q[k] = rotation::drift(q[k], l[k], inv_i, dt);
                // The body frame turned, so the world-frame ω of a non-spherical body changed.
                w[k] = rotation::angular_velocity(q[k], l[k], inv_i);
                m[k] = BodyMotion::predict(
                    x[k],
                    v[k],
                    w[k],
                    (q[k], l[k], inv_i),
                    (f * inv_mass[i] + gravity, t),
                    h,
                    bounding_radius[i],
                );
            }
        });
}
