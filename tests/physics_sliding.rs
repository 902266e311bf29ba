//! A sphere launched without spin along a plane slides, then rolls.
//!
//! With Coulomb friction μ and normal force N = m g, the friction force μ m g opposes the slip of
//! the contact point: the centre decelerates at μ g, the spin grows at α = μ m g r / I = 5μg/(2r)
//! (I = 2/5 m r²), so the slip v − ω r falls at 7μg/2 and vanishes at t_r = 2 v₀/(7μg), when
//! v = v₀ − μ g t_r = 5 v₀/7; from then on the sphere rolls at constant speed (no rolling
//! resistance here).
//!
//! In the engine the contact point is the middle of the overlap, r' = r − δ/2 below the centre, so
//! the torque arm and the slip are computed with r': the exact law of the discrete model is
//! α = μ m g r'/I and slip = v − ω r', giving t_r' = v₀ / (μg (1 + 5r'²/(2r²))). At the equilibrium
//! overlap δ/r ≈ 6e-4 (Hertz) this differs from the textbook by ~4e-4, far inside the 2 % of the
//! brief. Against t_r' the measurement is exact up to round-off: once sliding, the friction force is
//! exactly μN at every step (the trial spring-dashpot force is far above the limit from the first
//! step on), N = m g exactly (the sphere starts at the equilibrium overlap of the discrete law), and
//! constant forces are integrated exactly by velocity Verlet. So the dt-convergence assertion is
//! the round-off form: both steps must agree with the r'-corrected values to < 1e-6.
//!
//! The end of sliding is where the straight line fitted to the slip of the sliding phase reaches
//! zero; the rolling onset "when the slip becomes small" is its first zero, interpolated between
//! steps. They differ slightly (see `check`) because the spring–dashpot friction law regularises
//! the stop of the slip.

use polydem::body::BodyInit;
use polydem::contact_law::NormalLaw;
use polydem::material::{Material, PairTable};
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::wall::Plane;
use polydem::{World, WorldConfig};
use std::f64::consts::PI;

const G: f64 = 9.81;
const R: f64 = 0.01;
const MU: f64 = 0.3;
const V0: f64 = 0.5;

struct Sample {
    t: f64,
    /// Centre velocity along the launch direction.
    v: f64,
    /// Spin about the rolling axis ẑ × d̂ (positive when rolling forwards).
    omega: f64,
    /// Slip of the contact point along d̂.
    slip: f64,
}

struct Outcome {
    /// Fitted deceleration over the sliding phase, and spin acceleration.
    deceleration: f64,
    spin_up: f64,
    /// End of sliding: where the straight line fitted to the slip over the sliding phase reaches
    /// zero.
    t_slide_end: f64,
    /// Rolling onset: the first zero of the slip (interpolated between steps), and the speed then.
    t_roll: f64,
    v_roll: f64,
    /// Speed averaged over [1.5 t_r, 2 t_r] (rolling).
    v_late: f64,
    /// Largest |slip| in the rolling phase, over v₀.
    rolling_slip: f64,
    /// The engine's contact arm r' = r − δ/2 at equilibrium.
    arm: f64,
}

/// Least-squares slope of y(t).
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (st, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mt, my) = (st / n, sy / n);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mt) * (p.1 - my), b + (p.0 - mt).powi(2))
    });
    num / den
}

fn run(law: NormalLaw, steps_per_period: f64) -> Outcome {
    let material = Material {
        name: "ball".into(),
        density: 2500.0,
        youngs_modulus: 1e8,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: MU,
        rolling_friction: 0.0,
    };
    let mass = material.density * 4.0 / 3.0 * PI * R.powi(3);
    // E* and G* of a sphere on a plane of the same material (Johnson 1985 §4.2, §7.2).
    let nu = material.poisson_ratio;
    let e_star = material.youngs_modulus / (2.0 * (1.0 - nu * nu));
    let g_star = material.youngs_modulus / (4.0 * (2.0 - nu) * (1.0 + nu));
    // Equilibrium overlap under the weight, and the normal and tangential stiffnesses there.
    let (overlap, k_n, k_t) = match law {
        NormalLaw::Hertz => {
            let k = 4.0 / 3.0 * e_star * R.sqrt();
            let d = (mass * G / k).powf(2.0 / 3.0);
            (d, 1.5 * k * d.sqrt(), 8.0 * g_star * (R * d).sqrt())
        }
        NormalLaw::Linear { stiffness } => (mass * G / stiffness, stiffness, 2.0 / 7.0 * stiffness),
    };
    // Time step from the fastest oscillation: the tangential spring acting on the translating and
    // rotating sphere (effective mass m/(1 + m r²/I) = m/3.5) or the normal spring.
    let omega_max = (3.5 * k_t / mass).sqrt().max((k_n / mass).sqrt());
    let dt = 2.0 * PI / omega_max / steps_per_period;

    let laws = PairTable::new(std::slice::from_ref(&material), law, 2.0 / 7.0, &[]);
    let mut w = World::new(WorldConfig {
        time_step: dt,
        gravity: DVec3::new(0.0, 0.0, -G),
        materials: vec![material],
        pair_laws: laws,
        planes: vec![Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            material: 0,
        }],
        broad_phase: Default::default(),
        skin: None,
        threads: 1,
    })
    .unwrap();
    let dir = DVec3::new(3.0, 4.0, 0.0).normalize();
    let axis = DVec3::Z.cross(dir);
    w.add_body(BodyInit {
        shape: Shape::Sphere(Sphere::new(R)),
        material: 0,
        position: DVec3::new(0.0, 0.0, R - overlap),
        orientation: DQuat::IDENTITY,
        velocity: dir * V0,
        angular_velocity: DVec3::ZERO,
    });
    let arm = R - 0.5 * overlap;

    let t_textbook = 2.0 * V0 / (7.0 * MU * G);
    let total = (2.0 * t_textbook / dt).ceil() as usize;
    let mut samples = Vec::with_capacity(total + 1);
    let sample = |w: &World| {
        let (v, omega) = (w.bodies().velocity[0], w.bodies().angular_velocity[0]);
        let contact_velocity = v + omega.cross(-DVec3::Z * arm);
        Sample {
            t: w.time(),
            v: v.dot(dir),
            omega: omega.dot(axis),
            slip: contact_velocity.dot(dir),
        }
    };
    samples.push(sample(&w));
    for _ in 0..total {
        w.run_steps(1);
        assert_eq!(
            w.contacts().with_planes().count(),
            1,
            "the sphere left the plane"
        );
        samples.push(sample(&w));
    }

    // Onset: the slip falls linearly while sliding; the first step at which it is ≤ 0 and the one
    // before bracket the onset, and linear interpolation between them is exact for a linear slip.
    let k = samples
        .iter()
        .position(|s| s.slip <= 0.0)
        .expect("never started rolling");
    let (a, b) = (&samples[k - 1], &samples[k]);
    let t_roll = a.t + (b.t - a.t) * a.slip / (a.slip - b.slip);
    let v_roll = a.v + (b.v - a.v) * (t_roll - a.t) / (b.t - a.t);

    let sliding = |f: fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        samples
            .iter()
            .filter(|s| s.t > 0.1 * t_roll && s.t < 0.9 * t_roll)
            .map(|s| (s.t, f(s)))
            .collect()
    };
    let late: Vec<&Sample> = samples
        .iter()
        .filter(|s| s.t >= 1.5 * t_roll && s.t <= 2.0 * t_roll)
        .collect();
    // Line through the slip samples of the sliding phase: zero at its mean time minus mean/slope.
    let slip_line = sliding(|s| s.slip);
    let n = slip_line.len() as f64;
    let mean_t = slip_line.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_slip = slip_line.iter().map(|p| p.1).sum::<f64>() / n;
    Outcome {
        t_slide_end: mean_t - mean_slip / slope(&slip_line),
        deceleration: -slope(&sliding(|s| s.v)),
        spin_up: slope(&sliding(|s| s.omega)),
        t_roll,
        v_roll,
        v_late: late.iter().map(|s| s.v).sum::<f64>() / late.len() as f64,
        rolling_slip: samples[k + 1..]
            .iter()
            .map(|s| s.slip.abs())
            .fold(0.0, f64::max)
            / V0,
        arm,
    }
}

fn check(name: &str, law: NormalLaw) {
    let textbook_t = 2.0 * V0 / (7.0 * MU * G);
    let textbook_v = 5.0 * V0 / 7.0;
    let mut exact_errors = Vec::new();
    for steps in [25.0, 50.0] {
        let o = run(law, steps);
        // The discrete model's own solution with the contact arm r'.
        let ratio = (o.arm / R).powi(2);
        let t_exact = V0 / (MU * G * (1.0 + 2.5 * ratio));
        let v_exact = V0 - MU * G * t_exact;
        println!(
            "{name}, {steps} steps/period: deceleration {:.6} (μg {:.6}), spin-up {:.4} \
             (5μg r'/(2r²) {:.4}), sliding ends {:.6e}, slip vanishes {:.6e} (2v₀/7μg {:.6e}), v_roll {:.6} (5v₀/7 {:.6}), \
             v late {:.6}, max rolling slip {:.2e} v₀",
            o.deceleration,
            MU * G,
            o.spin_up,
            2.5 * MU * G * o.arm / (R * R),
            o.t_slide_end,
            o.t_roll,
            textbook_t,
            o.v_roll,
            textbook_v,
            o.v_late,
            o.rolling_slip,
        );
        // The brief's 2 % against the textbook values.
        assert!((o.deceleration / (MU * G) - 1.0).abs() < 0.02);
        assert!((o.spin_up / (2.5 * MU * G / R) - 1.0).abs() < 0.02);
        assert!((o.t_slide_end / textbook_t - 1.0).abs() < 0.02);
        assert!((o.t_roll / textbook_t - 1.0).abs() < 0.02);
        // The slip does not stop dead at the end of sliding: once the tangential dashpot force γ v_t
        // falls below μN (v_t ≲ μN/γ, a few mm/s) the friction leaves the Coulomb limit and the slip
        // decays over ~m/(3.5γ) ≈ 0.5 ms. That delays its first zero past the end of sliding by a
        // fraction of a millisecond, a property of the spring–dashpot model, not of the step:
        // measured 1e-3 (Hertz) and 2.5e-3 (linear) of t_r at both steps. Bound it by 0.5 %.
        assert!((o.t_roll / o.t_slide_end - 1.0).abs() < 5e-3);
        assert!((o.v_roll / textbook_v - 1.0).abs() < 0.02);
        // Rolling goes on at 5v₀/7: the stuck tangential spring only oscillates about it.
        assert!((o.v_late / textbook_v - 1.0).abs() < 0.02);
        assert!(o.rolling_slip < 0.02, "slips while rolling");
        exact_errors.push([
            o.deceleration / (MU * G) - 1.0,
            o.t_slide_end / t_exact - 1.0,
            o.v_roll / v_exact - 1.0,
        ]);
    }
    println!(
        "{name}: relative errors (deceleration, end of sliding, v at rolling onset) against the \
         r'-corrected solution, at 25 and 50 steps/period: {}",
        exact_errors
            .iter()
            .map(|e| format!("[{:+.1e} {:+.1e} {:+.1e}]", e[0], e[1], e[2]))
            .collect::<Vec<_>>()
            .join(" ")
    );
    // Both steps agree with the discrete model's exact solution to round-off (see the header);
    // 1e-6 leaves room for the accumulated rounding of ~1e4 steps and the least-squares fit.
    for e in exact_errors.iter().flatten() {
        assert!(e.abs() < 1e-6, "{exact_errors:?}");
    }
}

#[test]
fn hertz_mindlin_slide_then_roll() {
    check("Hertz–Mindlin", NormalLaw::Hertz);
}

#[test]
fn linear_slide_then_roll() {
    // Stiffness giving about the Hertz contact's stiffness at rest.
    check("Linear", NormalLaw::Linear { stiffness: 2.6e4 });
}
