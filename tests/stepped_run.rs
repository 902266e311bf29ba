//! A run driven in pieces (`run::SteppedRun`, what the Python package drives) writes the very
//! files, and ends in the very state, of the run driven in one go; and the changes a script may
//! make between pieces (`World::set_gravity`, `set_wall_motion`, `set_velocity`) keep the energy
//! ledger closing.

use polydem::checkpoint::SceneRecord;
use polydem::math::DVec3;
use polydem::run::{self, Control, SteppedRun};
use polydem::scene::{Prepared, Scene};
use polydem::world::WallMotionChangeError;
use std::path::Path;

/// Spheres poured into a box in two batches, a flow meter at mid-height.
const SPHERES: &str = r#"
[simulation]
duration = 0.05
output_interval = 0.01
threads = 1
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "glass"
[[plane]]
point = [-0.012, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
material = "glass"
[[plane]]
point = [0.012, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
material = "glass"
[[insert]]
method = "random"
material = "glass"
region_min = [-0.01, -0.01, 0.004]
region_max = [0.01, 0.01, 0.03]
count = 30
radius = 0.0015
seed = 3
every = 0.02
until = 0.03
[output]
csv_interval = 0.005
checkpoint_interval = 0.015
[[output.flow_meter]]
name = "half_way_down"
point = [0.0, 0.0, 0.006]
normal = [0.0, 0.0, -1.0]
"#;

/// A mesh-wall piston above a few spheres on a floor.
const PISTON: &str = r#"
[simulation]
duration = 0.01
time_step = 1e-5
threads = 1
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "glass"
[[mesh_wall]]
generator = { type = "rectangle", origin = [-0.02, -0.02, 0.0045], u = [0.0, 0.04, 0.0], v = [0.04, 0.0, 0.0] }
material = "glass"
[[particle]]
radius = 0.002
material = "glass"
position = [0.0, 0.0, 0.002]
"#;

fn load(dir: &Path, text: &str) -> (Prepared, Control) {
    let file = dir.join("scene.toml");
    std::fs::write(&file, text).unwrap();
    let scene = Scene::load(&file).unwrap();
    let record = SceneRecord::new(scene.file.clone(), scene.source.clone());
    let control = Control {
        scene: Some(record),
        stop: None,
    };
    (scene.build().unwrap(), control)
}

fn bodies_bits(p: &Prepared) -> Vec<u64> {
    let b = p.world.bodies();
    (0..b.len())
        .flat_map(|i| {
            let mut v = vec![b.id[i]];
            for x in [
                b.position[i],
                b.velocity[i],
                b.angular_momentum[i],
                b.force[i],
            ] {
                v.extend(x.to_array().map(f64::to_bits));
            }
            v
        })
        .collect()
}

#[test]
fn a_run_driven_in_pieces_writes_what_the_run_in_one_go_writes() {
    let dir = tempfile::tempdir().unwrap();
    let (mut whole, control) = load(dir.path(), SPHERES);
    run::run_with(
        &mut whole,
        &dir.path().join("whole"),
        control.clone(),
        |_| {},
    )
    .unwrap();

    let (prepared, control) = load(dir.path(), SPHERES);
    let pieces = dir.path().join("pieces");
    let mut stepped = SteppedRun::start(prepared, &pieces, control, |_| {}).unwrap();
    // Pieces that end on and off output, insertion and checkpoint steps.
    let mut step = 0;
    for piece in [1, 37, 462, 500, 999, 1, 700].into_iter().cycle() {
        if step >= stepped.end_step() {
            break;
        }
        step += piece;
        stepped.advance_to(step, |_| {}).unwrap();
        assert_eq!(stepped.world().steps_done(), step.min(stepped.end_step()));
    }
    let (prepared, _) = stepped.into_parts();
    assert_eq!(bodies_bits(&prepared), bodies_bits(&whole));
    let mut compared = 0;
    for entry in std::fs::read_dir(dir.path().join("whole")).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_dir() {
            continue;
        }
        let theirs = std::fs::read(pieces.join(entry.file_name())).unwrap();
        assert!(
            std::fs::read(entry.path()).unwrap() == theirs,
            "{:?} differs",
            entry.file_name()
        );
        compared += 1;
    }
    assert!(compared > 10, "only {compared} files compared");
    let checkpoints = polydem::checkpoint::checkpoints_in(&pieces);
    assert_eq!(checkpoints.last().unwrap().0, whole.world.steps_done());
}

#[test]
fn changes_between_pieces_keep_the_energy_ledger_closing() {
    let dir = tempfile::tempdir().unwrap();
    let (prepared, control) = load(dir.path(), PISTON);
    let mut stepped =
        SteppedRun::start(prepared, &dir.path().join("out"), control, |_| {}).unwrap();
    stepped.advance_to(300, |_| {}).unwrap();
    let total = |s: &SteppedRun| s.world().energy().total();
    let before = total(&stepped);

    let world = &mut stepped.prepared_mut().world;
    world.set_velocity(0, DVec3::new(0.1, 0.0, 0.0), DVec3::new(0.0, 5.0, 0.0));
    assert_eq!(world.bodies().velocity[0], DVec3::new(0.1, 0.0, 0.0));
    assert!((world.bodies().angular_velocity[0] - DVec3::new(0.0, 5.0, 0.0)).length() < 1e-12);
    world.set_gravity(DVec3::new(0.0, 0.0, -20.0));
    assert_eq!(world.gravity(), DVec3::new(0.0, 0.0, -20.0));
    let after = world.energy().total();
    assert!(
        (after - before).abs() < 1e-12 * before.abs().max(1e-9),
        "{before} → {after}"
    );

    // The piston starts down at 0.2 m/s; a motion that would make it jump is refused.
    let t = world.time();
    let dt = world.time_step();
    let motion = world.mesh_walls()[0].motion.clone();
    let jump = motion
        .clone()
        .with_velocity(DVec3::new(0.0, 0.0, -0.2))
        .unwrap();
    assert!(matches!(
        world.set_wall_motion(0, jump),
        Err(WallMotionChangeError::Jump { .. })
    ));
    let down = motion
        .with_velocity_changed_at(t, t + dt, DVec3::new(0.0, 0.0, -0.2))
        .unwrap();
    world.set_wall_motion(0, down).unwrap();
    stepped.advance_to(900, |_| {}).unwrap();
    let w = stepped.world();
    let e = w.energy();
    assert!(e.wall_work > 0.0, "the piston pushed: {e:?}");
    let scale = e.wall_work + e.dissipated + e.kinetic_translational;
    assert!(
        (e.total() - before).abs() < 0.02 * scale,
        "ledger drift {} of {scale}",
        e.total() - before
    );
}
