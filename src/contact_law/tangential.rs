//! Tangential (friction) force: a spring with Coulomb limit and history.

use super::normal::NormalForce;
use super::{History, Kinematics, NormalLaw, PairLaw};
use crate::math::DVec3;

#[derive(Clone, Copy, Debug, Default)]
pub struct TangentialForce {
    pub force: DVec3,
    /// The dashpot's part of `force` (zero while sliding): its work is booked a step late, with
    /// the normal dashpot's (`contact_law::History::damper_force`).
    pub damper: DVec3,
    pub elastic_energy: f64,
    /// What sliding took out this step (the spring's work less its change in energy).
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
/// the force is μ F_n along the trial force, the spring holds all of it and the dashpot is off (so
/// the spring never stores more than μ F_n / k_t, and while the contact slides one way the force
/// stays against the slip). Energy: the work the force does against
/// the relative motion, less the change in spring energy, is what was dissipated (with Mindlin's
/// overlap-dependent k_t this includes the small energy the changing stiffness adds or removes).
#[inline(always)]
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
    // Held, as the normal one, to what the step can take, on the tangential share of m*.
    let gamma = super::normal::bounded_dashpot(
        normal.damping_coefficient * ratio,
        k.dashpot_limit.tangential,
    );
    let damping = -gamma * k.tangential_velocity_end;
    let trial_xi = old_xi + k.tangential_velocity * dt;
    let trial = -kt * trial_xi + damping;
    let limit = law.friction * normal.total;
    // Compared squared: a sticking contact needs no root.
    let trial_squared = trial.length_squared();
    let (force, xi, damper) = if trial_squared <= limit * limit {
        (trial, trial_xi, damping)
    } else {
        // Sliding: the force is capped at μ F_n along the trial force, and the spring alone holds
        // it (ξ = −F/k_t), the dashpot off (Luding 2008's rule for the static limit, without
        // the dashpot in the stored spring). Resetting ξ to −(F − damping)/k_t instead (LAMMPS,
        // LIGGGHTS) leaves the spring pointing along the slip whenever the dashpot alone exceeds
        // μ F_n, and when k_t grows the next step's capped force pushes the body along its slip
        // (issue #11). Here the spring stays against the slip, so the next trial force is too.
        let force = trial * (limit / trial_squared.sqrt());
        (force, force * (-1.0 / kt), DVec3::ZERO)
    };
    history.tangential_spring = xi;
    history.tangential_stiffness = kt;
    let elastic_energy = 0.5 * kt * xi.length_squared();
    // Work of the spring on the relative motion by the trapezoidal rule (exact for a sticking
    // spring, whose energy change it then equals), less the change in stored energy: what
    // sliding took out. (What the dashpot took out is booked next step.)
    let spring_work = 0.5 * (old_kt * old_xi + kt * xi).dot(k.tangential_velocity) * dt;
    let old_energy = 0.5 * old_kt * old_xi.length_squared();
    TangentialForce {
        force,
        damper,
        elastic_energy,
        dissipated: spring_work - (elastic_energy - old_energy),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact_law::normal::normal_force;
    use crate::material::{Material, PairTable};
    use proptest::prelude::*;

    /// A Hertz–Mindlin pair of soft beads with a strong dashpot (e = 0.1), μ = 0.3.
    fn law() -> PairLaw {
        static LAW: std::sync::OnceLock<PairLaw> = std::sync::OnceLock::new();
        *LAW.get_or_init(|| {
            let bead = Material {
                name: "bead".into(),
                density: 2500.0,
                youngs_modulus: 5e6,
                poisson_ratio: 0.25,
                restitution: 0.1,
                friction: 0.3,
                rolling_friction: 0.0,
            };
            *PairTable::new(&[bead], NormalLaw::Hertz, 2.0 / 7.0, &[]).get(0, 0)
        })
    }

    /// The step of these tests.
    const DT: f64 = 1e-5;

    fn kinematics(overlap: f64, overlap_rate: f64, slip: DVec3, slip_end: DVec3) -> Kinematics {
        Kinematics {
            normal: DVec3::Z,
            overlap,
            overlap_rate,
            tangential_velocity: slip,
            tangential_velocity_end: slip_end,
            velocity_start: slip,
            relative_angular_velocity: DVec3::ZERO,
            effective_radius: 1e-3,
            effective_mass: 1e-5,
            overlap_volume: None,
            dashpot_limit: crate::contact_law::DashpotLimit::of_spheres(1e-5, 1.0 / DT),
        }
    }

    /// One step of the law; returns the force, the Coulomb limit and whether the trial force (the
    /// spring stretched by this step's slip, plus the dashpot) exceeded it, i.e. the contact slid.
    fn step(k: &Kinematics, history: &mut History, dt: f64) -> (DVec3, f64, bool) {
        let law = law();
        let n = normal_force(&law, k);
        let limit = law.friction * n.total;
        let kt = stiffness(&law, &n, k);
        let gamma = crate::contact_law::normal::bounded_dashpot(
            n.damping_coefficient * law.tangential_damping_ratio,
            k.dashpot_limit.tangential,
        );
        let trial_xi =
            rotate_into_plane(history.tangential_spring, k.normal) + k.tangential_velocity * dt;
        let trial = -kt * trial_xi - gamma * k.tangential_velocity_end;
        let sliding = trial.length() > limit;
        let t = tangential_force(&law, k, &n, history, dt);
        (t.force, limit, sliding)
    }

    /// Issue #11: after a step in which the dashpot alone exceeded μ F_n, the spring was left
    /// pointing along the slip, and when k_t grew the next step (the overlap deepening) the capped
    /// force pushed the body along its slip at the full μ F_n.
    #[test]
    fn friction_does_not_push_along_the_slip_after_the_dashpot_exceeded_the_limit() {
        let mut history = History::default();
        let dt = DT;
        // A grazing contact sliding fast: the dashpot alone is far above μ F_n.
        let fast = DVec3::new(2.0, 0.0, 0.0);
        let (_, _, slid) = step(&kinematics(1e-7, 0.0, fast, fast), &mut history, dt);
        assert!(slid);
        // Deeper, stiffer, slower, still sliding the same way.
        let slow = DVec3::new(0.05, 0.0, 0.0);
        let (force, limit, _) = step(&kinematics(2e-5, 0.0, slow, slow), &mut history, dt);
        assert!(
            force.dot(slow) <= 0.0,
            "friction {force} pushes along the slip {slow}"
        );
        assert!(force.length() <= limit * (1.0 + 1e-12));
    }

    proptest! {
        /// Over random histories of normal and tangential motion: the friction force never
        /// exceeds μ F_n; whenever the contact slides the spring holds no more than the Coulomb
        /// force, and the force opposes the slip unless the slip just reversed.
        #[test]
        fn friction_is_bounded_and_opposes_sliding(
            steps in prop::collection::vec(
                (1e-8..5e-5f64, -0.2..0.2f64, -1.0..1.0f64, -1.0..1.0f64, -0.1..0.1f64),
                1..40,
            ),
        ) {
            let mut history = History::default();
            let dt = DT;
            for (overlap, rate, vx, vy, change) in steps {
                let slip = DVec3::new(vx, vy, 0.0);
                let k = kinematics(overlap, rate, slip, slip * (1.0 + change));
                let spring_before = history.tangential_spring;
                let (force, limit, slid) = step(&k, &mut history, dt);
                prop_assert!(force.length() <= limit * (1.0 + 1e-12), "{force} over {limit}");
                // On a reversal (the spring loaded against the new slip) its release may push
                // along the motion: elastic recovery, not friction (Mindlin & Deresiewicz 1953).
                let reversal = spring_before.dot(slip) < 0.0;
                if slid {
                    let held = history.tangential_stiffness * history.tangential_spring.length();
                    prop_assert!(held <= limit * (1.0 + 1e-12), "spring holds {held} > {limit}");
                    if !reversal {
                        prop_assert!(force.dot(slip) <= 0.0, "friction {force} along the slip {slip}");
                    }
                }
            }
        }
    }
}
