use crate::material::MaterialId;
use crate::math::{Aabb, DVec3};

/// An infinite plane wall; bodies live on the side its normal points to.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub point: DVec3,
    /// Unit normal.
    pub normal: DVec3,
    pub material: MaterialId,
}

impl Plane {
    /// A square patch of the plane, centred on the point nearest `centre`, for drawing.
    pub fn patch(&self, centre: DVec3, half_size: f64) -> [DVec3; 4] {
        let origin = centre - self.normal * (centre - self.point).dot(self.normal);
        let u = self.normal.any_orthonormal_vector();
        let v = self.normal.cross(u);
        let (u, v) = (u * half_size, v * half_size);
        [
            origin - u - v,
            origin + u - v,
            origin + u + v,
            origin - u + v,
        ]
    }

    /// The polygon where the plane cuts the box `bounds`, its corners in order around it (3 to 6
    /// of them); empty when the plane misses the box. For drawing a plane wall as far as the
    /// scene reaches: the walls of a box of planes then meet at its edges.
    pub fn section(&self, bounds: &Aabb) -> Vec<DVec3> {
        let corner = |k: usize| {
            DVec3::new(
                if k & 1 == 0 {
                    bounds.min.x
                } else {
                    bounds.max.x
                },
                if k & 2 == 0 {
                    bounds.min.y
                } else {
                    bounds.max.y
                },
                if k & 4 == 0 {
                    bounds.min.z
                } else {
                    bounds.max.z
                },
            )
        };
        let distance = |p: DVec3| (p - self.point).dot(self.normal);
        let mut points: Vec<DVec3> = Vec::new();
        // The 12 edges join corners differing in one bit.
        for a in 0..8 {
            for bit in [1, 2, 4] {
                let b = a | bit;
                if b == a {
                    continue;
                }
                let (pa, pb) = (corner(a), corner(b));
                let (da, db) = (distance(pa), distance(pb));
                if (da <= 0.0) != (db <= 0.0) || da == 0.0 {
                    let t = if da == db { 0.0 } else { da / (da - db) };
                    let p = pa + (pb - pa) * t;
                    let size = bounds.extent().length().max(f64::MIN_POSITIVE);
                    if points.iter().all(|q| (*q - p).length() > 1e-12 * size) {
                        points.push(p);
                    }
                }
            }
        }
        if points.len() < 3 {
            return Vec::new();
        }
        // Order them by angle about their centroid, in the plane.
        let centre = points.iter().copied().sum::<DVec3>() / points.len() as f64;
        let u = self.normal.any_orthonormal_vector();
        let v = self.normal.cross(u);
        points.sort_by(|p, q| {
            let angle = |x: &DVec3| (*x - centre).dot(v).atan2((*x - centre).dot(u));
            angle(p).total_cmp(&angle(q))
        });
        points
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(point: DVec3, normal: DVec3) -> Plane {
        Plane {
            point,
            normal: normal.normalize(),
            material: 0,
        }
    }

    #[test]
    fn a_floor_cuts_a_box_in_its_bottom_face_and_a_diagonal_plane_in_a_hexagon() {
        let bounds = Aabb::new(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
        let floor = plane(DVec3::ZERO, DVec3::Z).section(&bounds);
        assert_eq!(floor.len(), 4);
        assert!(floor.iter().all(|p| p.z == 0.0));
        let area = |poly: &[DVec3]| {
            let c = poly[0];
            (1..poly.len() - 1)
                .map(|k| 0.5 * (poly[k] - c).cross(poly[k + 1] - c).length())
                .sum::<f64>()
        };
        assert!((area(&floor) - 2.0).abs() < 1e-12);
        // Through the centre of a cube, normal to its diagonal: a regular hexagon of side
        // √2/2 (area 3√3/4).
        let cube = Aabb::new(DVec3::ZERO, DVec3::ONE);
        let hexagon = plane(DVec3::splat(0.5), DVec3::ONE).section(&cube);
        assert_eq!(hexagon.len(), 6);
        assert!((area(&hexagon) - 3.0 * 3f64.sqrt() / 4.0).abs() < 1e-12);
        // Consecutive corners are neighbours: every side is √2/2 long.
        for k in 0..6 {
            let side = (hexagon[(k + 1) % 6] - hexagon[k]).length();
            assert!((side - 0.5f64.sqrt()).abs() < 1e-12, "{side}");
        }
        assert!(plane(DVec3::splat(3.0), DVec3::Z).section(&cube).is_empty());
    }
}
