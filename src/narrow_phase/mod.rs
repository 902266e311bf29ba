//! Narrow phase: the contact geometry of a pair that the broad phase found close.
//!
//! One file per pair of shape kinds. Each returns `None` when the bodies do not touch.

mod clip;
mod convex_convex;
mod convex_mesh;
mod convex_plane;
mod convex_sphere;
mod dispatch;
pub mod nonconvex;
pub mod separation;
mod sphere_mesh;
mod sphere_plane;
mod sphere_sphere;
mod vertex_penetration;

pub use clip::{ClipScratch, Plane};
pub use convex_convex::{convex_convex, VolumeContact};
pub use convex_mesh::{
    convex_mesh, convex_mesh_contacts, nonconvex_mesh_contacts, ConvexMeshScratch,
};
pub use convex_plane::convex_plane;
pub use convex_sphere::{convex_sphere, spherical_cap_volume, SphereContact};
pub use dispatch::{
    body_body, body_body_regions, body_plane, body_plane_regions, effective_radius, Posed,
};
pub use nonconvex::{RegionScratch, MAX_REGIONS};
pub use sphere_mesh::{
    closest_point_on_triangle, is_behind_mesh, sphere_mesh, sphere_mesh_contacts,
    sphere_mesh_contacts_among, triangles_within, MeshContact, MeshScratch, TriangleRegion,
};
pub use sphere_plane::{sphere_plane, touching_sphere_plane};
pub use sphere_sphere::{overlapping_spheres, sphere_sphere};
pub use vertex_penetration::{vertex_penetration, PenetratingPoint, PenetrationSet, PointKind};

use crate::contact_law::OverlapVolume;
use crate::math::DVec3;
use crate::wall::WallPose;

/// Where and how deeply two bodies overlap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Unit normal pointing from the second body (or wall) towards the first.
    pub normal: DVec3,
    /// Contact point: the middle of the overlap [m].
    pub point: DVec3,
    /// Overlap depth δ > 0 [m] (the mean depth V/A for a volume overlap).
    pub overlap: f64,
    /// Overlap volume and area of polyhedra under the volume law; `None` for point contacts.
    pub volume: Option<OverlapVolume>,
}

/// The part of a contact's geometry every contact has: what the contact store keeps per entry
/// (polyhedra's overlap volumes are kept apart, so that a sphere contact carries nothing it does
/// not use).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactPoint {
    pub normal: DVec3,
    pub point: DVec3,
    pub overlap: f64,
}

impl ContactPoint {
    pub fn with_volume(self, volume: Option<OverlapVolume>) -> Geometry {
        Geometry {
            normal: self.normal,
            point: self.point,
            overlap: self.overlap,
            volume,
        }
    }

    /// The same contact seen after the rigid motion `pose` (found on a moving wall in its
    /// reference placement, brought to the world). Identity poses leave it bit for bit.
    pub fn moved(mut self, pose: &WallPose) -> Self {
        if pose.is_identity() {
            return self;
        }
        self.normal = pose.rotation * self.normal;
        self.point = pose.to_world(self.point);
        self
    }
}

impl Geometry {
    pub fn contact_point(&self) -> ContactPoint {
        ContactPoint {
            normal: self.normal,
            point: self.point,
            overlap: self.overlap,
        }
    }

    /// The same contact seen after the rigid motion `pose` (found on a moving wall in its
    /// reference placement, brought to the world). Identity poses leave it bit for bit.
    pub fn moved(mut self, pose: &WallPose) -> Self {
        if pose.is_identity() {
            return self;
        }
        let moved = self.contact_point().moved(pose);
        (self.normal, self.point) = (moved.normal, moved.point);
        if let Some(v) = &mut self.volume {
            v.couple = pose.rotation * v.couple;
        }
        self
    }
}
