//! Margins grown with the bodies' speed (`step::margins`) make the candidate list last longer in
//! a bed where a few bodies move fast, and change no body's motion by a bit: the same scene run
//! with half a skin for every body (the rule the shares of a decomposed world keep) gives the
//! same positions, velocities and spins at every step, on a triangulated floor (whose near
//! triangles each sphere looks among follow its margin) with spheres thrown across it and down
//! onto it through a bed of resting ones.

mod common;

use polydem::body::BodyInit;
use polydem::math::{DQuat, DVec3};
use polydem::shape::{Shape, Sphere};
use polydem::World;

use common::Floor;

const RADIUS: f64 = 0.002;

/// Adds a sphere of radius [`RADIUS`] at `position`, moving at `velocity`, not spinning.
fn add_sphere(w: &mut World, position: DVec3, velocity: DVec3) {
    w.add_body(BodyInit {
        shape: Shape::Sphere(Sphere::new(RADIUS)),
        material: 0,
        position,
        orientation: DQuat::IDENTITY,
        velocity,
        angular_velocity: DVec3::ZERO,
    });
}

/// Adds 512 still spheres on an 8 × 8 × 8 lattice of `spacing` from the origin, x fastest.
fn add_lattice(w: &mut World, spacing: f64) {
    for k in 0..512 {
        let cell = DVec3::new((k % 8) as f64, ((k / 8) % 8) as f64, (k / 64) as f64);
        add_sphere(w, cell * spacing, DVec3::ZERO);
    }
}

/// 400 spheres of 2 mm resting on a floor of 20,000 triangles (2 mm squares cut in two), 10 mm
/// apart, and four thrown: one sliding across the floor at 1 m/s along a lane between two rows,
/// one into the first of a row, two falling onto the bed from 30 mm and 60 mm at 1.5 m/s.
fn bed(uniform_margins: bool) -> World {
    let mut w = common::world_on_floor(common::grain(0.0), Floor::Mesh(100), 1e-5);
    if uniform_margins {
        w.set_uniform_margins();
    }
    let mut add = |position: DVec3, velocity: DVec3| add_sphere(&mut w, position, velocity);
    for i in 0..20 {
        for j in 0..20 {
            let x = DVec3::new(-0.095 + 0.01 * i as f64, -0.095 + 0.01 * j as f64, RADIUS);
            add(x, DVec3::ZERO);
        }
    }
    add(DVec3::new(-0.098, -0.09, RADIUS), DVec3::new(1.0, 0.0, 0.0));
    add(
        DVec3::new(0.005, -0.1015, RADIUS),
        DVec3::new(0.0, 1.0, 0.0),
    );
    add(DVec3::new(-0.044, 0.02, 0.03), DVec3::new(0.0, 0.0, -1.5));
    add(DVec3::new(0.012, 0.048, 0.06), DVec3::new(0.2, 0.0, -1.5));
    w
}

fn bits(w: &World) -> Vec<u64> {
    let b = w.bodies();
    b.position
        .iter()
        .chain(&b.velocity)
        .chain(&b.angular_velocity)
        .flat_map(|v| v.to_array())
        .map(f64::to_bits)
        .collect()
}

/// Steps both worlds `spans` times `steps` steps, and asserts after each span that their bodies
/// are the same to the bit.
fn step_alike(a: &mut World, b: &mut World, spans: u64, steps: u64) {
    for _ in 0..spans {
        a.run_steps(steps);
        b.run_steps(steps);
        assert!(
            bits(a) == bits(b),
            "the bodies differ after {} steps",
            a.steps_done()
        );
    }
}

#[test]
fn margins_grown_with_speed_change_no_bit_and_make_the_list_less_often() {
    let mut by_speed = bed(false);
    let mut uniform = bed(true);
    step_alike(&mut by_speed, &mut uniform, 40, 100);
    let b = by_speed.bodies();
    // The throws met the bed: bodies of it were struck, and the falling spheres reached the
    // floor.
    let struck = b.velocity[..400]
        .iter()
        .filter(|v| v.length() > 0.05)
        .count();
    let contacts = by_speed.contacts();
    let on_floor = contacts.with_mesh_walls().count();
    assert!(
        struck >= 2 && on_floor >= 390,
        "{struck} struck, {on_floor} on the floor: no test"
    );
    let (made, made_uniform) = (by_speed.pair_rebuilds(), uniform.pair_rebuilds());
    assert!(
        2 * made < made_uniform,
        "list made {made} times, {made_uniform} with half a skin for every body"
    );
}

/// 512 still spheres of 2 mm on a lattice whose neighbours' gaps are three quarters of the skin,
/// and one thrown across a row of them: a uniform half skin makes every lattice neighbour a
/// candidate, margins by speed (the still bulk at the shrink limit, half of half the skin) none
/// of them, and both move the bodies by the same bits.
#[test]
fn the_still_bulk_takes_smaller_margins_and_fewer_candidates_with_the_same_bits() {
    let lattice = |uniform_margins: bool| {
        let mut w = common::wall_free_world(common::grain(0.0), DVec3::ZERO, 1e-5);
        if uniform_margins {
            w.set_uniform_margins();
        }
        // The default skin, a fifth of the smallest radius (the world has no bodies yet).
        let skin = RADIUS / 5.0;
        let spacing = 2.0 * RADIUS + 0.75 * skin;
        add_lattice(&mut w, spacing);
        // Along the row at y = z = 0, in the gap between it and the next layer up.
        let start = DVec3::new(-3.0 * RADIUS, 0.0, 0.5 * spacing);
        add_sphere(&mut w, start, DVec3::new(2.0, 0.0, 0.0));
        assert_eq!(w.skin(), skin);
        w
    };
    let (mut by_speed, mut uniform) = (lattice(false), lattice(true));
    by_speed.run_steps(1);
    uniform.run_steps(1);
    let (fewer, more) = (by_speed.contacts().entries(), uniform.contacts().entries());
    // 3 × 8 × 8 × 7 neighbours along the axes, 1,344.
    assert!(more >= 1344, "{more} candidates with a uniform half skin");
    assert!(fewer < 100, "{fewer} candidates with margins by speed");
    step_alike(&mut by_speed, &mut uniform, 20, 50);
    let struck = by_speed.bodies().velocity[..512]
        .iter()
        .filter(|v| v.length() > 0.01)
        .count();
    assert!(struck >= 2, "{struck} struck: no test");
}

/// Regression: a lattice of spheres laid out with an infinite spacing (a test's slip: the skin of
/// a world with no bodies yet, which is infinite), so at NaN (0 × ∞) and infinite coordinates,
/// and one sphere thrown at a finite x and an infinite z, made the neighbour search's cell grid
/// index a grid of no cells at the first step: its span was NaN along one axis and infinite
/// along another, and the count of cells along the second overflowed. The step now files the
/// bodies, and the run's check names the first whose state is not finite.
#[test]
fn bodies_at_infinity_are_searched_without_a_panic() {
    let mut w = common::wall_free_world(common::grain(0.0), DVec3::ZERO, 1e-5);
    let spacing = f64::INFINITY;
    add_lattice(&mut w, spacing);
    let thrown = DVec3::new(-3.0 * RADIUS, 0.0, 0.5 * spacing);
    add_sphere(&mut w, thrown, DVec3::new(2.0, 0.0, 0.0));
    w.run_steps(1);
    let why = polydem::run::blow_up(&w).expect("bodies at infinity are not a sound state");
    assert!(why.contains("body 0 has position (NaN"), "{why}");
}
