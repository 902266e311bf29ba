//! Rocking damping of area contacts: the normal dashpot spread over the contact patch.
//!
//! The normal force of a polyhedral contact acts at the overlap's centroid, and so does its
//! dashpot. When a body rocks on a face (turns about an axis in the contact plane) the centroid
//! shifts but its normal velocity stays zero to first order: a dashpot at one point cannot damp
//! rocking, and a cube resting on a cube rocks forever once disturbed. The elastic part needs no
//! such care — the volume law's centroid shift already gives the restoring moment of a pressure
//! k_v d(x) spread over the patch — so only the damping is added here: a pressure γ_n/A · v_n(x)
//! over the patch, with v_n(x) = ((ω_i − ω_j) × x)·n, has the moment −γ_n (I_patch/A) ω_t about
//! the centroid, ω_t the relative angular velocity in the contact plane. As for the twisting
//! friction the patch is taken as a disc of the same area A, radius a = √(A/π), so
//! I_patch/A = a²/4 (Johnson 1985 §7.3 spreads the tangential traction the same way).

use super::normal::NormalForce;
use super::{Kinematics, PairLaw};
use crate::math::DVec3;

#[derive(Clone, Copy, Debug, Default)]
pub struct RockingTorque {
    /// Torque on body i, in the contact plane [N m].
    pub torque: DVec3,
    /// Energy the dashpot took out over the step [J].
    pub dissipated: f64,
}

pub fn rocking_torque(
    law: &PairLaw,
    k: &Kinematics,
    normal: &NormalForce,
    dt: f64,
) -> RockingTorque {
    let Some(overlap) = k.overlap_volume else {
        return RockingTorque::default();
    };
    // No damping where the normal dashpot has none, nor on a contact that only pulls apart
    // (the cut-off normal force: the dashpot is not acting then either).
    if law.damping_volume <= 0.0 || overlap.area <= 0.0 || normal.total <= 0.0 {
        return RockingTorque::default();
    }
    // The normal dashpot as the law used it (held to what the step can take).
    let gamma_n = normal.damping_coefficient;
    let radius_squared = overlap.area / std::f64::consts::PI;
    let gamma = gamma_n * 0.25 * radius_squared;
    let omega = k.relative_angular_velocity;
    let tilt_rate = omega - k.normal * k.normal.dot(omega);
    RockingTorque {
        torque: -gamma * tilt_rate,
        dissipated: gamma * tilt_rate.length_squared() * dt,
    }
}
