//! Twisting friction of area contacts: the torque about the contact normal that friction spread
//! over a contact patch exerts when the bodies turn against each other about that normal.
//!
//! A point contact has none, so a cube spinning flat on a table would spin forever. Over a patch
//! of area A, taken as a disc of radius a = √(A/π), a tangential spring of stiffness k_t spread
//! uniformly gives the twisting stiffness k_tw = k_t a²/2, and full sliding the limit torque
//! μ F_n · 2a/3 (Johnson 1985 §7.3 for the disc; the spring–dashpot with a Coulomb limit as for
//! the tangential force, after LAMMPS' "marshall" twisting model).

use super::normal::NormalForce;
use super::{Kinematics, PairLaw, SpinHistory};

#[derive(Clone, Copy, Debug, Default)]
pub struct TwistingTorque {
    /// Torque on body i about the contact normal [N m].
    pub torque: f64,
    pub elastic_energy: f64,
    pub dissipated: f64,
}

pub fn twisting_torque(
    law: &PairLaw,
    k: &Kinematics,
    normal: &NormalForce,
    tangential_stiffness: f64,
    history: &mut SpinHistory,
    dt: f64,
) -> TwistingTorque {
    let Some(overlap) = k.overlap_volume else {
        return TwistingTorque::default();
    };
    if law.friction <= 0.0 || tangential_stiffness <= 0.0 || overlap.area <= 0.0 {
        history.twisting_torque = 0.0;
        return TwistingTorque::default();
    }
    let radius = (overlap.area / std::f64::consts::PI).sqrt();
    let stiffness = 0.5 * tangential_stiffness * radius * radius;
    let twist_rate = k.relative_angular_velocity.dot(k.normal);
    // A dashpot of the same spread as the spring, so that a twisting oscillation dies out like a
    // tangential one: γ_tw = γ_t a²/2 with γ_t = c √(m* k_t).
    // The tangential dashpot held to what the step can take, as in `tangential_force`.
    let gamma = super::normal::bounded_dashpot(
        law.damping_volume * (k.effective_mass * tangential_stiffness).sqrt(),
        k.dashpot_limit.tangential,
    ) * 0.5
        * radius
        * radius;
    let damping = -gamma * twist_rate;
    let old = history.twisting_torque;
    let old_stiffness = history.twisting_stiffness;
    let trial_spring = old - stiffness * twist_rate * dt;
    let trial = trial_spring + damping;
    let limit = law.friction * normal.total * 2.0 * radius / 3.0;
    let (torque, spring, damper_loss) = if trial.abs() <= limit {
        (trial, trial_spring, gamma * twist_rate * twist_rate * dt)
    } else {
        // Sliding: the limit against the twist, held by the spring alone, dashpot off (the rule
        // of the tangential spring, see `tangential_force`).
        let against = if twist_rate != 0.0 {
            -twist_rate
        } else {
            trial
        };
        let torque = limit.copysign(against);
        (torque, torque, 0.0)
    };
    history.twisting_torque = spring;
    history.twisting_stiffness = stiffness;
    let energy = |m: f64, s: f64| if s > 0.0 { 0.5 * m * m / s } else { 0.0 };
    let elastic_energy = energy(spring, stiffness);
    // Trapezoidal work of the spring against the relative twist, less the change in stored
    // energy (what sliding took out: zero while the spring holds), plus the dashpot's share.
    let spring_work = 0.5 * (old + spring) * twist_rate * dt;
    TwistingTorque {
        torque,
        elastic_energy,
        dissipated: -spring_work - (elastic_energy - energy(old, old_stiffness)) + damper_loss,
    }
}
