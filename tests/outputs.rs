//! What a run writes for the user (issue #14): per-body data in every per-body output, a legend
//! of material and shape numbers, as many polyhedra frames as particle frames when polyhedra
//! arrive later, separate intervals for VTK frames and CSV rows, walls named in their columns.

use polydem::run::run;
use polydem::scene::Scene;
use std::path::Path;

/// Spheres resting on a plate from the start; cubes dropped onto them at 0.02 s.
const SCENE: &str = r#"
[simulation]
duration = 0.06
output_interval = 0.01
threads = 1
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
[[material]]
name = "steel, rough"
density = 7800.0
youngs_modulus = 5.0e6
poisson_ratio = 0.3
restitution = 0.5
friction = 0.6
[shape.cube]
type = "box"
edges = [0.004, 0.004, 0.004]
[[plane]]
name = "floor"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "steel, rough"
[[insert]]
method = "lattice"
material = "glass"
region_min = [-0.01, -0.01, 0.0]
region_max = [0.01, 0.01, 0.004]
count = 16
radius = 0.002
[[insert]]
method = "lattice"
shape = "cube"
material = "steel, rough"
region_min = [-0.01, -0.01, 0.006]
region_max = [0.01, 0.01, 0.014]
count = 4
time = 0.02
[output]
csv_interval = 0.002
"#;

fn run_scene(dir: &Path, text: &str) -> std::path::PathBuf {
    let file = dir.join("scene.toml");
    std::fs::write(&file, text).unwrap();
    let mut prepared = Scene::load(&file).unwrap().build().unwrap();
    let out = dir.join("out");
    run(&mut prepared, &out, |_| {}).unwrap();
    out
}

/// The `Name`s of a `.vtp` file's DataArrays (from its XML header).
fn array_names(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes
        .windows(b"<AppendedData".len())
        .position(|w| w == b"<AppendedData")
        .unwrap();
    let header = String::from_utf8_lossy(&bytes[..end]);
    header
        .split("Name=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap().to_string())
        .collect()
}

fn count(dir: &Path, prefix: &str) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            let name = name.to_string_lossy();
            name.starts_with(prefix) && name.ends_with(".vtp")
        })
        .count()
}

#[test]
fn every_per_body_output_carries_the_body_fields() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_scene(dir.path(), SCENE);
    let fields = [
        "velocity",
        "speed",
        "angular_velocity",
        "force",
        "torque",
        "coordination",
        "wall_contacts",
        "material",
        "shape",
    ];
    let particles = array_names(&out.join("particles_000006.vtp"));
    let faces = array_names(&out.join("polyhedra_000006.vtp"));
    for f in fields {
        assert!(particles.iter().any(|n| n == f), "{f} not in {particles:?}");
        assert!(faces.iter().any(|n| n == f), "{f} not in {faces:?}");
    }
    assert!(faces.iter().any(|n| n == "id"));
    let legend = std::fs::read_to_string(out.join("legend.csv")).unwrap();
    assert_eq!(
        legend,
        "kind,number,name\nmaterial,0,glass\nmaterial,1,\"steel, rough\"\nshape,0,sphere\n\
         shape,1,cube\n"
    );
}

#[test]
fn polyhedra_arriving_later_still_get_a_frame_each_time() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_scene(dir.path(), SCENE);
    assert_eq!(count(&out, "particles_"), 7);
    assert_eq!(count(&out, "polyhedra_"), 7);
    let pvd = std::fs::read_to_string(out.join("polyhedra.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 7);
}

#[test]
fn frames_and_csv_rows_have_their_own_intervals() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_scene(dir.path(), SCENE);
    let energy = std::fs::read_to_string(out.join("energy.csv")).unwrap();
    // A header, the start, then every 2 ms for 60 ms.
    assert_eq!(energy.lines().count(), 1 + 1 + 30, "{energy}");
    let wall = std::fs::read_to_string(out.join("wall_forces.csv")).unwrap();
    assert_eq!(wall.lines().count(), 1 + 30);
    // The named wall heads its columns by name.
    assert!(
        wall.starts_with("time,floor_fx,floor_fy,floor_fz,floor_tx,"),
        "{wall}"
    );
    assert_eq!(count(&out, "particles_"), 7);
}

/// The values, not only the names: the last frame read back (with the crate's own reader)
/// agrees with the world it was written from, body by body and face by face.
#[test]
fn the_body_fields_hold_the_bodies_values() {
    use polydem::io::vtk_read::read_vtp;
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("scene.toml");
    // Long enough for the cubes to land on the spheres.
    std::fs::write(&file, SCENE.replace("duration = 0.06", "duration = 0.12")).unwrap();
    let mut prepared = Scene::load(&file).unwrap().build().unwrap();
    let out = dir.path().join("out");
    run(&mut prepared, &out, |_| {}).unwrap();
    let w = &prepared.world;
    let b = w.bodies();
    let frame = read_vtp(&out.join("particles_000012.vtp")).unwrap();
    let field = |name: &str| frame.point_array(name).unwrap().clone();
    let (ids, speed, force, coordination, walls) = (
        field("id"),
        field("speed"),
        field("force"),
        field("coordination"),
        field("wall_contacts"),
    );
    // Neighbours counted independently from the contact list.
    let mut neighbours = vec![std::collections::BTreeSet::new(); b.len()];
    let mut on_walls = vec![0; b.len()];
    for c in w.contacts().iter() {
        match c.key.partner.body() {
            Some(j) => {
                neighbours[c.key.a as usize].insert(j);
                neighbours[j as usize].insert(c.key.a);
            }
            None => on_walls[c.key.a as usize] += 1,
        }
    }
    assert!(neighbours.iter().any(|n| !n.is_empty()), "bodies touching");
    assert!(on_walls.iter().any(|&n| n > 0), "bodies on the floor");
    for i in 0..b.len() {
        assert_eq!(ids.values[i] as u64, b.id[i]);
        assert_eq!(speed.values[i], b.velocity[i].length());
        assert_eq!(force.tuple(i), b.force[i].to_array());
        assert_eq!(
            coordination.values[i] as usize,
            neighbours[i].len(),
            "body {i}"
        );
        assert_eq!(walls.values[i] as usize, on_walls[i], "body {i}");
    }
    // Every face of a cube carries its body's speed.
    let faces = read_vtp(&out.join("polyhedra_000012.vtp")).unwrap();
    let (face_id, face_speed) = (
        faces.cell_array("id").unwrap(),
        faces.cell_array("speed").unwrap(),
    );
    assert_eq!(face_id.len(), 4 * 6, "four cubes of six faces");
    for k in 0..face_id.len() {
        let body =
            b.id.iter()
                .position(|&id| id == face_id.values[k] as u64)
                .unwrap();
        assert_eq!(face_speed.values[k], b.velocity[body].length());
    }
}

/// Issue #14: a run ends with a summary of what it did — steps, wall time and mean rate,
/// bodies and contacts at the end, the energy ledger's closure in percent, and the files
/// written — as `polydem run` prints it.
#[test]
fn a_run_ends_with_a_summary_of_what_it_did() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("drop.toml");
    std::fs::write(
        &file,
        r#"
[simulation]
duration = 0.05
gravity = [0.0, 0.0, -9.81]
output_interval = 0.01
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.3
[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "glass"
[[particle]]
radius = 0.005
material = "glass"
position = [0.0, 0.0, 0.006]
"#,
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args([
            "run",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = String::from_utf8_lossy(&run.stdout);
    let line = |head: &str| {
        text.lines()
            .find(|l| l.starts_with(head))
            .unwrap_or_else(|| panic!("no '{head}' line in:\n{text}"))
            .to_string()
    };
    // The sphere rests on the plane at the end: one body, one contact.
    let done = line("done ");
    assert!(
        done.contains("particle-steps/s") && done.contains("(t = 0.05"),
        "{done}"
    );
    assert!(done.contains("1 bodies, 1 contacts"), "{done}");
    let energy = line("energy ");
    let percent: f64 = energy
        .split("closes to ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no percentage in: {energy}"));
    assert!((0.0..1.0).contains(&percent), "{energy}");
    // The files line counts what is on disk.
    let files = line("files ");
    let frames = std::fs::read_dir(&out)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "vtp")
        })
        .count();
    assert!(
        frames > 0 && files.contains(&format!("{frames} VTK files")),
        "{files} ({frames})"
    );
    assert!(
        files.contains("energy.csv") && files.contains("1 checkpoint,"),
        "{files}"
    );
}
