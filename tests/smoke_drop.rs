use polydem::body::BodyInit;
use polydem::contact_law::NormalLaw;
use polydem::material::{Material, PairTable};
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::wall::Plane;
use polydem::{World, WorldConfig};

#[test]
fn sphere_bounces_back_up() {
    let m = Material {
        name: "glass".into(),
        density: 2500.0,
        youngs_modulus: 1e8,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: 0.3,
        rolling_friction: 0.0,
    };
    let laws = PairTable::new(std::slice::from_ref(&m), NormalLaw::Hertz, 2.0 / 7.0, &[]);
    let mut w = World::new(WorldConfig {
        time_step: 1e-6,
        gravity: DVec3::new(0.0, 0.0, -9.81),
        materials: vec![m],
        pair_laws: laws,
        planes: vec![Plane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            material: 0,
        }],
        broad_phase: Default::default(),
        threads: 1,
    })
    .unwrap();
    w.add_body(BodyInit {
        shape: Shape::Sphere(Sphere::new(0.01)),
        material: 0,
        position: DVec3::new(0.0, 0.0, 0.11),
        orientation: DQuat::IDENTITY,
        velocity: DVec3::ZERO,
        angular_velocity: DVec3::ZERO,
    });
    let mut max_after = 0.0f64;
    let mut bounced = false;
    for _ in 0..400_000 {
        w.run_steps(1);
        if w.bodies.velocity[0].z > 0.0 {
            bounced = true;
        }
        if bounced {
            max_after = max_after.max(w.bodies.position[0].z - 0.01);
        }
    }
    println!("rebound height {max_after} vs expected {}", 0.25 * 0.1);
    assert!((max_after / 0.025 - 1.0).abs() < 0.02);
}
