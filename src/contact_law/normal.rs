//! Elastic normal force and normal damping.

use super::{Kinematics, NormalLaw, OverlapVolume, PairLaw, PolyhedralLaw};
use crate::math::DVec3;

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
    /// Torque on body i about the contact point from the pressure's distribution (volume law).
    pub couple: DVec3,
    /// Hertz's contact radius a = √(R* δ) [m] (0 for the other laws): Mindlin's tangential
    /// stiffness is 8 G* a.
    pub contact_radius: f64,
    /// The dashpot's coefficient γ_n = c √(m* S_n) [N s/m]; the tangential one is γ_n √(k_t/S_n).
    pub damping_coefficient: f64,
}

/// The dashpot `gamma` [N s/m] held to what the explicit step can take: `limit`, one of the
/// contact's [`super::DashpotLimit`]s. (A restitution of 0 asks for an infinite dashpot: it gets
/// the limit.)
#[inline(always)]
pub fn bounded_dashpot(gamma: f64, limit: f64) -> f64 {
    gamma.min(limit)
}

/// F_el(δ), S_n(δ) and the elastic energy for the law, without damping; and Hertz's contact
/// radius (0 for the linear law).
#[inline]
pub fn elastic(law: &PairLaw, overlap: f64, effective_radius: f64) -> (f64, f64, f64, f64) {
    match law.normal {
        NormalLaw::Linear { stiffness } => (
            stiffness * overlap,
            stiffness,
            0.5 * stiffness * overlap * overlap,
            0.0,
        ),
        NormalLaw::Hertz => {
            // F = K δ^{3/2}, K = 4/3 E* √R*; S_n = 3/2 K √δ = 2 E* √(R* δ); energy 2/5 K δ^{5/2}.
            // All three from one root, the contact radius a = √(R* δ): F = 4/3 E* δ a,
            // S_n = 2 E* a, energy 8/15 E* δ² a.
            let a = (effective_radius * overlap).sqrt();
            let e = law.effective_youngs_modulus;
            (
                4.0 / 3.0 * e * overlap * a,
                2.0 * e * a,
                8.0 / 15.0 * e * overlap * overlap * a,
                a,
            )
        }
    }
}

/// The volume law for polyhedra: an elastic foundation of stiffness k_v = E*/R* per unit
/// depth and area (R* of the volume-equivalent spheres) spread over the surfaces in contact,
/// W = (k_v/2) ∫ (φ_i + φ_j) dV (see `narrow_phase::clip::Winkler`). For a face contact the force
/// is k_v V along the face normal at the overlap's centroid — the volume law of Eliáš 2014
/// (Powder Technol. 264, 458) — and a face of area A is a linear spring of stiffness
/// k_v A = E* A/R*, that of a column of the bodies' size. Being the gradient of W it conserves
/// energy (Feng, Han & Owen 2012, CMAME 205–208, 169). Returns (force, tangent stiffness k_v A,
/// energy k_v W, torque about the contact point).
///
/// The vertex law (the seed's, Muth, Eberhard & Luding): a spring of stiffness k_p = E* R* at
/// every point of one body inside the other, pushing along the normal of the face it penetrates
/// by its depth; the overlap then carries Σ dᵢ nᵢ (load), its moment and ½ Σ dᵢ² (potential), and
/// the tangent stiffness is k_p per point.
pub fn volume_law(
    law: &PairLaw,
    overlap: OverlapVolume,
    effective_radius: f64,
) -> (f64, f64, f64, DVec3) {
    let (k, stiffness) = match overlap.law {
        PolyhedralLaw::Volume => {
            let kv = law.effective_youngs_modulus / effective_radius;
            (kv, kv * overlap.area)
        }
        PolyhedralLaw::Vertex => {
            let kp = law.effective_youngs_modulus * effective_radius;
            (kp, kp * overlap.points as f64)
        }
    };
    (
        k * overlap.load,
        stiffness,
        k * overlap.potential,
        k * overlap.couple,
    )
}

/// Normal force with viscous damping F_d = c √(m* S_n) dδ/dt (the form of Tsuji et al. 1992 for
/// Hertz, of Cundall & Strack 1979 for the linear spring), cut off at zero so that a contact never
/// pulls: the damping constant c of [`super::restitution`] accounts for the cut-off.
pub fn normal_force(law: &PairLaw, k: &Kinematics) -> NormalForce {
    let ((elastic, stiffness, elastic_energy, contact_radius), c, pressure_couple) =
        match k.overlap_volume {
            Some(v) => {
                let (force, stiffness, energy, pressure) = volume_law(law, v, k.effective_radius);
                (
                    (force, stiffness, energy, 0.0),
                    law.damping_volume,
                    -pressure * v.couple,
                )
            }
            None => (
                elastic(law, k.overlap, k.effective_radius),
                law.damping,
                DVec3::ZERO,
            ),
        };
    let damping_coefficient = bounded_dashpot(
        c * (k.effective_mass * stiffness).sqrt(),
        k.dashpot_limit.normal,
    );
    let total = (elastic + damping_coefficient * k.overlap_rate).max(0.0);
    NormalForce {
        elastic,
        total,
        stiffness,
        elastic_energy,
        damping_coefficient,
        // The pressure's moment, scaled with the force when damping or the no-tension cut-off
        // change it (the pressure is then taken as scaled uniformly). The vertex law's dashpot
        // is one, at the contact point: its couple is that of the springs, only ever cut down.
        contact_radius,
        couple: if elastic > 0.0 && k.overlap_volume.is_some() {
            let scale = total / elastic;
            match k.overlap_volume.map(|v| v.law) {
                Some(PolyhedralLaw::Vertex) => pressure_couple * scale.min(1.0),
                _ => pressure_couple * scale,
            }
        } else {
            DVec3::ZERO
        },
    }
}
