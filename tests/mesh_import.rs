//! Importing convex particle shapes from mesh files (`[shape.NAME] type = "mesh"`): STL (ASCII and
//! binary) and OBJ, welding, scaling, convexity, and the errors a user sees.
//!
//! The meshes are in `tests/data/`: a unit cube [0, 1]³ as ASCII STL (with some zero coordinates
//! written as ±1e-12 or -0, as exporters leave them), as binary STL and as OBJ with quad faces; an
//! L-shaped prism [0,2]×[0,1]×[0,1] ∪ [0,1]×[1,2]×[0,1] (volume 3, convex hull 3.5) as ASCII STL;
//! and a text file that is no mesh at all.

use polydem::io::mesh::{read_mesh, MeshError, MeshFormat};
use polydem::math::DVec3;
use polydem::scene::Scene;
use polydem::shape::import::{convex_from_mesh, MeshShapeError};
use polydem::shape::Shape;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new("tests/data").join(name)
}

fn close(a: f64, b: f64, relative: f64) -> bool {
    (a - b).abs() <= relative * b.abs()
}

#[test]
fn the_cube_in_every_format_has_the_volume_and_inertia_of_a_cube() {
    let scale = 0.001;
    let a: f64 = scale; // edge after scaling
    for (file, format) in [
        ("cube_ascii.stl", MeshFormat::Stl),
        ("cube_binary.stl", MeshFormat::Stl),
        ("cube_quads.obj", MeshFormat::Obj),
    ] {
        let mesh = read_mesh(&data(file), scale).unwrap();
        assert_eq!(mesh.info.format, format);
        assert_eq!(mesh.vertices.len(), 8, "{file}");
        assert_eq!(mesh.triangles.len(), 12, "{file}: quads are triangulated");
        let c = convex_from_mesh(&mesh.vertices, &mesh.triangles, false).unwrap();
        let volume = a.powi(3);
        assert!(
            close(c.mass.volume, volume, 1e-9),
            "{file}: {}",
            c.mass.volume
        );
        // A cube's inertia is m a² / 6 about every axis through its centre (unit density).
        for moment in c
            .polyhedron
            .unit_mass_properties()
            .principal_inertia_per_density
            .to_array()
        {
            assert!(
                close(moment, volume * a * a / 6.0, 1e-8),
                "{file}: {moment}"
            );
        }
        assert!(
            (c.mass.center_of_mass - DVec3::splat(0.5 * a)).length() < 1e-9 * a,
            "{file}"
        );
        assert!(c.hull_excess.unwrap() < 1e-9);
        assert_eq!(c.polyhedron.faces().len(), 6, "{file}");
    }
}

#[test]
fn welding_reports_the_merged_duplicates() {
    // STL repeats each corner for every triangle: 12 × 3 = 36 records of 8 corners.
    let binary = read_mesh(&data("cube_binary.stl"), 1.0).unwrap().info;
    assert_eq!(binary.file_vertices, 36);
    assert_eq!(binary.vertices, 8);
    assert_eq!(binary.welded, 28);
    assert_eq!(binary.near_duplicates, 0, "binary copies are bit-identical");
    assert_eq!(binary.degenerate_triangles, 0);
    // The ASCII cube writes some zeros as ±1e-12: merged only by welding.
    let ascii = read_mesh(&data("cube_ascii.stl"), 1.0).unwrap().info;
    assert_eq!(ascii.file_vertices, 36);
    assert_eq!(ascii.vertices, 8);
    assert_eq!(ascii.welded, 28);
    assert!(ascii.near_duplicates > 0 && ascii.near_duplicates <= 28);
    // OBJ shares its corners already.
    let obj = read_mesh(&data("cube_quads.obj"), 1.0).unwrap().info;
    assert_eq!(
        (obj.file_vertices, obj.welded, obj.file_triangles),
        (8, 0, 12)
    );
}

#[test]
fn the_l_shape_is_refused_unless_its_hull_is_asked_for() {
    let mesh = read_mesh(&data("l_shape.stl"), 1.0).unwrap();
    let e = convex_from_mesh(&mesh.vertices, &mesh.triangles, false).unwrap_err();
    let MeshShapeError::NotConvex { hull_excess, .. } = e else {
        panic!("{e}")
    };
    assert!(close(hull_excess, 0.5 / 3.0, 1e-9));
    let hull = convex_from_mesh(&mesh.vertices, &mesh.triangles, true).unwrap();
    assert!(close(hull.mass.volume, 3.5, 1e-12));
}

#[test]
fn missing_and_garbage_files_are_named() {
    let missing = data("no_such_mesh.stl");
    let e = read_mesh(&missing, 1.0).unwrap_err();
    assert!(matches!(e, MeshError::Read { .. }));
    assert!(
        e.to_string().contains(&missing.display().to_string()),
        "{e}"
    );
    let garbage = data("garbage.stl");
    let e = read_mesh(&garbage, 1.0).unwrap_err();
    assert!(matches!(e, MeshError::Parse { .. }), "{e}");
    assert!(
        e.to_string().contains(&garbage.display().to_string()),
        "{e}"
    );
    let e = read_mesh(&data("cube_quads.ply"), 1.0).unwrap_err();
    assert!(e.to_string().contains("unknown extension"), "{e}");
}

/// A scene in `tests/data/` (it need not exist: the text is given) with one particle of the shape
/// `[shape.grain]` described by `shape`.
fn scene(shape: &str) -> Result<polydem::scene::Prepared, String> {
    let text = format!(
        r#"[simulation]
duration = 0.01
threads = 1

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5

[shape.grain]
{shape}

[[particle]]
shape = "grain"
material = "m"
position = [0.0, 0.0, 0.0]
"#
    );
    let scene =
        Scene::parse(Path::new("tests/data/scene.toml"), text).map_err(|e| e.to_string())?;
    scene.build().map_err(|e| e.to_string())
}

/// The message of a scene that is refused.
fn refused(shape: &str) -> String {
    match scene(shape) {
        Ok(_) => panic!("accepted: {shape}"),
        Err(e) => e,
    }
}

#[test]
fn a_scene_builds_a_particle_from_a_mesh_beside_it() {
    for file in ["cube_ascii.stl", "cube_binary.stl", "cube_quads.obj"] {
        let prepared = scene(&format!(
            "type = \"mesh\"\nfile = \"{file}\"\nscale = 0.002"
        ))
        .unwrap();
        let world = &prepared.world;
        assert_eq!(world.bodies().len(), 1);
        let shape = &world.shapes()[world.bodies().shape[0] as usize];
        let Shape::Convex(p) = shape else {
            panic!("{file}: not a polyhedron")
        };
        assert!(close(p.unit_mass_properties().volume, 8e-9, 1e-9));
        assert!(close(world.bodies().mass[0], 2500.0 * 8e-9, 1e-9));
        // The file's origin is placed at `position`: the centre of mass is half an edge away.
        assert!((world.bodies().position[0] - DVec3::splat(0.001)).length() < 1e-12);
    }
}

#[test]
fn a_scene_reports_mesh_errors_with_scene_line_key_and_mesh_file() {
    let e = refused("type = \"mesh\"\nfile = \"l_shape.stl\"");
    assert_eq!(
        e,
        "tests/data/scene.toml:15: [shape.grain] file: tests/data/l_shape.stl is not convex (its \
         convex hull is 16.7 % larger): set nonconvex = true to use it as a non-convex particle, \
         or convex_hull = true to use its hull"
    );
    let hull =
        scene("type = \"mesh\"\nfile = \"l_shape.stl\"\nconvex_hull = true\nscale = 0.01").unwrap();
    let w = &hull.world;
    assert!(close(w.bodies().mass[0], 2500.0 * 3.5e-6, 1e-9));

    let e = refused("type = \"mesh\"\nfile = \"nothere.stl\"");
    assert!(e.starts_with("tests/data/scene.toml:15: [shape.grain] file: cannot read mesh file 'tests/data/nothere.stl'"), "{e}");
    let e = refused("type = \"mesh\"\nfile = \"garbage.stl\"");
    assert!(
        e.starts_with("tests/data/scene.toml:15: [shape.grain] file: mesh file 'tests/data/garbage.stl' is not a valid STL file"),
        "{e}"
    );
    let e = refused("type = \"mesh\"\nfile = \"cube_ascii.stl\"\nscale = 0");
    assert!(
        e.starts_with("tests/data/scene.toml:16: [shape.grain] scale: scale = 0 is not allowed"),
        "{e}"
    );
    let e = refused("type = \"mesh\"\nfile = \"cube_ascii.stl\"\nscale = -1");
    assert!(e.contains("scale = -1 is not allowed"), "{e}");
    let e = refused("type = \"mesh\"\nfile = \"cube.stl\"\nconvex = true");
    assert!(e.contains("unknown field `convex`"), "{e}");
}

#[test]
fn flat_tiny_and_non_finite_meshes_are_refused_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        std::fs::write(dir.path().join(name), text).unwrap();
    };
    // Two triangles back to back: flat.
    write(
        "flat.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 4 3 2 1\n",
    );
    // One triangle: 3 vertices.
    write("tiny.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write(
        "nan.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 inf\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
    );
    let scene_file = dir.path().join("scene.toml");
    let build = |file: &str| {
        let text = format!(
            "[simulation]\nduration = 1\n\n[[material]]\nname = \"m\"\ndensity = 1\n\
             youngs_modulus = 1e7\npoisson_ratio = 0.25\nrestitution = 0.5\nfriction = 0.5\n\n\
             [shape.grain]\ntype = \"mesh\"\nfile = \"{file}\"\n\n[[particle]]\nshape = \
             \"grain\"\nmaterial = \"m\"\nposition = [0, 0, 0]\n"
        );
        let error = match Scene::parse(&scene_file, text) {
            Ok(scene) => scene.build().err(),
            Err(e) => Some(e),
        };
        error.expect("refused").to_string()
    };
    let named = |file: &str| dir.path().join(file).display().to_string();
    let e = build("flat.obj");
    assert!(
        e.contains(&named("flat.obj")) && e.contains("zero volume"),
        "{e}"
    );
    let e = build("tiny.obj");
    assert!(
        e.contains(&named("tiny.obj")) && e.contains("3 distinct vertices"),
        "{e}"
    );
    let e = build("nan.obj");
    assert!(e.contains(&named("nan.obj")) && e.contains("finite"), "{e}");
}

#[test]
fn an_insertion_of_mesh_particles_is_sized_by_the_mesh() {
    // Validation sizes shape insertions by building the shape: it must find the mesh too.
    let text = r#"[simulation]
duration = 0.01
threads = 1

[[material]]
name = "m"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.25
restitution = 0.5
friction = 0.5

[shape.grain]
type = "mesh"
file = "cube_binary.stl"
scale = 0.001

[[insert]]
method = "lattice"
material = "m"
shape = "grain"
count = 8
region_min = [0.0, 0.0, 0.0]
region_max = [0.01, 0.01, 0.01]
"#;
    let prepared = Scene::parse(Path::new("tests/data/scene.toml"), text.to_string())
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(prepared.world.bodies().len(), 8);
}
