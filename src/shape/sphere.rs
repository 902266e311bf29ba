use super::UnitMassProperties;
use crate::math::DVec3;
use std::f64::consts::PI;

/// A solid sphere.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sphere {
    pub radius: f64,
}

impl Sphere {
    pub fn new(radius: f64) -> Self {
        Self { radius }
    }

    pub fn unit_mass_properties(&self) -> UnitMassProperties {
        let volume = 4.0 / 3.0 * PI * self.radius.powi(3);
        // I = 2/5 m r² for a solid sphere.
        let inertia = 0.4 * volume * self.radius * self.radius;
        UnitMassProperties {
            volume,
            principal_inertia_per_density: DVec3::splat(inertia),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_sphere_mass_properties() {
        let p = Sphere::new(1.0).unit_mass_properties();
        assert!((p.volume - 4.18879020478639).abs() < 1e-12);
        assert!((p.principal_inertia_per_density.x - 0.4 * p.volume).abs() < 1e-12);
    }
}
