//! The result does not depend on the number of threads: the same scene run with 1 and with 2
//! worker threads gives bit-identical positions, velocities, spins and energy ledger.
//!
//! The engine sorts contacts by pair and sums forces in contact order (see `World` and
//! `ContactList`), so no floating-point sum depends on how work is split among threads; this test
//! checks that promise on a dense, frictional, dissipative granular flow with many contacts.

mod common;

use polydem::body::BodyInit;
use polydem::material::Material;
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::World;

/// xorshift64*: a fixed pseudo-random sequence in [0, 1).
struct Rng(u64);

impl Rng {
    fn range(&mut self, a: f64, b: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64;
        a + (b - a) * u
    }
}

/// 343 polydisperse spheres in a 7×7×7 lattice, 1–3 mm apart with random velocities and spins,
/// thrown down into a box of five walls (open at the top) where they pile up. Time step about a
/// fifteenth of the shortest contact: coarse, but this test is about thread independence.
fn scene(threads: usize) -> World {
    scene_with(threads, Default::default())
}

fn scene_with(threads: usize, broad_phase: polydem::broad_phase::Method) -> World {
    let material = Material {
        name: "grain".into(),
        density: 2500.0,
        youngs_modulus: 1e8,
        poisson_ratio: 0.25,
        restitution: 0.5,
        friction: 0.5,
        rolling_friction: 0.1,
    };
    let (spacing, n) = (0.011, 7);
    let mut w = common::open_box_world(material, spacing * n as f64, 2e-5, broad_phase, threads);
    let mut rng = Rng(0x0123_4567_89ab_cdef);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let centre = (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * spacing;
                let mut random = || {
                    DVec3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    )
                };
                w.add_body(BodyInit {
                    shape: Shape::Sphere(Sphere::new(0.0045 + 0.0005 * random().x)),
                    material: 0,
                    position: centre + random() * 0.0003,
                    orientation: DQuat::IDENTITY,
                    velocity: random() * 0.5 - DVec3::Z,
                    angular_velocity: random() * 50.0,
                });
            }
        }
    }
    w
}

fn bits(v: DVec3) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

#[test]
fn one_and_two_threads_agree_bit_for_bit() {
    let mut worlds = [scene(1), scene(2)];
    assert_eq!(worlds[0].threads(), 1);
    assert_eq!(worlds[1].threads(), 2);
    let mut most_contacts = 0;
    for chunk in 0..10 {
        for w in &mut worlds {
            w.run_steps(1000);
        }
        let [a, b] = &worlds;
        let contacts = a.contacts().between_bodies().count() + a.contacts().with_planes().count();
        most_contacts = most_contacts.max(contacts);
        assert_eq!(
            contacts,
            b.contacts().between_bodies().count() + b.contacts().with_planes().count(),
            "chunk {chunk}"
        );
        for i in 0..a.bodies().len() {
            let (x, y) = (a.bodies(), b.bodies());
            assert_eq!(
                bits(x.position[i]),
                bits(y.position[i]),
                "position of {i}, chunk {chunk}"
            );
            assert_eq!(
                bits(x.velocity[i]),
                bits(y.velocity[i]),
                "velocity of {i}, chunk {chunk}"
            );
            assert_eq!(
                bits(x.angular_velocity[i]),
                bits(y.angular_velocity[i]),
                "angular velocity of {i}, chunk {chunk}"
            );
            assert_eq!(
                x.orientation[i].to_array().map(f64::to_bits),
                y.orientation[i].to_array().map(f64::to_bits)
            );
        }
        let (ea, eb) = (a.energy(), b.energy());
        assert_eq!(
            ea.total().to_bits(),
            eb.total().to_bits(),
            "energy ledger, chunk {chunk}"
        );
        println!(
            "after {} steps: {contacts} contacts, E_total {:.12e} J",
            a.steps_done(),
            ea.total()
        );
    }
    // A test of thread independence is only as good as the work there was to split.
    assert!(most_contacts > 500, "only {most_contacts} contacts");
}

/// Between two steps of one `World::run_steps` the closing half kick is left to the next step's
/// first pass (see `integrate::kick_drift`); one step at a time it is not. Both give the same
/// bits, and so they must when gravity changes between the two half kicks (a gravity table).
#[test]
fn a_batch_of_steps_gives_the_bits_of_single_steps() {
    use polydem::time_table::TimeTable;
    let swinging = || {
        let knots = (0..=20)
            .map(|k| {
                let t = k as f64 * 2e-3;
                (t, DVec3::new(3.0 * (k % 3) as f64 - 3.0, 0.0, -9.81))
            })
            .collect();
        scene(1).with_gravity_table(TimeTable::new(knots).expect("times increase"))
    };
    let (mut batch, mut single) = (swinging(), swinging());
    let mut most_contacts = 0;
    for chunk in 0..5 {
        batch.run_steps(400);
        for _ in 0..400 {
            single.step();
        }
        let (x, y) = (batch.bodies(), single.bodies());
        for i in 0..x.len() {
            for (u, v) in [
                (x.position[i], y.position[i]),
                (x.velocity[i], y.velocity[i]),
                (x.angular_momentum[i], y.angular_momentum[i]),
                (x.angular_velocity[i], y.angular_velocity[i]),
                (x.force[i], y.force[i]),
                (x.torque[i], y.torque[i]),
            ] {
                assert_eq!(bits(u), bits(v), "body {i}, chunk {chunk}");
            }
        }
        let (ea, eb) = (batch.energy(), single.energy());
        assert_eq!(ea.total().to_bits(), eb.total().to_bits(), "chunk {chunk}");
        let contacts =
            batch.contacts().between_bodies().count() + batch.contacts().with_planes().count();
        most_contacts = most_contacts.max(contacts);
    }
    assert!(most_contacts > 100, "only {most_contacts} contacts");
}

/// The broad phase only proposes candidate pairs; with the same skin every method proposes the
/// same set, so the trajectories must be identical to the last bit.
#[test]
fn every_broad_phase_gives_the_same_trajectory() {
    use polydem::broad_phase::Method;
    let methods = [Method::BruteForce, Method::CellGrid, Method::SweepAndPrune];
    let mut worlds: Vec<World> = methods.iter().map(|&m| scene_with(1, m)).collect();
    for w in &mut worlds {
        w.run_steps(4000);
    }
    let reference = &worlds[0];
    assert!(
        reference.contacts().between_bodies().count() > 100,
        "the scene must be dense"
    );
    for (w, method) in worlds.iter().zip(methods).skip(1) {
        assert_eq!(w.pair_rebuilds(), reference.pair_rebuilds(), "{method:?}");
        for i in 0..reference.bodies().len() {
            assert_eq!(
                bits(w.bodies().position[i]),
                bits(reference.bodies().position[i]),
                "{method:?}, body {i}"
            );
            assert_eq!(
                bits(w.bodies().angular_velocity[i]),
                bits(reference.bodies().angular_velocity[i]),
                "{method:?}, body {i}"
            );
        }
    }
}
