//! Tangential (friction) force: a spring with Coulomb limit and history.

use super::normal::NormalForce;
use super::{History, Kinematics, NormalLaw, PairLaw};
use crate::math::DVec3;

#[derive(Clone, Copy, Debug, Default)]
pub struct TangentialForce {
    pub force: DVec3,
    pub elastic_energy: f64,
    pub dissipated: f64,
}

/// Tangential stiffness k_t: Mindlin (1949) k_t = 8 G* √(R* δ) for Hertz, a fixed ratio of k_n for
/// the linear law and the volume law of polyhedra.
#[inline]
pub fn stiffness(law: &PairLaw, normal: &NormalForce, k: &Kinematics) -> f64 {
    if k.overlap_volume.is_some() {
        return law.tangential_stiffness_ratio * normal.stiffness;
    }
    match law.normal {
        NormalLaw::Linear { .. } => law.tangential_stiffness_ratio * normal.stiffness,
        // Mindlin: 8 G* a, a = √(R* δ) the contact radius the normal law found.
        NormalLaw::Hertz => 8.0 * law.effective_shear_modulus * normal.contact_radius,
    }
}

/// Spring–dashpot in the tangent plane, capped at μ F_n (Cundall & Strack 1979; the history
/// handling follows LAMMPS `gran_sub_mod_tangential.cpp`, "linear_history"/"mindlin").
///
/// The elongation ξ is kept from the previous step; as the contact turns, ξ is projected onto the
/// current tangent plane and rescaled to its former length so that turning alone neither creates
/// nor destroys spring energy. When the trial force exceeds the Coulomb limit the contact slides:
/// the force is set to the limit and ξ shortened to match. Energy: the work the force does against
/// the relative motion, less the change in spring energy, is what was dissipated (with Mindlin's
/// overlap-dependent k_t this includes the small energy the changing stiffness adds or removes).
#[inline]
pub fn tangential_force(
    law: &PairLaw,
    k: &Kinematics,
    normal: &NormalForce,
    history: &mut History,
    dt: f64,
) -> TangentialForce {
    let kt = stiffness(law, normal, k);
    if kt <= 0.0 || law.friction <= 0.0 {
        history.tangential_spring = DVec3::ZERO;
        return TangentialForce::default();
    }
    let old_xi = rotate_into_plane(history.tangential_spring, k.normal);
    let old_kt = history.tangential_stiffness;
    // The dashpot constant of the normal law in use: the volume law's for polyhedra (whose k_t is
    // linear in the normal stiffness, as the twisting dashpot assumes), Hertz's or the linear
    // spring's otherwise.
    // c √(m* k_t) = γ_n √(k_t/S_n), with the ratio fixed per law: no square root here.
    let ratio = if k.overlap_volume.is_some() {
        law.tangential_damping_ratio_volume
    } else {
        law.tangential_damping_ratio
    };
    let gamma = normal.damping_coefficient * ratio;
    let damping = -gamma * k.tangential_velocity_end;
    let mut xi = old_xi + k.tangential_velocity * dt;
    let mut force = -kt * xi + damping;
    let limit = law.friction * normal.total;
    // Compared squared: a sticking contact needs no root.
    let magnitude_squared = force.length_squared();
    if magnitude_squared > limit * limit {
        force *= limit / magnitude_squared.sqrt();
        // Spring elongation consistent with the limited force (LAMMPS: ξ = −(F + γ v_t)/k_t).
        xi = -(force - damping) / kt;
    }
    history.tangential_spring = xi;
    history.tangential_stiffness = kt;
    let elastic_energy = 0.5 * kt * xi.length_squared();
    // Work of the spring on the relative motion by the trapezoidal rule (exact for a sticking
    // spring, whose energy change it then equals), less the change in stored energy: what
    // sliding took out. Plus what the dashpot took out.
    let spring_work = 0.5 * (old_kt * old_xi + kt * xi).dot(k.tangential_velocity) * dt;
    let old_energy = 0.5 * old_kt * old_xi.length_squared();
    TangentialForce {
        force,
        elastic_energy,
        dissipated: spring_work - (elastic_energy - old_energy)
            + gamma * k.tangential_velocity_end.length_squared() * dt,
    }
}

/// Projects a history vector onto the plane normal to `n`, keeping its length.
#[inline]
pub fn rotate_into_plane(v: DVec3, n: DVec3) -> DVec3 {
    let length_squared = v.length_squared();
    if length_squared == 0.0 {
        return v;
    }
    let projected = v - n * n.dot(v);
    let projected_squared = projected.length_squared();
    if projected_squared == 0.0 {
        return DVec3::ZERO;
    }
    projected * (length_squared / projected_squared).sqrt()
}
