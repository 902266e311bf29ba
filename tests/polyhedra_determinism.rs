//! Polyhedra, like spheres, give results independent of the thread count: rocks and cubes
//! poured into a box with 1 and with 2 worker threads are bit-identical after every stage.
//!
//! The polyhedral narrow phase runs per pair in parallel with per-thread scratch buffers; the
//! contact list is sorted by pair and forces are summed in contact order (see `World`), so no
//! floating-point sum may depend on how the work is split. The scene is dense, frictional and
//! dissipative: 24 random rocks and 16 cubes at random orientations thrown down into a box,
//! run until they pile up with many face, edge and vertex contacts.

use polydem::scene::Scene;
use polydem::World;
use std::path::Path;

const SCENE: &str = r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -9.81]
threads = THREADS

[[material]]
name = "stone"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5

[shape.rock]
type = "rock"
vertices = 16
size = 0.008
elongation = [1.0, 0.7, 0.5]
seed = 11

[shape.cube]
type = "box"
edges = [0.007, 0.007, 0.007]

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "stone"

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
material = "stone"

[[plane]]
point = [0.05, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
material = "stone"

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "stone"

[[plane]]
point = [0.0, 0.05, 0.0]
normal = [0.0, -1.0, 0.0]
material = "stone"

[[insert]]
method = "random"
material = "stone"
shape = "rock"
region_min = [0.0, 0.0, 0.005]
region_max = [0.05, 0.05, 0.1]
count = 24
seed = 3
velocity = [0.0, 0.0, -0.5]

[[insert]]
method = "random"
material = "stone"
shape = "cube"
region_min = [0.0, 0.0, 0.005]
region_max = [0.05, 0.05, 0.1]
count = 16
seed = 4
velocity = [0.0, 0.0, -0.5]
"#;

fn world(threads: usize) -> World {
    let text = SCENE.replace("THREADS", &threads.to_string());
    Scene::parse(Path::new("determinism.toml"), text)
        .expect("scene parses")
        .build()
        .expect("scene builds")
        .world
}

/// Every number that describes the state, as bits.
fn state(w: &World) -> Vec<u64> {
    let b = w.bodies();
    let mut s = Vec::new();
    for i in 0..b.len() {
        for v in [
            b.position[i],
            b.velocity[i],
            b.angular_momentum[i],
            b.force[i],
            b.torque[i],
        ] {
            s.extend(v.to_array().map(f64::to_bits));
        }
        s.extend(b.orientation[i].to_array().map(f64::to_bits));
    }
    let e = w.energy();
    s.extend(
        [
            e.kinetic_translational,
            e.kinetic_rotational,
            e.elastic,
            e.dissipated,
        ]
        .map(f64::to_bits),
    );
    s
}

#[test]
fn rocks_and_cubes_are_bit_identical_for_any_thread_count() {
    let (mut one, mut two) = (world(1), world(2));
    assert_eq!((one.threads(), two.threads()), (1, 2));
    assert_eq!(one.bodies().len(), 40);
    let dt = one.time_step();
    // 0.15 s: the bodies fall onto the floor and each other (the first impacts come at ~0.01 s)
    // and are piling up, with many contacts, at the end. Compared every 1000 steps.
    let steps = (0.15 / dt).round() as u64;
    let mut most_contacts = 0;
    let mut done = 0;
    while done < steps {
        let n = 1000.min(steps - done);
        one.run_steps(n);
        two.run_steps(n);
        done += n;
        assert!(
            state(&one) == state(&two),
            "1 and 2 threads differ after {done} steps"
        );
        most_contacts = most_contacts
            .max(one.contacts().between_bodies().count() + one.contacts().with_planes().count());
    }
    println!(
        "{steps} steps of {dt:.3e} s, up to {most_contacts} contacts, {} at the end: bit-identical",
        one.contacts().between_bodies().count() + one.contacts().with_planes().count()
    );
    assert!(
        most_contacts >= 40,
        "too few contacts to test anything: {most_contacts}"
    );
}

/// Between two steps of one `World::run_steps` the closing half kick is left to the next step's
/// first pass; one step at a time it is not. Both give the same bits, for rocks (whose frame
/// turns ω) and cubes alike.
#[test]
fn a_batch_of_steps_gives_the_bits_of_single_steps() {
    let (mut batch, mut single) = (world(1), world(1));
    // As the test above: 0.15 s, until the bodies pile up.
    let steps = (0.15 / batch.time_step()).round() as u64;
    let mut most_contacts = 0;
    while batch.steps_done() < steps {
        let n = 1000.min(steps - batch.steps_done());
        batch.run_steps(n);
        for _ in 0..n {
            single.step();
        }
        assert!(
            state(&batch) == state(&single),
            "batch and single steps differ after {} steps",
            batch.steps_done()
        );
        most_contacts = most_contacts.max(
            batch.contacts().between_bodies().count() + batch.contacts().with_planes().count(),
        );
    }
    assert!(
        most_contacts >= 40,
        "too few contacts to test anything: {most_contacts}"
    );
}
