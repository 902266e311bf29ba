//! Time stepping: velocity Verlet for translation, a symplectic splitting for rotation.
//!
//! One step is kick(dt/2) → drift(dt) → [new forces] → kick(dt/2) (Verlet 1967; Swope et al.
//! 1982). Rotation uses the same pattern on the world-frame angular momentum L: the torque kicks L,
//! and the torque-free drift turns the orientation by the splitting of [`rotation`] while L stays
//! fixed (Dullweber, Leimkuhler & McLachlan 1997). Both parts are time-reversible and symplectic,
//! so a free body keeps its energy and angular momentum over long runs.
//!
//! The step touches every body twice, not five times (once between two steps of a batch): [`kick_drift`] does the first half kick and
//! the drift and packs the motion the contact loops read ([`BodyMotion`]) in the same pass, and
//! the closing half kick ([`Kick::apply`]) runs in the pass that sums each body's contact forces
//! (`step::accumulate`), while they are in registers. Between two steps of one batch
//! (`World::run_steps`) nothing reads the forces or the velocities, and both the sums and the
//! closing half kick are left to the next [`kick_drift`] ([`Closing`]), which reads the same
//! arrays anyway: one pass over the bodies a step instead of two (the same operations in the same
//! order, so the same bits).

mod isotropic;
pub mod last_level_cache;
pub mod motion;
pub mod rotation;

use isotropic::Arrays;
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

/// Completes a body's force and moment sums, which hold its own contacts' loads (those it is
/// body `a` of), with the loads of the contacts whose partner it is (`step::IncomingSums`).
pub trait ForceSums: Sync {
    /// Body `body`'s whole force and moment, from the sums of its own contacts.
    fn complete(&self, body: usize, force: DVec3, torque: DVec3) -> (DVec3, DVec3);
    /// Asks for what [`ForceSums::complete`] of `body` will read (a hint only).
    fn prefetch(&self, body: usize);
    /// Whether the sums still need completing: false when the contact loop has done it.
    fn needed(&self) -> bool;
}

/// What the last step left to the next [`kick_drift`]: its force sums (`sums`) and its closing
/// half kick.
pub struct Closing<'a, S: ForceSums> {
    pub kick: Kick,
    pub sums: &'a S,
}

/// One body's velocities and what the kick reads of it.
pub struct KickedBody<'a> {
    pub velocity: &'a mut DVec3,
    pub angular_momentum: &'a mut DVec3,
    pub angular_velocity: &'a mut DVec3,
    /// These two by reference: an isotropic body's kick does not read the orientation, and the
    /// compiler made a copy of both on the stack for the out-of-line path of other bodies, whose
    /// reading back in halves stalled the force sums' pass once per body (8 % of its samples).
    pub orientation: &'a DQuat,
    pub inv_inertia: &'a DVec3,
    pub inv_mass: f64,
}

impl Kick {
    #[inline(always)]
    pub fn apply(&self, body: KickedBody, force: DVec3, torque: DVec3) {
        *body.velocity += (force * body.inv_mass + self.gravity) * self.h;
        *body.angular_momentum += torque * self.h;
        *body.angular_velocity = rotation::angular_velocity(
            *body.orientation,
            *body.angular_momentum,
            *body.inv_inertia,
        );
    }
}

/// The first half of a step for every body: the half kick with the forces of the last
/// evaluation (still in `bodies.force` and `bodies.torque`), the drift over `dt`, and the motion
/// the contact loops read, with the velocities at the end of the step predicted from the same
/// forces (see [`BodyMotion::predict`]). `closing`: the last step's force sums and closing half
/// kick, if that step left them to this pass; the sums are then completed first (and written:
/// `bodies.force` and `bodies.torque` are the whole loads after this pass, as after the sums').
pub fn kick_drift<S: ForceSums>(
    bodies: &mut Bodies,
    gravity: DVec3,
    dt: f64,
    motion: &mut Vec<BodyMotion>,
    closing: Option<Closing<S>>,
) {
    let kick = Kick {
        gravity,
        h: 0.5 * dt,
    };
    crate::tight::resize_tight(motion, bodies.len(), BodyMotion::default());
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
    let (inv_mass, inv_inertia) = (&*inv_mass, &*inv_inertia);
    let bounding_radius = &*bounding_radius;
    let stream_motion = motion::streams_motion(position.len());
    let (closing_kick, sums) = match closing {
        Some(c) => (Some(c.kick), Some(c.sums).filter(|s| s.needed())),
        None => (None, None),
    };
    position
        .par_chunks_mut(BODIES_PER_TASK)
        .zip(velocity.par_chunks_mut(BODIES_PER_TASK))
        .zip(orientation.par_chunks_mut(BODIES_PER_TASK))
        .zip(angular_momentum.par_chunks_mut(BODIES_PER_TASK))
        .zip(angular_velocity.par_chunks_mut(BODIES_PER_TASK))
        .zip(motion.par_chunks_mut(BODIES_PER_TASK))
        .zip(force.par_chunks_mut(BODIES_PER_TASK))
        .zip(torque.par_chunks_mut(BODIES_PER_TASK))
        .enumerate()
        .for_each(|(c, (((((((x, v), q), l), w), m), f), t))| {
            let bodies = c * BODIES_PER_TASK..c * BODIES_PER_TASK + x.len();
            if let Some(sums) = sums {
                complete_sums(sums, bodies.start, f, t);
            }
            let (force, torque) = (&*f, &*t);
            let mut arrays = Arrays {
                position: x,
                velocity: v,
                orientation: q,
                angular_momentum: l,
                angular_velocity: w,
                motion: m,
                inv_mass: &inv_mass[bodies.clone()],
                inv_inertia: &inv_inertia[bodies.clone()],
                force,
                torque,
                bounding_radius: &bounding_radius[bodies],
                stream_motion,
            };
            kick_drift_task(&mut arrays, closing_kick, kick, dt);
            motion::end_streaming(stream_motion);
        });
}

/// The force and moment sums of the task's bodies from `first` on (their own contacts' in
/// `force` and `torque`), completed by `sums`: a loop of its own before the kicks, which then
/// read the task's sums from the cache. It asks for nothing ahead: a body's incoming loads lie
/// near the last body's in the store, and the hardware's prefetch found them; asked for eight
/// bodies ahead (as `step::accumulate` does, whose loop has the kick's work between), the loop
/// took 1.49 s of the 65k window where without it took 1.18–1.30 s, and 0.42 s of the 10k
/// window for 0.29 s (a timer around this loop in a probe build; docs/benchmarks.md).
fn complete_sums<S: ForceSums>(sums: &S, first: usize, force: &mut [DVec3], torque: &mut [DVec3]) {
    for (k, (f, t)) in force.iter_mut().zip(torque.iter_mut()).enumerate() {
        (*f, *t) = sums.complete(first + k, *f, *t);
    }
}

/// [`kick_drift`] over one task's bodies: isotropic ones four at a time where the CPU can.
fn kick_drift_task(arrays: &mut Arrays, closing: Option<Kick>, kick: Kick, dt: f64) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, which is all `kick_drift_avx` is compiled for.
        unsafe { kick_drift_avx(arrays, closing, kick, dt) };
        return;
    }
    // SAFETY: off x86-64 the four-wide path is plain arrays; on it, without AVX, `by_fours` is
    // false and the path is not taken.
    let by_fours = cfg!(not(target_arch = "x86_64"));
    unsafe { kick_drift_bodies(arrays, closing, kick, dt, by_fours) };
}

/// [`kick_drift_bodies`] compiled for AVX, whose 256-bit registers hold an `F4`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn kick_drift_avx(arrays: &mut Arrays, closing: Option<Kick>, kick: Kick, dt: f64) {
    kick_drift_bodies(arrays, closing, kick, dt, true);
}

/// The last step's closing half kick (if it was left to this pass), then the opening half kick
/// and the drift, of the bodies of `arrays` in order: four isotropic bodies at once when
/// `by_fours` (`isotropic::four`), the others one by one.
///
/// # Safety
/// `by_fours` only on a CPU with AVX, from code compiled for it (off x86-64, always).
#[inline(always)]
unsafe fn kick_drift_bodies(
    arrays: &mut Arrays,
    closing: Option<Kick>,
    kick: Kick,
    dt: f64,
    by_fours: bool,
) {
    let count = arrays.position.len();
    let mut k = 0;
    while k < count {
        let four = by_fours
            && k + 4 <= count
            && rotation::is_isotropic(arrays.inv_inertia[k])
            && rotation::is_isotropic(arrays.inv_inertia[k + 1])
            && rotation::is_isotropic(arrays.inv_inertia[k + 2])
            && rotation::is_isotropic(arrays.inv_inertia[k + 3]);
        // SAFETY: `by_fours` only where the four-wide path may run (the caller's promise).
        if four && unsafe { isotropic::four(arrays, k, closing, kick, dt) } {
            k += 4;
        } else {
            kick_drift_one(arrays, k, closing, kick, dt);
            k += 1;
        }
    }
}

/// The closing half kick left to this pass (if any), the opening half kick and the drift of
/// body `k` of `arrays`.
#[inline(always)]
fn kick_drift_one(arrays: &mut Arrays, k: usize, closing: Option<Kick>, kick: Kick, dt: f64) {
    if let Some(closing) = closing {
        // As `step::accumulate` would have given it, with the same forces.
        let body = KickedBody {
            velocity: &mut arrays.velocity[k],
            angular_momentum: &mut arrays.angular_momentum[k],
            angular_velocity: &mut arrays.angular_velocity[k],
            orientation: &arrays.orientation[k],
            inv_mass: arrays.inv_mass[k],
            inv_inertia: &arrays.inv_inertia[k],
        };
        closing.apply(body, arrays.force[k], arrays.torque[k]);
    }
    let Arrays {
        position: x,
        velocity: v,
        orientation: q,
        angular_momentum: l,
        angular_velocity: w,
        motion: m,
        ..
    } = arrays;
    let (f, t, inv_i) = (arrays.force[k], arrays.torque[k], arrays.inv_inertia[k]);
    let (inv_mass, h) = (arrays.inv_mass[k], kick.h);
    if rotation::is_isotropic(inv_i) {
        // A sphere (or a cube, a regular polyhedron): the general path below, with the steps its
        // isotropic branches take and nothing else; ω = L/I is the same before and after the
        // drift.
        let acceleration = f * inv_mass + kick.gravity;
        v[k] += acceleration * h;
        l[k] += t * h;
        w[k] = l[k] * inv_i.x;
        x[k] += v[k] * dt;
        q[k] = rotation::drift_isotropic(q[k], l[k], inv_i, dt);
        let packed = BodyMotion {
            position: x[k],
            velocity: v[k],
            angular_velocity: w[k],
            velocity_end: v[k] + acceleration * h,
            angular_velocity_end: (l[k] + t * h) * inv_i.x,
            radius: arrays.bounding_radius[k],
        };
        motion::write(&mut m[k], packed, arrays.stream_motion);
        return;
    }
    let body = KickedBody {
        velocity: &mut v[k],
        angular_momentum: &mut l[k],
        angular_velocity: &mut w[k],
        orientation: &q[k],
        inv_mass,
        inv_inertia: &arrays.inv_inertia[k],
    };
    kick.apply(body, f, t);
    x[k] += v[k] * dt;
    q[k] = rotation::drift(q[k], l[k], inv_i, dt);
    // The body frame turned, so the world-frame ω of a non-spherical body changed.
    w[k] = rotation::angular_velocity(q[k], l[k], inv_i);
    let packed = BodyMotion::predict(
        x[k],
        v[k],
        w[k],
        (q[k], l[k], inv_i),
        (f * inv_mass + kick.gravity, t),
        h,
        arrays.bounding_radius[k],
    );
    motion::write(&mut m[k], packed, arrays.stream_motion);
}
