//! A spinning sphere dropped on a plane (after Chung & Ooi 2011, Granular Matter 13:643, test 6:
//! aluminium alloy sphere of radius 0.1 m at 0.2 m/s normal speed, μ = 0.4; here with a
//! restitution of 0.5, so the tangential dashpot is on). When the spin is large enough the contact
//! slides throughout the impact and rigid-body impulse theory gives the outcome exactly:
//! J_t = μ J_n = μ m (1 + e) v_n, so v_t' = μ (1 + e) v_n and ω' = ω − 5 μ (1 + e) v_n / (2 R).
//! Regression test of issue #11: the stored tangential spring pointed along the slip after steps
//! in which the dashpot alone exceeded μ F_n, and the rebound was 46–120 % off this branch.

use polydem::body::BodyInit;
use polydem::contact_law::NormalLaw;
use polydem::material::{Material, PairTable};
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::wall::Plane;
use polydem::{World, WorldConfig};

const RADIUS: f64 = 0.1;
const SPEED: f64 = 0.2;
const FRICTION: f64 = 0.4;
const RESTITUTION: f64 = 0.5;

/// Rebound velocity and spin of the sphere dropped with spin `spin` about y (no gravity).
fn drop(spin: f64) -> (DVec3, DVec3) {
    let alloy = Material {
        name: "aluminium alloy".into(),
        density: 2700.0,
        youngs_modulus: 7e10,
        poisson_ratio: 0.33,
        restitution: RESTITUTION,
        friction: FRICTION,
        rolling_friction: 0.0,
    };
    let laws = PairTable::new(
        std::slice::from_ref(&alloy),
        NormalLaw::Hertz,
        2.0 / 7.0,
        &[],
    );
    let mut w = World::new(WorldConfig {
        // About a hundredth of the impact (0.96 ms).
        time_step: 1e-5,
        gravity: DVec3::ZERO,
        materials: vec![alloy],
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
    w.add_body(BodyInit {
        shape: Shape::Sphere(Sphere { radius: RADIUS }),
        material: 0,
        position: DVec3::new(0.0, 0.0, RADIUS + 1e-5),
        orientation: DQuat::IDENTITY,
        velocity: DVec3::new(0.0, 0.0, -SPEED),
        angular_velocity: DVec3::new(0.0, spin, 0.0),
    });
    // The impact lasts about 1 ms; 3 ms leaves the sphere well clear.
    w.run_steps(300);
    assert!(w.contacts().is_empty(), "still touching");
    (w.bodies().velocity[0], w.bodies().angular_velocity[0])
}

#[test]
fn a_spinning_sphere_rebounds_on_the_sliding_branch() {
    let impulse_per_mass = FRICTION * (1.0 + RESTITUTION) * SPEED;
    // Sliding throughout needs R ω > 7/2 μ (1 + e) v_n (0.42 m/s here).
    for spin in [10.0, 20.0, 40.0] {
        let (v, w) = drop(spin);
        // The contact point moves along −x, so friction pushes the sphere along +x.
        let expected_v = impulse_per_mass;
        let expected_change = -2.5 * impulse_per_mass / RADIUS;
        println!(
            "spin {spin}: v_x {:.5} (expected {expected_v:.5}), ω_y {:.4} (expected {:.4}), \
             v_z {:.5}",
            v.x,
            w.y,
            spin + expected_change,
            v.z
        );
        assert!(
            (v.z / (RESTITUTION * SPEED) - 1.0).abs() < 0.01,
            "rebound {}",
            v.z
        );
        assert!(
            (v.x / expected_v - 1.0).abs() < 0.01,
            "tangential {} vs {expected_v}",
            v.x
        );
        let change = w.y - spin;
        assert!(
            (change / expected_change - 1.0).abs() < 0.01,
            "spin change {change} vs {expected_change}"
        );
    }
}
