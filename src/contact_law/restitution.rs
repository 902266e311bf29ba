//! The damping constant that gives a chosen coefficient of restitution.
//!
//! With F = F_el(δ) + c √(m* S_n(δ)) δ̇ and F_el ∝ δ (linear) or δ^{3/2} (Hertz), the equation of a
//! binary collision, m* δ̈ = −F, becomes free of every scale once δ and t are made dimensionless:
//! s'' = −(f(s) + c √f'(s) s') with f(s) = s or s^{3/2}. The restitution coefficient e = −s'_out/s'_in
//! therefore depends on c alone, for any masses, radii, moduli and impact speeds (for Hertz this is
//! the velocity independence noted by Tsuji et al. 1992). The force is cut off at zero (no tension),
//! which changes e(c) from the textbook closed form of the linear model (Schwager & Pöschel 2007
//! discuss exactly this); instead of a closed form we integrate the dimensionless equation once per
//! material pair and invert e(c) by bisection, so that the rebound matches the user's e exactly for
//! both laws.

use super::NormalLaw;

/// Dimensionless c such that a collision under `law` rebounds with coefficient `restitution`.
pub fn damping_for_restitution(law: NormalLaw, restitution: f64) -> f64 {
    if restitution >= 1.0 {
        return 0.0;
    }
    if restitution <= 0.0 {
        // Perfectly plastic: no finite dashpot reaches it; the law holds it to the strongest
        // the step can take (`contact_law::DASHPOT_BOUND`).
        return f64::INFINITY;
    }
    let mut hi = 1.0;
    while restitution_for_damping(law, hi) > restitution && hi < 1e6 {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if restitution_for_damping(law, mid) > restitution {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Coefficient of restitution of a collision with dimensionless damping `c` (4th-order Runge–Kutta
/// on the dimensionless collision equation).
pub fn restitution_for_damping(law: NormalLaw, c: f64) -> f64 {
    let accel = |s: f64, v: f64| -> f64 {
        if s <= 0.0 {
            return 0.0;
        }
        let (f, df) = match law {
            NormalLaw::Linear { .. } => (s, 1.0),
            NormalLaw::Hertz => (s * s.sqrt(), 1.5 * s.sqrt()),
        };
        -(f + c * df.sqrt() * v).max(0.0)
    };
    let h = 2e-4;
    let (mut s, mut v) = (0.0_f64, 1.0_f64);
    let mut t = 0.0;
    while t < 200.0 {
        let (k1s, k1v) = (v, accel(s, v));
        let (k2s, k2v) = (
            v + 0.5 * h * k1v,
            accel(s + 0.5 * h * k1s, v + 0.5 * h * k1v),
        );
        let (k3s, k3v) = (
            v + 0.5 * h * k2v,
            accel(s + 0.5 * h * k2s, v + 0.5 * h * k2v),
        );
        let (k4s, k4v) = (v + h * k3v, accel(s + h * k3s, v + h * k3v));
        s += h / 6.0 * (k1s + 2.0 * k2s + 2.0 * k3s + k4s);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        t += h;
        // Separated: either out of contact, or the force has vanished while receding so the
        // bodies fly apart at constant speed.
        if s <= 0.0 || (v < 0.0 && accel(s, v) == 0.0) {
            return -v;
        }
    }
    // Overdamped so strongly that the bodies have not separated: no rebound worth the name.
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    const LINEAR: NormalLaw = NormalLaw::Linear { stiffness: 1.0 };

    #[test]
    fn undamped_collisions_are_elastic() {
        for law in [LINEAR, NormalLaw::Hertz] {
            assert_eq!(damping_for_restitution(law, 1.0), 0.0);
            assert!((restitution_for_damping(law, 0.0) - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn inversion_reproduces_the_requested_restitution() {
        for law in [LINEAR, NormalLaw::Hertz] {
            for e in [0.95, 0.9, 0.5, 0.1, 0.02] {
                let c = damping_for_restitution(law, e);
                assert!(
                    (restitution_for_damping(law, c) - e).abs() < 1e-6,
                    "{law:?} e={e}"
                );
            }
        }
    }

    #[test]
    fn linear_damping_is_close_to_the_closed_form_without_cut_off() {
        // Without the no-tension cut-off, e = exp(−πζ/√(1−ζ²)) with c = 2ζ (Cundall & Strack).
        // The cut-off removes the pulling phase, so more damping is needed for the same e, but for
        // weak damping the pulling phase is short and the two must nearly agree.
        for e in [0.9_f64, 0.5] {
            let zeta = -e.ln() / (std::f64::consts::PI.powi(2) + e.ln().powi(2)).sqrt();
            let c = damping_for_restitution(LINEAR, e);
            assert!(c > 2.0 * zeta, "cut-off must need more damping");
            assert!(
                c < 2.0 * zeta * 1.35,
                "e={e}: c={c} vs closed form {}",
                2.0 * zeta
            );
        }
    }
}
