//! Non-convex particles in whole scenes: contacts in several regions at once, resting poses, and
//! the two descriptions of one body (mesh with the vertex law, convex parts with the volume law).

use polydem::contact::Partner;
use polydem::io::output::{OutputOptions, RunOutput};
use polydem::math::{DQuat, DVec3};
use polydem::scene::{Prepared, Scene};
use polydem::shape::Shape;
use polydem::World;
use std::path::Path;

fn build(text: &str) -> Prepared {
    Scene::parse(Path::new("nonconvex.toml"), text.to_string())
        .expect("scene parses")
        .build()
        .expect("scene builds")
}

const MATERIAL: &str = r#"
[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25
restitution = 0.3
friction = 0.5

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "m"
"#;

/// The rotation (as axis × angle) that turns a flat cross (arms along x and y, thickness along
/// z) upright into the yz plane and then by 45° about x: its arms point along the diagonals of
/// the yz plane, two of them down like a Λ.
fn astride() -> [f64; 3] {
    let q = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_4)
        * DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
    q.to_scaled_axis().to_array()
}

/// A thick cross sits astride an arm of a flat cross lying on the floor: its two lower arms rest
/// on the arm's two top edges, like a saddle, and nothing else holds it up. Its weight goes
/// through two separate contact regions of the one pair at once, both in the contact list and in
/// the force network output (one line each).
#[test]
fn a_cross_astride_another_rests_on_two_regions() {
    let [rx, ry, rz] = astride();
    let text = format!(
        r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -9.81]
threads = 1
{MATERIAL}
[shape.flat]
type = "cross"
length = 0.03
width = 0.006
thickness = 0.006

[shape.thick]
type = "cross"
length = 0.03
width = 0.006
thickness = 0.016

[[particle]]
shape = "flat"
material = "m"
position = [0.0, 0.0, 0.003]

# Its inner arm faces touch the +x arm's top edges (y = ±0.003, z = 0.006) at a centre height
# of 0.009 + 0.003 √2 = 0.013243; 57 µm higher it falls onto them.
[[particle]]
shape = "thick"
material = "m"
position = [0.0125, 0.0, 0.0133]
rotation = [{rx}, {ry}, {rz}]
"#
    );
    let mut p = build(&text);
    let w = &mut p.world;
    w.run_steps((0.6 / w.time_step()) as u64);
    let pair: Vec<_> = w
        .contacts()
        .iter()
        .filter(|c| (c.key.a, c.key.partner) == (0, Partner::Body(1)))
        .collect();
    let weight = w.bodies().mass[1] * 9.81;
    for c in &pair {
        println!(
            "slot {} at {:.5?}: normal {:.3?}, normal force {:.4e} N",
            c.key.region,
            c.geometry.point.to_array(),
            c.geometry.normal.to_array(),
            c.report.normal_force
        );
    }
    assert_eq!(pair.len(), 2, "two regions");
    // One on each side of the arm (y < 0 and y > 0), normals at 45°, sharing the weight (how
    // it splits between normal and friction forces is statically indeterminate).
    assert!(pair[0].geometry.point.y * pair[1].geometry.point.y < 0.0);
    for c in &pair {
        assert!((c.geometry.normal.z + std::f64::consts::FRAC_1_SQRT_2).abs() < 0.01);
        assert!(
            c.report.normal_force > 0.25 * weight,
            "{}",
            c.report.normal_force
        );
    }
    let (f0, f1) = (pair[0].report.normal_force, pair[1].report.normal_force);
    assert!((f0 / f1 - 1.0).abs() < 0.01, "{f0} vs {f1}");
    // Each region keeps its slot, and with it its friction spring (part of the weight hangs on
    // friction), step after step.
    let sides: Vec<(u8, f64, DVec3)> = pair
        .iter()
        .map(|c| {
            (
                c.key.region,
                c.geometry.point.y.signum(),
                c.history.tangential_spring,
            )
        })
        .collect();
    assert!(sides.iter().all(|s| s.2.length() > 0.0), "{sides:?}");
    let mut later = build(&text);
    later
        .world
        .run_steps(((0.6 + 0.05) / later.world.time_step()) as u64);
    for c in later
        .world
        .contacts()
        .iter()
        .filter(|c| (c.key.a, c.key.partner) == (0, Partner::Body(1)))
    {
        let (_, side, spring) = sides
            .iter()
            .copied()
            .find(|s| s.0 == c.key.region)
            .expect("the same slots");
        assert_eq!(side, c.geometry.point.y.signum());
        assert!((c.history.tangential_spring - spring).length() < 1e-3 * spring.length());
    }
    // At rest: the two regions carry the weight (the force on the upper cross, body 1).
    let on_upper: DVec3 = pair.iter().map(|c| -c.load.force).sum();
    assert!(
        (on_upper - DVec3::Z * weight).length() < 1e-3 * weight,
        "{on_upper}"
    );
    assert!(w.bodies().velocity[1].length() < 1e-5);

    // The force network: one line per contact, the pair's two bent at their contact points.
    let dir = tempfile::tempdir().unwrap();
    let options = OutputOptions {
        force_network: true,
        packing_region: None,
        extent: None,
        wall_names: Vec::new(),
    };
    let mut out = RunOutput::create(dir.path(), w, &options, Default::default()).unwrap();
    out.write(w).unwrap();
    let vtp = std::fs::read(dir.path().join("contacts_000000.vtp")).unwrap();
    let header = String::from_utf8_lossy(&vtp[..vtp.len().min(4000)]);
    let lines = format!(
        "NumberOfLines=\"{}\"",
        w.contacts().between_bodies().count() + w.contacts().with_planes().count()
    );
    assert!(header.contains(&lines), "{header}");
    assert_eq!(w.contacts().between_bodies().count(), 2);
}

/// An L-shaped block dropped tilted onto the floor tumbles and comes to rest in a statically
/// stable pose: its centre of mass above the polygon its contact corners span, with a margin,
/// and it stays there.
#[test]
fn an_l_shape_comes_to_rest_in_a_stable_pose() {
    for (k, rotation) in [[0.9, 0.4, 0.2], [0.1, 1.2, 0.5], [2.0, -0.6, 0.3]]
        .iter()
        .enumerate()
    {
        let text = format!(
            r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -9.81]
threads = 1
{MATERIAL}
[shape.l]
type = "l_shape"
length_x = 0.03
length_y = 0.02
width = 0.008
height = 0.006

[[particle]]
shape = "l"
material = "m"
position = [0.0, 0.0, 0.03]
rotation = {rotation:?}
"#
        );
        let mut p = build(&text);
        let w = &mut p.world;
        w.run_steps((1.0 / w.time_step()) as u64);
        let speed =
            w.bodies().velocity[0].length() + w.bodies().angular_velocity[0].length() * 0.02;
        assert!(speed < 1e-5, "case {k}: still moving, {speed:e} m/s");
        let margin = stability_margin(w, 0);
        println!("case {k}: centre of mass {margin:.4e} m inside the support polygon");
        assert!(margin > 1e-3, "case {k}: margin {margin:e}");
        let before = (w.bodies().position[0], w.bodies().orientation[0]);
        w.run_steps((0.3 / w.time_step()) as u64);
        let moved = (w.bodies().position[0] - before.0).length();
        let turned = w.bodies().orientation[0].angle_between(before.1);
        assert!(
            moved < 1e-7 && turned < 1e-5,
            "case {k}: drifted {moved:e} m, {turned:e} rad"
        );
    }
}

/// How far the body's centre of mass lies inside the convex polygon of its corners touching the
/// floor (z below 10 µm), seen from above; negative outside.
fn stability_margin(w: &World, body: usize) -> f64 {
    let Shape::NonConvex(p) = &w.shapes()[w.bodies().shape[body] as usize] else {
        panic!("a non-convex body")
    };
    let (x, q) = (w.bodies().position[body], w.bodies().orientation[body]);
    let mut touching: Vec<[f64; 2]> = p
        .vertices()
        .iter()
        .map(|&v| x + q * v)
        .filter(|v| v.z < 1e-5)
        .map(|v| [v.x, v.y])
        .collect();
    touching.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    touching.dedup();
    let hull = convex_hull_2d(&touching);
    assert!(hull.len() >= 3, "rests on {} corners", hull.len());
    let c = [x.x, x.y];
    // Distance to the nearest edge of the counter-clockwise hull, positive inside.
    (0..hull.len())
        .map(|k| {
            let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            (ex * (c[1] - a[1]) - ey * (c[0] - a[0])) / (ex * ex + ey * ey).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Counter-clockwise convex hull of sorted points (Andrew's monotone chain).
fn convex_hull_2d(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let sequence: Vec<[f64; 2]> = if pass == 0 {
            points.to_vec()
        } else {
            points.iter().rev().copied().collect()
        };
        for p in sequence {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 1e-15
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The heap's angle from its shape: for a cone of height H and base radius R the material's
/// mean height is H/4 and its mean distance from the axis R/2, so tan θ = H/R = 2 z̄ / r̄, taken
/// over the body centres (heights above the floor, distances from their mean axis).
fn heap_angle(w: &World) -> f64 {
    let b = w.bodies();
    let n = b.len() as f64;
    let centre: DVec3 = b.position.iter().sum::<DVec3>() / n;
    let height = b.position.iter().map(|x| x.z).sum::<f64>() / n;
    let radius = b
        .position
        .iter()
        .map(|x| ((x.x - centre.x).powi(2) + (x.y - centre.y).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    (2.0 * height / radius).atan().to_degrees()
}

/// Pours jacks (20 mm, 4 mm bars) and, separately, spheres of the same volume onto a floor, four
/// every 0.05 s until `until`, lets them settle until `duration`, and returns both heap angles.
fn heap_angles(until: f64, duration: f64) -> [f64; 2] {
    let pour = |particle: &str| {
        format!(
            r#"
[simulation]
duration = {duration}
gravity = [0.0, 0.0, -9.81]
threads = 1

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
rolling_friction = 0.1

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "m"

[shape.jack]
type = "jack"
length = 0.02
width = 0.004

[[insert]]
method = "random"
material = "m"
{particle}
region_min = [-0.03, -0.03, 0.03]
region_max = [0.03, 0.03, 0.08]
count = 4
seed = 5
every = 0.05
until = {until}
"#
        )
    };
    let mut angles = [0.0; 2];
    // Volume-equivalent radius of the jack: (3 V / 4π)^(1/3), V = 3 L w² − 2 w³.
    let volume: f64 = 3.0 * 0.02 * 0.004f64.powi(2) - 2.0 * 0.004f64.powi(3);
    let radius = (3.0 * volume / (4.0 * std::f64::consts::PI)).cbrt();
    for (k, particle) in ["shape = \"jack\"".to_string(), format!("radius = {radius}")]
        .iter()
        .enumerate()
    {
        let mut p = build(&pour(particle));
        while p.world.time() < duration {
            let next = p.next_insertion_time().unwrap_or(duration).min(duration);
            let steps = ((next - p.world.time()) / p.world.time_step())
                .ceil()
                .max(1.0) as u64;
            p.world.run_steps(steps);
            p.insert_due();
        }
        let w = &p.world;
        let kinetic = w.energy().kinetic_translational;
        angles[k] = heap_angle(w);
        println!(
            "{particle}: {} bodies, heap angle {:.1}°, kinetic energy {kinetic:.2e} J",
            w.bodies().len(),
            angles[k]
        );
    }
    angles
}

/// Jacks poured onto the floor interlock and stand in a steep heap; spheres of the same volume
/// and material (with rolling resistance, which the jacks do not need) poured the same way roll
/// apart into a flat one. Both angles are printed (docs/validation.md). About 27 bodies each.
#[test]
fn poured_jacks_stand_steeper_than_spheres() {
    let [jacks, spheres] = heap_angles(0.3, 0.6);
    assert!(jacks > spheres + 10.0, "{jacks} vs {spheres}");
}

/// The same with about 75 bodies each, for the figures in docs/validation.md (a few minutes):
/// `cargo test --release --test nonconvex_contacts -- --ignored --nocapture larger_heaps`.
#[test]
#[ignore]
fn larger_heaps() {
    let [jacks, spheres] = heap_angles(0.9, 1.4);
    assert!(jacks > spheres + 10.0, "{jacks} vs {spheres}");
}

/// One L-shaped block described two ways: as its mesh (vertex law, the default for non-convex
/// bodies) and as the union of its two convex boxes (volume law, part by part; the two parts'
/// contacts with the floor combine into one, as the mesh's is one region). Dropped the same way
/// they must behave alike: the same resting pose, and the same rebound (the damping is set from
/// the coefficient of restitution for either law, so the first bounce of a flat drop reaches e²
/// of the height, whatever the stiffness).
#[test]
fn an_l_shape_as_mesh_and_as_convex_parts_behaves_alike() {
    let scene = |parts: bool, restitution: f64, height: f64, rotation: [f64; 3]| {
        format!(
            r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -9.81]
threads = 1

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e6
poisson_ratio = 0.25
restitution = {restitution}
friction = 0.5

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "m"

[shape.l]
type = "l_shape"
length_x = 0.03
length_y = 0.02
width = 0.008
height = 0.006
parts = {parts}

[[particle]]
shape = "l"
material = "m"
position = [0.0, 0.0, {height}]
rotation = {rotation:?}
"#
        )
    };
    // Resting pose after a tilted drop: which way is up in the body, and the height.
    let mut poses = Vec::new();
    for parts in [false, true] {
        let mut p = build(&scene(parts, 0.3, 0.02, [0.35, 0.25, 0.4]));
        let w = &mut p.world;
        w.run_steps((0.8 / w.time_step()) as u64);
        let up = w.bodies().orientation[0].inverse() * DVec3::Z;
        let speed = w.bodies().velocity[0].length();
        println!(
            "parts = {parts}: at rest {speed:.1e} m/s, centre at height {:.6} m, up in the body \
             {:.4?}",
            w.bodies().position[0].z,
            up.to_array()
        );
        assert!(speed < 1e-5);
        poses.push((w.bodies().position[0].z, up));
    }
    let ((z0, up0), (z1, up1)) = (poses[0], poses[1]);
    assert!(up0.angle_between(up1) < 0.01, "{up0} vs {up1}");
    assert!((z0 - z1).abs() < 0.02 * z0, "{z0} vs {z1}");

    // Rebound of a flat drop (lying on its L face): the first apex over the drop height.
    let mut ratios = Vec::new();
    for parts in [false, true] {
        // Centred: placed at 0.003 + h, its bottom face falls h.
        let h = 0.01;
        let mut p = build(&scene(parts, 0.5, 0.003 + h, [0.0; 3]));
        let w = &mut p.world;
        let mut touched = false;
        let mut apex = 0.0f64;
        while w.time() < 0.25 {
            w.run_steps(1);
            let z = w.bodies().position[0].z - 0.003;
            if w.contacts().with_planes().next().is_some() {
                touched = true;
            } else if touched {
                apex = apex.max(z);
                if w.bodies().velocity[0].z < 0.0 {
                    break;
                }
            }
        }
        let ratio = apex / h;
        println!("parts = {parts}: rebound to {ratio:.4} of the drop height (e² = 0.25)");
        ratios.push(ratio);
    }
    // The vertex law's springs sit at the L's corners, whose centroid is not under the centre of
    // mass: the mesh leaves the floor slightly turning, with a little of the energy in rotation.
    for r in &ratios {
        assert!((r / 0.25 - 1.0).abs() < 0.1, "{ratios:?}");
    }
    assert!((ratios[0] / ratios[1] - 1.0).abs() < 0.06, "{ratios:?}");
}

/// Non-convex bodies, like spheres and convex polyhedra, give results independent of the thread
/// count: jacks, stars (one with convex parts) and spheres dropped into a corner, with 1 and 2
/// worker threads, bit-identical after every step (the regions are found per pair, each pair's
/// contacts written to its own slots, and gathered in pair order).
#[test]
fn non_convex_bodies_do_not_depend_on_the_thread_count() {
    let scene = |threads: usize| {
        format!(
            r#"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, -9.81]
threads = {threads}
{MATERIAL}
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
material = "m"

[shape.jack]
type = "jack"
length = 0.02
width = 0.004

[shape.star]
type = "star"
radius = 0.005
spike_length = 0.005

[shape.split_star]
type = "star"
radius = 0.005
spike_length = 0.005
parts = true

[[insert]]
method = "random"
material = "m"
shape = "jack"
region_min = [0.0, -0.03, 0.01]
region_max = [0.06, 0.03, 0.06]
count = 6
seed = 4

[[insert]]
method = "random"
material = "m"
shape = "star"
region_min = [0.0, -0.03, 0.07]
region_max = [0.06, 0.03, 0.09]
count = 3
seed = 5

[[insert]]
method = "random"
material = "m"
shape = "split_star"
region_min = [0.0, -0.03, 0.1]
region_max = [0.06, 0.03, 0.12]
count = 3
seed = 6

[[insert]]
method = "random"
material = "m"
radius = 0.004
region_min = [0.0, -0.03, 0.13]
region_max = [0.06, 0.03, 0.15]
count = 4
seed = 7
"#
        )
    };
    let mut one = build(&scene(1)).world;
    let mut two = build(&scene(2)).world;
    assert_eq!((one.threads(), two.threads()), (1, 2));
    let state = |w: &World| -> Vec<u64> {
        let b = w.bodies();
        (0..b.len())
            .flat_map(|i| {
                [b.position[i], b.velocity[i], b.angular_momentum[i]]
                    .into_iter()
                    .flat_map(|v| v.to_array())
                    .chain(b.orientation[i].to_array())
            })
            .map(f64::to_bits)
            .collect()
    };
    let (mut regional, mut most) = (0, 0);
    for _ in 0..60 {
        one.run_steps(100);
        two.run_steps(100);
        assert_eq!(state(&one), state(&two), "at t = {}", one.time());
        assert_eq!(
            one.energy().total().to_bits(),
            two.energy().total().to_bits()
        );
        regional = regional.max(one.contacts().iter().filter(|c| c.key.region > 0).count());
        most = most.max(one.contacts().between_bodies().count());
    }
    println!(
        "t = {:.3} s: {} contacts, at most {most} between bodies, {regional} in slots > 0",
        one.time(),
        one.contacts().between_bodies().count() + one.contacts().with_planes().count()
    );
    // The comparison means something only if the bodies met each other on the way.
    assert!(most > 5 && regional > 0, "{most}, {regional}");
}
