use super::{ContactPoint, Geometry};
use crate::math::DVec3;

/// Two spheres overlap when their centres are closer than the sum of their radii.
pub fn sphere_sphere(xi: DVec3, ri: f64, xj: DVec3, rj: f64) -> Option<Geometry> {
    let reach = ri + rj;
    // Written so that a NaN position gives a (NaN) contact: a blown-up body must show, not vanish.
    let apart = (xi - xj).length_squared() >= reach * reach;
    (!apart).then(|| {
        let c = overlapping_spheres(xi, ri, xj, rj);
        Geometry {
            normal: c.normal,
            point: c.point,
            overlap: c.overlap,
            volume: None,
        }
    })
}

/// The contact of two spheres known to overlap; the normal points from `j` to `i`. Shared with
/// the fused sphere path (`step::spheres`), which tests the overlap itself.
#[inline(always)]
pub fn overlapping_spheres(xi: DVec3, ri: f64, xj: DVec3, rj: f64) -> ContactPoint {
    let d = xi - xj;
    let distance = d.length_squared().sqrt();
    // Coincident centres have no defined normal; any direction is as good, but it must be
    // deterministic. One division, not three.
    let normal = if distance > 0.0 {
        d * (1.0 / distance)
    } else {
        DVec3::Z
    };
    let overlap = ri + rj - distance;
    ContactPoint {
        normal,
        point: xj + normal * (rj - 0.5 * overlap),
        overlap,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_spheres() {
        let g = sphere_sphere(DVec3::new(1.5, 0.0, 0.0), 1.0, DVec3::ZERO, 1.0).unwrap();
        assert_eq!(g.normal, DVec3::X);
        assert!((g.overlap - 0.5).abs() < 1e-15);
        assert!((g.point.x - 0.75).abs() < 1e-15);
    }

    #[test]
    fn touching_is_not_overlapping() {
        assert!(sphere_sphere(DVec3::new(2.0, 0.0, 0.0), 1.0, DVec3::ZERO, 1.0).is_none());
    }
}
