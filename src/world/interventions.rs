//! What a script may change between steps (a loading protocol, a parameter sweep): gravity, the
//! motion of a mesh wall, the velocity of a body. Each keeps the energy ledger closing, as the
//! scene's own time tables and insertions do; bodies are inserted and removed with
//! `world/population.rs`.

use super::World;
use crate::integrate;
use crate::math::DVec3;
use crate::wall::WallMotion;

/// Why a new motion cannot be given to a mesh wall.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WallMotionChangeError {
    #[error("there is no mesh wall {wall} (the world has {count})")]
    NoSuchWall { wall: usize, count: usize },
    #[error(
        "the new motion would move mesh wall {wall} by {distance:.3e} m at once (t = {time:.6} \
         s): it must agree with the old one until now"
    )]
    Jump {
        wall: usize,
        time: f64,
        distance: f64,
    },
}

impl World {
    /// Sets gravity from now on [m/s²], replacing a gravity table. The change of the bodies'
    /// potential energy where they are is booked as work done on them (`gravity_work`), as a
    /// gravity table's changes are.
    pub fn set_gravity(&mut self, gravity: DVec3) {
        self.change_gravity(gravity);
        self.gravity_table = None;
    }

    /// Gives mesh wall `wall` a new motion from now on. The motion must put the wall where it is
    /// now (build it with `WallMotion::with_velocity_changed_at` or `with_rpm_changed_at` from
    /// the wall's motion at [`World::time`]); the work the wall does is booked as before.
    pub fn set_wall_motion(
        &mut self,
        wall: usize,
        motion: WallMotion,
    ) -> Result<(), WallMotionChangeError> {
        let count = self.mesh_walls.len();
        let w = self
            .mesh_walls
            .get_mut(wall)
            .ok_or(WallMotionChangeError::NoSuchWall { wall, count })?;
        let distance = super::snapshot::farthest_move(w, &motion.pose(self.wall_time), &w.pose());
        let size = w.bounds().extent().length().max(f64::MIN_POSITIVE);
        if distance > 1e-12 * size {
            return Err(WallMotionChangeError::Jump {
                wall,
                time: self.wall_time,
                distance,
            });
        }
        w.motion = motion;
        w.set_time(self.wall_time);
        Ok(())
    }

    /// Sets the velocity [m/s] and angular velocity [rad/s] of the body at `index`. The kinetic
    /// energy given or taken is booked with the energy brought in (`inserted`), so the ledger
    /// still closes.
    pub fn set_velocity(&mut self, index: usize, velocity: DVec3, angular_velocity: DVec3) {
        let before = self.body_energy(index);
        let b = &mut self.bodies;
        b.velocity[index] = velocity;
        // L = R I Rᵀ ω, as when the body was added.
        let q = b.orientation[index];
        b.angular_momentum[index] = q * (b.inertia[index] * (q.inverse() * angular_velocity));
        b.angular_velocity[index] = integrate::rotation::angular_velocity(
            q,
            b.angular_momentum[index],
            b.inv_inertia[index],
        );
        self.energy_inserted += self.body_energy(index) - before;
    }
}
