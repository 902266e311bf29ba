use crate::material::MaterialId;
use crate::math::DVec3;

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
}
