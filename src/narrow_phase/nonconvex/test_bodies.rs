//! Bodies and poses shared by the tests of the region contacts.

use super::{Pose, Solid};
use crate::math::{DQuat, DVec3};
use crate::shape::nonconvex_generators::NonConvexMesh;
use crate::shape::NonConvexPolyhedron;

/// A generated body and the pose that puts it at `x`, turned by `q`, as it was described.
pub struct Body {
    pub shape: NonConvexPolyhedron,
    pub mass: crate::shape::MassProperties,
}

impl Body {
    pub fn pose(&self, x: DVec3, q: DQuat) -> Pose {
        Pose {
            position: x + q * self.mass.center_of_mass,
            orientation: (q * self.mass.principal_rotation()).normalize(),
        }
    }

    pub fn at(&self, x: DVec3) -> Pose {
        self.pose(x, DQuat::IDENTITY)
    }

    pub fn solid(&self) -> Solid<'_> {
        Solid::Mesh(&self.shape)
    }
}

pub fn mesh(m: NonConvexMesh) -> Body {
    let (shape, mass) = m.build(false).unwrap();
    Body { shape, mass }
}

pub fn at(x: DVec3) -> Pose {
    Pose {
        position: x,
        orientation: DQuat::IDENTITY,
    }
}
