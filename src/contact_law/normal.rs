//! Elastic normal force and normal damping.

use super::{Kinematics, NormalLaw, OverlapVolume, PairLaw};

/// Normal force of one contact, split into its elastic and damping parts.
#[derive(Clone, Copy, Debug)]
pub struct NormalForce {
    /// Elastic part F_el(δ) [N].
    pub elastic: f64,
    /// Total normal force, elastic plus damping, never attractive [N].
    pub total: f64,
    /// Tangent stiffness S_n = dF_el/dδ [N/m].
    pub stiffness: f64,
    /// Elastic energy ∫F_el dδ [J].
    pub elastic_energy: f64,
}

impl NormalForce {
    /// Work done by the non-elastic part of the normal force against the relative motion over
    /// `dt`: what damping (and the no-tension cut-off) took out of the bodies.
    pub fn dissipated(&self, overlap_rate: f64, dt: f64) -> f64 {
        (self.total - self.elastic) * overlap_rate * dt
    }
}

/// F_el(δ) and S_n(δ) for the law, without damping.
pub fn elastic(law: &PairLaw, overlap: f64, effective_radius: f64) -> (f64, f64, f64) {
    match law.normal {
        NormalLaw::Linear { stiffness } => (
            stiffness * overlap,
            stiffness,
            0.5 * stiffness * overlap * overlap,
        ),
        NormalLaw::Hertz => {
            // F = K δ^{3/2}, K = 4/3 E* √R*; S_n = 3/2 K √δ = 2 E* √(R* δ); energy 2/5 K δ^{5/2}.
            let k = 4.0 / 3.0 * law.effective_youngs_modulus * effective_radius.sqrt();
            let root = overlap.sqrt();
            (
                k * overlap * root,
                1.5 * k * root,
                0.4 * k * overlap * overlap * root,
            )
        }
    }
}

/// The volume law for polyhedra: F = k_v V with k_v = E*/R* (Eliáš 2014, "Simulation of railway
/// ballast using crushable polyhedral particles", Powder Technol. 264, 458, for the form; R* of
/// the volume-equivalent spheres gives k_v its scale: a flat contact of area A then has the
/// stiffness E* A / R* of a column of the body's size). Tangent stiffness S_n = dF/dδ = k_v A.
/// Elastic energy ½ F V/A: exact while the contact area does not change with depth (faces in
/// contact), an approximation for vertex and edge contacts.
pub fn volume_law(law: &PairLaw, overlap: OverlapVolume, effective_radius: f64) -> (f64, f64, f64) {
    let kv = law.effective_youngs_modulus / effective_radius;
    let force = kv * overlap.volume;
    let depth = if overlap.area > 0.0 {
        overlap.volume / overlap.area
    } else {
        0.0
    };
    (force, kv * overlap.area, 0.5 * force * depth)
}

/// Normal force with viscous damping F_d = c √(m* S_n) dδ/dt (the form of Tsuji et al. 1992 for
/// Hertz, of Cundall & Strack 1979 for the linear spring), cut off at zero so that a contact never
/// pulls: the damping constant c of [`super::restitution`] accounts for the cut-off.
pub fn normal_force(law: &PairLaw, k: &Kinematics) -> NormalForce {
    let ((elastic, stiffness, elastic_energy), c) = match k.overlap_volume {
        Some(v) => (volume_law(law, v, k.effective_radius), law.damping_volume),
        None => (elastic(law, k.overlap, k.effective_radius), law.damping),
    };
    let damping = c * (k.effective_mass * stiffness).sqrt() * k.overlap_rate;
    NormalForce {
        elastic,
        total: (elastic + damping).max(0.0),
        stiffness,
        elastic_energy,
    }
}
