//! Moving walls, wall forces and flow meters driven through the scene file as a user would.

use polydem::run::run;
use polydem::scene::Scene;
use std::path::Path;

const BELT: &str = r#"
[simulation]
duration = 1.0
time_step = "auto"
output_interval = 0.05

[[material]]
name = "beads"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5

# A conveyor belt: a fixed strip whose surface moves at 0.5 m/s along x; beads fall off its end.
[[mesh_wall]]
material = "beads"
generator = { type = "rectangle", origin = [-0.05, -0.02, 0.0], u = [0.1, 0.0, 0.0], v = [0.0, 0.04, 0.0], divisions = [5, 2] }
motion = { surface_velocity = [0.5, 0.0, 0.0] }

[domain]
min = [-0.1, -0.1, -0.05]
max = [0.2, 0.1, 0.1]

[[insert]]
method = "lattice"
material = "beads"
region_min = [-0.045, -0.015, 0.004]
region_max = [-0.015, 0.015, 0.012]
count = 9
radius = 0.004

[[output.flow_meter]]
name = "belt_end"
point = [0.05, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]

[[output.flow_meter]]
name = "leaving"
min = [-0.06, -0.03, -0.01]
max = [0.06, 0.03, 0.03]
"#;

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn belt_carries_beads_through_the_flow_meters() {
    let scene = Scene::parse(Path::new("belt.toml"), BELT.to_string()).unwrap();
    let mut prepared = scene.build().unwrap();
    let bodies = prepared.world.bodies().len();
    assert_eq!(bodies, 9);
    let mass: f64 = prepared.world.bodies().mass.iter().sum();
    let dir = tempfile::tempdir().unwrap();
    run(&mut prepared, dir.path(), |_| {}).unwrap();
    let w = &prepared.world;
    // The belt carried every bead off its end (rolling at 2/7 of 0.5 m/s, 8 cm takes 0.6 s)...
    assert_eq!(
        w.bodies_removed() as usize,
        bodies,
        "{} left",
        w.bodies().len()
    );
    // ...through the plane and out of the box, each counted once.
    let (header, rows) = read_csv(&dir.path().join("flow.csv"));
    assert_eq!(
        header,
        [
            "time",
            "belt_end_mass",
            "belt_end_bodies",
            "belt_end_rate",
            "leaving_mass",
            "leaving_bodies",
            "leaving_rate"
        ]
    );
    let last = rows.last().unwrap();
    assert_eq!(last[2], bodies as f64);
    assert!((last[1] - mass).abs() < 1e-12 * mass);
    assert_eq!(last[5], bodies as f64);
    // The mean rates over the intervals add up to the mass passed.
    let mut passed = 0.0;
    let mut previous_time = 0.0;
    for r in &rows {
        passed += r[3] * (r[0] - previous_time);
        previous_time = r[0];
    }
    assert!((passed - mass).abs() < 1e-9 * mass, "{passed} vs {mass}");
    // The belt's forces: one wall, six columns; it pushed the beads along +x, so the beads
    // pushed it along −x, and carried their weight while they were on it.
    let (header, rows) = read_csv(&dir.path().join("wall_forces.csv"));
    assert_eq!(header.len(), 7);
    assert_eq!(header[1], "wall0_fx");
    assert!(rows.iter().any(|r| r[1] < 0.0));
    let first = &rows[0];
    let weight = mass * 9.81;
    assert!(first[3] < -0.3 * weight, "{first:?}");
    // The belt's work is in the ledger.
    let (header, rows) = read_csv(&dir.path().join("energy.csv"));
    let column = header.iter().position(|h| h == "wall_work").unwrap();
    assert!(rows.last().unwrap()[column] > 0.0);
}

#[test]
fn bad_motions_and_meters_name_their_key() {
    let cases = [
        (
            "motion = { surface_velocity = [0.5, 0.0, 0.0] }",
            "motion = { rpm = 10.0 }",
            "[[mesh_wall]] #1 motion.axis",
        ),
        (
            "motion = { surface_velocity = [0.5, 0.0, 0.0] }",
            "motion = { velocity_table = [[0.0, 1.0, 0.0, 0.0], [0.0, 2.0, 0.0, 0.0]] }",
            "[[mesh_wall]] #1 motion.velocity_table",
        ),
        (
            "name = \"leaving\"",
            "name = \"belt_end\"",
            "flow_meter[1].name",
        ),
        (
            "normal = [1.0, 0.0, 0.0]",
            "normal = [0.0, 0.0, 0.0]",
            "flow_meter[0].normal",
        ),
    ];
    for (from, to, key) in cases {
        let text = BELT.replacen(from, to, 1);
        let scene = Scene::parse(Path::new("belt.toml"), text).unwrap();
        let error = scene.build().err().expect("refused").to_string();
        assert!(error.contains(key), "{key}: {error}");
        assert!(error.contains("belt.toml"), "{error}");
    }
}

#[test]
fn a_turning_screw_keeps_its_casing_fixed_or_is_refused() {
    let screw = |casing: &str, part: &str| {
        format!(
            "generator = {{ type = \"screw\", shaft_radius = 0.01, flight_radius = 0.04, \
             pitch = 0.05, turns = 2, thickness = 0.004, {casing}part = \"{part}\" }}\n\
             motion = {{ rpm = 60.0, axis = [0.0, 0.0, 1.0] }}"
        )
    };
    let belt = BELT
        .lines()
        .filter(|l| !l.starts_with("generator =") && !l.starts_with("motion ="))
        .collect::<Vec<_>>()
        .join("\n");
    let with = |wall: &str| {
        belt.replacen(
            "[[mesh_wall]]\nmaterial = \"beads\"",
            &format!("[[mesh_wall]]\nmaterial = \"beads\"\n{wall}"),
            1,
        )
    };
    let build = |wall: &str| {
        Scene::parse(Path::new("screw.toml"), with(wall))
            .unwrap()
            .build()
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    // A screw alone may turn, and so may its flight apart from its casing.
    assert!(build(&screw("", "all")).is_ok());
    assert!(build(&screw("trough_clearance = 0.002, ", "screw")).is_ok());
    // Flight and trough in one turning wall: refused, saying how to split them.
    let error = build(&screw("trough_clearance = 0.002, ", "all")).expect_err("refused");
    assert!(error.contains("screw.toml"), "{error}");
    assert!(error.contains("[[mesh_wall]] #1 generator.part"), "{error}");
    assert!(error.contains("part = \"casing\""), "{error}");
    let error = build(&screw(
        "tube_clearance = 0.002, trough_clearance = 0.002, ",
        "screw",
    ))
    .expect_err("refused");
    assert!(error.contains("[[mesh_wall]] #1 generator"), "{error}");
    assert!(error.contains("not both"), "{error}");
}
