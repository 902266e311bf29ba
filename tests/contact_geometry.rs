//! The contact store keeps no geometry for sphere pairs, and none at all in a world of spheres and
//! planes (`contact::StoreLayout`), nor law reports there: what `World::contacts()` gives is found
//! again from the bodies, the loads and the histories. The geometry must be what the narrow phase
//! finds, to the bit, and a world that keeps every other contact's geometry and every report
//! (here because it has a mesh wall far from the bodies) must run the same bits and report the
//! same contacts: the same bits but for the normal force, which is found again as F·n and so
//! agrees to rounding. With and without rolling friction, whose springs' energy is found again
//! from the spin histories.

mod common;

use polydem::body::BodyInit;
use polydem::contact::{ContactRef, Partner};
use polydem::math::{DQuat, DVec3};
use polydem::narrow_phase::{sphere_plane, sphere_sphere};
use polydem::rng::SplitMix64;
use polydem::shape::{Shape, Sphere};
use polydem::wall::generators;
use polydem::World;

/// Rolling friction of the worlds the tests compare: none, and some.
const ROLLING_FRICTION: [f64; 2] = [0.0, 0.1];

/// 125 spheres of 1 mm radius thrown into an open box of planes: contacts with each other and
/// with the floor and the side walls after 4,000 steps, under `rolling_friction`. With
/// `far_wall`, a mesh wall 1 m above them that none reaches.
fn pour(far_wall: bool, rolling_friction: f64) -> World {
    let material = common::grain(rolling_friction);
    let (spacing, n) = (2.2e-3, 5usize);
    let width = spacing * n as f64 + 1e-3;
    let mut w = common::open_box_world(material, width, 1e-5, Default::default(), 1);
    if far_wall {
        let ceiling = generators::rectangle(
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.0, width, 0.0),
            DVec3::new(width, 0.0, 0.0),
            2,
            2,
        )
        .unwrap()
        .into_wall(0)
        .unwrap();
        w = w.with_mesh_walls(vec![ceiling]);
    }
    let mut rng = SplitMix64::new(0x2545_f491_4f6c_dd1d);
    let mut random = || {
        DVec3::new(
            rng.uniform(-0.5, 0.5),
            rng.uniform(-0.5, 0.5),
            rng.uniform(-0.5, 0.5),
        )
    };
    for k in 0..n * n * n {
        let (i, j, l) = (k % n, k / n % n, k / (n * n));
        let jitter = random() * 2e-4;
        let velocity = (random() - DVec3::new(0.0, 0.0, 1.5)) * 0.3;
        w.add_body(BodyInit {
            shape: Shape::Sphere(Sphere { radius: 1e-3 }),
            material: 0,
            position: DVec3::new(i as f64, j as f64, l as f64) * spacing
                + DVec3::splat(1.5e-3)
                + jitter,
            orientation: DQuat::IDENTITY,
            velocity,
            angular_velocity: random() * 100.0,
        });
    }
    for _ in 0..4000 {
        w.step();
    }
    w
}

/// Each contact as text: key, geometry, load, histories and elastic energy (Debug prints the
/// bits).
fn described(w: &World) -> Vec<String> {
    w.contacts()
        .iter()
        .map(|c: ContactRef| {
            let (key, g, load, history, spin) = (c.key, c.geometry, c.load, c.history, c.spin);
            let energy = c.report.elastic_energy;
            format!("{key:?} {g:?} {load:?} {history:?} {spin:?} {energy:?}")
        })
        .collect()
}

/// Each contact's normal force.
fn normal_forces(w: &World) -> Vec<f64> {
    w.contacts().iter().map(|c| c.report.normal_force).collect()
}

#[test]
fn sphere_contacts_read_the_narrow_phase_geometry_found_again_from_the_bodies() {
    let w = pour(false, 0.0);
    assert!(
        w.contacts().store().geometry().is_empty(),
        "a world of spheres and planes keeps no contact geometry"
    );
    let (b, planes) = (w.bodies(), w.planes());
    let (mut pairs, mut walls) = (0, 0);
    for c in w.contacts().iter() {
        let a = c.key.a as usize;
        let found = match c.key.partner {
            Partner::Body(j) => {
                pairs += 1;
                let j = j as usize;
                sphere_sphere(b.position[a], 1e-3, b.position[j], 1e-3)
            }
            Partner::Plane(p) => {
                walls += 1;
                let plane = &planes[p as usize];
                sphere_plane(b.position[a], 1e-3, plane.point, plane.normal)
            }
            Partner::Mesh(_) => unreachable!("no mesh walls here"),
        };
        let found = found.expect("a touching contact that the narrow phase finds");
        assert_eq!(c.geometry, found, "{:?}", c.key);
        assert!(c.geometry.overlap > 0.0 && c.report.normal_force >= 0.0);
    }
    assert!(
        pairs > 100 && walls > 20,
        "{pairs} sphere pairs, {walls} on walls"
    );
}

#[test]
fn keeping_the_geometry_changes_no_bit_of_the_run_or_its_contacts() {
    for rolling_friction in ROLLING_FRICTION {
        keeping_the_geometry_changes_no_bit(rolling_friction);
    }
}

fn keeping_the_geometry_changes_no_bit(rolling_friction: f64) {
    let (lean, kept) = (pour(false, rolling_friction), pour(true, rolling_friction));
    assert!(lean.contacts().store().geometry().is_empty());
    let rolling_springs = lean
        .contacts()
        .iter()
        .filter(|c| c.spin.is_some_and(|s| s.rolling_stiffness > 0.0));
    assert_eq!(
        rolling_springs.count() > 100,
        rolling_friction > 0.0,
        "rolling springs where there is rolling friction"
    );
    assert_eq!(
        kept.contacts().store().geometry().len(),
        kept.contacts().entries(),
        "a world with a mesh wall keeps one geometry per entry"
    );
    let state = |w: &World| {
        let b = w.bodies();
        format!("{:?}", (&b.position, &b.velocity, &b.angular_momentum))
    };
    assert_eq!(state(&lean), state(&kept));
    assert_eq!(described(&lean), described(&kept));
    assert!(described(&lean).len() > 150);
    // The lean world finds F_n again as F·n, F = n F_n + F_t: |n|² is 1 within two units in the
    // last place and F_t·n is |F_t| ≤ μ F_n (μ = 0.5 here) times a few, so 1e-14 of F_n holds
    // with room. A contact whose force was cut off at zero reads exactly zero.
    let (lean_forces, kept_forces) = (normal_forces(&lean), normal_forces(&kept));
    let energy = |w: &World| w.energy().elastic.to_bits();
    assert_eq!(energy(&lean), energy(&kept), "the ledger's elastic energy");
    assert_eq!(lean_forces.len(), kept_forces.len());
    let mut differ = 0;
    for (k, (&found, &kept)) in lean_forces.iter().zip(&kept_forces).enumerate() {
        assert!(
            (found - kept).abs() <= 1e-14 * kept,
            "contact {k}: normal force {found:e} found again, {kept:e} kept"
        );
        assert_eq!(found == 0.0, kept == 0.0, "contact {k}");
        differ += (found != kept) as usize;
    }
    assert!(lean_forces.iter().filter(|&&f| f > 0.0).count() > 150);
    println!(
        "{differ} of {} normal forces differ in their last bits",
        lean_forces.len()
    );
}

/// Bodies taken out of a world carry their contacts' elastic energy out with them (the ledger's
/// `removed`): found again in the lean world, it must be the bits the other world kept.
#[test]
fn removed_bodies_carry_out_the_same_contact_energy_whether_reports_are_kept_or_not() {
    for rolling_friction in ROLLING_FRICTION {
        removed_bodies_carry_out_the_same_energy(rolling_friction);
    }
}

fn removed_bodies_carry_out_the_same_energy(rolling_friction: f64) {
    let (mut lean, mut kept) = (pour(false, rolling_friction), pour(true, rolling_friction));
    let keep: Vec<bool> = (0..lean.bodies().len()).map(|i| i % 3 != 0).collect();
    let elastic_before = lean.energy().elastic;
    for w in [&mut lean, &mut kept] {
        w.remove_bodies(&keep);
    }
    let (lean_energy, kept_energy) = (lean.energy(), kept.energy());
    assert_eq!(
        lean_energy.removed.to_bits(),
        kept_energy.removed.to_bits(),
        "{} J against {} J",
        lean_energy.removed,
        kept_energy.removed
    );
    assert_eq!(lean_energy.elastic.to_bits(), kept_energy.elastic.to_bits());
    assert!(lean_energy.elastic > 0.0 && lean_energy.elastic < elastic_before);
}
