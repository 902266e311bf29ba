//! `polydem render` and `polydem plot` (issue #15): a known scene gives the expected pixels, a
//! turned cube turns its silhouette, broken files are named, and a short run renders and plots.

use std::path::Path;
use std::process::Command;

use polydem::io::vtk::{write_force_network, BodyFields, ForceNetwork};
use polydem::io::{write_particles, write_polygons, ParticleFrame, PolygonMesh, PvdSeries};
use polydem::math::{DQuat, DVec3};
use polydem::picture::camera::View;
use polydem::picture::render::{render_run, render_snapshot, scene_box, Picture, RenderOptions};
use polydem::picture::run_files::{FrameChoice, RunFiles};

const SPHERE: DVec3 = DVec3::new(-1.0, 0.0, 0.0);
const CUBE: DVec3 = DVec3::new(1.0, 0.0, 0.0);

/// A unit cube's corners and outward faces, turned by `q` and moved to `centre`.
fn cube(centre: DVec3, q: DQuat, id: u32) -> PolygonMesh {
    let vertices = (0..8)
        .map(|k| {
            let corner = DVec3::new(
                if k & 1 == 0 { -0.5 } else { 0.5 },
                if k & 2 == 0 { -0.5 } else { 0.5 },
                if k & 4 == 0 { -0.5 } else { 0.5 },
            );
            centre + q * corner
        })
        .collect();
    let polygons = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    PolygonMesh {
        vertices,
        cell_ids: vec![id; 6],
        polygons,
    }
}

/// Writes a run folder of one frame: a sphere (id 0, radius 0.5) at `SPHERE` when `sphere`, a
/// cube (id 1) at `CUBE` turned by `q`, and a floor square at z = −0.6.
fn write_scene(dir: &Path, q: DQuat, sphere: bool) {
    let mut ids = vec![1u64];
    let mut positions = vec![CUBE];
    let mut radii = vec![0.75f64.sqrt()];
    if sphere {
        ids.insert(0, 0);
        positions.insert(0, SPHERE);
        radii.insert(0, 0.5);
    }
    let n = ids.len();
    let zeros = vec![DVec3::ZERO; n];
    let velocities: Vec<DVec3> = (0..n).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
    let speeds: Vec<f64> = velocities.iter().map(|v| v.length()).collect();
    let materials: Vec<u32> = ids.iter().map(|&id| id as u32).collect();
    let counts = vec![0u32; n];
    let frame = ParticleFrame {
        ids: &ids,
        positions: &positions,
        radii: &radii,
        orientations: &vec![q; n],
        fields: BodyFields {
            velocities: &velocities,
            speeds: &speeds,
            angular_velocities: &zeros,
            forces: &zeros,
            torques: &zeros,
            coordination: &counts,
            wall_contacts: &counts,
            materials: &materials,
            shapes: &materials,
        },
    };
    let time = 0.25;
    write_particles(&dir.join("particles_000000.vtp"), &frame, time).unwrap();
    PvdSeries::new(dir.join("particles.pvd"))
        .add(time, "particles_000000.vtp", 0)
        .unwrap();
    write_polygons(
        &dir.join("polyhedra_000000.vtp"),
        &cube(CUBE, q, 1),
        "id",
        time,
    )
    .unwrap();
    PvdSeries::new(dir.join("polyhedra.pvd"))
        .add(time, "polyhedra_000000.vtp", 0)
        .unwrap();
    let floor = PolygonMesh {
        vertices: vec![
            DVec3::new(-2.5, -2.5, -0.6),
            DVec3::new(2.5, -2.5, -0.6),
            DVec3::new(2.5, 2.5, -0.6),
            DVec3::new(-2.5, 2.5, -0.6),
        ],
        polygons: vec![vec![0, 1, 2, 3]],
        cell_ids: vec![0],
    };
    write_polygons(&dir.join("walls_000000.vtp"), &floor, "wall", time).unwrap();
    PvdSeries::new(dir.join("walls.pvd"))
        .add(time, "walls_000000.vtp", 0)
        .unwrap();
}

fn render(dir: &Path, options: &RenderOptions) -> Picture {
    let run = RunFiles::open(dir).unwrap();
    let snap = run.load(0, options.force_network).unwrap();
    render_snapshot("test", &snap, options).unwrap()
}

fn pixel_at(p: &Picture, world: DVec3) -> [u8; 3] {
    let s = p.camera.project(world);
    p.pixel(s.x as usize, s.y as usize)
}

#[test]
fn a_sphere_a_cube_and_a_floor_are_where_and_how_they_should_be() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path(), DQuat::IDENTITY, true);
    let options = RenderOptions {
        colour: "id".into(),
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let p = render(dir.path(), &options);
    assert_eq!((p.width, p.height, p.rgb.len()), (400, 300, 400 * 300 * 3));

    // Coloured by id over 0..1: the sphere (id 0) blue, the cube (id 1) red.
    let [r, g, b] = pixel_at(&p, SPHERE);
    assert!(b > r + 60 && b > g, "sphere centre {r} {g} {b}");
    // The cube's centre is hidden behind its front faces: those faces are what shows there.
    let [r, g, b] = pixel_at(&p, CUBE);
    assert!(r > b + 60 && r > g, "cube centre {r} {g} {b}");
    // The floor in front of both: a light, tinted grey (semi-transparent over white).
    let [r, g, b] = pixel_at(&p, DVec3::new(0.0, -2.0, -0.6));
    assert!(
        r < 245 && r > 150 && r.abs_diff(g) < 30 && g.abs_diff(b) < 30,
        "floor {r} {g} {b}"
    );
    // Far off the floor, above the sphere: the white background.
    assert_eq!(pixel_at(&p, DVec3::new(-1.0, 0.0, 2.0)), [255; 3]);

    // A shaded picture, neither blank nor uniform.
    let distinct: std::collections::HashSet<[u8; 3]> = (0..p.height)
        .flat_map(|y| (0..p.width).map(move |x| (x, y)))
        .map(|(x, y)| p.pixel(x, y))
        .collect();
    assert!(distinct.len() > 200, "{} colours", distinct.len());
}

/// Width in pixels of what is not background on the picture row through `world`.
fn silhouette_width(p: &Picture, world: DVec3) -> usize {
    let y = p.camera.project(world).y as usize;
    let x0 = p.camera.project(world - DVec3::new(1.0, 0.0, 0.0)).x as usize;
    let x1 = p.camera.project(world + DVec3::new(1.0, 0.0, 0.0)).x as usize;
    (x0..x1).filter(|&x| p.pixel(x, y) != [255; 3]).count()
}

#[test]
fn the_cube_silhouette_turns_with_its_orientation() {
    let options = RenderOptions {
        view: View::Front,
        colour: "id".into(),
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let straight = tempfile::tempdir().unwrap();
    write_scene(straight.path(), DQuat::IDENTITY, false);
    let turned = tempfile::tempdir().unwrap();
    write_scene(
        turned.path(),
        DQuat::from_rotation_z(std::f64::consts::FRAC_PI_4),
        false,
    );
    let a = render(straight.path(), &options);
    let b = render(turned.path(), &options);
    // The camera is fitted to the bounding sphere, which does not turn: same camera.
    assert_eq!(a.camera, b.camera);
    let wa = silhouette_width(&a, CUBE) as f64;
    let wb = silhouette_width(&b, CUBE) as f64;
    // Seen from the front, a cube turned 45° about the vertical is √2 times as wide.
    assert!(
        (wa - a.camera.scale()).abs() <= 2.0,
        "{wa} px for 1 m at {}",
        a.camera.scale()
    );
    assert!((wb / wa - 2f64.sqrt()).abs() < 0.05, "{wa} → {wb}");
    let differing = a
        .rgb
        .chunks(3)
        .zip(b.rgb.chunks(3))
        .filter(|(x, y)| x != y)
        .count();
    assert!(differing > 1000, "{differing}");
}

#[test]
fn a_broken_file_is_named_and_unknown_fields_list_the_known_ones() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path(), DQuat::IDENTITY, true);
    let options = RenderOptions {
        colour: "temperature".into(),
        width: 200,
        height: 150,
        ..RenderOptions::default()
    };
    let err = render_run(dir.path(), FrameChoice::Last, &options, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("particles_000000.vtp") && err.contains("temperature"),
        "{err}"
    );
    assert!(err.contains("velocity") && err.contains("speed"), "{err}");

    let file = dir.path().join("polyhedra_000000.vtp");
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
    let err = render_run(
        dir.path(),
        FrameChoice::Last,
        &RenderOptions::default(),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("polyhedra_000000.vtp"), "{err}");

    let err = render_run(
        dir.path(),
        FrameChoice::Index(3),
        &RenderOptions::default(),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("frames 0 to 0"), "{err}");
}

#[test]
fn the_force_network_is_drawn_over_the_particles() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path(), DQuat::IDENTITY, true);
    let network = ForceNetwork {
        points: vec![SPHERE, CUBE],
        lines: vec![vec![0, 1]],
        normal_force: vec![2.0],
        force: vec![DVec3::X],
        wall_contact: vec![0],
    };
    write_force_network(&dir.path().join("contacts_000000.vtp"), &network, 0.25).unwrap();
    PvdSeries::new(dir.path().join("contacts.pvd"))
        .add(0.25, "contacts_000000.vtp", 0)
        .unwrap();
    let options = RenderOptions {
        view: View::Front,
        force_network: true,
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let p = render(dir.path(), &options);
    // Halfway between the centres, in the gap between the bodies: the line, in colour.
    let [r, g, b] = pixel_at(&p, DVec3::ZERO);
    assert!(r.max(g).max(b) - r.min(g).min(b) > 60, "line {r} {g} {b}");
}

fn png_size(path: &Path) -> (u32, u32) {
    assert!(
        std::fs::metadata(path).unwrap().len() > 1000,
        "{}",
        path.display()
    );
    image::image_dimensions(path).unwrap()
}

#[test]
fn a_short_run_renders_and_plots_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("drop.toml");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bouncing_sphere.toml"),
    )
    .unwrap()
    .replace("duration = 1.0", "duration = 0.03");
    std::fs::write(&scene, text).unwrap();
    let out = dir.path().join("drop");
    let polydem = env!("CARGO_BIN_EXE_polydem");
    let run = |args: &[&str]| {
        let o = Command::new(polydem).args(args).output().unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).to_string()
    };
    run(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let out_str = out.to_str().unwrap();

    let picture = dir.path().join("last.png");
    run(&[
        "render",
        out_str,
        "--size",
        "320x240",
        "--out",
        picture.to_str().unwrap(),
    ]);
    assert_eq!(png_size(&picture), (320, 240));

    let series = dir.path().join("series");
    let printed = run(&[
        "render",
        out_str,
        "--frame",
        "all",
        "--view",
        "front",
        "--size",
        "160x120",
        "--out",
        series.to_str().unwrap(),
    ]);
    let frames = std::fs::read_dir(&series).unwrap().count();
    assert!(
        frames > 3 && printed.lines().count() == frames,
        "{frames} frames"
    );
    assert_eq!(png_size(&series.join("render_000001.png")), (160, 120));

    let gif = dir.path().join("run.gif");
    run(&[
        "render",
        out_str,
        "--frame",
        "all",
        "--size",
        "160x120",
        "--out",
        gif.to_str().unwrap(),
    ]);
    let mut decoder = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(&gif).unwrap())
        .unwrap();
    let mut gif_frames = 0;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.width, frame.height), (160, 120));
        gif_frames += 1;
    }
    assert_eq!(gif_frames, frames);

    let plots = dir.path().join("plots");
    run(&["plot", out_str, "--out", plots.to_str().unwrap()]);
    for name in ["energy.png", "contacts.png", "wall_forces.png"] {
        let (w, h) = png_size(&plots.join(name));
        assert!(w >= 600 && h >= 300, "{name}: {w}x{h}");
    }

    let o = Command::new(polydem)
        .args(["render", dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("particles.pvd"));
}

#[test]
fn cuts_remove_walls_and_with_cut_bodies_the_bodies_too() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path(), DQuat::IDENTITY, true);
    let base = RenderOptions {
        view: View::Top,
        colour: "id".into(),
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let floor_point = DVec3::new(-2.0, 2.0, -0.6);
    let whole = render(dir.path(), &base);
    assert_ne!(pixel_at(&whole, floor_point), [255; 3], "the floor shows");
    let cut = RenderOptions {
        cuts: vec!["x<0".parse().unwrap()],
        ..base.clone()
    };
    let p = render(dir.path(), &cut);
    assert_eq!(p.camera, whole.camera, "a cut does not move the camera");
    assert_eq!(
        pixel_at(&p, floor_point),
        [255; 3],
        "the floor is cut away at x < 0"
    );
    let [r, g, b] = pixel_at(&p, SPHERE);
    assert!(b > r + 60 && b > g, "the sphere stays: {r} {g} {b}");
    let sections = RenderOptions {
        cut_bodies: true,
        ..cut
    };
    let p = render(dir.path(), &sections);
    assert_eq!(
        pixel_at(&p, SPHERE),
        [255; 3],
        "the sphere's centre is at x < 0"
    );
    let [r, _, b] = pixel_at(&p, CUBE);
    assert!(r > b + 60, "the cube at x > 0 stays");
}

#[test]
fn materials_are_categories_with_a_colour_each() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path(), DQuat::IDENTITY, true);
    let options = RenderOptions {
        colour: "material".into(),
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let p = render(dir.path(), &options);
    // Material 0 blue, material 1 orange (not the scale's red: green well above blue).
    let [r, g, b] = pixel_at(&p, SPHERE);
    assert!(b > r + 40 && b > g, "sphere {r} {g} {b}");
    let [r, g, b] = pixel_at(&p, CUBE);
    assert!(r > g && g > b + 30, "cube {r} {g} {b}");
}

#[test]
fn a_series_keeps_one_camera_while_bodies_come_and_go() {
    let with_sphere = tempfile::tempdir().unwrap();
    write_scene(with_sphere.path(), DQuat::IDENTITY, true);
    let without = tempfile::tempdir().unwrap();
    write_scene(without.path(), DQuat::IDENTITY, false);
    // Without the floor, which would frame both alike.
    for dir in [with_sphere.path(), without.path()] {
        std::fs::remove_file(dir.join("walls.pvd")).unwrap();
    }
    let options = RenderOptions {
        view: View::Front,
        colour: "id".into(),
        range: Some((0.0, 1.0)),
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let a = render(with_sphere.path(), &options);
    let b = render(without.path(), &options);
    assert_ne!(
        a.camera, b.camera,
        "each frame alone is framed on its own contents"
    );

    let snap = |dir: &Path| RunFiles::open(dir).unwrap().load(0, false).unwrap();
    let (a_low, a_high) = scene_box(&snap(with_sphere.path())).unwrap().unwrap();
    let (b_low, b_high) = scene_box(&snap(without.path())).unwrap().unwrap();
    assert!(a_low.x < b_low.x, "the sphere reaches further left");
    let shared = RenderOptions {
        fit_box: Some((a_low.min(b_low), a_high.max(b_high))),
        ..options
    };
    let a = render(with_sphere.path(), &shared);
    let b = render(without.path(), &shared);
    assert_eq!(a.camera, b.camera);
    // The cube stays where it was.
    assert_eq!(pixel_at(&a, CUBE), pixel_at(&b, CUBE));
}
