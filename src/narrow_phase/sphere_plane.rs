use super::Geometry;
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
    Some(Geometry {
        normal,
        point: x - normal * (r - 0.5 * overlap),
        overlap,
        volume: None,
    })
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
