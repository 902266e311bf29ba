//! Estimate of the largest stable and accurate time step.

use crate::contact_law::{restitution, NormalLaw, DASHPOT_BOUND};
use crate::material::Material;
use std::f64::consts::PI;

/// A body the step must suit: its bounding radius [m], mass [kg] and material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    pub radius: f64,
    pub mass: f64,
    pub material: u32,
    /// For a polyhedron: its volume-equivalent radius and largest face area (see below).
    pub polyhedron: Option<(f64, f64)>,
    /// For a body under the vertex law (a non-convex mesh): the corners of its largest flat
    /// face, the springs a flat contact can hold (see below).
    pub vertex_springs: Option<usize>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// The step [s].
    pub seconds: f64,
    /// How it was found, for the user.
    pub reason: String,
    /// The deepest overlap the expected impacts bring, relative to the body's size.
    pub deepest: Option<DeepOverlap>,
}

/// The deepest overlap of an expected impact: δ_max over the body's (volume-equivalent) radius.
/// A contact law is a model of small overlaps; at overlaps comparable to the bodies' size bodies
/// pass through each other or are thrown out (20 m cubes of E = 10 MPa falling 400 m gained 7×
/// their energy: issue #11, point 4).
#[derive(Clone, Debug, PartialEq)]
pub struct DeepOverlap {
    pub ratio: f64,
    /// The material whose stiffness sets it.
    pub material: u32,
    /// δ_max ∝ E^(−1/power): 5/2 for Hertz, 2 for the linear and volume laws; `None` when the
    /// stiffness is `[contact] stiffness` (the linear law of spheres), not a modulus.
    pub modulus_power: Option<f64>,
    /// Which impact, for the user.
    pub what: String,
}

/// Steps per contact the estimate allows at least: the validation tests show the energy ledger
/// within a few tenths of a percent and rebounds within 2 % from about this resolution on.
pub const STEPS_PER_CONTACT: f64 = 25.0;

/// The strongest dashpot the estimate plans for, as γ dt/m* at the peak of the expected contact:
/// below [`DASHPOT_BOUND`], where the law would cut it, so that the restitution asked for is the
/// one obtained (issue #11, point 3).
pub const DASHPOT_STEP: f64 = 0.8 * DASHPOT_BOUND;

/// Below this restitution the estimate plans for this one: a smaller e needs a dashpot the step
/// cannot resolve, and such contacts get the strongest the step can take (e ≈ 0.005).
pub const RESTITUTION_STEP_FLOOR: f64 = 0.01;

/// Steps per contact that resolve both the spring ([`STEPS_PER_CONTACT`]) and the dashpot of a
/// pair of restitution `e`: γ dt/m* = c ω_max dt ≤ [`DASHPOT_STEP`], with ω_max the largest
/// √(S_n/m*) of the contact, ω_max t_c = 4.0303 for Hertz (S_n = 3/2 F/δ at δ_max; t_c of
/// [`impact_duration`]) and π for a linear spring.
fn steps_per_contact(law: NormalLaw, e: f64, cache: &mut Vec<(bool, u64, f64)>) -> f64 {
    let hertz = matches!(law, NormalLaw::Hertz);
    if let Some(&(_, _, steps)) = cache
        .iter()
        .find(|(h, bits, _)| *h == hertz && *bits == e.to_bits())
    {
        return steps;
    }
    let c = restitution::damping_for_restitution(law, e.max(RESTITUTION_STEP_FLOOR));
    let omega_duration = if hertz { 4.0303 } else { PI };
    let steps = (omega_duration * c / DASHPOT_STEP).max(STEPS_PER_CONTACT);
    cache.push((hertz, e.to_bits(), steps));
    steps
}

/// How a contact's steps were chosen, for the user.
fn steps_reason(steps: f64, e: f64) -> String {
    if steps > STEPS_PER_CONTACT {
        format!("1/{steps:.0} (for the dashpot of restitution {e})")
    } else {
        format!("1/{steps:.0}")
    }
}

/// What the scene tells about the contacts to expect.
pub struct Conditions<'a> {
    pub materials: &'a [Material],
    /// Materials of the walls bodies can hit.
    pub wall_materials: &'a [u32],
    pub law: NormalLaw,
    /// Largest impact speed to expect [m/s]: initial speeds plus a free fall across the scene.
    pub impact_speed: f64,
}

/// The estimate for a set of bodies, or `None` without bodies. The smallest of:
///
/// - Hertz: 20 % of the Rayleigh time T_R = π r √(ρ/G) / (0.1631 ν + 0.8766) of each body
///   (Li, Xu & Thornton 2005, Powder Technol. 160, 219), which bounds the elastic wave speed;
/// - Hertz: 1/[`STEPS_PER_CONTACT`] of the duration of the fastest expected impact, body on body
///   at twice `impact_speed` and body on wall at `impact_speed`: t_c = 2.943 δ_max/v with
///   δ_max = (15 m* v²/(16 E* √R*))^{2/5} (Johnson 1985 §11.1). Impacts shorten with speed, and
///   soft DEM materials make them short compared with T_R;
/// - linear spring: 1/[`STEPS_PER_CONTACT`] of the contact duration π √(m*/k) of the lightest
///   bodies, m* = m/2 (Cundall & Strack 1979 take a fraction of √(m/k));
/// - polyhedra: 1/[`STEPS_PER_CONTACT`] of the duration π √(m*/k) of a flat contact: under the
///   volume law k = E* A/R* for the largest face A; under the vertex law (non-convex meshes)
///   k = n E* R* for the n corners of the largest flat face.
///
/// Strongly damped pairs (e ≲ 0.05) get more steps per contact, so that their dashpot is
/// resolved too ([`steps_per_contact`]).
pub fn estimate(bodies: impl Iterator<Item = Candidate>, c: &Conditions) -> Option<Estimate> {
    let mut best: Option<Estimate> = None;
    let mut deepest: Option<DeepOverlap> = None;
    let mut deep =
        |ratio: f64, material: u32, modulus_power: Option<f64>, what: &dyn Fn() -> String| {
            if ratio.is_finite() && deepest.as_ref().is_none_or(|d| ratio > d.ratio) {
                deepest = Some(DeepOverlap {
                    ratio,
                    material,
                    modulus_power,
                    what: what(),
                });
            }
        };
    let mut cache = Vec::new();
    let mut steps = |law: NormalLaw, a: &Material, b: &Material| {
        let e = 0.5 * (a.restitution + b.restitution);
        (steps_per_contact(law, e, &mut cache), e)
    };
    let mut consider = |seconds: f64, reason: &dyn Fn() -> String| {
        if best.as_ref().is_none_or(|b| seconds < b.seconds) {
            best = Some(Estimate {
                seconds,
                reason: reason(),
                deepest: None,
            });
        }
    };
    for body in bodies {
        let m = &c.materials[body.material as usize];
        if let Some((radius, area)) = body.polyhedron {
            // Volume law: a flat contact of area A is a linear spring of stiffness E* A / R*.
            for (other, mass, r) in std::iter::once((m, 0.5 * body.mass, 0.5 * radius)).chain(
                c.wall_materials
                    .iter()
                    .map(|&w| (&c.materials[w as usize], body.mass, radius)),
            ) {
                let e = effective_modulus(m, other);
                let (stiffness, how) = match body.vertex_springs {
                    // Vertex law: springs E* R* at the face's corners.
                    Some(n) => (e * r * n as f64, "flat on its vertex springs"),
                    None => (e * area / r, "face-on"),
                };
                let duration = PI * (mass / stiffness).sqrt();
                // Face-on at the impact speed (twice that between two bodies): δ = v √(m*/k).
                let speed = if mass < body.mass {
                    2.0 * c.impact_speed
                } else {
                    c.impact_speed
                };
                deep(
                    speed * (mass / stiffness).sqrt() / radius,
                    body.material,
                    Some(2.0),
                    &|| {
                        format!(
                            "a polyhedron ('{}', mass {:.3e} kg) landing {how} on a '{}' face at \
                             {speed:.3} m/s",
                            m.name, body.mass, other.name
                        )
                    },
                );
                let (n, e) = steps(NormalLaw::Linear { stiffness }, m, other);
                consider(duration / n, &|| {
                    format!(
                        "{} of the contact duration {duration:.3e} s of a polyhedron ('{}', \
                         mass {:.3e} kg) pressed {how} against a '{}' face",
                        steps_reason(n, e),
                        m.name,
                        body.mass,
                        other.name
                    )
                });
            }
            continue;
        }
        match c.law {
            NormalLaw::Hertz => {
                let rayleigh = PI * body.radius * (m.density / m.shear_modulus()).sqrt()
                    / (0.1631 * m.poisson_ratio + 0.8766);
                consider(0.2 * rayleigh, &|| {
                    format!(
                        "20% of the Rayleigh time {rayleigh:.3e} s of a body of radius {:.3e} m \
                         ('{}')",
                        body.radius, m.name
                    )
                });
                if c.impact_speed > 0.0 {
                    let pair = impact_duration(
                        m,
                        m,
                        0.5 * body.mass,
                        0.5 * body.radius,
                        2.0 * c.impact_speed,
                    );
                    let depth = impact_depth(
                        m,
                        m,
                        0.5 * body.mass,
                        0.5 * body.radius,
                        2.0 * c.impact_speed,
                    );
                    deep(depth / body.radius, body.material, Some(2.5), &|| {
                        format!(
                            "two bodies of radius {:.3e} m ('{}') meeting at {:.3} m/s",
                            body.radius,
                            m.name,
                            2.0 * c.impact_speed
                        )
                    });
                    let (n, e) = steps(c.law, m, m);
                    consider(pair / n, &|| {
                        format!(
                            "{} of the {pair:.3e} s impact of two bodies of radius {:.3e} m \
                             ('{}') at {:.3} m/s",
                            steps_reason(n, e),
                            body.radius,
                            m.name,
                            2.0 * c.impact_speed
                        )
                    });
                    for &w in c.wall_materials {
                        let wall = &c.materials[w as usize];
                        let t = impact_duration(m, wall, body.mass, body.radius, c.impact_speed);
                        let depth = impact_depth(m, wall, body.mass, body.radius, c.impact_speed);
                        deep(depth / body.radius, body.material, Some(2.5), &|| {
                            format!(
                                "a body of radius {:.3e} m ('{}') hitting a '{}' wall at {:.3} m/s",
                                body.radius, m.name, wall.name, c.impact_speed
                            )
                        });
                        let (n, e) = steps(c.law, m, wall);
                        consider(t / n, &|| {
                            format!(
                                "{} of the {t:.3e} s impact of a body of radius {:.3e} m ('{}') \
                                 on a '{}' wall at {:.3} m/s",
                                steps_reason(n, e),
                                body.radius,
                                m.name,
                                wall.name,
                                c.impact_speed
                            )
                        });
                    }
                }
            }
            NormalLaw::Linear { stiffness } => {
                let duration = PI * (0.5 * body.mass / stiffness).sqrt();
                // Body on wall at the impact speed, δ = v √(m/k) (two bodies at twice the speed
                // with m* = m/2 go √2 deeper).
                let depth = 2.0f64.sqrt() * c.impact_speed * (body.mass / stiffness).sqrt();
                deep(depth / body.radius, body.material, None, &|| {
                    format!(
                        "two bodies of mass {:.3e} kg meeting at {:.3} m/s",
                        body.mass,
                        2.0 * c.impact_speed
                    )
                });
                // The most damped pair the body meets: itself or a wall.
                let (n, e) = std::iter::once(m)
                    .chain(c.wall_materials.iter().map(|&w| &c.materials[w as usize]))
                    .map(|other| steps(c.law, m, other))
                    .fold((0.0, 1.0), |a, b| if b.0 > a.0 { b } else { a });
                consider(duration / n, &|| {
                    format!(
                        "{} of the contact duration {duration:.3e} s of two bodies of mass \
                         {:.3e} kg (stiffness {stiffness:.3e} N/m)",
                        steps_reason(n, e),
                        body.mass
                    )
                });
            }
        }
    }
    best.map(|b| Estimate { deepest, ..b })
}

/// Deepest overlap of an undamped Hertz impact at speed `v`: δ_max = (15 m v²/(16 E* √r))^{2/5}
/// (Johnson 1985 §11.1).
pub fn impact_depth(a: &Material, b: &Material, m: f64, r: f64, v: f64) -> f64 {
    let e = effective_modulus(a, b);
    (15.0 * m * v * v / (16.0 * e * r.sqrt())).powf(0.4)
}

/// Duration of an undamped Hertz impact at speed `v` (Johnson 1985 §11.1; the constant
/// 2.943275 = Γ(2/5)Γ(1/2)/(5/2 Γ(9/10)) is checked in `tests/physics_hertz_impact.rs`).
pub fn impact_duration(a: &Material, b: &Material, m: f64, r: f64, v: f64) -> f64 {
    2.943275 * impact_depth(a, b, m, r, v) / v
}

/// E* of two materials (Johnson 1985).
fn effective_modulus(a: &Material, b: &Material) -> f64 {
    1.0 / ((1.0 - a.poisson_ratio.powi(2)) / a.youngs_modulus
        + (1.0 - b.poisson_ratio.powi(2)) / b.youngs_modulus)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glass() -> Material {
        Material {
            name: "glass".into(),
            density: 2500.0,
            youngs_modulus: 1e7,
            poisson_ratio: 0.25,
            restitution: 0.5,
            friction: 0.5,
            rolling_friction: 0.0,
        }
    }

    #[test]
    fn fast_impacts_of_soft_bodies_shorten_the_step() {
        let materials = [glass()];
        let body = Candidate {
            radius: 0.004,
            mass: 2500.0 * 4.0 / 3.0 * PI * 0.004f64.powi(3),
            material: 0,
            polyhedron: None,
            vertex_springs: None,
        };
        let conditions = |v| Conditions {
            materials: &materials,
            wall_materials: &[0],
            law: NormalLaw::Hertz,
            impact_speed: v,
        };
        let at_rest = estimate([body].into_iter(), &conditions(0.0)).unwrap();
        assert!(at_rest.reason.contains("Rayleigh"));
        let falling = estimate([body].into_iter(), &conditions(1.7)).unwrap();
        assert!(falling.seconds < at_rest.seconds && falling.reason.contains("impact"));
        // The chosen step resolves the wall impact with the promised number of steps.
        let t = impact_duration(&materials[0], &materials[0], body.mass, body.radius, 1.7);
        assert!(t / falling.seconds >= STEPS_PER_CONTACT * (1.0 - 1e-12));
        assert!(estimate(std::iter::empty(), &conditions(1.0)).is_none());
    }
}
