//! A tall box (1 × 1 × 4 cm, standing on a 1 × 1 face) on fixed inclines: rigid-body statics
//! decides whether it stays, slides or topples.
//!
//! With base width b, height h (b/h = 1/4, tipping angle atan(b/h) = 14.04°) and friction μ on an
//! incline θ (started at rest, in contact):
//! - tan θ < min(μ, b/h): the friction holds it (tan θ < μ) and the weight's line of action falls
//!   inside the base (tan θ < b/h): it stays;
//! - tan θ > b/h and μ > tan θ: it cannot slide, the weight falls outside the base: it topples
//!   (turns about its lower edge and ends on its side, a turn of 90°);
//! - μ < tan θ and μ < b/h: it slides. While sliding the contact force leans back from the normal
//!   by atan μ and passes through the centre of mass (no turning), so it meets the base μ h/2 from
//!   its centre — inside the base while μ < b/h. It slides without tipping, even at tan θ > b/h
//!   (the 20° case), at a = g (sin θ − μ cos θ).
//!
//! Cases are chosen 15 % or more away from each threshold in tan θ. What rigid-body statics
//! ignores is the compliance of the contact: the box starts touching but unloaded, so friction and
//! its moment come on within the first millisecond, the box rocks, and at rest it leans on the
//! downhill part of its base (the volume law's overlap is a wedge, partly lifted off when the
//! friction moment m g sin θ h/2 exceeds what a full-face wedge can take). The stiffer the
//! contact, the smaller that lean: with E = 1e8 Pa (static overlap ~0.2 µm) it is 2e-4 rad at
//! 10° and ~1e-3 rad at 12° (tan θ 15 % below b/h, resting on the last fifth of its base),
//! against the tipping angle of 0.245 rad. Thresholds:
//! - "stays": turns by less than 0.01 rad at any time (1/25 of the tipping angle, 5× the lean
//!   measured at 12°), and its centre moves by less than 0.1 mm (the lean moves it by h/2 × tilt
//!   ≈ 4e-5 m; the friction spring's own elongation is ~1e-7 m; any sliding phase at the measured
//!   accelerations would carry it centimetres);
//! - "slides": the acceleration down the slope, fitted over 0.1–0.4 s, is g (sin θ − μ cos θ)
//!   within 2 % (during the first few ms the rocking base slips back and forth, which shifts the
//!   velocity, not its slope), and it turns by less than 0.5° at any time (a thirtieth of the
//!   tipping angle);
//! - "topples": turns by more than 60° — far past the tipping angle, no way back — and ends on
//!   its side, 90° ± 5° from standing.

use polydem::math::{DQuat, DVec3};
use polydem::scene::Scene;
use std::path::Path;

const G: f64 = 9.81;
const B: f64 = 0.01;
const H: f64 = 0.04;

struct Outcome {
    /// Displacement of the centre down the slope [m].
    slid: f64,
    /// Acceleration down the slope fitted over 0.1 s to the end [m/s²].
    acceleration: f64,
    /// Largest turn from the initial orientation over the run, and the final turn [rad].
    max_turn: f64,
    final_turn: f64,
    /// Speed at the end [m/s].
    speed: f64,
}

fn turn_angle(q: DQuat) -> f64 {
    2.0 * q.xyz().length().atan2(q.w.abs())
}

fn run(theta_degrees: f64, mu: f64, duration: f64) -> Outcome {
    let theta = theta_degrees.to_radians();
    let normal = DVec3::new(-theta.sin(), 0.0, theta.cos());
    let down = DVec3::new(-theta.cos(), 0.0, -theta.sin());
    let centre = normal * (0.5 * H);
    let text = format!(
        r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -{G}]
threads = 1

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e8
poisson_ratio = 0.25
restitution = 0.5
friction = {mu}

[shape.post]
type = "box"
edges = [{B}, {B}, {H}]

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [{nx}, 0.0, {nz}]
material = "m"

[[particle]]
shape = "post"
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
    let mut p = Scene::parse(Path::new("topple.toml"), text)
        .expect("scene parses")
        .build()
        .expect("scene builds");
    let w = &mut p.world;
    let dt = w.time_step();
    let (x0, q0) = (w.bodies().position[0], w.bodies().orientation[0]);
    let chunk = (0.01 / dt).round() as u64;
    let mut max_turn = 0.0f64;
    // Least-squares line through the speed down the slope, from 0.1 s on.
    let (mut st, mut sv, mut stt, mut stv, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
    while w.time() < duration - 0.5 * dt {
        w.run_steps(chunk);
        max_turn = max_turn.max(turn_angle(w.bodies().orientation[0] * q0.inverse()));
        if w.time() > 0.1 {
            let (t, v) = (w.time(), w.bodies().velocity[0].dot(down));
            (st, sv, stt, stv, n) = (st + t, sv + v, stt + t * t, stv + t * v, n + 1.0);
        }
    }
    Outcome {
        slid: (w.bodies().position[0] - x0).dot(down),
        acceleration: (n * stv - st * sv) / (n * stt - st * st),
        max_turn,
        final_turn: turn_angle(w.bodies().orientation[0] * q0.inverse()),
        speed: w.bodies().velocity[0].length(),
    }
}

#[test]
fn tall_box_stays_below_both_thresholds() {
    // tan θ = 0.176 and 0.213 < b/h = 0.25 < μ.
    for (theta, mu) in [(10.0, 0.5), (12.0, 0.8)] {
        let o = run(theta, mu, 0.4);
        println!(
            "stay θ = {theta}°, μ = {mu}: moved {:.2e} m, turned {:.2e} rad (max {:.2e}), speed \
             {:.1e} m/s",
            o.slid, o.final_turn, o.max_turn, o.speed
        );
        assert!(o.slid.abs() < 1e-4, "θ = {theta}: moved {} m", o.slid);
        assert!(o.max_turn < 0.01, "θ = {theta}: turned {} rad", o.max_turn);
    }
}

#[test]
fn tall_box_topples_when_friction_holds_it() {
    // tan θ = 0.287, 0.364 > b/h = 0.25; μ = 0.8 > tan θ.
    for (theta, mu) in [(16.0, 0.8), (20.0, 0.8)] {
        let o = run(theta, mu, 0.6);
        println!(
            "topple θ = {theta}°, μ = {mu}: turned {:.1}° (max {:.1}°), moved {:.2e} m, speed \
             {:.1e} m/s",
            o.final_turn.to_degrees(),
            o.max_turn.to_degrees(),
            o.slid,
            o.speed
        );
        assert!(
            o.max_turn > 60f64.to_radians(),
            "θ = {theta}: did not topple (turned {}°)",
            o.max_turn.to_degrees()
        );
        // On its side: 90° from standing, to within the few degrees a box lying on an edge or
        // still rocking could differ.
        assert!(
            (o.final_turn.to_degrees() - 90.0).abs() < 5.0,
            "θ = {theta}: ended at {}°",
            o.final_turn.to_degrees()
        );
    }
}

#[test]
fn tall_box_slides_without_tipping_when_friction_is_low() {
    // μ = 0.15 < b/h = 0.25; tan θ = 0.213 and 0.364 > μ (the second also beyond b/h).
    for (theta, mu) in [(12.0f64, 0.15), (20.0, 0.15)] {
        let o = run(theta, mu, 0.4);
        let a = G * (theta.to_radians().sin() - mu * theta.to_radians().cos());
        let error = o.acceleration / a - 1.0;
        println!(
            "slide θ = {theta}°, μ = {mu}: a = {:.6} m/s² vs g(sin θ − μ cos θ) = {a:.6} (rel. \
             {error:+.1e}), moved {:.4e} m, turned {:.2e} rad (max {:.2e})",
            o.acceleration, o.slid, o.final_turn, o.max_turn
        );
        assert!(
            error.abs() < 0.02,
            "θ = {theta}: acceleration off by {error:e}"
        );
        assert!(
            o.max_turn < 0.5f64.to_radians(),
            "θ = {theta}: turned {}",
            o.max_turn
        );
    }
}
