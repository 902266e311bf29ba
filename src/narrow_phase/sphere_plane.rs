use super::{ContactPoint, Geometry};
use crate::math::DVec3;

/// A sphere against the half-space behind a plane through `point` with unit `normal` (pointing
/// into the free side).
pub fn sphere_plane(x: DVec3, r: f64, point: DVec3, normal: DVec3) -> Option<Geometry> {
    let height = (x - point).dot(normal);
    let overlap = r - height;
    // A sphere entirely behind the plane is outside the domain, not in contact.
    if overlap <= 0.0 || height <= -r {
        return None;
    }
    Some(touching_sphere_plane(x, r, point, normal).with_volume(None))
}

/// The contact of a sphere that touches a plane ([`sphere_plane`] found it), by the same
/// operations: what the contact store gives when it is read, having kept none.
pub fn touching_sphere_plane(x: DVec3, r: f64, point: DVec3, normal: DVec3) -> ContactPoint {
    let overlap = r - (x - point).dot(normal);
    ContactPoint {
        normal,
        point: x - normal * (r - 0.5 * overlap),
        overlap,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_resting_into_floor() {
        let g = sphere_plane(DVec3::new(3.0, 2.0, 0.9), 1.0, DVec3::ZERO, DVec3::Z).unwrap();
        assert!((g.overlap - 0.1).abs() < 1e-12);
        assert!((g.point - DVec3::new(3.0, 2.0, -0.05)).length() < 1e-12);
        assert!(sphere_plane(DVec3::new(0.0, 0.0, 1.0), 1.0, DVec3::ZERO, DVec3::Z).is_none());
    }
}
