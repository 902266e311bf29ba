//! A mesh body and a sphere: the sphere against the body's surface as against a mesh wall, in
//! the body's frame.

use super::super::separation::bounding_spheres_separated;
use super::super::sphere_mesh::sphere_mesh_contacts;
use super::super::Geometry;
use super::regions::RegionScratch;
use super::{Pose, MAX_REGIONS};
use crate::math::DVec3;
use crate::shape::NonConvexPolyhedron;

/// The contacts of a mesh body with a sphere (`centre`, `radius`), normals pointing from the
/// sphere towards the body: the sphere–mesh contacts of the body's surface (one per local
/// minimum of the distance, see `sphere_mesh`), worked in the body frame.
pub fn mesh_sphere(
    shape: &NonConvexPolyhedron,
    pose: Pose,
    centre: DVec3,
    radius: f64,
    scratch: &mut RegionScratch,
    out: &mut Vec<Geometry>,
) {
    out.clear();
    if bounding_spheres_separated(pose.position, shape.bounding_radius(), centre, radius) {
        return;
    }
    let local = pose.orientation.inverse() * (centre - pose.position);
    let RegionScratch {
        mesh,
        mesh_contacts,
        ..
    } = scratch;
    sphere_mesh_contacts(local, radius, shape.surface(), mesh, mesh_contacts);
    for c in mesh_contacts.iter().take(MAX_REGIONS) {
        let g = c.geometry;
        out.push(Geometry {
            normal: -(pose.orientation * g.normal),
            point: pose.position + pose.orientation * g.point,
            overlap: g.overlap,
            volume: None,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_bodies::mesh;
    use super::*;
    use crate::shape::nonconvex_generators::jack;

    #[test]
    fn sphere_in_the_crook_of_a_jack_touches_two_arms() {
        let j = mesh(jack(3.0, 1.0).unwrap());
        let mut s = RegionScratch::new();
        let mut out = Vec::new();
        // Between the +x and +y arms (faces y = 0.5 and x = 0.5), radius 0.5, 0.01 deep each.
        let r = 0.5;
        let c = DVec3::new(1.0 - 0.01, 1.0 - 0.01, 0.0);
        mesh_sphere(&j.shape, j.at(DVec3::ZERO), c, r, &mut s, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        for g in &out {
            assert!((g.overlap - 0.01).abs() < 1e-12);
            // From the sphere towards the jack: −x or −y.
            assert!(
                (g.normal + DVec3::X).length() < 1e-12 || (g.normal + DVec3::Y).length() < 1e-12
            );
        }
    }
}
