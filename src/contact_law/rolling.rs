//! Rolling resistance: an elastic–plastic spring–dashpot torque ("EPSD2", Ai et al. 2011,
//! Powder Technol. 206, 269; stiffness of Wensrich & Katterfeld 2012, Powder Technol. 217, 409).

use super::normal::NormalForce;
use super::tangential::rotate_into_plane;
use super::{Kinematics, PairLaw, SpinHistory};
use crate::math::DVec3;

#[derive(Clone, Copy, Debug, Default)]
pub struct RollingTorque {
    pub torque: DVec3,
    pub elastic_energy: f64,
    pub dissipated: f64,
}

/// Torque on body i opposing the relative rolling, k_r = 2.25 μ_r² R*² k_n, capped at
/// μ_r R* F_n. The spring is incremental in the torque (kept in the history), as in EPSD2.
pub fn rolling_torque(
    law: &PairLaw,
    k: &Kinematics,
    normal: &NormalForce,
    history: &mut SpinHistory,
    dt: f64,
) -> RollingTorque {
    // Polyhedra resist rolling by their shape; the model is for round bodies.
    if law.rolling_friction <= 0.0 || k.overlap_volume.is_some() {
        return RollingTorque::default();
    }
    let r = k.effective_radius;
    let kr = 2.25 * law.rolling_friction.powi(2) * r * r * normal.stiffness;
    if kr <= 0.0 {
        history.rolling_torque = DVec3::ZERO;
        return RollingTorque::default();
    }
    // Only rolling (rotation about tangent axes) is resisted, not twisting about the normal.
    let omega = k.relative_angular_velocity - k.normal * k.normal.dot(k.relative_angular_velocity);
    let old = rotate_into_plane(history.rolling_torque, k.normal);
    let old_energy = if history.rolling_stiffness > 0.0 {
        0.5 * old.length_squared() / history.rolling_stiffness
    } else {
        0.0
    };
    let mut torque = old - kr * omega * dt;
    let limit = law.rolling_friction * r * normal.total;
    let magnitude = torque.length();
    if magnitude > limit {
        torque *= limit / magnitude;
    }
    history.rolling_torque = torque;
    history.rolling_stiffness = kr;
    let elastic_energy = 0.5 * torque.length_squared() / kr;
    // Trapezoidal work, as for the tangential spring: zero dissipation while the spring holds.
    let work_on_bodies = 0.5 * (old + torque).dot(omega) * dt;
    RollingTorque {
        torque,
        elastic_energy,
        dissipated: -work_on_bodies - (elastic_energy - old_energy),
    }
}
