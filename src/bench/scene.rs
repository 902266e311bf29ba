//! Whole-scene benchmark: a scene file stepped a fixed number of steps with no output, timing only
//! a window at the end (the settled bed), for the side-by-side comparison with other DEM codes in
//! `scripts/bench_peers.sh`.
//!
//! "Contacts per particle" is defined as in the peer scripts (`bench/peers/`): 2 × the number of
//! touching body–body pairs / the number of bodies. Contacts with walls are counted apart.

use crate::math::DVec3;
use crate::scene::Scene;
use crate::shape::Shape;
use crate::World;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// What one benchmark run measured.
#[derive(Clone, Debug)]
pub struct SceneTiming {
    /// The scene file's name without its extension.
    pub name: String,
    /// Threads per rank, and MPI ranks (1: one process).
    pub threads: usize,
    pub ranks: usize,
    pub bodies: usize,
    /// Untimed steps taken before `steps`, after which the bodies were stopped (see [`settle`]).
    pub settle_steps: u64,
    /// Steps taken after settling, and the step the timed window starts at (it ends at `steps`).
    pub steps: u64,
    pub window_start: u64,
    /// Wall-clock time of the window [s].
    pub seconds: f64,
    /// Wall-clock time of everything before the window: building the scene and the first
    /// `window_start` steps [s].
    pub seconds_before_window: f64,
    /// Contacts at the end.
    pub contacts: ContactCounts,
    /// Peak resident memory of the process (VmHWM) [bytes], where the system reports it.
    pub peak_rss_bytes: Option<u64>,
}

impl SceneTiming {
    /// Bodies × window steps / window seconds.
    pub fn particle_steps_per_second(&self) -> f64 {
        let steps = (self.steps - self.window_start) as f64;
        self.bodies as f64 * steps / self.seconds.max(1e-12)
    }

    /// 2 × body–body contacts / bodies.
    pub fn contacts_per_particle(&self) -> f64 {
        2.0 * self.contacts.body_body as f64 / (self.bodies.max(1) as f64)
    }

    /// The one machine-readable line `polydem bench scene` prints: `key=value` fields separated
    /// by spaces, after the code's name and the scene's.
    pub fn line(&self) -> String {
        let rss = match self.peak_rss_bytes {
            Some(bytes) => format!(
                " peak_rss_bytes={bytes} rss_bytes_per_body={:.0}",
                bytes as f64 / self.bodies.max(1) as f64
            ),
            None => String::new(),
        };
        let settle = match self.settle_steps {
            0 => String::new(),
            n => format!(" settle={n}"),
        };
        let ranks = match self.ranks {
            1 => String::new(),
            n => format!(" ranks={n}"),
        };
        format!(
            "polydem {} threads={}{ranks} bodies={}{settle} window={}..{} seconds={:.3} \
             particle_steps_per_s={:.3e} contacts_per_particle={:.3} wall_contacts={}{rss}",
            self.name,
            self.threads,
            self.bodies,
            self.window_start,
            self.steps,
            self.seconds,
            self.particle_steps_per_second(),
            self.contacts_per_particle(),
            self.contacts.body_wall,
        )
    }
}

/// Touching pairs at one moment, each counted once (a pair touching in several regions, as
/// non-convex bodies can, counts once).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContactCounts {
    /// Pairs of bodies in contact.
    pub body_body: usize,
    /// Pairs of a body and a wall (plane or mesh wall) in contact.
    pub body_wall: usize,
}

/// Counts the world's current contacts (in a share of a decomposed world, those its owned bodies
/// count: see `Bodies::ghost`). The one place the benchmark reads the contact lists.
pub fn contact_counts(world: &World) -> ContactCounts {
    use crate::contact::ContactRef;
    fn pairs<'a>(contacts: impl Iterator<Item = ContactRef<'a>>) -> usize {
        // The store is sorted by (a, partner, region), so a pair's contacts are adjacent.
        let mut previous = None;
        contacts
            .map(|c| (c.key.a, c.key.partner))
            .filter(|&k| previous.replace(k) != Some(k))
            .count()
    }
    let contacts = world.contacts();
    let counted = |c: &ContactRef| world.bodies().counts(c.key.a as usize);
    ContactCounts {
        body_body: pairs(contacts.between_bodies().filter(counted)),
        body_wall: pairs(
            contacts
                .iter()
                .filter(|c| c.key.partner.is_wall() && counted(c)),
        ),
    }
}

/// Translational plus rotational kinetic energy of the bodies [J]: near zero once settled.
pub(super) fn kinetic_energy(world: &World) -> f64 {
    let e = world.energy();
    e.kinetic_translational + e.kinetic_rotational
}

/// Peak resident set size of this process (`VmHWM` in `/proc/self/status`) [bytes]; `None`
/// where there is no such file (not Linux).
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kilobytes: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kilobytes * 1024)
}

/// Loads `file` as `polydem run` does, with the threads overridden if asked; refuses scenes that
/// insert bodies during the run.
pub(super) fn load(file: &Path, threads: Option<usize>) -> Result<World, String> {
    let mut scene = Scene::load(file).map_err(|e| e.to_string())?;
    if let Some(threads) = threads {
        scene.spec.simulation.threads = threads;
    }
    let prepared = scene.build().map_err(|e| e.to_string())?;
    if !prepared.schedule.is_empty() {
        return Err(format!(
            "'{}' inserts bodies during the run; a benchmark scene must place all its bodies at \
             the start (insertions with time = 0 and no `every`)",
            file.display()
        ));
    }
    Ok(prepared.world)
}

/// Refuses an empty timing window.
pub(super) fn check_window(steps: u64, window_start: u64) -> Result<(), String> {
    if window_start >= steps {
        return Err(format!(
            "the window must not be empty: --window-start {window_start} must be below --steps {steps}"
        ));
    }
    Ok(())
}

/// The scene file's name without its extension.
pub(super) fn scene_name(file: &Path) -> String {
    file.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Takes `steps` steps, then stops every body (zero velocity and spin), if `steps` > 0: a bed
/// settled this way is the state handed to the peer codes at rest (`polydem bench initial
/// --settle-steps`), and polydem continues from the same state. The contact histories are kept.
/// Runs are deterministic whatever the thread count, so every run settles to the same state.
pub fn settle(world: &mut World, steps: u64) {
    if steps == 0 {
        return;
    }
    world.run_steps(steps);
    let b = world.bodies_mut();
    for v in [
        &mut b.velocity,
        &mut b.angular_momentum,
        &mut b.angular_velocity,
    ] {
        v.iter_mut().for_each(|v| *v = DVec3::ZERO);
    }
}

/// Loads `file` as `polydem run` does, overrides the threads if asked, settles it for
/// `settle_steps` (see [`settle`]), then takes `steps` steps without writing anything and times
/// steps `window_start..steps`. The scene's `duration` and output settings are ignored.
/// `progress` is told what happens before the window.
pub fn run(
    file: &Path,
    settle_steps: u64,
    steps: u64,
    window_start: u64,
    threads: Option<usize>,
    mut progress: impl FnMut(&str),
) -> Result<SceneTiming, String> {
    check_window(steps, window_start)?;
    let start = Instant::now();
    let mut world = load(file, threads)?;
    let world = &mut world;
    progress(&format!(
        "built {} bodies in {:.2} s; time step {:.3e} s, {} threads",
        world.bodies().len(),
        start.elapsed().as_secs_f64(),
        world.time_step(),
        world.threads()
    ));
    if settle_steps > 0 {
        settle(world, settle_steps);
        progress(&format!(
            "settled {settle_steps} steps after {:.2} s; bodies stopped",
            start.elapsed().as_secs_f64()
        ));
    }
    world.run_steps(window_start);
    let seconds_before_window = start.elapsed().as_secs_f64();
    let counts = contact_counts(world);
    progress(&format!(
        "step {window_start} after {seconds_before_window:.2} s: {} body-body contacts, {} wall \
         contacts ({} candidates), kinetic energy {:.4e} J",
        counts.body_body,
        counts.body_wall,
        world.contacts().entries(),
        kinetic_energy(world)
    ));
    let window = Instant::now();
    let before = *world.stage_times();
    let rebuilds_before = world.pair_rebuilds();
    world.run_steps(steps - window_start);
    let seconds = window.elapsed().as_secs_f64();
    let after = *world.stage_times();
    let in_window = crate::step::StageTimes {
        integrate: after.integrate - before.integrate,
        candidates: after.candidates - before.candidates,
        regions: after.regions - before.regions,
        detect_and_evaluate: after.detect_and_evaluate - before.detect_and_evaluate,
        accumulate: after.accumulate - before.accumulate,
        other: after.other - before.other,
    };
    progress(&format!(
        "step {steps}: kinetic energy {:.4e} J; window by stage: {}; candidate list made {} \
         times",
        kinetic_energy(world),
        in_window.summary(),
        world.pair_rebuilds() - rebuilds_before
    ));
    Ok(SceneTiming {
        name: scene_name(file),
        threads: world.threads(),
        ranks: 1,
        bodies: world.bodies().len(),
        settle_steps,
        steps,
        window_start,
        seconds,
        seconds_before_window,
        contacts: contact_counts(world),
        peak_rss_bytes: peak_rss_bytes(),
    })
}

/// Builds `file`, settles it for `settle_steps` (see [`settle`]; 0: the bodies as placed) and
/// writes its bodies (see [`write_bodies`]), so that the peer codes start from the very state
/// `run` with the same `settle_steps` times from. Returns how many bodies were written.
pub fn write_initial_bodies(
    file: &Path,
    settle_steps: u64,
    threads: Option<usize>,
    out: &Path,
) -> Result<usize, String> {
    let mut world = load(file, threads)?;
    settle(&mut world, settle_steps);
    let write = |out: &Path| -> std::io::Result<()> {
        let mut w = std::io::BufWriter::new(std::fs::File::create(out)?);
        write_bodies(&world, &mut w)?;
        w.flush()
    };
    write(out).map_err(|e| format!("writing '{}': {e}", out.display()))?;
    Ok(world.bodies().len())
}

/// Writes the world's plane walls, mesh walls and bodies, one line each, space-separated, in SI
/// units:
///
/// - `plane x y z nx ny nz`: a point of the plane and its unit normal (pointing to the bodies)
/// - `triangle wall ax ay az bx by bz cx cy cz`: a triangle of mesh wall `wall` (numbered from 0)
///   where it is now, counter-clockwise seen from the bodies
/// - `sphere x y z radius density`
/// - `polyhedron x y z density n x1 y1 z1 … xn yn zn`: the centre of mass, the mass density, then
///   the n corners in world coordinates (the body is their convex hull).
///
/// Lines starting with `#` are comments. Velocities are not written: the bodies are to start at
/// rest. Non-convex bodies are refused, and so are moving mesh walls (a peer would need their
/// motion too).
pub fn write_bodies(world: &World, out: &mut impl Write) -> std::io::Result<()> {
    let b = world.bodies();
    writeln!(
        out,
        "# polydem bodies: {} bodies, {} planes, {} mesh walls (SI units)",
        b.len(),
        world.planes().len(),
        world.mesh_walls().len()
    )?;
    writeln!(
        out,
        "# plane x y z nx ny nz (a point and the normal towards the bodies)"
    )?;
    writeln!(
        out,
        "# triangle wall ax ay az bx by bz cx cy cz (counter-clockwise seen from the bodies)"
    )?;
    writeln!(out, "# sphere x y z radius density")?;
    writeln!(
        out,
        "# polyhedron x y z density n x1 y1 z1 ... (centre of mass, n corners in world coordinates)"
    )?;
    for p in world.planes() {
        let (x, n) = (p.point, p.normal);
        writeln!(out, "plane {} {} {} {} {} {}", x.x, x.y, x.z, n.x, n.y, n.z)?;
    }
    for (w, wall) in world.mesh_walls().iter().enumerate() {
        if !wall.motion.is_fixed() {
            return Err(std::io::Error::other(format!(
                "mesh wall {w} moves: only fixed mesh walls can be written"
            )));
        }
        let pose = wall.pose();
        for t in 0..wall.triangles().len() {
            write!(out, "triangle {w}")?;
            for corner in wall.corners(t as u32) {
                let v = pose.to_world(corner);
                write!(out, " {} {} {}", v.x, v.y, v.z)?;
            }
            writeln!(out)?;
        }
    }
    for i in 0..b.len() {
        let x = b.position[i];
        let density = world.materials()[b.material[i] as usize].density;
        match &world.shapes()[b.shape[i] as usize] {
            Shape::Sphere(s) => {
                writeln!(out, "sphere {} {} {} {} {density}", x.x, x.y, x.z, s.radius)?
            }
            Shape::Convex(p) => {
                let n = p.vertices().len();
                write!(out, "polyhedron {} {} {} {density} {n}", x.x, x.y, x.z)?;
                for v in p.vertices() {
                    let v = x + b.orientation[i] * *v;
                    write!(out, " {} {} {}", v.x, v.y, v.z)?;
                }
                writeln!(out)?;
            }
            Shape::NonConvex(_) => {
                return Err(std::io::Error::other(format!(
                    "body {} is non-convex: only spheres and convex polyhedra can be written",
                    b.id[i]
                )))
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The step and the material of the test scenes.
    const HEADER: &str = r#"
[simulation]
time_step = 1.0e-6
duration = 1.0e-3

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5
"#;

    /// Two spheres pressed slightly together on a floor, and a cube resting on the floor apart.
    const BODIES: &str = r#"
[shape.cube]
type = "box"
edges = [0.01, 0.01, 0.01]

[[plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
material = "m"

[[particle]]
radius = 0.001
material = "m"
position = [0.0, 0.0, 0.000999]

[[particle]]
radius = 0.001
material = "m"
position = [0.001999, 0.0, 0.000999]

[[particle]]
shape = "cube"
material = "m"
position = [0.05, 0.0, 0.004999]
"#;

    fn scene_file(dir: &tempfile::TempDir) -> std::path::PathBuf {
        let file = dir.path().join("three.toml");
        std::fs::write(&file, format!("{HEADER}{BODIES}")).unwrap();
        file
    }

    #[test]
    fn counts_each_touching_pair_once() {
        let dir = tempfile::tempdir().unwrap();
        let mut prepared = Scene::load(&scene_file(&dir)).unwrap().build().unwrap();
        prepared.world.run_steps(2);
        let counts = contact_counts(&prepared.world);
        assert_eq!(counts.body_body, 1);
        // Each sphere touches the floor, and the cube's face touches it (once, however many
        // regions or corners).
        assert_eq!(counts.body_wall, 3);
    }

    #[test]
    fn times_the_window_and_prints_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let mut notes = Vec::new();
        let t = run(&scene_file(&dir), 0, 20, 10, Some(1), |n| {
            notes.push(n.to_string())
        })
        .unwrap();
        assert_eq!((t.name.as_str(), t.bodies, t.threads), ("three", 3, 1));
        assert_eq!((t.window_start, t.steps), (10, 20));
        assert!(t.seconds > 0.0 && t.particle_steps_per_second() > 0.0);
        assert!((t.contacts_per_particle() - 2.0 / 3.0).abs() < 1e-12);
        let line = t.line();
        assert!(line.starts_with("polydem three threads=1 bodies=3 window=10..20 "));
        assert!(line.contains(" contacts_per_particle=0.667 wall_contacts=3"));
        assert_eq!(notes.len(), 3);
        let empty = run(&scene_file(&dir), 0, 10, 10, None, |_| {});
        assert!(empty.unwrap_err().contains("must be below --steps"));
    }

    /// A sphere over a floor given as a mesh wall of two triangles (`motion`: the wall's, if any).
    fn mesh_floor_scene(dir: &tempfile::TempDir, motion: &str) -> std::path::PathBuf {
        let file = dir.path().join("floor.toml");
        let text = format!(
            r#"{HEADER}
[[mesh_wall]]
material = "m"
generator = {{ type = "rectangle", origin = [-0.01, -0.02, 0.0], u = [0.03, 0.0, 0.0], v = [0.0, 0.04, 0.0] }}
{motion}

[[particle]]
radius = 0.001
material = "m"
position = [0.0, 0.0, 0.002]
"#
        );
        std::fs::write(&file, text).unwrap();
        file
    }

    #[test]
    fn writes_a_fixed_mesh_wall_as_triangles_facing_the_bodies() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("floor.bodies");
        let scene = mesh_floor_scene(&dir, "");
        assert_eq!(write_initial_bodies(&scene, 0, None, &out).unwrap(), 1);
        let text = std::fs::read_to_string(&out).unwrap();
        let triangles: Vec<Vec<f64>> = text
            .lines()
            .filter(|l| l.starts_with("triangle "))
            .map(|l| {
                l.split_whitespace()
                    .skip(1)
                    .map(|v| v.parse().unwrap())
                    .collect()
            })
            .collect();
        assert_eq!(triangles.len(), 2);
        let mut area = 0.0;
        for t in &triangles {
            assert_eq!((t.len(), t[0]), (10, 0.0));
            let corner = |k: usize| DVec3::new(t[1 + 3 * k], t[2 + 3 * k], t[3 + 3 * k]);
            let (a, b, c) = (corner(0), corner(1), corner(2));
            assert!([a, b, c].iter().all(|p| p.z == 0.0));
            // Counter-clockwise seen from the sphere above: the normal points up.
            let n = (b - a).cross(c - a);
            assert!(n.z > 0.0, "{t:?}");
            area += 0.5 * n.length();
        }
        assert!((area - 0.03 * 0.04).abs() < 1e-15, "{area}");
        assert!(text.lines().any(|l| l.starts_with("sphere ")));

        let moving = mesh_floor_scene(&dir, "motion = { velocity = [0.0, 0.0, 0.1] }");
        let e = write_initial_bodies(&moving, 0, None, &out).unwrap_err();
        assert!(e.contains("mesh wall 0 moves"), "{e}");
    }

    #[test]
    fn writes_planes_spheres_and_polyhedron_corners() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("three.bodies");
        assert_eq!(
            write_initial_bodies(&scene_file(&dir), 0, None, &out).unwrap(),
            3
        );
        let text = std::fs::read_to_string(&out).unwrap();
        let lines: Vec<Vec<&str>> = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.split_whitespace().collect())
            .collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[0], ["plane", "0", "0", "0", "0", "0", "1"]);
        assert_eq!(lines[1], ["sphere", "0", "0", "0.000999", "0.001", "2500"]);
        assert_eq!(lines[2][0], "sphere");
        let cube = &lines[3];
        assert_eq!(cube[0], "polyhedron");
        assert_eq!(&cube[4..6], ["2500", "8"]);
        let numbers: Vec<f64> = cube[1..].iter().map(|v| v.parse().unwrap()).collect();
        let centre = DVec3::new(numbers[0], numbers[1], numbers[2]);
        assert!((centre - DVec3::new(0.05, 0.0, 0.004999)).length() < 1e-12);
        assert_eq!(numbers.len(), 5 + 3 * 8);
        for corner in numbers[5..].chunks(3) {
            let d = DVec3::new(corner[0], corner[1], corner[2]) - centre;
            // Axis-aligned: every corner is 5 mm from the centre along each axis.
            for c in d.to_array() {
                assert!((c.abs() - 0.005).abs() < 1e-12, "{d}");
            }
        }
    }
}
