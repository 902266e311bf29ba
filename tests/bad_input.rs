//! Bad scene files get a clear error from the real `polydem` binary, never a panic: the message
//! names the file (and line and key where there is one) and says what is allowed, the exit code is
//! non-zero, and `run --out DIR` leaves no DIR behind. Valid scenes check and run cleanly.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// File name every scene is written under (each in its own temporary folder).
const SCENE: &str = "scene.toml";

/// A valid scene: a glass bead resting above a plate. Cases edit one line of it.
const BASE: &str = r#"[simulation]
duration = 0.002
output_interval = 0.0005

[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e9
poisson_ratio = 0.25
restitution = 0.8
friction = 0.3

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "glass"

[[particle]]
radius = 0.005
material = "glass"
position = [0.0, 0.0, 0.006]
"#;

/// A second bead beside the first, touching nothing.
const SECOND_PARTICLE: &str = r#"
[[particle]]
radius = 0.005
material = "glass"
position = [0.02, 0.0, 0.006]
velocity = [-0.5, 0.0, 0.0]
"#;

fn polydem(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_polydem"))
        .args(args)
        .output()
        .expect("the polydem binary starts")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `BASE` with the one line `from` replaced by `to`.
fn edit(from: &str, to: &str) -> String {
    assert_eq!(BASE.matches(from).count(), 1, "'{from}' must occur once");
    BASE.replacen(from, to, 1)
}

/// `BASE` with `extra` appended.
fn plus(extra: &str) -> String {
    format!("{BASE}{extra}")
}

/// What an error message must show as its location: the file and the 1-based line holding
/// `marker` (the first such line).
fn at(scene: &str, marker: &str) -> String {
    let line = scene
        .lines()
        .position(|l| l.contains(marker))
        .unwrap_or_else(|| panic!("'{marker}' is not in the scene"))
        + 1;
    format!("{SCENE}:{line}:")
}

/// Asserts a failed command: non-zero exit, an `error:` line naming `file`, every one of
/// `expected` in stderr, and no panic. Returns stderr.
fn assert_refused(output: &Output, file: &Path, expected: &[&str]) -> String {
    let stderr = text(&output.stderr);
    assert!(
        !output.status.success(),
        "expected failure, got success; stdout:\n{}",
        text(&output.stdout)
    );
    assert!(!stderr.contains("panicked"), "panic:\n{stderr}");
    assert!(stderr.starts_with("error: "), "stderr:\n{stderr}");
    assert!(
        stderr.contains(&file.display().to_string()),
        "stderr does not name {}:\n{stderr}",
        file.display()
    );
    for e in expected {
        assert!(stderr.contains(e), "stderr lacks '{e}':\n{stderr}");
    }
    stderr
}

/// Writes `scene` (or nothing, for `None`) to a fresh folder; `check` and `run --out DIR` must
/// both refuse it with every string of `expected` in the message, and leave no DIR behind.
/// Returns the message of `check`.
fn refused(scene: Option<&str>, expected: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join(SCENE);
    if let Some(scene) = scene {
        std::fs::write(&file, scene).unwrap();
    }
    let message = assert_refused(
        &polydem(&["check".as_ref(), file.as_os_str()]),
        &file,
        expected,
    );
    let out = dir.path().join("out");
    let run = polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(assert_refused(&run, &file, expected), message);
    assert!(!out.exists(), "a refused run created {}", out.display());
    message
}

/// Writes `scene` to `dir` and runs `polydem check` on it, which must succeed; returns stdout.
fn checked(dir: &Path, scene: &str) -> String {
    let file = dir.join(SCENE);
    std::fs::write(&file, scene).unwrap();
    accepted(&polydem(&["check".as_ref(), file.as_os_str()]))
}

/// Asserts a successful command; returns its stdout.
fn accepted(output: &Output) -> String {
    let (stdout, stderr) = (text(&output.stdout), text(&output.stderr));
    assert!(
        output.status.success() && !stderr.contains("panicked"),
        "failed:\n{stdout}\n{stderr}"
    );
    stdout
}

#[test]
fn base_scene_is_valid() {
    let dir = tempfile::tempdir().unwrap();
    assert!(checked(dir.path(), &plus(SECOND_PARTICLE)).contains("scene is valid"));
}

#[test]
fn missing_file() {
    refused(None, &["cannot read scene file", "No such file"]);
}

#[test]
fn toml_syntax_error_gives_the_right_line() {
    let scene = edit("density = 2500.0", "density = = 2500.0");
    let m = refused(Some(&scene), &[&at(&scene, "density = =")]);
    // The offending line is quoted.
    assert!(m.contains("    density = = 2500.0"), "{m}");
}

#[test]
fn unknown_key_is_named_with_its_line_and_the_known_keys() {
    let scene = edit("density = 2500.0", "densty = 2500.0");
    refused(
        Some(&scene),
        &[&at(&scene, "densty"), "unknown field `densty`", "`density`"],
    );
}

#[test]
fn negative_density() {
    let scene = edit("density = 2500.0", "density = -1.0");
    refused(
        Some(&scene),
        &[
            &at(&scene, "density"),
            "[[material]] #1 density",
            "must be > 0",
        ],
    );
}

#[test]
fn restitution_outside_0_1() {
    for e in ["-0.1", "1.5"] {
        let scene = edit("restitution = 0.8", &format!("restitution = {e}"));
        refused(
            Some(&scene),
            &[
                &at(&scene, "restitution"),
                "restitution",
                "must lie in [0, 1]",
            ],
        );
    }
}

#[test]
fn poisson_ratio_outside_its_range() {
    for nu in ["0.5", "-1.0"] {
        let scene = edit("poisson_ratio = 0.25", &format!("poisson_ratio = {nu}"));
        refused(
            Some(&scene),
            &[
                &at(&scene, "poisson_ratio"),
                "poisson_ratio",
                "must lie in (-1, 0.5)",
            ],
        );
    }
}

#[test]
fn overlapping_particles() {
    let scene = plus(&SECOND_PARTICLE.replace("[0.02,", "[0.005,"));
    let second_header = at(
        &scene.replacen("[[particle]]", "[[first]]", 1),
        "[[particle]]",
    );
    refused(
        Some(&scene),
        &[
            &second_header,
            "[[particle]] #2",
            "overlaps [[particle]] #1",
            "initial_overlap_tolerance",
            "move them apart",
        ],
    );
}

#[test]
fn particle_overlapping_a_plane() {
    let scene = edit(
        "position = [0.0, 0.0, 0.006]",
        "position = [0.0, 0.0, 0.002]",
    );
    refused(
        Some(&scene),
        &[
            &at(&scene, "[[particle]]"),
            "overlaps [[plane]] #1",
            "side the plane's normal points to",
        ],
    );
}

/// A cube on a mesh floor: valid resting on it, refused when it starts sunk into it (polyhedra
/// met mesh walls only by refusal once; now their overlap is checked like a sphere's).
#[test]
fn polyhedron_on_a_mesh_wall_is_checked_for_overlap() {
    let cube_on_mesh = |z: f64| {
        format!(
            r#"{}
[shape.cube]
type = "box"
edges = [0.01, 0.01, 0.01]

[[mesh_wall]]
material = "glass"
generator = {{ type = "rectangle", origin = [0.02, -0.1, 0.03], u = [0.2, 0.0, 0.0], v = [0.0, 0.2, 0.0], divisions = [5, 5] }}

[[particle]]
shape = "cube"
material = "glass"
position = [0.053, 0.0, {z}]
"#,
            BASE
        )
    };
    let dir = tempfile::tempdir().unwrap();
    assert!(checked(dir.path(), &cube_on_mesh(0.0351)).contains("scene is valid"));
    let scene = cube_on_mesh(0.034);
    let header = at(
        &scene.replacen("[[particle]]", "[[first]]", 1),
        "[[particle]]",
    );
    refused(
        Some(&scene),
        &[
            &header,
            "overlaps [[mesh_wall]] #1",
            "move it to the side the wall faces",
        ],
    );
}

#[test]
fn time_step_above_the_stable_limit_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    // The estimate, as `check` prints it for time_step = "auto" (the default).
    let auto = checked(dir.path(), BASE);
    let estimate = auto
        .lines()
        .find_map(|l| l.strip_prefix("time step"))
        .and_then(|l| l.split_whitespace().next())
        .expect("check prints the time step")
        .to_string();
    assert!(auto.contains("(auto)"), "{auto}");

    let too_large = edit("duration = 0.002", "duration = 0.002\ntime_step = 1e-3");
    refused(
        Some(&too_large),
        &[
            &at(&too_large, "time_step"),
            "above the stable estimate",
            &estimate,
            "force_time_step = true",
        ],
    );
    let forced = too_large.replace(
        "time_step = 1e-3",
        "time_step = 1e-3\nforce_time_step = true",
    );
    let stdout = checked(dir.path(), &forced);
    assert!(
        stdout.contains(&format!("given; stable estimate {estimate}"))
            && stdout.contains("scene is valid"),
        "{stdout}"
    );
}

#[test]
fn nan_is_refused() {
    for (from, to, key) in [
        (
            "position = [0.0, 0.0, 0.006]",
            "position = [nan, 0.0, 0.006]",
            "[[particle]] #1 position",
        ),
        (
            "density = 2500.0",
            "density = nan",
            "[[material]] #1 density",
        ),
        (
            "normal = [0.0, 0.0, 1.0]",
            "normal = [0.0, nan, 1.0]",
            "[[plane]] #1 normal",
        ),
    ] {
        let scene = edit(from, to);
        refused(
            Some(&scene),
            &[&at(&scene, to), key, "NaN is not a finite number"],
        );
    }
}

#[test]
fn unknown_material_name() {
    let scene = plus(&SECOND_PARTICLE.replace("\"glass\"", "\"sand\""));
    refused(
        Some(&scene),
        &[
            &at(&scene, "\"sand\""),
            "[[particle]] #2 material",
            "no material named 'sand'",
            "[\"glass\"]",
        ],
    );
}

#[test]
fn duplicate_material_name() {
    let material = &BASE[BASE.find("[[material]]").unwrap()..BASE.find("[[plane]]").unwrap()];
    let scene = plus(&format!("\n{material}"));
    let second = scene.rfind("name = \"glass\"").unwrap();
    let line = scene[..second].lines().count() + 1;
    refused(
        Some(&scene),
        &[
            &format!("{SCENE}:{line}:"),
            "[[material]] #2 name",
            "'glass' is defined twice",
        ],
    );
}

#[test]
fn linear_contact_needs_a_stiffness() {
    let scene = plus("\n[contact]\nnormal = \"linear\"\n");
    refused(
        Some(&scene),
        &[
            &at(&scene, "[contact]"),
            "[contact] stiffness",
            "needs `stiffness` [N/m]",
        ],
    );
}

/// An `[[insert]]` of `body` appended to the base scene, filling a 10 cm box above the plate.
fn insertion(body: &str) -> String {
    plus(&format!(
        "\n[[insert]]\nmaterial = \"glass\"\nregion_min = [0.0, 0.0, 0.02]\n\
         region_max = [0.1, 0.1, 0.12]\n{body}\n"
    ))
}

#[test]
fn insertions_that_do_not_fit_give_advice() {
    let scene = insertion("method = \"lattice\"\ncount = 1200\nradius = 0.005");
    refused(
        Some(&scene),
        &[
            &at(&scene, "[[insert]]"),
            "1000 lattice sites",
            "1200 spheres were asked for",
            "enlarge the region or ask for fewer",
        ],
    );
    let scene = insertion("method = \"random\"\ncount = 1200\nradius = 0.005");
    refused(
        Some(&scene),
        &[
            &at(&scene, "[[insert]]"),
            "random filling jams",
            "use method = \"lattice\"",
        ],
    );
    // More sphere volume than any packing holds: refused before drawing a single sphere.
    let scene = insertion("method = \"random\"\ncount = 1000000000000\nradius = 0.005");
    refused(
        Some(&scene),
        &[
            &at(&scene, "count ="),
            "[[insert]] #1 count",
            "ask for fewer",
        ],
    );
}

#[test]
fn insertion_of_zero_spheres() {
    let scene = insertion("method = \"lattice\"\ncount = 0\nradius = 0.005");
    refused(
        Some(&scene),
        &[&at(&scene, "count ="), "count must be at least 1"],
    );
}

#[test]
fn insertion_region_max_not_above_region_min() {
    for max in ["[0.1, 0.0, 0.12]", "[0.1, 0.1, 0.01]"] {
        let scene = insertion("method = \"lattice\"\ncount = 10\nradius = 0.005")
            .replace("[0.1, 0.1, 0.12]", max);
        refused(
            Some(&scene),
            &[
                &at(&scene, "region_max"),
                "[[insert]] #1 region_max",
                "greater than region_min on every axis",
            ],
        );
    }
}

#[test]
fn radius_distribution_with_min_above_max_or_an_empty_window() {
    for (distribution, expected) in [
        (
            "{ kind = \"uniform\", min = 0.006, max = 0.004 }",
            "radius_distribution.max: 0.004 is below min",
        ),
        // Drawing radii by rejection from this would never end.
        (
            "{ kind = \"normal\", mean = 0.005, std_dev = 0.001, min = 0.005, max = 0.005 }",
            "widen [min, max]",
        ),
    ] {
        let scene = insertion(&format!(
            "method = \"random\"\ncount = 10\nradius_distribution = {distribution}"
        ));
        refused(
            Some(&scene),
            &[&at(&scene, "radius_distribution"), expected],
        );
    }
}

#[test]
fn every_example_checks_and_prints_its_time_step() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&examples)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    assert!(!scenes.is_empty());
    for scene in scenes {
        let stdout = accepted(&polydem(&["check".as_ref(), scene.as_os_str()]));
        assert!(
            stdout.contains("time step")
                && stdout.contains(" s (")
                && stdout.contains("scene is valid"),
            "{}:\n{stdout}",
            scene.display()
        );
    }
}

#[test]
fn tiny_run_writes_complete_output_and_no_temporaries() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join(SCENE);
    std::fs::write(&file, plus(SECOND_PARTICLE)).unwrap();
    let out = dir.path().join("out");
    accepted(&polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]));
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    for wanted in ["energy.csv", "particles.pvd", "walls.pvd"] {
        assert!(
            names.iter().any(|n| n == wanted),
            "no {wanted} in {names:?}"
        );
    }
    for series in ["particles_", "walls_"] {
        assert!(
            names
                .iter()
                .any(|n| n.starts_with(series) && n.ends_with(".vtp")),
            "no {series}*.vtp in {names:?}"
        );
    }
    assert!(
        names.iter().all(|n| !n.starts_with('.')),
        "temporary files left: {names:?}"
    );
    // Start plus one row per output interval: 0.002 s / 0.0005 s = 4 more.
    let energy = std::fs::read_to_string(out.join("energy.csv")).unwrap();
    assert_eq!(energy.lines().count(), 1 + 5, "{energy}");
}

/// Issue #12: a run whose state stops being finite (here a bead thrown at 1e200 m/s, whose
/// kinetic energy overflows) stops at once with an error that says what blew up, where and when,
/// and a non-zero exit; the frame written before it stays.
#[test]
fn a_run_that_blows_up_stops_and_says_why() {
    let scene = edit(
        "position = [0.0, 0.0, 0.006]\n",
        "position = [0.0, 0.0, 0.006]\nvelocity = [1.0e200, 0.0, 0.0]\n",
    )
    .replace(
        "output_interval = 0.0005\n",
        "output_interval = 0.0005\ntime_step = 1.0e-6\nforce_time_step = true\n",
    );
    let dir = tempfile::tempdir().unwrap();
    let (file, out) = (dir.path().join(SCENE), dir.path().join("out"));
    std::fs::write(&file, &scene).unwrap();
    let output = polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let stderr = text(&output.stderr);
    assert!(
        !output.status.success(),
        "exit 0 after a blow-up:\n{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    for expected in ["blew up", "body 0", "velocity", "t = ", SCENE] {
        assert!(
            stderr.contains(expected),
            "'{expected}' missing from:\n{stderr}"
        );
    }
    // The last frame holds the state at the blow-up, the non-finite velocity as it is; the
    // CSV series read back, their last row with the overflowed kinetic energy.
    let last = assert_last_frame_is_the_blow_up(&out, &stderr);
    let velocity = last.point_array("velocity").unwrap();
    assert!(!velocity.values[0].is_finite() || !velocity.values[0].powi(2).is_finite());
    let energy = polydem::io::csv_read::read_table(&out.join("energy.csv")).unwrap();
    let kinetic = energy.column("kinetic_translational").unwrap();
    assert!(!kinetic.last().unwrap().is_finite(), "{kinetic:?}");
}

/// Issue #12: a duration shorter than half a step ran a whole step; one of more steps than any run
/// can take saturated the step count and never ended. Both are refused, at the `duration` key.
#[test]
fn durations_out_of_reach_of_the_step_are_refused() {
    let forced = |duration: &str| {
        edit("duration = 0.002\n", &format!("duration = {duration}\n")).replace(
            "output_interval = 0.0005\n",
            "time_step = 1.0e-6\nforce_time_step = true\n",
        )
    };
    let short = forced("1.0e-7");
    refused(
        Some(&short),
        &[
            &at(&short, "duration ="),
            "duration",
            "shorter than half the time step",
        ],
    );
    let long = forced("1.0e9");
    refused(
        Some(&long),
        &[&at(&long, "duration ="), "duration", "1.000e15 steps"],
    );
}

/// `--set KEY=VALUE` and `--duration` change the scene as if the file said so, and are checked
/// like the file: a bad value names the key and the override, a bad key path the override.
#[test]
fn command_line_overrides_are_checked_like_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join(SCENE);
    std::fs::write(&file, BASE).unwrap();
    let check = |extra: &[&str]| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["check".as_ref(), file.as_os_str()];
        args.extend(extra.iter().map(std::ffi::OsStr::new));
        polydem(&args)
    };
    let out = accepted(&check(&[
        "--duration",
        "0.004",
        "--set",
        "simulation.output_interval=0.001",
    ]));
    assert!(out.contains("duration     0.004 s"), "{out}");
    assert!(out.contains("output every 0.001 s"), "{out}");

    let e = assert_refused(
        &check(&["--set", "material[0].restitution=1.5"]),
        &file,
        &["restitution", "[0, 1]", "--set material[0].restitution=1.5"],
    );
    assert!(e.contains(&at(BASE, "restitution")), "{e}");
    assert_refused(
        &check(&["--set", "material[1].friction=0.2"]),
        &file,
        &["--set material[1].friction=0.2", "no `material[1]`"],
    );
    let bad = check(&["--set", "simulation.duration"]);
    assert!(!bad.status.success());
    assert!(
        text(&bad.stderr).contains("KEY=VALUE"),
        "{}",
        text(&bad.stderr)
    );
}

/// `check` on a scene whose bodies arrive during the run says what will come, and estimates the
/// run time from a short trial.
#[test]
fn check_tells_the_bodies_to_come_and_an_estimated_run_time() {
    let dir = tempfile::tempdir().unwrap();
    let scene = plus(
        r#"
[[insert]]
method = "random"
material = "glass"
region_min = [-0.05, -0.05, 0.02]
region_max = [0.05, 0.05, 0.04]
count = 5
radius = 0.002
time = 0.0005
every = 0.0005
"#,
    );
    let out = checked(dir.path(), &scene);
    // From 0.5 ms every 0.5 ms to the end at 2 ms: 4 times, 20 bodies at most.
    assert!(
        out.contains("[[insert]] #1: 5 'sphere' bodies every 0.0005 s from 0.0005 s, 4 times: up to 20 bodies"),
        "{out}"
    );
    assert!(out.contains("estimate     roughly "), "{out}");
}

#[test]
fn wall_names_must_be_usable_as_column_heads_and_distinct() {
    let named = |name: &str| {
        edit(
            "material = \"glass\"\n\n[[particle]]",
            &format!("material = \"glass\"\nname = \"{name}\"\n\n[[particle]]"),
        )
    };
    refused(
        Some(&named("floor plate")),
        &["[[plane]] #1 name", "letters, digits"],
    );
    let two = format!(
        "{}\n[[plane]]\nname = \"floor\"\npoint = [0.0, 0.0, 1.0]\nnormal = [0.0, 0.0, -1.0]\nmaterial = \"glass\"\n",
        named("floor")
    );
    refused(
        Some(&two),
        &["[[plane]] #2 name", "two walls are called \"floor\""],
    );
}

/// A mesh wall pushes bodies out of the side its triangles face. One that faces away from the
/// bodies falling onto it would let them through or shoot them out (issue #12): refused, with
/// the way to turn it.
#[test]
fn mesh_walls_facing_away_from_the_bodies_are_refused() {
    // A closed box whose triangles face out (a solid block), with the bead inside it.
    let block = plus(
        "\n[[mesh_wall]]\nmaterial = \"glass\"\n\
         generator = { type = \"box\", min = [-0.1, -0.1, -0.1], max = [0.1, 0.1, 0.1], facing = \"outward\" }\n",
    );
    refused(
        Some(&block),
        &["[[particle]] #1", "back of [[mesh_wall]] #1", "facing"],
    );
    // The same box facing in (a container) holds it.
    let dir = tempfile::tempdir().unwrap();
    checked(dir.path(), &block.replace("\"outward\"", "\"inward\""));

    // A chute from a mesh file wound the wrong way, under the bead.
    let stl = dir.path().join("chute.stl");
    std::fs::write(
        &stl,
        "solid chute\n\
         facet normal 0 0 -1\n outer loop\n  vertex -0.1 -0.1 0.001\n  vertex -0.1 0.1 0.001\n  vertex 0.1 -0.1 0.001\n endloop\nendfacet\n\
         facet normal 0 0 -1\n outer loop\n  vertex 0.1 -0.1 0.001\n  vertex -0.1 0.1 0.001\n  vertex 0.1 0.1 0.001\n endloop\nendfacet\n\
         endsolid chute\n",
    )
    .unwrap();
    let chute = |flip: &str| {
        plus(&format!(
            "\n[[mesh_wall]]\nmaterial = \"glass\"\nfile = {:?}\n{flip}\n",
            stl.display().to_string()
        ))
    };
    refused(
        Some(&chute("")),
        &["back of [[mesh_wall]] #1", "flip = true"],
    );
    checked(dir.path(), &chute("flip = true"));
}

/// Beads dropped with a forced time step 30 times the stable one: every number stays finite, but
/// the energy grows a thousandfold within a few steps.
const GROWING_ENERGY: &str = r#"[simulation]
duration = 0.05
output_interval = 0.005
time_step = 6.0e-4
force_time_step = true

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

[[insert]]
method = "random"
seed = 1
material = "glass"
region_min = [-0.01, -0.01, 0.0]
region_max = [0.01, 0.01, 0.05]
count = 50
radius = 0.002
"#;

/// A forced time step 30 times the stable one: every number stays finite, but the energy grows
/// a thousandfold within a few steps. The energy watchdog stops the run and says why.
#[test]
fn a_run_whose_energy_grows_stops_and_says_why() {
    let scene = GROWING_ENERGY;
    let dir = tempfile::tempdir().unwrap();
    let (file, out) = (dir.path().join(SCENE), dir.path().join("out"));
    std::fs::write(&file, scene).unwrap();
    let output = polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    for expected in ["blew up", "energy ledger", "time step", SCENE] {
        assert!(
            stderr.contains(expected),
            "'{expected}' missing from:\n{stderr}"
        );
    }
    // Stopped early, not at the end.
    let pvd = std::fs::read_to_string(out.join("particles.pvd")).unwrap();
    assert!(pvd.matches("<DataSet").count() < 5, "{pvd}");
}

/// Values no physical DEM scene has (a mistyped exponent) are refused before they reach the time
/// step or the output writer.
#[test]
fn physically_impossible_values_are_refused() {
    refused(
        Some(&edit("youngs_modulus = 5.0e9", "youngs_modulus = 1e-320")),
        &[
            "[[material]] #1 youngs_modulus",
            "outside any physical range",
        ],
    );
    refused(
        Some(&edit("density = 2500.0", "density = 1e-300")),
        &["[[material]] #1 density", "outside any physical range"],
    );
    refused(
        Some(&edit("radius = 0.005", "radius = 1e-30")),
        &["[[particle]] #1 radius", "outside any physical range"],
    );
}

/// Counts of generated shapes and walls that would exhaust memory are refused with the key.
#[test]
fn absurd_generator_counts_are_refused() {
    let prism = plus(
        "\n[shape.prism]\ntype = \"prism\"\nsides = 1000000000\ncircumradius = 0.01\nheight = 0.01\n",
    );
    refused(Some(&prism), &["[shape.prism] sides", "10000"]);
    let drum = plus(
        "\n[[mesh_wall]]\nmaterial = \"glass\"\n\
         generator = { type = \"cylinder\", radius = 0.5, height = 0.1, segments = 1000000000 }\n",
    );
    refused(
        Some(&drum),
        &["[[mesh_wall]] #1 generator.segments", "100000"],
    );
}

/// `--threads 100000` is refused instead of trying to start them all.
#[test]
fn absurd_thread_counts_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (file, out) = (dir.path().join(SCENE), dir.path().join("out"));
    std::fs::write(&file, BASE).unwrap();
    let run = polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--threads".as_ref(),
        "100000".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert_refused(&run, &file, &["[simulation] threads", "100000 threads"]);
    assert!(!out.exists());
}

/// A scene file with a byte that is not UTF-8 is located to its line and column.
#[test]
fn a_byte_that_is_not_utf8_is_located() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join(SCENE);
    let mut bytes = BASE.as_bytes().to_vec();
    let at = BASE.find("glass").unwrap() + 2;
    bytes[at] = 0xe4;
    std::fs::write(&file, &bytes).unwrap();
    let line = BASE[..at].matches('\n').count() + 1;
    let output = polydem(&["check".as_ref(), file.as_os_str()]);
    assert_refused(
        &output,
        &file,
        &[&format!("{SCENE}:{line}:11:"), "byte 0xe4", "UTF-8"],
    );
}

/// `watchdog = "warn"`: an expert who knows why the energy grows gets the warning once and the
/// run goes on to its end.
#[test]
fn the_watchdog_can_be_told_to_warn() {
    let scene = &GROWING_ENERGY
        .replace("duration = 0.05", "duration = 0.02")
        .replace(
            "force_time_step = true\n",
            "force_time_step = true\nwatchdog = \"warn\"\n",
        );
    let dir = tempfile::tempdir().unwrap();
    let (file, out) = (dir.path().join(SCENE), dir.path().join("out"));
    std::fs::write(&file, scene).unwrap();
    let output = polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let stderr = text(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert_eq!(stderr.matches("watchdog = \"warn\"").count(), 1, "{stderr}");
}

/// A bead in a closed mesh box, no gravity, thrown at a wall with a forced time step so long
/// that it jumps through the wall between two steps: it never touches it, so its energy and
/// speed stay what they were, and only the check for bodies behind closed walls sees it.
const THROUGH_THE_WALL: &str = r#"[simulation]
duration = 0.02
output_interval = 0.004
time_step = 2.0e-3
force_time_step = true
gravity = [0.0, 0.0, 0.0]

[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e9
poisson_ratio = 0.25
restitution = 0.8
friction = 0.3

[[mesh_wall]]
name = "box"
material = "glass"
generator = { type = "box", min = [-0.05, -0.05, -0.05], max = [0.05, 0.05, 0.05], facing = "inward" }

[[particle]]
radius = 0.005
material = "glass"
position = [0.0, 0.0, 0.0]
velocity = [20.0, 0.0, 0.0]
"#;

/// Runs `scene` in a fresh folder; returns the output, the folder (kept alive) and the output
/// folder.
fn run_in_folder(scene: &str) -> (Output, tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let (file, out) = (dir.path().join(SCENE), dir.path().join("out"));
    std::fs::write(&file, scene).unwrap();
    let output = polydem(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    (output, dir, out)
}

/// The frames of the particles series, read back, with their times and states.
fn particle_frames(out: &Path) -> Vec<polydem::io::vtk_read::PolyData> {
    let pvd = polydem::io::vtk_read::read_pvd(&out.join("particles.pvd")).unwrap();
    pvd.iter()
        .map(|e| polydem::io::vtk_read::read_vtp(&e.file).unwrap())
        .collect()
}

/// Every series of a run stopped by the watchdog ends with one frame marked as the state at the
/// blow-up, at the time of the last CSV row; the frames before it are regular (unmarked) and
/// every file reads back.
fn assert_last_frame_is_the_blow_up(out: &Path, stderr: &str) -> polydem::io::vtk_read::PolyData {
    let frames = particle_frames(out);
    let (last, before) = frames.split_last().expect("frames");
    assert!(!before.is_empty(), "the first frame is gone");
    assert!(
        before.iter().all(|f| f.state.is_none()),
        "a regular frame marked"
    );
    let state = last.state.as_deref().expect("the last frame is marked");
    assert!(
        state.starts_with("blow-up: the run blew up at t = "),
        "{state}"
    );
    let walls = polydem::io::vtk_read::read_pvd(&out.join("walls.pvd")).unwrap();
    let last_walls = polydem::io::vtk_read::read_vtp(&walls.last().unwrap().file).unwrap();
    assert_eq!(last_walls.state.as_deref(), Some(state));
    assert_eq!(walls.len(), frames.len());
    let pvd = std::fs::read_to_string(out.join("particles.pvd")).unwrap();
    assert!(pvd.contains("<!-- blow-up: "), "{pvd}");
    // The terminal names the file.
    let name = format!("particles_{:06}.vtp", frames.len() - 1);
    assert!(stderr.contains(&name), "'{name}' missing from:\n{stderr}");
    let energy = polydem::io::csv_read::read_table(&out.join("energy.csv")).unwrap();
    let times = energy.column("time").unwrap();
    assert_eq!(
        times.last().copied(),
        last.time,
        "the last row is at the blow-up"
    );
    last.clone()
}

/// Issue #12: a body found behind a closed mesh wall stops the run, naming the wall, the body,
/// where and when, with the likely causes; the last frame is the state at the blow-up.
#[test]
fn a_body_that_went_through_a_closed_wall_stops_the_run() {
    let (output, _dir, out) = run_in_folder(THROUGH_THE_WALL);
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for expected in [
        "blew up",
        "body 0",
        "behind [[mesh_wall]] #1 (\"box\"",
        "outside the closed container",
        "gone through the wall",
        "time step above the stable one",
        "t = 4.000000e-3 s",
        SCENE,
    ] {
        assert!(
            stderr.contains(expected),
            "'{expected}' missing from:\n{stderr}"
        );
    }
    let last = assert_last_frame_is_the_blow_up(&out, &stderr);
    // The bead is where the message says: behind the wall at x = 0.05.
    assert!(last.points[0].x > 0.05, "{:?}", last.points);

    // Told to warn, the run goes on to its end, saying it once.
    let (output, _dir, _) = run_in_folder(&THROUGH_THE_WALL.replace(
        "force_time_step = true\n",
        "force_time_step = true\nwatchdog = \"warn\"\n",
    ));
    let stderr = text(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert_eq!(
        stderr.matches("behind [[mesh_wall]]").count(),
        1,
        "{stderr}"
    );
}

/// A bead bouncing in a closed box, as a sound run: the check for bodies behind walls stays
/// silent.
#[test]
fn a_bead_bouncing_in_a_closed_box_runs_to_its_end() {
    let scene = THROUGH_THE_WALL
        .replace("time_step = 2.0e-3\nforce_time_step = true\n", "")
        .replace("duration = 0.02", "duration = 0.01")
        .replace("output_interval = 0.004", "output_interval = 0.0005")
        .replace("gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0, -9.81]")
        .replace(
            "position = [0.0, 0.0, 0.0]",
            "position = [0.04, 0.0, -0.04]",
        )
        .replace("velocity = [20.0, 0.0, 0.0]", "velocity = [2.0, 0.0, -2.0]");
    let (output, _dir, out) = run_in_folder(&scene);
    let stderr = text(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("behind"), "{stderr}");
    let frames = particle_frames(&out);
    assert_eq!(frames.len(), 21);
    assert!(frames.iter().all(|f| f.state.is_none()));
    // It did hit the walls (and came back).
    let x = frames.last().unwrap().points[0].x;
    assert!(x.abs() < 0.045, "{x}");
}

/// Regression test of issue #12: a particle placed outside a closed inward-facing mesh box (or
/// inside a solid block) was accepted, where a plane refuses the same. Now the start is refused,
/// naming the particle's line, the wall and the side; the same bead inside the box is accepted.
#[test]
fn a_particle_outside_a_closed_container_is_refused() {
    let outside =
        THROUGH_THE_WALL.replace("position = [0.0, 0.0, 0.0]", "position = [0.2, 0.0, 0.0]");
    refused(
        Some(&outside),
        &[
            &at(&outside, "[[particle]]"),
            "lies behind [[mesh_wall]] #1",
            "outside the closed container it forms",
        ],
    );
    let block = THROUGH_THE_WALL.replace("facing = \"inward\"", "facing = \"outward\"");
    refused(
        Some(&block),
        &[
            "lies behind [[mesh_wall]] #1",
            "inside the solid its triangles enclose",
        ],
    );
    let dir = tempfile::tempdir().unwrap();
    assert!(checked(dir.path(), THROUGH_THE_WALL).contains("scene is valid"));
}

/// Under `mpirun -np 2` each process of a build without the `mpi` feature would run the whole
/// scene and write the same files over each other's: such a run is refused, saying why and what
/// to do, and writes nothing. One rank is an ordinary run. (Built with `mpi`, the run goes on
/// ranks: `.ci/mpi`.)
#[test]
#[cfg(not(feature = "mpi"))]
fn a_run_started_by_mpirun_on_several_ranks_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join(SCENE);
    std::fs::write(&scene, BASE).unwrap();
    let out = dir.path().join("out");
    let launched = |variable: &str, ranks: &str| {
        Command::new(env!("CARGO_BIN_EXE_polydem"))
            .args([
                "run".as_ref(),
                scene.as_os_str(),
                "--out".as_ref(),
                out.as_os_str(),
            ])
            .env(variable, ranks)
            .output()
            .expect("the polydem binary starts")
    };
    for variable in ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"] {
        let output = launched(variable, "2");
        assert!(!output.status.success());
        let message = text(&output.stderr);
        for expected in [
            "one of 2 processes",
            "several MPI ranks",
            "--features mpi",
            "without mpirun",
            "--threads",
        ] {
            assert!(message.contains(expected), "{variable}: {message}");
        }
        assert!(!out.exists(), "a refused run wrote {}", out.display());
    }
    accepted(&launched("OMPI_COMM_WORLD_SIZE", "1"));
}
