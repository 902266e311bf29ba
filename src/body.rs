//! Rigid-body state, stored as arrays (structure of arrays).
//!
//! The step loop touches positions, velocities and forces of every body each step; keeping each
//! quantity contiguous lets those loops vectorise and split across threads without gathering.
//! Index `i` in every array is the same body. Bodies never move between indices during a step.

use crate::material::MaterialId;
use crate::math::{permute_in_place, DQuat, DVec3};
use crate::shape::Shape;

/// Index of a shape in the world's shape table (bodies of equal shape share one entry).
pub type ShapeId = u32;

/// Everything needed to add one body to the world.
#[derive(Clone, Debug)]
pub struct BodyInit {
    pub shape: Shape,
    pub material: MaterialId,
    pub position: DVec3,
    pub orientation: DQuat,
    pub velocity: DVec3,
    pub angular_velocity: DVec3,
}

/// One body's every number, as plain data: what a share of a decomposed world receives to hold
/// a body it did not (see `decomposition`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyRecord {
    pub id: u64,
    pub shape: ShapeId,
    pub material: MaterialId,
    pub bounding_radius: f64,
    pub equivalent_radius: f64,
    pub mass: f64,
    pub inertia: DVec3,
    pub motion: BodyMotionState,
}

/// What a step changes of a body: what a share of a decomposed world copies, after every step,
/// from a body's owner into its ghosts.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BodyMotionState {
    pub position: DVec3,
    pub orientation: DQuat,
    pub velocity: DVec3,
    pub angular_momentum: DVec3,
    pub angular_velocity: DVec3,
    pub force: DVec3,
    pub torque: DVec3,
}

impl BodyMotionState {
    /// Numbers per state in [`BodyMotionState::to_array`].
    pub const LEN: usize = 22;

    /// The state as plain numbers (for a transport that sends arrays of numbers).
    pub fn to_array(&self) -> [f64; Self::LEN] {
        let mut a = [0.0; Self::LEN];
        let parts: [&[f64]; 7] = [
            &self.position.to_array(),
            &self.orientation.to_array(),
            &self.velocity.to_array(),
            &self.angular_momentum.to_array(),
            &self.angular_velocity.to_array(),
            &self.force.to_array(),
            &self.torque.to_array(),
        ];
        let mut k = 0;
        for part in parts {
            a[k..k + part.len()].copy_from_slice(part);
            k += part.len();
        }
        a
    }

    /// The state [`BodyMotionState::to_array`] gave (`a` holds [`BodyMotionState::LEN`] numbers).
    pub fn from_slice(a: &[f64]) -> Self {
        let v = |k: usize| DVec3::from_slice(&a[k..k + 3]);
        BodyMotionState {
            position: v(0),
            orientation: DQuat::from_slice(&a[3..7]),
            velocity: v(7),
            angular_momentum: v(10),
            angular_velocity: v(13),
            force: v(16),
            torque: v(19),
        }
    }
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Bodies {
    /// User-visible identifier, stable for the life of the body.
    pub id: Vec<u64>,
    pub shape: Vec<ShapeId>,
    pub material: Vec<MaterialId>,
    /// Radius of a sphere about the centre of mass enclosing the shape (the sphere's radius).
    pub bounding_radius: Vec<f64>,
    /// Radius of the sphere of equal volume (the sphere's radius): the size in contact laws.
    pub equivalent_radius: Vec<f64>,

    pub position: Vec<DVec3>,
    /// Body frame → world frame.
    pub orientation: Vec<DQuat>,
    pub velocity: Vec<DVec3>,
    /// Angular momentum in the world frame: the integrated rotational state (see `integrate`).
    pub angular_momentum: Vec<DVec3>,
    /// World-frame angular velocity, derived from the angular momentum after each update.
    pub angular_velocity: Vec<DVec3>,

    pub mass: Vec<f64>,
    pub inv_mass: Vec<f64>,
    /// Principal moments of inertia (body frame).
    pub inertia: Vec<DVec3>,
    pub inv_inertia: Vec<DVec3>,

    /// Contact force and torque accumulated in the current step (world frame).
    pub force: Vec<DVec3>,
    pub torque: Vec<DVec3>,

    /// Whether the body is a ghost: a copy, held by one share of a decomposed world, of a body
    /// that another share owns and steps (see `decomposition`). A ghost is stepped like any body,
    /// so that the owned bodies it touches see it move, but the energy ledger, the meters, the
    /// wall loads and the outputs leave it to its owner. Empty when no body is a ghost (the
    /// usual world, and checkpoints of it).
    #[serde(default)]
    pub ghost: Vec<bool>,
}

impl Bodies {
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Room for `additional` more bodies, exactly: a scene's bodies are counted before they are
    /// added, and pushing them one by one would double every array up to twice their number.
    pub fn reserve(&mut self, additional: usize) {
        self.id.reserve_exact(additional);
        self.shape.reserve_exact(additional);
        self.material.reserve_exact(additional);
        self.bounding_radius.reserve_exact(additional);
        self.equivalent_radius.reserve_exact(additional);
        self.position.reserve_exact(additional);
        self.orientation.reserve_exact(additional);
        self.velocity.reserve_exact(additional);
        self.angular_momentum.reserve_exact(additional);
        self.angular_velocity.reserve_exact(additional);
        self.mass.reserve_exact(additional);
        self.inv_mass.reserve_exact(additional);
        self.inertia.reserve_exact(additional);
        self.inv_inertia.reserve_exact(additional);
        self.force.reserve_exact(additional);
        self.torque.reserve_exact(additional);
        if !self.ghost.is_empty() {
            self.ghost.reserve_exact(additional);
        }
    }

    /// Room for one more body. Bodies added during a run come a few at a time (an inlet, a
    /// share's ghosts and migrants): the arrays grow by a sixteenth, not by doubling (a conveyor
    /// filled to 100,000 bodies would have held room for 131,072).
    fn room_for_one(&mut self) {
        let len = self.id.len();
        if len == self.id.capacity() {
            // The room kept beyond the length (`tight::with_room`), at least sixteen bodies.
            self.reserve((crate::tight::with_room(len) - len).max(16));
        }
    }

    /// Appends a body; `mass` and `inertia` come from the shape's mass properties and density.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        id: u64,
        shape: ShapeId,
        material: MaterialId,
        bounding_radius: f64,
        equivalent_radius: f64,
        mass: f64,
        inertia: DVec3,
        init: &BodyInit,
    ) {
        self.room_for_one();
        let orientation = init.orientation.normalize();
        // L = R I Rᵀ ω, from the user-given world-frame angular velocity.
        let omega_body = orientation.inverse() * init.angular_velocity;
        let angular_momentum = orientation * (inertia * omega_body);
        self.id.push(id);
        self.shape.push(shape);
        self.material.push(material);
        self.bounding_radius.push(bounding_radius);
        self.equivalent_radius.push(equivalent_radius);
        self.position.push(init.position);
        self.orientation.push(orientation);
        self.velocity.push(init.velocity);
        self.angular_momentum.push(angular_momentum);
        self.angular_velocity.push(init.angular_velocity);
        self.mass.push(mass);
        self.inv_mass.push(1.0 / mass);
        self.inertia.push(inertia);
        self.inv_inertia.push(inertia.recip());
        self.force.push(DVec3::ZERO);
        self.torque.push(DVec3::ZERO);
        if !self.ghost.is_empty() {
            self.ghost.push(false);
        }
    }

    /// Whether body `i` is a ghost (see [`Bodies::ghost`]).
    #[inline]
    pub fn is_ghost(&self, i: usize) -> bool {
        self.ghost.get(i).copied().unwrap_or(false)
    }

    /// Whether body `i` counts in this world's sums (ledger, meters, wall loads, outputs): every
    /// body but a ghost.
    #[inline]
    pub fn counts(&self, i: usize) -> bool {
        !self.is_ghost(i)
    }

    /// Body `i`'s every number.
    pub fn record(&self, i: usize) -> BodyRecord {
        BodyRecord {
            id: self.id[i],
            shape: self.shape[i],
            material: self.material[i],
            bounding_radius: self.bounding_radius[i],
            equivalent_radius: self.equivalent_radius[i],
            mass: self.mass[i],
            inertia: self.inertia[i],
            motion: self.motion_state(i),
        }
    }

    /// What a step changed of body `i`.
    pub fn motion_state(&self, i: usize) -> BodyMotionState {
        BodyMotionState {
            position: self.position[i],
            orientation: self.orientation[i],
            velocity: self.velocity[i],
            angular_momentum: self.angular_momentum[i],
            angular_velocity: self.angular_velocity[i],
            force: self.force[i],
            torque: self.torque[i],
        }
    }

    /// Makes body `i`'s motion `m`, bit for bit.
    pub fn set_motion_state(&mut self, i: usize, m: &BodyMotionState) {
        self.position[i] = m.position;
        self.orientation[i] = m.orientation;
        self.velocity[i] = m.velocity;
        self.angular_momentum[i] = m.angular_momentum;
        self.angular_velocity[i] = m.angular_velocity;
        self.force[i] = m.force;
        self.torque[i] = m.torque;
    }

    /// Appends the body `r` describes, bit for bit, a ghost if `ghost`.
    pub fn push_record(&mut self, r: &BodyRecord, ghost: bool) {
        if ghost && self.ghost.is_empty() {
            self.ghost.resize(self.len(), false);
        }
        self.room_for_one();
        self.id.push(r.id);
        self.shape.push(r.shape);
        self.material.push(r.material);
        self.bounding_radius.push(r.bounding_radius);
        self.equivalent_radius.push(r.equivalent_radius);
        self.position.push(r.motion.position);
        self.orientation.push(r.motion.orientation);
        self.velocity.push(r.motion.velocity);
        self.angular_momentum.push(r.motion.angular_momentum);
        self.angular_velocity.push(r.motion.angular_velocity);
        self.mass.push(r.mass);
        self.inv_mass.push(1.0 / r.mass);
        self.inertia.push(r.inertia);
        self.inv_inertia.push(r.inertia.recip());
        self.force.push(r.motion.force);
        self.torque.push(r.motion.torque);
        if !self.ghost.is_empty() {
            self.ghost.push(ghost);
        }
    }

    /// Marks which bodies are ghosts (`ghost[i]`); none: the mask is dropped.
    pub fn set_ghosts(&mut self, ghost: &[bool]) {
        debug_assert_eq!(ghost.len(), self.len());
        self.ghost.clear();
        if ghost.iter().any(|&g| g) {
            self.ghost.extend_from_slice(ghost);
        }
    }

    /// Keeps the bodies whose `keep` flag is set, in their order; the others are removed.
    pub fn retain(&mut self, keep: &[bool]) {
        fn compact<T: Copy>(values: &mut Vec<T>, keep: &[bool]) {
            let mut next = 0;
            for i in 0..values.len() {
                if keep[i] {
                    values[next] = values[i];
                    next += 1;
                }
            }
            values.truncate(next);
        }
        compact(&mut self.id, keep);
        compact(&mut self.shape, keep);
        compact(&mut self.material, keep);
        compact(&mut self.bounding_radius, keep);
        compact(&mut self.equivalent_radius, keep);
        compact(&mut self.position, keep);
        compact(&mut self.orientation, keep);
        compact(&mut self.velocity, keep);
        compact(&mut self.angular_momentum, keep);
        compact(&mut self.angular_velocity, keep);
        compact(&mut self.mass, keep);
        compact(&mut self.inv_mass, keep);
        compact(&mut self.inertia, keep);
        compact(&mut self.inv_inertia, keep);
        compact(&mut self.force, keep);
        compact(&mut self.torque, keep);
        if !self.ghost.is_empty() {
            compact(&mut self.ghost, keep);
        }
    }

    /// Puts the bodies in a new order: body `k` becomes what body `order[k]` was.
    pub fn permute(&mut self, order: &[u32]) {
        debug_assert_eq!(order.len(), self.len());
        let done = &mut Vec::new();
        permute_in_place(&mut self.id, order, done);
        permute_in_place(&mut self.shape, order, done);
        permute_in_place(&mut self.material, order, done);
        permute_in_place(&mut self.bounding_radius, order, done);
        permute_in_place(&mut self.equivalent_radius, order, done);
        permute_in_place(&mut self.position, order, done);
        permute_in_place(&mut self.orientation, order, done);
        permute_in_place(&mut self.velocity, order, done);
        permute_in_place(&mut self.angular_momentum, order, done);
        permute_in_place(&mut self.angular_velocity, order, done);
        permute_in_place(&mut self.mass, order, done);
        permute_in_place(&mut self.inv_mass, order, done);
        permute_in_place(&mut self.inertia, order, done);
        permute_in_place(&mut self.inv_inertia, order, done);
        permute_in_place(&mut self.force, order, done);
        permute_in_place(&mut self.torque, order, done);
        if !self.ghost.is_empty() {
            permute_in_place(&mut self.ghost, order, done);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::{Shape, Sphere};
    use crate::tight::with_room;

    /// Regression (issue #18, memory): bodies inserted during a run, one push at a time, doubled
    /// every array up to twice their count.
    #[test]
    fn bodies_added_one_by_one_keep_a_little_room_not_twice_their_count() {
        let init = BodyInit {
            shape: Shape::Sphere(Sphere { radius: 1e-3 }),
            material: 0,
            position: DVec3::ZERO,
            orientation: DQuat::IDENTITY,
            velocity: DVec3::ZERO,
            angular_velocity: DVec3::ZERO,
        };
        let mut bodies = Bodies::default();
        for id in 0..3000 {
            bodies.push(id, 0, 0, 1e-3, 1e-3, 1e-5, DVec3::splat(4e-12), &init);
        }
        assert_eq!(bodies.len(), 3000);
        let most = with_room(3000) + 16;
        let capacities = [
            bodies.id.capacity(),
            bodies.position.capacity(),
            bodies.orientation.capacity(),
            bodies.inv_inertia.capacity(),
            bodies.torque.capacity(),
        ];
        assert!(capacities.iter().all(|&c| c <= most), "{capacities:?}");
    }

    #[test]
    fn a_motion_state_goes_through_an_array_bit_for_bit() {
        let s = BodyMotionState {
            position: DVec3::new(1.0, -2.0, 3.5),
            orientation: DQuat::from_xyzw(0.1, 0.2, 0.3, 0.927),
            velocity: DVec3::new(-0.0, 1e-300, f64::MAX),
            angular_momentum: DVec3::new(4.0, 5.0, 6.0),
            angular_velocity: DVec3::new(7.0, 8.0, 9.0),
            force: DVec3::new(10.0, 11.0, 12.0),
            torque: DVec3::new(13.0, 14.0, 15.0),
        };
        let back = BodyMotionState::from_slice(&s.to_array());
        assert_eq!(back, s);
        assert!(back.velocity.x.is_sign_negative());
    }
}
