//! Each body's contact force is its own contacts' loads (where it is body `a`) and then its
//! incoming ones', added in store order, however the contact loop splits the store: the loop adds
//! up `a`'s side itself, chunk by chunk and run by run, while the store keeps only the partner's
//! side (issue #18). A large sphere among small ones has more own entries than one run of the
//! loop holds, so its sum runs across runs.

mod common;

use polydem::body::BodyInit;
use polydem::contact::CHUNK_ENTRIES;
use polydem::math::{DQuat, DVec3};
use polydem::rng::SplitMix64;
use polydem::shape::{Shape, Sphere};
use polydem::World;

/// Small spheres around the large one: on a sphere of radius about 21 mm, 3.6 mm apart (they
/// do not reach each other), each pressed 10 µm into the large sphere.
const SMALL: usize = 400;

/// A 20 mm sphere (added first: the smaller id, so body `a` of every pair) with [`SMALL`]
/// 1 mm spheres on its surface, with random velocities and spins, in the middle of a box 0.2 m
/// wide whose walls none comes near.
fn world(threads: usize) -> World {
    let material = common::grain(0.0);
    let mut w = common::open_box_world(material, 0.2, 1e-6, Default::default(), threads);
    let centre = DVec3::splat(0.1);
    let (big, small) = (0.02, 0.001);
    let body = |radius: f64, position: DVec3, velocity: DVec3, angular_velocity: DVec3| BodyInit {
        shape: Shape::Sphere(Sphere::new(radius)),
        material: 0,
        position,
        orientation: DQuat::IDENTITY,
        velocity,
        angular_velocity,
    };
    w.add_body(body(big, centre, DVec3::ZERO, DVec3::Z * 3.0));
    let mut rng = SplitMix64::new(7);
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for k in 0..SMALL {
        // A Fibonacci lattice on the sphere.
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / SMALL as f64;
        let (s, phi) = ((1.0 - z * z).sqrt(), golden * k as f64);
        let direction = DVec3::new(s * phi.cos(), s * phi.sin(), z);
        let mut random = || DVec3::new(rng.normal(), rng.normal(), rng.normal());
        let position = centre + direction * (big + small - 1e-5);
        w.add_body(body(small, position, random() * 0.01, random() * 10.0));
    }
    w
}

fn bits(v: DVec3) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

/// Whichever completes the sums: the pass over the bodies, or the contact loop itself (a world
/// this small would leave it to the pass).
#[test]
fn a_bodys_sum_is_its_own_loads_then_its_incoming_ones_across_runs_of_the_loop() {
    for in_loop in [false, true] {
        let mut w = world(2);
        w.set_sums_in_contact_loop(Some(in_loop));
        w.run_steps(3);
        assert_eq!(w.contacts().store().completes_sums(), in_loop);
        check_sums(&w);
    }
}

/// Each body's force (to the bit) and moment (to rounding: the store does not keep `a`'s side)
/// found again from the store's loads, own entries then incoming ones.
fn check_sums(w: &World) {
    let store = w.contacts().store();
    let (loads, bodies) = (store.loads(), w.bodies());
    // The large sphere's own entries fill more than one run of the contact loop, and touch.
    assert!(store.own(0).len() > CHUNK_ENTRIES, "{:?}", store.own(0));
    assert_eq!(
        w.contacts().len(),
        SMALL,
        "every small sphere touches the large one"
    );
    for i in 0..bodies.len() {
        let (mut force, mut torque, mut scale) = (DVec3::ZERO, DVec3::ZERO, 0.0);
        for e in store.own(i) {
            force += loads[e].force;
            // Body a's moment, which the store does not keep, from the balance of moments:
            // τ_a + τ_b = (c_b − c_a) × F.
            let partner = store.keys()[e].partner.body().expect("no wall is near") as usize;
            let arm = bodies.position[partner] - bodies.position[i];
            torque += arm.cross(loads[e].force) - loads[e].torque_b;
            scale += arm.length() * loads[e].force.length();
        }
        for &e in store.incoming(i) {
            let e = e as usize;
            force -= loads[e].force;
            torque += loads[e].torque_b;
            scale += loads[e].torque_b.length();
        }
        assert_eq!(bits(force), bits(bodies.force[i]), "force on body {i}");
        let off = (torque - bodies.torque[i]).length();
        assert!(
            off <= 1e-12 * scale,
            "torque on body {i}: {off:e} of {scale:e}"
        );
    }
    assert!(bodies.force[0].length() > 0.0 && bodies.torque[0].length() > 0.0);
}

/// The sums completed in the contact loop, right after the chunks that write a body's loads
/// (`step::complete_sums`), against the pass over the bodies after the loop: the same bits for
/// every body, on one and two threads, in the large sphere among small ones (one body whose
/// entries span several chunks, and partners in all of them) and in a scrambled bed of 2,197
/// spheres with rolling friction (many chunks, bodies put in space order).
#[test]
fn sums_completed_in_the_contact_loop_give_the_bits_of_the_pass_over_the_bodies() {
    type Maker = fn(usize) -> World;
    let makers: [(&str, Maker, u64); 2] = [
        ("large among small", world, 50),
        (
            "scrambled bed",
            |threads| common::scrambled_bed(13, threads),
            300,
        ),
    ];
    for (name, make, steps) in makers {
        let run = |threads: usize, in_loop: bool| {
            let mut w = make(threads);
            w.set_sums_in_contact_loop(Some(in_loop));
            w.run_steps(steps);
            assert_eq!(w.contacts().store().completes_sums(), in_loop, "{name}");
            w
        };
        let reference = run(1, false);
        let a = reference.bodies();
        assert!(
            !reference.contacts().is_empty(),
            "{name}: no contacts, no test"
        );
        for (threads, in_loop) in [(1, true), (2, true), (2, false)] {
            let w = run(threads, in_loop);
            let b = w.bodies();
            for i in 0..a.len() {
                let what = format!("{name}, {threads} threads, in loop {in_loop}: body {i}");
                assert_eq!(bits(a.force[i]), bits(b.force[i]), "force, {what}");
                assert_eq!(bits(a.torque[i]), bits(b.torque[i]), "torque, {what}");
                assert_eq!(bits(a.position[i]), bits(b.position[i]), "position, {what}");
                assert_eq!(bits(a.velocity[i]), bits(b.velocity[i]), "velocity, {what}");
            }
        }
    }
}

#[test]
fn a_body_with_more_own_entries_than_a_run_gets_the_same_bits_on_one_and_two_threads() {
    let mut worlds = [world(1), world(2)];
    for w in &mut worlds {
        w.run_steps(50);
    }
    let [a, b] = &worlds;
    for i in 0..a.bodies().len() {
        let (x, y) = (a.bodies(), b.bodies());
        assert_eq!(bits(x.force[i]), bits(y.force[i]), "force on body {i}");
        assert_eq!(bits(x.torque[i]), bits(y.torque[i]), "torque on body {i}");
        assert_eq!(bits(x.velocity[i]), bits(y.velocity[i]), "velocity of {i}");
        assert_eq!(
            bits(x.angular_velocity[i]),
            bits(y.angular_velocity[i]),
            "spin of {i}"
        );
    }
}
