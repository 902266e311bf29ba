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
}

impl Bodies {
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
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
    }
}
