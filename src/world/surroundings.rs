//! What surrounds the bodies over a step: gravity (its time table, and the work a change of it
//! does), and the walls (where the mesh walls are, how they move over the step, and what the
//! contacts put on them).

use super::World;
use crate::contact::Placement;
use crate::math::DVec3;
use crate::step::WallsNow;

impl World {
    /// Sets gravity to the gravity table's value in the middle of this step (so a ramp gives the
    /// exact change of velocity: the midpoint rule is exact on linear pieces).
    pub(super) fn follow_gravity(&mut self) {
        let Some(table) = &self.gravity_table else {
            return;
        };
        let g = table.value(self.time + 0.5 * self.time_step);
        if g != self.gravity {
            self.change_gravity(g);
        }
    }

    /// Makes `gravity` the field. A change of the field with the bodies where they are changes
    /// their potential energy −Σ m g·x: that change is booked as work done on them, so the
    /// energy ledger still closes (a ghost's by its owner, as everything the ledger adds up).
    pub(super) fn change_gravity(&mut self, gravity: DVec3) {
        let change = gravity - self.gravity;
        let b = &self.bodies;
        self.gravity_work -= (0..b.len())
            .filter(|&i| b.counts(i))
            .map(|i| b.mass[i] * change.dot(b.position[i]))
            .sum::<f64>();
        self.gravity = gravity;
    }

    /// Puts the moving mesh walls where they are at time `t`.
    pub(super) fn move_walls_to(&mut self, t: f64) {
        self.wall_time = t;
        for wall in &mut self.mesh_walls {
            wall.set_time(t);
        }
    }

    /// Each moving mesh wall's motion over the step ending at the walls' time, and at its end.
    pub(super) fn update_wall_states(&mut self, dt: f64) {
        let (now, end) = (self.wall_time - 0.5 * dt, self.wall_time);
        self.wall_states.clear();
        self.wall_states.extend(
            self.mesh_walls.iter().map(|w| {
                (!w.motion.is_fixed()).then(|| [w.motion.state(now), w.motion.state(end)])
            }),
        );
    }

    /// Books the contacts' reactions on the walls over the step `dt` (`step::WallLoads::book`).
    pub(super) fn book_wall_loads(&mut self, dt: f64) {
        let walls = WallsNow {
            planes: &self.planes,
            meshes: &self.mesh_walls,
            states: &self.wall_states,
            time: self.wall_time,
        };
        let at = Placement {
            bodies: &self.bodies,
            shapes: &self.shapes,
            planes: &self.planes,
            laws: &self.pair_laws,
        };
        self.wall_loads.book(&self.contacts, at, walls, dt);
    }
}

#[cfg(test)]
mod tests {
    use crate::math::DVec3;

    /// `World::set_gravity` booked the work of a change of gravity on every body, ghosts too,
    /// where the gravity table's changes left ghosts to their owners: in a share of a decomposed
    /// world a ghost's potential energy would have been booked twice (by its owner too).
    #[test]
    fn set_gravity_books_no_work_on_ghosts() {
        let heights = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.0, 2.0)];
        let mut world = crate::world::spheres_among_walls(Vec::new(), &heights);
        world.bodies.ghost = vec![false, true];
        let mass = world.bodies.mass[0];
        world.set_gravity(DVec3::new(0.0, 0.0, -10.0));
        // −m Δg·x of the owned body at z = 1 m alone: +10 m.
        assert_eq!(world.gravity_work, 10.0 * mass);
        assert_eq!(world.gravity, DVec3::new(0.0, 0.0, -10.0));
    }
}
