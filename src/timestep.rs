//! Estimate of the largest stable and accurate time step.

use crate::body::Bodies;
use crate::contact_law::NormalLaw;
use crate::material::Material;
use std::f64::consts::PI;

#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The step [s].
    pub seconds: f64,
    /// How it was found, for the user.
    pub reason: String,
}

/// The estimate for a set of bodies under a normal law, or `None` without bodies.
///
/// Hertz: 20 % of the shortest Rayleigh time T_R = π r √(ρ/G) / (0.1631 ν + 0.8766) over the
/// bodies, set by small, stiff, light ones (Li, Xu & Thornton 2005, Powder Technol. 160, 219;
/// 20–40 % is common practice).
/// Linear spring: 1/20 of the contact duration π √(m*/k) of the two lightest bodies, m* = m/2
/// (Cundall & Strack 1979 take a fraction of √(m/k)); a sphere on a wall has m* = m, so its contact
/// lasts longer and is covered by the same bound.
pub fn estimate(bodies: &Bodies, materials: &[Material], law: NormalLaw) -> Option<Estimate> {
    if bodies.is_empty() {
        return None;
    }
    match law {
        NormalLaw::Hertz => {
            let mut best: Option<(f64, usize)> = None;
            for i in 0..bodies.len() {
                let m = &materials[bodies.material[i] as usize];
                let r = bodies.bounding_radius[i];
                let rayleigh = PI * r * (m.density / m.shear_modulus()).sqrt()
                    / (0.1631 * m.poisson_ratio + 0.8766);
                if best.is_none_or(|(t, _)| rayleigh < t) {
                    best = Some((rayleigh, i));
                }
            }
            let (rayleigh, i) = best?;
            Some(Estimate {
                seconds: 0.2 * rayleigh,
                reason: format!(
                    "20% of the Rayleigh time {rayleigh:.3e} s of the smallest body \
                     (radius {:.3e} m, material '{}')",
                    bodies.bounding_radius[i], materials[bodies.material[i] as usize].name
                ),
            })
        }
        NormalLaw::Linear { stiffness } => {
            let lightest = bodies.mass.iter().cloned().fold(f64::INFINITY, f64::min);
            let duration = PI * (0.5 * lightest / stiffness).sqrt();
            Some(Estimate {
                seconds: duration / 20.0,
                reason: format!(
                    "1/20 of the contact duration {duration:.3e} s of the lightest bodies \
                     (mass {lightest:.3e} kg, stiffness {stiffness:.3e} N/m)"
                ),
            })
        }
    }
}
