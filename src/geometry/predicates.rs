//! Exact geometric predicates on `f64` points.
//!
//! Thin wrappers over Shewchuk's adaptive-precision predicates (Shewchuk 1997, "Adaptive precision
//! floating-point arithmetic and fast robust geometric predicates", the `robust` crate): the
//! returned value may be inexact, but its SIGN is always the sign of the exact determinant of the
//! `f64` inputs. Every topological decision in `geometry/` (hull visibility, ray crossings) goes
//! through these, so that no decision depends on rounding.

use crate::math::DVec3;
use robust::{Coord, Coord3D};

fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Sign-exact orientation of `d` relative to the plane through `a`, `b`, `c`.
///
/// Positive when `d` lies on the side that `(b − a) × (c − a)` points to ("above" a triangle that
/// is counter-clockwise seen from above), zero when the four points are exactly coplanar. The value
/// approximates `((b − a) × (c − a)) · (d − a)`, six times the signed volume of the tetrahedron.
///
/// Shewchuk's `orient3d` has the opposite convention (positive below), hence the minus sign.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    -robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Sign-exact 2-D orientation of the projections onto the plane of coordinates `(i, j)`.
#[inline]
pub fn orient2d_projected(a: DVec3, b: DVec3, c: DVec3, i: usize, j: usize) -> f64 {
    robust::orient2d(
        Coord { x: a[i], y: a[j] },
        Coord { x: b[i], y: b[j] },
        Coord { x: c[i], y: c[j] },
    )
}

/// Exactly true when `a`, `b` and `c` lie on one line (or coincide).
///
/// `(b − a) × (c − a)` vanishes exactly when all three of its components do, and each component is
/// the 2-D orientation of the projection onto one coordinate plane.
pub fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    orient2d_projected(a, b, c, 0, 1) == 0.0
        && orient2d_projected(a, b, c, 1, 2) == 0.0
        && orient2d_projected(a, b, c, 2, 0) == 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_convention_is_right_handed() {
        let o = DVec3::ZERO;
        let (x, y) = (DVec3::X, DVec3::Y);
        assert!(orient3d(o, x, y, DVec3::Z) > 0.0);
        assert!(orient3d(o, x, y, -DVec3::Z) < 0.0);
        assert_eq!(orient3d(o, x, y, DVec3::new(3.0, -7.0, 0.0)), 0.0);
    }

    #[test]
    fn nearly_coplanar_points_get_the_exact_sign() {
        // d is 1 ulp above the plane z = 0.5 spanned by the other three: naive evaluation of the
        // determinant with these magnitudes loses the sign, the adaptive predicate does not.
        let a = DVec3::new(0.5, 0.5, 0.5);
        let b = DVec3::new(12.0, 12.0, 0.5);
        let c = DVec3::new(24.0, 24.1, 0.5);
        let d = DVec3::new(1e3, -3e3, 0.5 + f64::EPSILON / 2.0);
        assert!(orient3d(a, b, c, d) > 0.0);
        let d_on = DVec3::new(1e3, -3e3, 0.5);
        assert_eq!(orient3d(a, b, c, d_on), 0.0);
    }

    #[test]
    fn collinearity_is_exact() {
        let a = DVec3::new(0.1, 0.2, 0.3);
        assert!(collinear(a, 2.0 * a, 4.0 * a));
        // 2 + 2⁻⁵¹ is the next double after 2.
        let (o, b) = (DVec3::ZERO, DVec3::ONE);
        assert!(!collinear(o, b, DVec3::new(2.0, 2.0, 2.0 + 2f64.powi(-51))));
        assert!(collinear(a, a, DVec3::ONE));
    }
}
