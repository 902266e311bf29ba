//! A flat box on an inclined plane: it sticks while tan θ < μ and slides with
//! a = g (sin θ − μ cos θ) when tan θ > μ.
//!
//! The box (4 × 4 × 1 cm, lying on a 4 × 4 face) starts at rest, touching the plane
//! n = (−sin θ, 0, cos θ) with its big face. Its height over width (1/4) is far below μ, so the
//! friction at its base can never tip it: it slides without turning (asserted).
//!
//! Sliding: once the contact slides, the friction force is the Coulomb limit μ F_n exactly (the
//! capped spring–dashpot), F_n = m g cos θ once the initial settling into the plane has died out
//! (a few contact durations, 0.85 ms), so the acceleration is constant and velocity Verlet
//! integrates it exactly. The only errors are the remains of that settling and round-off, so the
//! result does not depend on the step (there is no discretisation error to shrink; the measured
//! error, ~1e-7, is printed) and the brief's 2 % holds with a huge margin.
//!
//! Sticking: the friction spring takes the load m g sin θ with the static elongation
//! ξ_s = m g sin θ / k_t, k_t = (2/7) k_n, k_n = E* A / R* (the volume law's face stiffness):
//! ≈ 0.9 µm here. The box moves by about that (plus an overshoot while the load comes on, at most
//! ξ_s again for a suddenly applied load, and a slip of order ½ g sin θ t² during the first
//! ~0.3 ms in which F_n, and with it μ F_n, builds up: ~0.2 µm), so 3 ξ_s bounds it. Once it sticks
//! it must not creep: the displacement over the last 0.25 s must stay below 1e-10 m (round-off
//! ~1e-17 m).

use polydem::math::DVec3;
use polydem::scene::{Prepared, Scene};
use std::path::Path;

const G: f64 = 9.81;
const MU: f64 = 0.5;
const DENSITY: f64 = 2500.0;
const YOUNG: f64 = 1.0e7;
const POISSON: f64 = 0.25;
const WIDTH: f64 = 0.04;
const HEIGHT: f64 = 0.01;

fn incline(theta_degrees: f64) -> (Prepared, DVec3, DVec3) {
    incline_under(theta_degrees, "volume")
}

/// The box on the incline with the polyhedral contact law `law` ("volume" or "vertex").
fn incline_under(theta_degrees: f64, law: &str) -> (Prepared, DVec3, DVec3) {
    let theta = theta_degrees.to_radians();
    let normal = DVec3::new(-theta.sin(), 0.0, theta.cos());
    // Down the slope.
    let down = DVec3::new(-theta.cos(), 0.0, -theta.sin());
    let centre = normal * (0.5 * HEIGHT);
    let text = format!(
        r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -{G}]
threads = 1

[contact]
polyhedra = "{law}"

[[material]]
name = "m"
density = {DENSITY}
youngs_modulus = {YOUNG}
poisson_ratio = {POISSON}
restitution = 0.5
friction = {MU}

[shape.slab]
type = "box"
edges = [{WIDTH}, {WIDTH}, {HEIGHT}]

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [{nx}, 0.0, {nz}]
material = "m"

[[particle]]
shape = "slab"
material = "m"
position = [{x}, 0.0, {z}]
rotation = [0.0, {rot}, 0.0]
"#,
        nx = normal.x,
        nz = normal.z,
        x = centre.x,
        z = centre.z,
        rot = -theta,
    );
    let p = Scene::parse(Path::new("incline.toml"), text)
        .expect("scene parses")
        .build()
        .expect("scene builds");
    (p, down, normal)
}

fn turn_angle(q: polydem::math::DQuat) -> f64 {
    2.0 * q.xyz().length().atan2(q.w.abs())
}

#[test]
fn flat_box_sticks_below_the_friction_angle() {
    let theta: f64 = 20.0; // tan θ = 0.364 < μ = 0.5
    let (mut p, down, _) = incline(theta);
    let w = &mut p.world;
    let dt = w.time_step();
    let (x0, q0) = (w.bodies().position[0], w.bodies().orientation[0]);
    let mass = w.bodies().mass[0];
    // Static elongation of the friction spring.
    let e_star = YOUNG / (2.0 * (1.0 - POISSON * POISSON));
    let r_eq = (3.0 * WIDTH * WIDTH * HEIGHT / (4.0 * std::f64::consts::PI)).cbrt();
    let k_n = e_star * WIDTH * WIDTH / r_eq;
    let xi = mass * G * theta.to_radians().sin() / (2.0 / 7.0 * k_n);

    w.run_steps((0.25 / dt).round() as u64);
    let x_mid = w.bodies().position[0];
    w.run_steps((0.25 / dt).round() as u64);
    let x_end = w.bodies().position[0];
    let along = (x_end - x0).dot(down);
    let creep = (x_end - x_mid).length();
    let turn = turn_angle(w.bodies().orientation[0] * q0.inverse());
    println!(
        "θ = {theta}°: moved {along:.3e} m down the slope in 0.5 s (ξ_s = {xi:.3e} m), {creep:.1e} \
         m over the last 0.25 s, turned {turn:.1e} rad, speed {:.1e} m/s",
        w.bodies().velocity[0].length()
    );
    assert!(
        along.abs() < 3.0 * xi,
        "slipped {along:e} m (ξ_s = {xi:e} m)"
    );
    assert!(creep < 1e-10, "creeping: {creep:e} m in 0.25 s");
    assert!(w.bodies().velocity[0].length() < 1e-6);
    // The box does turn, elastically: friction acts at the base, h/2 below the centre, and its
    // moment m g sin θ h/2 is taken by the volume law's rocking stiffness k_v I_face
    // (I_face = w⁴/12, the face's second moment of area: the pressure k_v d(x) of a wedge-shaped
    // overlap). The measured tilt must be that one, not a rocking or toppling motion: to 1 %
    // (the lever arm is h/2 + δ/2 rather than h/2, 6e-5 relative; measured 4e-5).
    let tilt =
        mass * G * theta.to_radians().sin() * 0.5 * HEIGHT / (e_star / r_eq * WIDTH.powi(4) / 12.0);
    println!("elastic tilt {turn:.4e} rad vs M/(k_v I) = {tilt:.4e} rad");
    assert!((turn / tilt - 1.0).abs() < 0.01, "turned by {turn:e} rad");
}

#[test]
fn flat_box_slides_above_the_friction_angle() {
    slides_above_the_friction_angle("volume");
}

/// The same under the vertex law (one spring per touching corner), to the 1 % issue #11 asks. (This
/// box, settling at rest first, does not show the 25 % excess the issue reports for a cube under
/// the vertex law; the law's fix is tested in `contact_law::tangential` and
/// `tests/physics_spinning_impact.rs`.)
#[test]
fn flat_box_slides_above_the_friction_angle_under_the_vertex_law() {
    slides_above_the_friction_angle("vertex");
}

fn slides_above_the_friction_angle(law: &str) {
    let theta: f64 = 35.0; // tan θ = 0.700 > μ = 0.5
    let (mut p, down, normal) = incline_under(theta, law);
    let expected = G * (theta.to_radians().sin() - MU * theta.to_radians().cos());
    let w = &mut p.world;
    let dt = w.time_step();
    let (x0, q0) = (w.bodies().position[0], w.bodies().orientation[0]);
    // Sample the speed down the slope from 0.05 s (long after the settling) to 0.4 s and fit a
    // straight line (least squares).
    w.run_steps((0.05 / dt).round() as u64);
    let (mut st, mut sv, mut stt, mut stv, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut max_off_line = 0.0f64;
    for _ in 0..70 {
        w.run_steps((0.005 / dt).round() as u64);
        let (t, v) = (w.time(), w.bodies().velocity[0].dot(down));
        st += t;
        sv += v;
        stt += t * t;
        stv += t * v;
        n += 1.0;
        // The box stays on the plane: its centre keeps its height over it.
        let height = (w.bodies().position[0] - x0).dot(normal);
        max_off_line = max_off_line.max(height.abs());
    }
    let slope = (n * stv - st * sv) / (n * stt - st * st);
    let error = slope / expected - 1.0;
    let turn = turn_angle(w.bodies().orientation[0] * q0.inverse());
    println!(
        "{law} law, θ = {theta}°: a = {slope:.8} m/s² vs g(sin θ − μ cos θ) = {expected:.8} (rel. {error:+.1e}); \
         height change {max_off_line:.1e} m, turned {turn:.1e} rad"
    );
    assert!(error.abs() < 0.01, "acceleration off by {error:e}");
    // Sinking into the plane by the static overlap (~0.6 µm) is all the centre may move normal to
    // it; a turn of 1e-3 rad would already be a visible tilt (0.06°) — the box does not topple.
    assert!(max_off_line < 1e-5);
    assert!(turn < 1e-3, "turned by {turn:e} rad");
}
