//! Checkpoint and resume (issue #13): a run stopped at a checkpoint and resumed ends in the very
//! state, and writes the very files, of the run that never stopped — bit for bit, whatever the
//! thread counts. Checked for spheres with sliding and rolling history, insertions during the run
//! and a flow meter; for convex and non-convex polyhedra (several contact regions) in a turning
//! drum; stopped by a checkpoint interval and by a signal. Checkpoints that cannot be resumed
//! (another scene, truncated, a future format) are refused with a message that says why.

use polydem::checkpoint;
use polydem::run::{self, Control, ResumeOptions, RunError, RunEvent};
use polydem::scene::{Prepared, Scene};
use std::path::{Path, PathBuf};

/// Spheres with friction and rolling friction, poured in three batches into a box, a flow meter
/// across the box at mid-height; gravity tilts sideways from 0.05 s to 0.09 s (a stage that the
/// resumed part of the run goes through).
const SPHERES: &str = r#"
[simulation]
duration = 0.12
output_interval = 0.02
threads = 1
gravity_table = [[0.05, 0.0, 0.0, -9.81], [0.09, 3.0, 0.0, -9.81]]
[contact]
normal = "hertz"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
rolling_friction = 0.05
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
[[plane]]
point = [0.0, -0.012, 0.0]
normal = [0.0, 1.0, 0.0]
material = "glass"
[[plane]]
point = [0.0, 0.012, 0.0]
normal = [0.0, -1.0, 0.0]
material = "glass"
[[insert]]
method = "random"
material = "glass"
region_min = [-0.01, -0.01, 0.004]
region_max = [0.01, 0.01, 0.03]
count = 40
radius = 0.0015
seed = 3
every = 0.03
until = 0.07
[[output.flow_meter]]
name = "half_way_down"
point = [0.0, 0.0, 0.006]
normal = [0.0, 0.0, -1.0]
"#;

/// Non-convex jacks and cubes in a closed drum that is at rest for 0.03 s, then spun up to 30 rpm
/// by 0.05 s; the jacks start near the bottom (they land on the drum with several arms), the
/// cubes come in two batches during the run.
fn polyhedra() -> String {
    let jack = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data/jack.stl");
    format!(
        r#"
[simulation]
duration = 0.12
output_interval = 0.03
threads = 2
[[material]]
name = "plastic"
density = 1200.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = 0.1
friction = 0.5
[shape.jack]
type = "mesh"
file = "{}"
scale = 0.001
nonconvex = true
[shape.cube]
type = "box"
edges = [0.01, 0.01, 0.01]
[[mesh_wall]]
material = "plastic"
generator = {{ type = "cylinder", radius = 0.06, height = 0.05, segments = 48, closed = true }}
rotation = [1.5707963267948966, 0.0, 0.0]
translation = [0.0, 0.025, 0.0]
motion = {{ rpm_table = [[0.03, 0.0], [0.05, 30.0]], axis = [0.0, 1.0, 0.0] }}
[[insert]]
method = "random"
shape = "jack"
material = "plastic"
region_min = [-0.03, -0.02, -0.05]
region_max = [0.03, 0.02, -0.025]
count = 3
seed = 4
[[insert]]
method = "random"
shape = "cube"
material = "plastic"
region_min = [-0.04, -0.02, -0.035]
region_max = [0.04, 0.02, -0.005]
count = 3
seed = 2
time = 0.01
every = 0.02
until = 0.03
"#,
        jack.display().to_string().replace('\\', "/")
    )
}

/// Writes `text` as `name` in `dir` and loads it.
fn scene(dir: &Path, name: &str, text: &str) -> (Scene, PathBuf) {
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    (Scene::load(&file).unwrap(), file)
}

/// Runs `text` to its end in `out`, with checkpoints every `interval` if given.
fn run_scene(dir: &Path, text: &str, out: &Path, interval: Option<f64>) -> Prepared {
    let (scene, _) = scene(dir, "scene.toml", text);
    let record = checkpoint::SceneRecord::new(scene.file.clone(), scene.source.clone());
    let mut prepared = scene.build().unwrap();
    prepared.checkpoint_interval = interval;
    let control = Control {
        scene: Some(record),
        stop: None,
    };
    run::run_with(&mut prepared, out, control, |_| {}).unwrap();
    prepared
}

fn resume(out: &Path, options: &ResumeOptions) -> Result<(Prepared, Vec<String>), RunError> {
    let mut notes = Vec::new();
    let (prepared, _) = run::resume(out, options, Control::default(), |e| {
        if let RunEvent::Note(n) = e {
            notes.push(n)
        }
    })?;
    Ok((prepared, notes))
}

/// Every bit of the bodies' state, in body-id order.
fn state_bits(p: &Prepared) -> Vec<u64> {
    let b = p.world.bodies();
    let mut order: Vec<usize> = (0..b.len()).collect();
    order.sort_by_key(|&i| b.id[i]);
    order
        .iter()
        .flat_map(|&i| {
            let mut v = vec![b.id[i]];
            for x in [
                b.position[i],
                b.velocity[i],
                b.angular_momentum[i],
                b.force[i],
                b.torque[i],
            ] {
                v.extend(x.to_array().map(f64::to_bits));
            }
            v.extend(b.orientation[i].to_array().map(f64::to_bits));
            v
        })
        .collect()
}

/// The output files both runs must have written identically.
fn assert_same_files(a: &Path, b: &Path) {
    let mut compared = 0;
    for entry in std::fs::read_dir(a).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_dir() {
            continue;
        }
        let name = entry.file_name();
        let theirs = std::fs::read(b.join(&name))
            .unwrap_or_else(|e| panic!("{} in the resumed run: {e}", name.to_string_lossy()));
        assert!(
            std::fs::read(entry.path()).unwrap() == theirs,
            "{} differs",
            name.to_string_lossy()
        );
        compared += 1;
    }
    assert!(compared > 5, "only {compared} files compared");
    let files = |dir: &Path| {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap())
            .filter(|e| e.file_type().unwrap().is_file())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    assert_eq!(files(a), files(b), "the runs wrote other files");
}

/// Runs `text` whole, and again with checkpoints every third of its duration; removes the last
/// checkpoint and the files written after the one before, resumes from that, and compares.
fn stop_at_a_checkpoint_and_resume(text: &str, resume_threads: usize) {
    let dir = tempfile::tempdir().unwrap();
    let whole = run_scene(dir.path(), text, &dir.path().join("whole"), None);
    let out = dir.path().join("stopped");
    let duration = whole.duration;
    run_scene(dir.path(), text, &out, Some(duration / 3.0));
    let kept = checkpoint::checkpoints_in(&out);
    assert_eq!(kept.len(), 2, "the last two checkpoints are kept: {kept:?}");
    let (last_step, last) = &kept[1];
    assert_eq!(*last_step, whole.world.steps_done(), "one at the end");
    std::fs::remove_file(last).unwrap();
    // What the resumed run must write again: the series and the last frame.
    let frames = |dir: &Path| {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with("particles_"))
            .collect();
        names.sort();
        names
    };
    let last_frame = frames(&out).pop().unwrap();
    for f in ["energy.csv", "particles.pvd", &last_frame] {
        std::fs::remove_file(out.join(f)).unwrap();
    }
    let options = ResumeOptions {
        threads: Some(resume_threads),
        ..ResumeOptions::default()
    };
    let (resumed, notes) = resume(&out, &options).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    assert_eq!(resumed.world.steps_done(), whole.world.steps_done());
    assert!(
        state_bits(&resumed) == state_bits(&whole),
        "resumed state differs"
    );
    assert_eq!(
        resumed.world.energy().dissipated.to_bits(),
        whole.world.energy().dissipated.to_bits()
    );
    assert_same_files(&dir.path().join("whole"), &out);
}

#[test]
fn spheres_with_rolling_history_insertions_and_a_flow_meter_resume_bit_for_bit() {
    stop_at_a_checkpoint_and_resume(SPHERES, 2);
}

#[test]
fn polyhedra_and_jacks_in_a_turning_drum_resume_bit_for_bit() {
    stop_at_a_checkpoint_and_resume(&polyhedra(), 1);
}

/// The drum scene does exercise what it is meant to: convex polyhedra (the cubes) touching, and
/// non-convex bodies (the jacks) touching in more than one region.
#[test]
fn the_drum_scene_has_contacts_in_several_regions() {
    let dir = tempfile::tempdir().unwrap();
    let p = run_scene(dir.path(), &polyhedra(), &dir.path().join("run"), None);
    let contacts = p.world.contacts();
    let touching: Vec<_> = contacts
        .iter()
        .filter(|c| c.report.normal_force > 0.0)
        .collect();
    assert!(
        touching.iter().any(|c| c.key.region > 0),
        "no second region"
    );
    let shapes = p.world.shapes();
    let shape_of = |i: u32| &shapes[p.world.bodies().shape[i as usize] as usize];
    assert!(
        touching
            .iter()
            .any(|c| matches!(shape_of(c.key.a), polydem::shape::Shape::Convex(_))),
        "no cube touches anything"
    );
}

#[test]
fn a_finished_run_runs_further_as_if_it_had_been_longer() {
    let dir = tempfile::tempdir().unwrap();
    let longer = SPHERES.replace("duration = 0.12", "duration = 0.16");
    let whole = run_scene(dir.path(), &longer, &dir.path().join("whole"), None);
    let out = dir.path().join("short");
    run_scene(dir.path(), SPHERES, &out, None);
    let options = ResumeOptions {
        duration: Some(0.16),
        ..ResumeOptions::default()
    };
    let (resumed, _) = resume(&out, &options).unwrap();
    assert!(state_bits(&resumed) == state_bits(&whole));
    // The same scene file with the longer duration is accepted too.
    let (_, file) = scene(dir.path(), "longer.toml", &longer);
    let out2 = dir.path().join("short2");
    run_scene(dir.path(), SPHERES, &out2, None);
    let options = ResumeOptions {
        scene: Some(file),
        ..ResumeOptions::default()
    };
    let (resumed, _) = resume(&out2, &options).unwrap();
    assert!(state_bits(&resumed) == state_bits(&whole));
}

#[test]
fn a_changed_scene_is_refused_naming_what_differs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    run_scene(dir.path(), SPHERES, &out, None);
    let changed = SPHERES
        .replace("friction = 0.5", "friction = 0.3")
        .replace("count = 40", "count = 41");
    let (_, file) = scene(dir.path(), "changed.toml", &changed);
    let options = ResumeOptions {
        scene: Some(file),
        ..ResumeOptions::default()
    };
    let message = resume(&out, &options).err().unwrap().to_string();
    for expected in ["material[0].friction", "insert[0].count", "changed.toml"] {
        assert!(message.contains(expected), "{message}");
    }
    let listed = message.split("a resumed run").next().unwrap();
    assert!(!listed.contains("simulation"), "{message}");
}

/// The scene's checkpoint file bytes, and where it is.
fn only_checkpoint(out: &Path) -> (PathBuf, Vec<u8>) {
    let all = checkpoint::checkpoints_in(out);
    assert_eq!(all.len(), 1);
    let path = all[0].1.clone();
    let bytes = std::fs::read(&path).unwrap();
    (path, bytes)
}

#[test]
fn truncated_and_future_checkpoints_are_refused_and_an_older_one_is_used_instead() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    run_scene(dir.path(), SPHERES, &out, None);
    let (path, bytes) = only_checkpoint(&out);

    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let message = resume(&out, &ResumeOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("truncated"), "{message}");
    assert!(message.contains(&path.display().to_string()), "{message}");

    let mut future = bytes.clone();
    future[12..16].copy_from_slice(&(checkpoint::FORMAT_VERSION + 1).to_le_bytes());
    std::fs::write(&path, &future).unwrap();
    let message = resume(&out, &ResumeOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("newer polydem"), "{message}");

    // A damaged newest checkpoint beside a good older one: the older is used, and the user told.
    let mut damaged = bytes.clone();
    let last = damaged.len() - 1;
    damaged[last] ^= 0xff;
    std::fs::write(&path, &bytes).unwrap();
    let newer = checkpoint::checkpoint_path(&out, u64::MAX / 2);
    std::fs::write(&newer, &damaged).unwrap();
    let (resumed, notes) = resume(&out, &ResumeOptions::default()).unwrap();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].contains("damaged"), "{notes:?}");
    assert!(resumed.world.steps_done() > 0);
}

#[test]
fn a_folder_without_checkpoints_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let message = resume(dir.path(), &ResumeOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("checkpoints"), "{message}");
    assert!(message.contains("no checkpoint"), "{message}");
}

/// Issue #12, point 4: a run asked to stop (as Ctrl-C does) at a step off the output times writes
/// a checkpoint, then a final frame of every series and a row of every CSV file at that step,
/// marked as the interrupt's; `resume` removes them and continues the series as if the run had
/// never stopped, file for file.
#[test]
fn an_interrupt_writes_a_final_frame_that_resume_takes_back() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let dir = tempfile::tempdir().unwrap();
    let whole_dir = dir.path().join("whole");
    run_scene(dir.path(), SPHERES, &whole_dir, None);

    let (scene, _) = scene(dir.path(), "scene.toml", SPHERES);
    let record = checkpoint::SceneRecord::new(scene.file.clone(), scene.source.clone());
    let mut prepared = scene.build().unwrap();
    let dt = prepared.world.time_step();
    // Between the third and the fourth frame, off the output times.
    let stop_after = (0.05 / dt) as u64;
    let out = dir.path().join("stopped");
    let stop = Arc::new(AtomicBool::new(false));
    let control = Control {
        scene: Some(record),
        stop: Some(Arc::clone(&stop)),
    };
    let err = run::run_with(&mut prepared, &out, control, |e| {
        if let RunEvent::Progress(w) = e {
            if w.steps_done() > stop_after {
                stop.store(true, Ordering::Relaxed);
            }
        }
    })
    .err()
    .expect("stopped");
    let RunError::Interrupted {
        time,
        checkpoint: Some(_),
        frame: Some(frame),
    } = &err
    else {
        panic!("{err}");
    };
    assert!(time % 0.02 > 1e-6, "stopped at an output time: {time}");
    let message = err.to_string();
    assert!(
        message.contains(&frame.display().to_string()) && message.contains("polydem resume"),
        "{message}"
    );
    // The final frame: the last of every series, marked; the frames before are not.
    use polydem::io::vtk_read::{read_pvd, read_vtp};
    for series in ["particles", "walls"] {
        let entries = read_pvd(&out.join(format!("{series}.pvd"))).unwrap();
        let (last, before) = entries.split_last().unwrap();
        assert_eq!(last.time, *time);
        let state = read_vtp(&last.file).unwrap().state.expect("marked");
        assert!(state.starts_with("interrupted at t = "), "{state}");
        assert!(before
            .iter()
            .all(|e| read_vtp(&e.file).unwrap().state.is_none()));
    }
    assert_eq!(
        read_pvd(&out.join("particles.pvd"))
            .unwrap()
            .last()
            .unwrap()
            .file,
        *frame
    );
    for csv in ["energy.csv", "wall_forces.csv", "flow.csv"] {
        let table = polydem::io::csv_read::read_table(&out.join(csv)).unwrap();
        assert_eq!(table.column("time").unwrap().last(), Some(time), "{csv}");
    }

    let (resumed, notes) = resume(&out, &ResumeOptions::default()).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    assert_eq!(resumed.duration, prepared.duration);
    assert_same_files(&whole_dir, &out);
}

/// `polydem run` stopped by SIGINT writes a checkpoint and exits with 130; `polydem resume`
/// finishes the run with the files of a run that was never stopped.
#[cfg(unix)]
#[test]
fn a_run_stopped_by_a_signal_resumes_bit_for_bit() {
    use std::process::Command;
    let bin = env!("CARGO_BIN_EXE_polydem");
    let dir = tempfile::tempdir().unwrap();
    // Long enough to be stopped in the middle.
    let text = SPHERES
        .replace("duration = 0.12", "duration = 0.6")
        .replace("output_interval = 0.02", "output_interval = 0.05");
    let (_, file) = scene(dir.path(), "scene.toml", &text);
    let whole = dir.path().join("whole");
    let status = Command::new(bin)
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            whole.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");

    let out = dir.path().join("stopped");
    let child = Command::new(bin)
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Stop it once it has written its second frame.
    let started = std::time::Instant::now();
    while !out.join("particles_000001.vtp").exists() {
        assert!(started.elapsed().as_secs() < 120, "no second frame");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let stopped = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&stopped.stderr);
    assert_eq!(stopped.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("polydem resume"), "{stderr}");
    // The series ends at the step where the run stopped: a final frame (marked, unless that step
    // was an output time), and the CSV rows.
    let entries = polydem::io::vtk_read::read_pvd(&out.join("particles.pvd")).unwrap();
    let last = entries.last().unwrap();
    let energy = polydem::io::csv_read::read_table(&out.join("energy.csv")).unwrap();
    assert_eq!(energy.column("time").unwrap().last(), Some(&last.time));
    let state = polydem::io::vtk_read::read_vtp(&last.file).unwrap().state;
    if let Some(state) = &state {
        assert!(state.starts_with("interrupted"), "{state}");
        let name = last.file.file_name().unwrap().to_string_lossy();
        assert!(stderr.contains(&*name), "{stderr}");
    }
    let kept = checkpoint::checkpoints_in(&out);
    assert_eq!(kept.len(), 1, "{kept:?}");
    assert!(
        !out.join("particles_000012.vtp").exists(),
        "stopped at the end"
    );

    let resumed = Command::new(bin)
        .args(["resume", out.to_str().unwrap(), "--threads", "2"])
        .output()
        .unwrap();
    assert!(resumed.status.success(), "{resumed:?}");
    assert_same_files(&whole, &out);
}

/// A drum may be turned at another speed from the checkpoint on, not in the past: the new
/// motion must put it where the run had it.
#[test]
fn a_wall_may_change_speed_from_the_checkpoint_on() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let text = polyhedra();
    run_scene(dir.path(), &text, &out, None);
    let old = "rpm_table = [[0.03, 0.0], [0.05, 30.0]]";
    let faster = text
        .replace(
            old,
            "rpm_table = [[0.03, 0.0], [0.05, 30.0], [0.125, 30.0], [0.13, 60.0]]",
        )
        .replace("duration = 0.12", "duration = 0.15");
    let (_, file) = scene(dir.path(), "faster.toml", &faster);
    let options = ResumeOptions {
        scene: Some(file),
        ..ResumeOptions::default()
    };
    let (resumed, _) = resume(&out, &options).unwrap();
    let w = resumed.world.mesh_walls()[0]
        .motion
        .angular_velocity(resumed.world.time());
    assert!((w.length() - std::f64::consts::TAU).abs() < 1e-12, "{w}");

    let rewritten = text.replace(old, "rpm_table = [[0.03, 0.0], [0.05, 60.0]]");
    let (_, file) = scene(dir.path(), "rewritten.toml", &rewritten);
    let out2 = dir.path().join("run2");
    run_scene(dir.path(), &text, &out2, None);
    let options = ResumeOptions {
        scene: Some(file),
        ..ResumeOptions::default()
    };
    let message = resume(&out2, &options).err().unwrap().to_string();
    assert!(message.contains("mesh wall 0 would be"), "{message}");
}

/// The scene file edited after the run started: `resume` says what changed and how to go on,
/// rather than silently continuing with either version. A run started with `--set` overrides
/// is compared with its file plus the overrides.
#[test]
fn an_edited_scene_file_is_noticed_on_resume() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let edited = SPHERES.replace("restitution = 0.5", "restitution = 0.6");
    // Started with --set material[0].friction=0.4 on the file as it was.
    let file = dir.path().join("scene.toml");
    std::fs::write(&file, SPHERES).unwrap();
    let set: Vec<polydem::scene::overrides::Override> =
        vec!["material[0].friction=0.4".parse().unwrap()];
    let scene = Scene::load_with(&file, &set).unwrap();
    let record =
        checkpoint::SceneRecord::new(file.clone(), scene.source.clone()).with_overrides(&set);
    let mut prepared = scene.build().unwrap();
    let control = Control {
        scene: Some(record),
        stop: None,
    };
    run::run_with(&mut prepared, &out, control, |_| {}).unwrap();
    let longer = ResumeOptions {
        duration: Some(0.14),
        ..ResumeOptions::default()
    };
    // Unchanged file: the overrides are taken into account, nothing to say.
    let (resumed, notes) = resume(&out, &longer).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    assert_eq!(resumed.world.pair_laws().get(0, 0).friction, 0.4);

    std::fs::write(&file, &edited).unwrap();
    let message = resume(&out, &longer).err().unwrap().to_string();
    for expected in [
        "has changed",
        "material[0].restitution",
        "--scene",
        "--stored-scene",
    ] {
        assert!(message.contains(expected), "{message}");
    }
    let as_started = ResumeOptions {
        stored_scene: true,
        ..longer.clone()
    };
    assert!(resume(&out, &as_started).is_ok());
}

/// A run into a folder an earlier run used removes that run's frames, series and checkpoints
/// (ParaView would show the old frames, `resume` would take the old checkpoint for the new run's)
/// and nothing else.
#[test]
fn a_new_run_in_a_used_folder_leaves_nothing_of_the_old_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let longer = SPHERES.replace("duration = 0.12", "duration = 0.16");
    run_scene(dir.path(), &longer, &out, None);
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    std::fs::write(out.join(".particles_000099.vtp.tmp-1-2"), "killed").unwrap();
    assert!(out.join("particles_000008.vtp").exists());

    let shorter = SPHERES.replace("duration = 0.12", "duration = 0.04");
    let p = run_scene(dir.path(), &shorter, &out, None);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let frames = names.iter().filter(|n| n.starts_with("particles_")).count();
    assert_eq!(frames, 3, "{names:?}");
    assert!(names.contains(&"notes.txt".to_string()), "{names:?}");
    assert!(!names.iter().any(|n| n.contains(".tmp-")), "{names:?}");
    let kept = checkpoint::checkpoints_in(&out);
    assert_eq!(kept.len(), 1, "{kept:?}");
    assert_eq!(kept[0].0, p.world.steps_done());
}

/// Issue #14: the face of an inlet read from a mesh file places the bodies still to come, so a
/// resumed run whose face file has changed is refused, like one whose wall file has.
#[test]
fn a_changed_inlet_face_file_is_refused_on_resume() {
    let dir = tempfile::tempdir().unwrap();
    let square = |z: f64| {
        let mut s = String::from("solid face\n");
        for t in [
            [[0.0, 0.0, z], [0.02, 0.0, z], [0.02, 0.02, z]],
            [[0.0, 0.0, z], [0.02, 0.02, z], [0.0, 0.02, z]],
        ] {
            s.push_str("facet normal 0 0 0\n outer loop\n");
            for v in t {
                s.push_str(&format!("  vertex {} {} {}\n", v[0], v[1], v[2]));
            }
            s.push_str(" endloop\nendfacet\n");
        }
        s + "endsolid face\n"
    };
    std::fs::write(dir.path().join("face.stl"), square(0.1)).unwrap();
    let text = r#"
[simulation]
duration = 0.02
output_interval = 0.01
gravity = [0.0, 0.0, 0.0]
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.3
[[insert]]
method = "random"
material = "glass"
radius = 0.001
every = 0.01
inlet = { file = "face.stl", flip = true, speed = 0.5, rate = 500.0 }
"#;
    let out = dir.path().join("run");
    run_scene(dir.path(), text, &out, None);
    let options = ResumeOptions {
        duration: Some(0.04),
        ..ResumeOptions::default()
    };
    std::fs::write(dir.path().join("face.stl"), square(0.12)).unwrap();
    let message = resume(&out, &options).err().expect("refused").to_string();
    assert!(
        message.contains("builds other shapes or walls"),
        "{message}"
    );
    // Put back, it resumes.
    std::fs::write(dir.path().join("face.stl"), square(0.1)).unwrap();
    let (resumed, _) = resume(&out, &options).unwrap();
    assert_eq!(resumed.world.bodies().len(), 25);
}
