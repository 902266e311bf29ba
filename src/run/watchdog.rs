//! The energy watchdog: a run whose energy ledger stops closing has blown up, even while every
//! number is still finite. A time step far above the stable one multiplies the energy by
//! thousands within a few hundred steps and throws the bodies out of their box, yet stays finite
//! for a long while (issue #12); the ledger shows it at once.

use crate::energy::EnergyReport;
use crate::wall::SolidSide;
use crate::World;

/// The ledger total may drift by at most this fraction of the energy in play before the run is
/// stopped. Sound runs drift by well under a percent (docs/validation.md); this only catches
/// runs that have gone wrong.
pub const ALLOWED_DRIFT: f64 = 0.5;

/// The ledger at the start, and the most energy that has been in play since.
pub struct EnergyWatch {
    start: EnergyReport,
    in_play: f64,
}

impl EnergyWatch {
    pub fn new(world: &World) -> Self {
        let start = world.energy();
        let mut watch = Self {
            start,
            in_play: 0.0,
        };
        watch.in_play = watch.energy_in_play(&start);
        watch
    }

    /// Every energy the run has moved: kinetic, elastic, what was dissipated, the potential energy
    /// released or taken up, and what insertions, removals, walls and gravity changes brought or
    /// took. Drift is measured against the largest this has been.
    fn energy_in_play(&self, e: &EnergyReport) -> f64 {
        e.kinetic_translational
            + e.kinetic_rotational
            + e.elastic.abs()
            + e.dissipated.abs()
            + (e.potential - self.start.potential).abs()
            + e.inserted.abs()
            + e.removed.abs()
            + e.wall_work.abs()
            + e.gravity_work.abs()
    }

    /// `None` while the ledger closes; else why the run must stop.
    pub fn check(&mut self, world: &World) -> Option<String> {
        self.check_ledger(&world.energy(), world.time(), world.steps_done())
    }

    /// [`EnergyWatch::check`] of the ledger `e` at `time`, after `steps` steps.
    pub fn check_ledger(&mut self, e: &EnergyReport, time: f64, steps: u64) -> Option<String> {
        let e = *e;
        self.in_play = self.in_play.max(self.energy_in_play(&e));
        let drift = e.total() - self.start.total();
        // Energy created is the failure; energy lost beyond the ledger would show as negative
        // drift, and only creation throws bodies about.
        if drift > ALLOWED_DRIFT * self.in_play && self.in_play > 0.0 {
            return Some(format!(
                "the run blew up at t = {:.6e} s (step {}): the energy ledger's total grew by \
                 {drift:.3e} J, more than half of all the energy that has been in play \
                 ({:.3e} J); a sound run stays within a percent. Kinetic energy is now {:.3e} J. \
                 Likely causes: a time step above the stable one (`force_time_step`; `polydem \
                 check` prints the estimate), or material values out of any physical range. The \
                 frames written before are valid.",
                time,
                steps,
                self.in_play,
                e.kinetic_translational + e.kinetic_rotational
            ));
        }
        None
    }
}

/// The first body faster than `limit` [m/s], as a message saying which, how fast and why it
/// matters; `None` while every body is slower. O(bodies).
pub fn too_fast(world: &World, limit: f64) -> Option<String> {
    let b = world.bodies();
    let limit2 = limit * limit;
    let i = (0..b.len()).find(|&i| b.velocity[i].length_squared() > limit2)?;
    Some(format!(
        "the run blew up at t = {:.6e} s (step {}): body {} moves at {:.3e} m/s, more than ten \
         times the fastest impact the scene can bring ({:.3e} m/s: its initial and insertion \
         speeds, a fall across the whole scene, its walls' surfaces, the release of overlaps at \
         the start). Likely causes: a time step above the stable one, or material values out of \
         any physical range. The frames written before are valid.",
        world.time(),
        world.steps_done(),
        b.id[i],
        b.velocity[i].length(),
        limit / 10.0
    ))
}

/// The closed mesh walls of a world, each with the side of it that is solid: a body whose centre
/// lies there has gone through the wall, a blow-up that no energy or speed check need see (a body
/// jumping through a wall in one step touches nothing). Open sheets (a chute) have no inside: a
/// body behind one is refused at the start (`scene::wall_sides`) and shows during the run only by
/// the other checks.
pub struct WallSides {
    walls: Vec<ClosedWall>,
}

/// One closed mesh wall and its solid side.
struct ClosedWall {
    /// The wall's index among the mesh walls.
    index: usize,
    side: SolidSide,
}

impl WallSides {
    /// The closed mesh walls of `world` (open ones and ones enclosing no volume are left out).
    pub fn new(world: &World) -> Self {
        let walls = world
            .mesh_walls()
            .iter()
            .enumerate()
            .filter_map(|(index, w)| SolidSide::of(w).map(|side| ClosedWall { index, side }))
            .collect();
        Self { walls }
    }

    /// Whether there is a closed wall to check.
    pub fn is_empty(&self) -> bool {
        self.walls.is_empty()
    }

    /// `None` while every body's centre is on the open side of every closed mesh wall; else a
    /// message naming the first body found behind one (`names`: the walls' names, planes first,
    /// as in `wall_forces.csv`). O(bodies × log triangles).
    pub fn check(&self, world: &World, names: &[String]) -> Option<String> {
        let b = world.bodies();
        for wall in &self.walls {
            let mesh = &world.mesh_walls()[wall.index];
            let behind = (0..b.len()).find(|&i| wall.side.contains(mesh, b.position[i]));
            let Some(i) = behind else { continue };
            let name = names
                .get(world.planes().len() + wall.index)
                .map(|n| format!(" (\"{n}\" in wall_forces.csv)"))
                .unwrap_or_default();
            let side = wall.side.describe();
            let p = b.position[i];
            return Some(format!(
                "the run blew up at t = {:.6e} s (step {}): the centre of body {} is at \
                 ({:.4e}, {:.4e}, {:.4e}) m, behind [[mesh_wall]] #{}{name}: {side}, where no \
                 body can be. It has gone through the wall. Likely causes: a time step above the \
                 stable one (a body moving further in one step than a contact can stop it; \
                 `polydem check` prints the estimate), a wall too soft for the speed of the \
                 bodies hitting it (a Young's modulus so low that the overlap grows past the \
                 body's radius), or a wall moved by its `motion` faster than the bodies can \
                 follow. The frames written before are valid.",
                world.time(),
                world.steps_done(),
                b.id[i],
                p.x,
                p.y,
                p.z,
                wall.index + 1,
            ));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    fn world_with(walls: Vec<crate::wall::MeshWall>, positions: &[DVec3]) -> World {
        crate::world::spheres_among_walls(walls, positions)
    }

    fn unit_box(facing: crate::wall::Facing) -> crate::wall::MeshWall {
        crate::wall::generators::box_mesh(DVec3::splat(-1.0), DVec3::splat(1.0), 2, facing)
            .unwrap()
            .into_wall(0)
            .unwrap()
    }

    #[test]
    fn bodies_behind_closed_walls_are_found_on_the_solid_side_only() {
        use crate::wall::Facing;
        let (inside, outside) = (DVec3::new(0.3, -0.2, 0.5), DVec3::new(1.5, 0.0, 0.0));
        // A container (facing in): outside is solid.
        let world = world_with(vec![unit_box(Facing::Inward)], &[inside, outside]);
        let sides = WallSides::new(&world);
        let why = sides.check(&world, &[]).unwrap();
        assert!(
            why.contains("body 1") && why.contains("outside the closed"),
            "{why}"
        );
        let world = world_with(vec![unit_box(Facing::Inward)], &[inside]);
        assert!(WallSides::new(&world).check(&world, &[]).is_none());
        // A block (facing out): inside is solid.
        let world = world_with(vec![unit_box(Facing::Outward)], &[outside, inside]);
        let why = WallSides::new(&world)
            .check(&world, &["block".into()])
            .unwrap();
        assert!(
            why.contains("body 1") && why.contains("inside the solid"),
            "{why}"
        );
        assert!(why.contains("(\"block\" in wall_forces.csv)"), "{why}");
        // An open sheet has no solid side: not checked.
        let sheet =
            crate::wall::MeshWall::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]], 0)
                .unwrap();
        let world = world_with(vec![sheet], &[DVec3::new(0.1, 0.1, -0.5)]);
        assert!(WallSides::new(&world).is_empty());
        // A moving container (faster than anything, through the body from behind, where it
        // does not act): the body is judged against where the wall is now.
        let mut moving = unit_box(Facing::Inward);
        moving.motion = crate::wall::WallMotion::fixed()
            .with_velocity(DVec3::new(20.0, 0.0, 0.0))
            .unwrap();
        let mut world = world_with(vec![moving], &[DVec3::new(1.2, 0.0, 0.0)]);
        let sides = WallSides::new(&world);
        assert!(sides.check(&world, &[]).is_some());
        world.run_steps(2500); // the box moved by 0.5 m: now from -0.5 to 1.5
        assert!(sides.check(&world, &[]).is_none());
    }

    #[test]
    fn a_body_faster_than_the_limit_is_named() {
        let mut world = world_with(Vec::new(), &[DVec3::ZERO, DVec3::Y]);
        for (v, speed) in world.bodies_mut().velocity.iter_mut().zip([1.0, 30.0]) {
            *v = DVec3::X * speed;
        }
        assert!(too_fast(&world, 40.0).is_none());
        let why = too_fast(&world, 20.0).unwrap();
        assert!(why.contains("body 1 moves at 3.000e1 m/s"), "{why}");
    }
}
