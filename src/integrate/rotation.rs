//! Free (torque-free) rotation of a rigid body: the "drift" part of the
//! rotational velocity-Verlet / leapfrog step.
//!
//! # Conventions
//! * `q: DQuat` maps the body frame to the world frame (`x_world = q * x_body`).
//! * The body frame is the principal-axis frame, so the inertia tensor is
//!   diagonal there; the engine passes its inverse `inv_inertia = (1/Ixx, 1/Iyy, 1/Izz)`.
//! * The angular momentum `l_world` is stored in the WORLD frame. During a
//!   torque-free drift it is exactly constant (Euler's equations in the
//!   world frame read dL/dt = torque = 0); only the orientation changes.
//!
//! The engine's time step is: half-kick `l_world += torque * dt/2`, then
//! [`drift`] over `dt`, then recompute contacts/torques, then another half-kick.
//! Because the kicks are exact and [`drift`] is symplectic and time-reversible,
//! for conservative torques the whole step is symplectic and reversible (a
//! Strang splitting of H = T(L, q) + V(q)); dissipative contact torques break
//! that only through the physics, not through the integrator.
//!
//! # Scheme
//! The free rigid-body Hamiltonian in body coordinates is
//! T = L1²/(2I1) + L2²/(2I2) + L3²/(2I3). Each term Tᵢ alone generates an
//! exactly solvable flow: a rotation of the body about its own principal axis
//! eᵢ with the constant rate Lᵢ/Iᵢ (Lᵢ is a constant of the Tᵢ-flow), while the
//! body-frame momentum L_b rotates the opposite way so that L_world = q·L_b is
//! unchanged. Dullweber, Leimkuhler & McLachlan (1997), J. Chem. Phys. 107,
//! 5840 (their symmetric splitting method; the NO_SQUISH scheme of Miller et
//! al. 2002, J. Chem. Phys. 116, 8649, is the same splitting written for
//! quaternions) compose
//! them symmetrically:
//!
//! S(h) = R1(h/2) ∘ R2(h/2) ∘ R3(h) ∘ R2(h/2) ∘ R1(h/2),
//!
//! which is symplectic (composition of exact Hamiltonian flows), time
//! reversible (symmetric: S(-h) = S(h)⁻¹) and second order. Every sub-flow is a
//! rotation, so |L| and |q| are conserved to round-off; the energy error is
//! bounded (backward error analysis, Hairer, Lubich & Wanner 2006, ch. IX) and
//! O(h²).
//!
//! **Chosen scheme (measured):** [`drift`] uses this 2nd-order step S(h).
//! On the Dzhanibekov test below (1×2×3 box, |ω| ≈ 1 rad/s) the maximum
//! relative energy error of S is ≈ 0.073·(|ω|h)² (7.3e-8 at h = 1e-3 s,
//! 7.3e-6 at h = 1e-2 s) and does not grow with time (1e5 steps); |L| is
//! conserved to 1e-15 and the flip period is within ≈ 2e-7 of the
//! Landau–Lifshitz value at h = 1e-3. That meets the 1e-6 energy requirement
//! for |ω|h ≲ 3e-3, which DEM steps (limited by contact stiffness, typically
//! 1e-6…1e-4 s) satisfy by orders of magnitude. Moreover, with torques the
//! full kick–drift–kick step is a Strang splitting and only 2nd order anyway,
//! so a higher-order drift cannot raise the global order.
//!
//! For torque-free-dominated runs with coarse steps, [`drift_order4`] composes
//! S into the 4th-order symmetric "triple jump" of Yoshida (1990), Phys. Lett.
//! A 150, 262:
//!
//! S4(h) = S(w1 h) ∘ S(w0 h) ∘ S(w1 h), w1 = 1/(2 − 2^{1/3}), w0 = 1 − 2 w1,
//!
//! with adjacent R1 half-rotations merged (13 axis rotations instead of 5,
//! about twice the time per call). Measured: energy error 6e-14 at h = 1e-3, 3e-10 at
//! h = 1e-2, 3e-8 at h = 3e-2; period error O(h⁴) (ratio 16 on halving h).
//! Both are symplectic and exactly time reversible.
//!
//! Isotropic bodies (spheres, cubes, regular polyhedra: I1 = I2 = I3) have
//! ω = L/I constant in the world frame, so the drift is the exact rotation by
//! the angle |ω|h about ω — one quaternion product, no splitting error.

use glam::{DQuat, DVec3};

/// Relative tolerance below which the three principal moments are treated as
/// equal and the exact isotropic rotation is used.
pub const ISOTROPIC_REL_TOL: f64 = 1e-12;

/// One sub-rotation of the splitting: rotate about body axis `axis` (0,1,2)
/// for the time `coeff * dt`.
type SubStep = (usize, f64);

/// Second-order symmetric splitting of Dullweber, Leimkuhler & McLachlan (1997):
/// R1(h/2) R2(h/2) R3(h) R2(h/2) R1(h/2).
const ORDER2: [SubStep; 5] = [(0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)];

/// Yoshida (1990) triple-jump weights for a symmetric 2nd-order map:
/// w1 = 1/(2 − 2^{1/3}), w0 = −2^{1/3}/(2 − 2^{1/3}) = 1 − 2 w1.
const YOSHIDA_W1: f64 = 1.351_207_191_959_657_8;
const YOSHIDA_W0: f64 = -1.702_414_383_919_315_3;

/// S(w1 h) S(w0 h) S(w1 h) with the touching R1 half-steps merged.
const ORDER4: [SubStep; 13] = [
    (0, 0.5 * YOSHIDA_W1),
    (1, 0.5 * YOSHIDA_W1),
    (2, YOSHIDA_W1),
    (1, 0.5 * YOSHIDA_W1),
    (0, 0.5 * (YOSHIDA_W1 + YOSHIDA_W0)),
    (1, 0.5 * YOSHIDA_W0),
    (2, YOSHIDA_W0),
    (1, 0.5 * YOSHIDA_W0),
    (0, 0.5 * (YOSHIDA_W0 + YOSHIDA_W1)),
    (1, 0.5 * YOSHIDA_W1),
    (2, YOSHIDA_W1),
    (1, 0.5 * YOSHIDA_W1),
    (0, 0.5 * YOSHIDA_W1),
];

/// True if the three principal (inverse) moments agree within
/// [`ISOTROPIC_REL_TOL`] relative to the largest.
#[inline(always)]
pub fn is_isotropic(inv_inertia: DVec3) -> bool {
    let max = inv_inertia.abs().max_element();
    let spread = inv_inertia.max_element() - inv_inertia.min_element();
    spread <= ISOTROPIC_REL_TOL * max
}

/// Advance the orientation of a torque-free rigid body over `dt` with the
/// 2nd-order symplectic, time-reversible splitting of Dullweber, Leimkuhler &
/// McLachlan (1997) (see the module docs); isotropic bodies rotate exactly.
///
/// `l_world` is constant during the drift and is therefore not returned.
/// `dt` may be negative (backward integration is the exact inverse up to
/// round-off). The result is renormalised.
#[inline]
pub fn drift(q: DQuat, l_world: DVec3, inv_inertia: DVec3, dt: f64) -> DQuat {
    if is_isotropic(inv_inertia) {
        return drift_isotropic(q, l_world, inv_inertia, dt);
    }
    drift_split(q, l_world, inv_inertia, dt, &ORDER2)
}

/// 4th-order variant of [`drift`]: Yoshida (1990) triple jump of the DLM (1997)
/// step (13 axis rotations instead of 5). Same properties (symplectic, time
/// reversible, |L| exact) but the energy/trajectory error is O(dt⁴) instead of
/// O(dt²). Worth it only when |ω|·dt is larger than ~1e-3 and torques are
/// weak (otherwise the kick–drift–kick step is 2nd order regardless).
#[inline]
pub fn drift_order4(q: DQuat, l_world: DVec3, inv_inertia: DVec3, dt: f64) -> DQuat {
    if is_isotropic(inv_inertia) {
        return drift_isotropic(q, l_world, inv_inertia, dt);
    }
    drift_split(q, l_world, inv_inertia, dt, &ORDER4)
}

/// Exact drift for I1 = I2 = I3: ω = L/I is constant in the world frame, so
/// q(t+dt) = exp(ω dt / 2) q(t) (world-frame rotation acts from the left).
#[inline(always)]
pub(crate) fn drift_isotropic(q: DQuat, l_world: DVec3, inv_inertia: DVec3, dt: f64) -> DQuat {
    // Mean of the (equal) inverse moments, so tiny differences below the
    // tolerance do not bias one axis.
    let inv_i = (inv_inertia.x + inv_inertia.y + inv_inertia.z) / 3.0;
    let rot = rotation_by(l_world * (inv_i * dt));
    renormalize(rot * q)
}

/// Brings a quaternion that is of unit length to round-off back to unit length, with one Newton
/// step for 1/√(q·q) instead of a square root and a division (a fifth of an isotropic body's
/// integration): the error after it is O((q·q − 1)²), far below round-off.
#[inline(always)]
fn renormalize(q: DQuat) -> DQuat {
    q * (1.5 - 0.5 * q.length_squared())
}

/// The square of the largest angle [`rotation_by`] turns by its series.
pub(crate) const SERIES_LIMIT: f64 = 2.5e-3;

/// The rotation by the angle |v| about v, exp(v/2) as a quaternion. A DEM step turns a body by
/// far less than 0.05 rad, where the Taylor series of sin(θ/2)/θ and cos(θ/2) to θ⁶ are exact to
/// round-off (the first omitted terms, θ⁸/185,794,560 and θ⁸/10,321,920, are below 4e-18): no
/// square root and no sine, which cost a third of a falling sphere's integration.
#[inline(always)]
pub fn rotation_by(v: DVec3) -> DQuat {
    let t2 = v.length_squared();
    if t2 >= SERIES_LIMIT {
        return DQuat::from_scaled_axis(v);
    }
    let sin_half_over_angle =
        0.5 - t2 * (1.0 / 48.0 - t2 * (1.0 / 3840.0 - t2 * (1.0 / 645_120.0)));
    let cos_half = 1.0 - t2 * (1.0 / 8.0 - t2 * (1.0 / 384.0 - t2 * (1.0 / 46_080.0)));
    let axis = v * sin_half_over_angle;
    DQuat::from_xyzw(axis.x, axis.y, axis.z, cos_half)
}

/// Compose exact principal-axis rotations according to `steps`.
///
/// Sub-flow of Tᵢ = Lᵢ²/(2Iᵢ) for a time τ (DLM 1997): the body
/// turns about its own axis eᵢ by θ = Lᵢ τ / Iᵢ, i.e. q ← q·Rᵢ(θ) (body-frame
/// rotation acts from the right), and the body-frame momentum turns by −θ,
/// L_b ← Rᵢ(−θ) L_b, so that q·L_b = L_world stays fixed. Lᵢ itself is
/// invariant, so θ is known exactly at the start of the sub-step.
#[inline]
fn drift_split(q: DQuat, l_world: DVec3, inv_inertia: DVec3, dt: f64, steps: &[SubStep]) -> DQuat {
    let mut q = q.normalize();
    let mut lb = q.inverse() * l_world;
    for &(axis, coeff) in steps {
        let h = coeff * dt;
        let theta = lb[axis] * inv_inertia[axis] * h;
        // One sin/cos of θ/2 serves both the quaternion and the vector
        // rotation (double-angle identities).
        let (s, c) = (0.5 * theta).sin_cos();
        let sin_t = 2.0 * s * c;
        let cos_t = 1.0 - 2.0 * s * s;
        // Rotation of L_b by −θ about eᵢ acts on the other two components
        // (j, k) in cyclic order (i, j, k):  L_j' =  cosθ L_j + sinθ L_k,
        //                                   L_k' = −sinθ L_j + cosθ L_k.
        let (j, k) = match axis {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        let (lj, lk) = (lb[j], lb[k]);
        lb[j] = cos_t * lj + sin_t * lk;
        lb[k] = -sin_t * lj + cos_t * lk;
        let r = match axis {
            0 => DQuat::from_xyzw(s, 0.0, 0.0, c),
            1 => DQuat::from_xyzw(0.0, s, 0.0, c),
            _ => DQuat::from_xyzw(0.0, 0.0, s, c),
        };
        q *= r;
    }
    q.normalize()
}

/// World-frame angular velocity ω = q·(I⁻¹·(q⁻¹·L)) (I⁻¹ diagonal in the body
/// frame).
#[inline(always)]
pub fn angular_velocity(q: DQuat, l_world: DVec3, inv_inertia: DVec3) -> DVec3 {
    // Spheres (the common case) need no change of frame. Inlined, so that the common case costs a
    // few comparisons where it is called (three times per body and step); as a call it took a
    // quarter of a falling sphere's step (its vector arguments went through memory).
    if is_isotropic(inv_inertia) {
        return l_world * inv_inertia.x;
    }
    angular_velocity_in_body_frame(q, l_world, inv_inertia)
}

#[inline(never)]
fn angular_velocity_in_body_frame(q: DQuat, l_world: DVec3, inv_inertia: DVec3) -> DVec3 {
    q * (inv_inertia * (q.inverse() * l_world))
}

/// Rotational kinetic energy T = ½ L_b·I⁻¹·L_b with L_b = q⁻¹·L (body frame).
#[inline]
pub fn rotational_energy(q: DQuat, l_world: DVec3, inv_inertia: DVec3) -> f64 {
    let lb = q.inverse() * l_world;
    0.5 * lb.dot(inv_inertia * lb)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series rotation agrees with glam's sin/cos one to round-off on both sides of the
    /// switch, and for tiny angles (where from_scaled_axis divides by the angle).
    #[test]
    fn small_angle_rotation_matches_the_exact_one() {
        for &angle in &[1e-12, 1e-6, 1e-3, 0.01, 0.0499, 0.05, 0.0501, 0.2, 1.0] {
            for axis in [DVec3::X, DVec3::new(1.0, -2.0, 0.5).normalize()] {
                let v = axis * angle;
                let (series, exact) = (rotation_by(v), DQuat::from_scaled_axis(v));
                let error = (series - exact).length();
                assert!(error < 4e-16, "angle {angle}: error {error:e}");
                assert!((series.length() - 1.0).abs() < 4e-16);
            }
        }
        assert_eq!(rotation_by(DVec3::ZERO), DQuat::IDENTITY);
    }

    /// Complete elliptic integral of the first kind K(k) via the
    /// arithmetic–geometric mean: K(k) = π / (2·AGM(1, k')), k' = √(1−k²)
    /// (Abramowitz & Stegun 1964, 17.6). Takes k'² directly, which near the
    /// separatrix (k → 1) is computed without cancellation.
    fn elliptic_k_from_kprime2(kprime2: f64) -> f64 {
        let mut a = 1.0_f64;
        let mut g = kprime2.sqrt();
        for _ in 0..64 {
            if (a - g).abs() <= 1e-16 * a {
                break;
            }
            let an = 0.5 * (a + g);
            g = (a * g).sqrt();
            a = an;
        }
        std::f64::consts::PI / (2.0 * a)
    }

    #[test]
    fn elliptic_k_known_values() {
        // K(0) = π/2; K(1/√2) = Γ(1/4)²/(4√π) = 1.854074677301372
        assert!((elliptic_k_from_kprime2(1.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!((elliptic_k_from_kprime2(0.5) - 1.854_074_677_301_372).abs() < 1e-14);
        // K(k=0.99) = 3.356600523361192 (k'^2 = 1 - 0.9801)
        assert!((elliptic_k_from_kprime2(1.0 - 0.99 * 0.99) - 3.356_600_523_361_192).abs() < 1e-12);
    }

    /// Analytic period of the body-frame angular velocity about the
    /// intermediate axis for the torque-free asymmetric top (Landau & Lifshitz,
    /// Mechanics, 3rd ed. 1976, §37, notation I1 < I2 < I3).
    ///
    /// Case L² > 2E·I2:  τ = λt, λ² = (I3−I2)(L²−2EI1)/(I1I2I3),
    ///   k² = (I2−I1)(2EI3−L²)/((I3−I2)(L²−2EI1)),  ω2 ∝ sn τ.
    /// Case L² < 2E·I2: the same with indices 1 ↔ 3 exchanged.
    /// sn has period 4K(k) in τ, so T = 4K(k)/λ.
    ///
    /// The needed differences are formed directly from ω to avoid
    /// cancellation: L² − 2E·Iₘ = Σᵢ Iᵢ(Iᵢ − Iₘ)ωᵢ², and
    /// k'² = 1 − k² = (I3−I1)(L²−2EI2)/((I3−I2)(L²−2EI1)) in case 1.
    fn analytic_flip_period(inertia: DVec3, omega_body: DVec3) -> f64 {
        // Sort the principal axes so that i1 < i2 < i3.
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| inertia[a].partial_cmp(&inertia[b]).unwrap());
        let (i1, i2, i3) = (inertia[idx[0]], inertia[idx[1]], inertia[idx[2]]);
        let d = |im: f64| -> f64 {
            (0..3)
                .map(|n| inertia[n] * (inertia[n] - im) * omega_body[n] * omega_body[n])
                .sum()
        };
        let l2_m_2ei1 = d(i1); // L² − 2E I1 ≥ 0
        let l2_m_2ei2 = d(i2); // sign selects the case
        let l2_m_2ei3 = d(i3); // L² − 2E I3 ≤ 0
        let (lambda2, kprime2) = if l2_m_2ei2 > 0.0 {
            (
                (i3 - i2) * l2_m_2ei1 / (i1 * i2 * i3),
                (i3 - i1) * l2_m_2ei2 / ((i3 - i2) * l2_m_2ei1),
            )
        } else {
            (
                (i2 - i1) * (-l2_m_2ei3) / (i1 * i2 * i3),
                (i3 - i1) * (-l2_m_2ei2) / ((i2 - i1) * (-l2_m_2ei3)),
            )
        };
        4.0 * elliptic_k_from_kprime2(kprime2) / lambda2.sqrt()
    }

    /// 1×2×3 box of density 1: m = 6, principal moments m(b²+c²)/12 etc.
    fn box_inertia() -> DVec3 {
        let (a, b, c) = (1.0_f64, 2.0_f64, 3.0_f64);
        let m = a * b * c;
        DVec3::new(
            m * (b * b + c * c) / 12.0, // 6.5  (largest)
            m * (a * a + c * c) / 12.0, // 5.0  (intermediate)
            m * (a * a + b * b) / 12.0, // 2.5  (smallest)
        )
    }

    struct FlipRun {
        /// Mean measured period between successive +→− sign changes of ω_y.
        period: f64,
        /// Number of full periods measured.
        n_periods: usize,
        max_rel_energy_err: f64,
        max_rel_l_err: f64,
    }

    /// Integrate the torque-free box spun about its intermediate (y) axis.
    fn run_flip(
        omega0: DVec3,
        q0: DQuat,
        dt: f64,
        n_steps: usize,
        step: fn(DQuat, DVec3, DVec3, f64) -> DQuat,
    ) -> FlipRun {
        let inertia = box_inertia();
        let inv = inertia.recip();
        let mut q = q0;
        let l_world = q * (inertia * omega0);
        let e0 = rotational_energy(q, l_world, inv);
        let l0 = l_world.length();
        let mut max_de = 0.0_f64;
        let mut max_dl = 0.0_f64;
        // Body-frame intermediate-axis angular velocity.
        let wy = |q: DQuat| (inv * (q.inverse() * l_world)).y;
        let mut prev = wy(q);
        let mut crossings = Vec::new();
        for n in 0..n_steps {
            q = step(q, l_world, inv, dt);
            let cur = wy(q);
            if prev > 0.0 && cur <= 0.0 {
                // Linear interpolation of the crossing time; its error is
                // O(dt² ω̈/ω̇) ≈ 1e-7 of dt here, negligible.
                let frac = prev / (prev - cur);
                crossings.push((n as f64 + frac) * dt);
            }
            prev = cur;
            let e = rotational_energy(q, l_world, inv);
            max_de = max_de.max(((e - e0) / e0).abs());
            // |L| seen from the body: this is what a body-frame integrator
            // would have to conserve (world L is constant by construction).
            let lb = (q.inverse() * l_world).length();
            max_dl = max_dl.max(((lb - l0) / l0).abs());
        }
        assert!(crossings.len() >= 3, "too few flips: {}", crossings.len());
        let n_periods = crossings.len() - 1;
        let period = (crossings[n_periods] - crossings[0]) / n_periods as f64;
        FlipRun {
            period,
            n_periods,
            max_rel_energy_err: max_de,
            max_rel_l_err: max_dl,
        }
    }

    fn generic_q0() -> DQuat {
        DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 0.7)
    }

    /// Dzhanibekov flip: spin about the intermediate axis, small perturbation.
    ///
    /// Tolerance: a symplectic splitting reproduces a modified Hamiltonian
    /// H̃ = H + O(hᵖ) exactly (backward error analysis, Hairer, Lubich &
    /// Wanner 2006, ch. IX), so the simulated orbit is a closed orbit of H̃
    /// whose period differs from the exact one by O(hᵖ) — a systematic shift,
    /// not an accumulating phase error. Crude bound for p = 2, |ω|h = 1e-3:
    /// the energy deviates by ≤ 7e-8 relative; near the separatrix
    /// T ≈ (2/λ)·ln(16/k'²) with k'² ∝ L² − 2E·I2 ≈ 0.035 ≪ 2E·I2 ≈ 25.5, so
    /// δT/T ≲ (7e-8·25.5/0.035)/ln(16/k'²) ≈ 5e-5/7.7 ≈ 1e-5 (measured 2e-7:
    /// the O(h²) modification of H̃ is mostly oscillatory along the orbit).
    /// The required 1% is thus extremely loose; we additionally assert 1e-5
    /// for order 2 (the bound) and 1e-9 for order 4 to catch regressions, and
    /// energy / |L| within 1e-6 over 1e5 steps.
    #[test]
    fn dzhanibekov_flip_period_and_conservation() {
        let omega0 = DVec3::new(0.1, 1.0, 0.1);
        let inertia = box_inertia();
        let t_analytic = analytic_flip_period(inertia, omega0);
        let dt = 1e-3;
        let n_steps = 100_000;
        // T ≈ 31.7 s: 1e5 steps of 1e-3 s cover > 3 periods.
        assert!(
            n_steps as f64 * dt > 3.0 * t_analytic,
            "run must cover > 2 full periods"
        );
        for (name, step, tol) in [
            ("drift (order 2)", drift as fn(_, _, _, _) -> _, 1e-5),
            ("drift_order4", drift_order4, 1e-9),
        ] {
            let run = run_flip(omega0, generic_q0(), dt, n_steps, step);
            let rel = (run.period - t_analytic).abs() / t_analytic;
            eprintln!(
                "{name}: analytic T = {t_analytic:.12}, measured T = {:.12} over {} periods, \
                 rel err {rel:.3e}; max |dE|/E = {:.3e}, max |d|L||/|L| = {:.3e}",
                run.period, run.n_periods, run.max_rel_energy_err, run.max_rel_l_err
            );
            assert!(run.n_periods >= 2);
            assert!(rel < 1e-2, "{name}: period error {rel} above 1%");
            assert!(
                rel < tol,
                "{name}: period error {rel} far above the expected O(h^p) level"
            );
            assert!(run.max_rel_energy_err < 1e-6, "{name}: energy drift");
            assert!(run.max_rel_l_err < 1e-6, "{name}: |L| drift");
        }
    }

    /// The other branch of the Landau–Lifshitz solution (L² < 2E·I2):
    /// perturb towards the smallest axis only.
    #[test]
    fn dzhanibekov_flip_other_branch() {
        let omega0 = DVec3::new(0.0, 1.0, 0.15);
        let inertia = box_inertia();
        let l2_m_2ei2: f64 = (0..3)
            .map(|n| inertia[n] * (inertia[n] - inertia.y) * omega0[n] * omega0[n])
            .sum();
        assert!(l2_m_2ei2 < 0.0);
        let t_analytic = analytic_flip_period(inertia, omega0);
        let run = run_flip(omega0, DQuat::IDENTITY, 1e-3, 100_000, drift);
        let rel = (run.period - t_analytic).abs() / t_analytic;
        eprintln!(
            "flip (L^2<2EI2): analytic T = {t_analytic:.12}, measured T = {:.12} ({} periods), \
             rel err {rel:.3e}, max |dE|/E = {:.3e}",
            run.period, run.n_periods, run.max_rel_energy_err
        );
        assert!(run.n_periods >= 2);
        assert!(rel < 1e-5);
        assert!(run.max_rel_energy_err < 1e-6);
    }

    /// Halving dt must shrink the period error (by ~2² for the 2nd-order
    /// scheme, ~2⁴ for the 4th-order one) unless it is already at round-off.
    /// Coarse steps are used so that the error is well above round-off (at
    /// dt = 1e-3 the 4th-order error is ~1e-13, i.e. already round-off).
    #[test]
    fn period_error_shrinks_with_dt() {
        let omega0 = DVec3::new(0.1, 1.0, 0.1);
        let t_analytic = analytic_flip_period(box_inertia(), omega0);
        let t_end = 3.2 * t_analytic;
        for (name, step, dt, min_ratio) in [
            ("drift (order 2)", drift as fn(_, _, _, _) -> _, 0.01, 3.0),
            ("drift_order4", drift_order4, 0.05, 10.0),
        ] {
            let err = |dt: f64| {
                let run = run_flip(omega0, generic_q0(), dt, (t_end / dt) as usize, step);
                (run.period - t_analytic).abs() / t_analytic
            };
            let (e1, e2) = (err(dt), err(0.5 * dt));
            eprintln!(
                "{name}: dt = {dt}: rel period err {e1:.3e}; dt/2: {e2:.3e}; ratio {:.2}",
                e1 / e2
            );
            assert!(e2 < 1e-10 || e1 / e2 > min_ratio, "{name}: {e1} -> {e2}");
        }
    }

    /// Isotropic inertia: the drift is the exact rotation by |ω|dt about ω.
    #[test]
    fn isotropic_is_exact_rotation() {
        let inv = DVec3::splat(1.0 / 0.4);
        let l = DVec3::new(0.3, -1.2, 0.7);
        let q0 = generic_q0();
        let dt = 0.37;
        let q1 = drift(q0, l, inv, dt);
        let omega = angular_velocity(q0, l, inv);
        assert!((omega - l * inv).length() < 1e-14);
        let (axis, angle) = (q1 * q0.inverse()).to_axis_angle();
        let expected = omega.length() * dt;
        assert!((angle - expected).abs() < 1e-12, "{angle} vs {expected}");
        assert!((axis - omega.normalize()).length() < 1e-12);
        // A body-fixed vector along ω stays put; one perpendicular turns by the angle.
        let w_hat = omega.normalize();
        let perp = w_hat.any_orthonormal_vector();
        let perp_body = q0.inverse() * perp;
        let perp_new = q1 * perp_body;
        let cos = perp.dot(perp_new);
        assert!((cos - expected.cos()).abs() < 1e-12);
        assert!((q1 * (q0.inverse() * w_hat) - w_hat).length() < 1e-12);
        // Also within the relative tolerance: tiny anisotropy is treated as isotropic.
        assert!(is_isotropic(DVec3::new(2.5, 2.5 * (1.0 + 1e-13), 2.5)));
        assert!(!is_isotropic(DVec3::new(2.5, 2.5 * (1.0 + 1e-9), 2.5)));
        // Energy and ω are unchanged.
        let e0 = rotational_energy(q0, l, inv);
        let e1 = rotational_energy(q1, l, inv);
        assert!(((e1 - e0) / e0).abs() < 1e-14);
    }

    /// Symmetric compositions of exact flows are time reversible:
    /// drift(drift(q, +dt), −dt) = q.
    #[test]
    fn time_reversible() {
        let l = DVec3::new(0.4, 5.0, -0.6);
        let q0 = generic_q0();
        for inv in [
            box_inertia().recip(),
            DVec3::splat(0.5),
            DVec3::new(1.0, 0.2, 3.0),
        ] {
            for dt in [1e-3, 0.05, 0.3] {
                for step in [drift as fn(_, _, _, _) -> _, drift_order4] {
                    let q1 = step(q0, l, inv, dt);
                    let q2 = step(q1, l, inv, -dt);
                    let diff = (q2 - q0).length().min((q2 + q0).length());
                    assert!(diff < 1e-12, "inv {inv:?} dt {dt}: {diff:e}");
                    assert!((q1 - q0).length() > 1e-6);
                }
            }
        }
    }

    /// Sub-flows are exact rotations: the body-frame |L| and |q| are kept,
    /// and a body spinning exactly about a principal axis keeps spinning there.
    #[test]
    fn principal_axis_spin_is_exact() {
        let inertia = box_inertia();
        let inv = inertia.recip();
        let q0 = generic_q0();
        for axis in 0..3 {
            let mut w = DVec3::ZERO;
            w[axis] = 2.0;
            let l = q0 * (inertia * w);
            let dt = 0.01;
            let mut q = q0;
            for _ in 0..1000 {
                q = drift(q, l, inv, dt);
            }
            let expected = q0 * DQuat::from_scaled_axis(w * 1000.0 * dt);
            let diff = (q - expected).length().min((q + expected).length());
            assert!(diff < 1e-10, "axis {axis}: {diff:e}");
            assert!((q.length() - 1.0).abs() < 1e-15);
        }
    }

    /// Zero momentum and zero dt are no-ops.
    #[test]
    fn trivial_cases() {
        let q0 = generic_q0();
        let inv = box_inertia().recip();
        assert!((drift(q0, DVec3::ZERO, inv, 0.1) - q0).length() < 1e-15);
        assert!((drift(q0, DVec3::new(1.0, 2.0, 3.0), inv, 0.0) - q0).length() < 1e-15);
        assert!((drift(q0, DVec3::ZERO, DVec3::ONE, 0.1) - q0).length() < 1e-15);
        assert_eq!(rotational_energy(q0, DVec3::ZERO, inv), 0.0);
    }

    /// The same flip through the whole engine, as a user would set it up: a 1 × 2 × 3 m box
    /// particle from a scene file (mass properties from its surface, body frame on its principal
    /// axes, whatever order they come in), spun about its intermediate axis (y in the user's frame)
    /// with no gravity and nothing to touch, integrated by `World::run_steps`.
    #[test]
    fn box_particle_in_a_world_flips_with_the_analytic_period() {
        use crate::scene::Scene;
        let text = r#"
[simulation]
duration = 100.0
time_step = 1e-3
force_time_step = true
gravity = [0.0, 0.0, 0.0]

[[material]]
name = "m"
density = 1.0
youngs_modulus = 1e7
poisson_ratio = 0.25
restitution = 1.0
friction = 0.0

[shape.brick]
type = "box"
edges = [1.0, 2.0, 3.0]

[[particle]]
shape = "brick"
material = "m"
position = [0.0, 0.0, 0.0]
angular_velocity = [0.1, 1.0, 0.1]
"#;
        let mut world = Scene::parse(std::path::Path::new("flip.toml"), text.to_string())
            .unwrap()
            .build()
            .unwrap()
            .world;
        let b = world.bodies();
        // The principal moments are the box's, in some order.
        let mut moments = b.inertia[0].to_array();
        moments.sort_by(f64::total_cmp);
        assert!((moments[0] - 2.5).abs() < 1e-12 && (moments[1] - 5.0).abs() < 1e-12);
        assert!((moments[2] - 6.5).abs() < 1e-12);
        let axis = (0..3)
            .find(|&k| (b.inertia[0][k] - 5.0).abs() < 1e-9)
            .unwrap();
        let omega_body = b.orientation[0].inverse() * DVec3::new(0.1, 1.0, 0.1);
        let expected = analytic_flip_period(b.inertia[0], omega_body);
        let energy = |w: &crate::World| {
            let e = w.energy();
            e.kinetic_rotational + e.kinetic_translational
        };
        let (e0, l0) = (energy(&world), world.bodies().angular_momentum[0].length());
        let intermediate = |w: &crate::World| {
            (w.bodies().orientation[0].inverse() * w.bodies().angular_velocity[0])[axis]
        };
        let (mut previous, mut crossings) = (intermediate(&world), Vec::new());
        let (mut worst_e, mut worst_l) = (0.0_f64, 0.0_f64);
        for n in 0..100_000u32 {
            world.run_steps(1);
            let now = intermediate(&world);
            if previous > 0.0 && now <= 0.0 {
                crossings.push((f64::from(n) + previous / (previous - now)) * 1e-3);
            }
            previous = now;
            worst_e = worst_e.max((energy(&world) / e0 - 1.0).abs());
            worst_l = worst_l.max((world.bodies().angular_momentum[0].length() / l0 - 1.0).abs());
        }
        let periods = crossings.len() - 1;
        assert!(periods >= 2, "too few flips: {crossings:?}");
        let period = (crossings[periods] - crossings[0]) / periods as f64;
        println!(
            "world: period {period} vs analytic {expected}, energy {worst_e:.1e}, |L| {worst_l:.1e}"
        );
        // Tolerances as in the direct test above (1e-5 on the period; the issue asks 1e-6 on
        // energy and |L| over 1e5 steps).
        assert!((period / expected - 1.0).abs() < 1e-5);
        assert!(worst_e < 1e-6 && worst_l < 1e-6);
    }
}
