//! Non-convex particles from mesh files and built-in shapes: what a user sees for every kind of
//! bad mesh (open, non-manifold, turned over, self-intersecting, flat), for bad parts and bad
//! parameters — the scene file, line and key, the mesh file, and what to do — and that repaired
//! input (welded duplicates, `reorient = true`) is accepted with a note.

use polydem::math::DVec3;
use polydem::scene::{Prepared, Scene};
use polydem::shape::nonconvex_generators::l_shape;
use polydem::shape::Shape;
use std::path::Path;

/// An ASCII STL of the triangles, every corner written out (as exporters do).
fn stl(vertices: &[DVec3], triangles: &[[usize; 3]]) -> String {
    let mut s = String::from("solid test\n");
    for t in triangles {
        s += "facet normal 0 0 0\nouter loop\n";
        for &i in t {
            let v = vertices[i];
            s += &format!("vertex {} {} {}\n", v.x, v.y, v.z);
        }
        s += "endloop\nendfacet\n";
    }
    s + "endsolid test\n"
}

/// A scene with one particle of `[shape.grain]` given by `keys`, next to the mesh files in `dir`.
fn scene(dir: &Path, keys: &str) -> Result<Prepared, String> {
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
{keys}

[[particle]]
shape = "grain"
material = "m"
position = [0.0, 0.0, 0.0]
"#
    );
    Scene::parse(&dir.join("scene.toml"), text)
        .map_err(|e| e.to_string())?
        .build()
        .map_err(|e| e.to_string())
}

fn refused(dir: &Path, keys: &str) -> String {
    match scene(dir, keys) {
        Ok(_) => panic!("accepted: {keys}"),
        Err(e) => e,
    }
}

/// The L-shape (2 × 1.2 × 0.5 in file units, arms 0.6 wide) and a folder holding it.
fn l_mesh() -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let m = l_shape(2.0, 1.2, 0.6, 0.5).unwrap();
    (m.vertices, m.triangles)
}

fn write(dir: &Path, name: &str, vertices: &[DVec3], triangles: &[[usize; 3]]) {
    std::fs::write(dir.join(name), stl(vertices, triangles)).unwrap();
}

fn mesh_keys(file: &str, extra: &str) -> String {
    format!("type = \"mesh\"\nfile = \"{file}\"\nscale = 0.01\nnonconvex = true\n{extra}")
}

#[test]
fn a_good_mesh_becomes_a_non_convex_particle_with_a_note_on_welding() {
    let dir = tempfile::tempdir().unwrap();
    let (v, t) = l_mesh();
    write(dir.path(), "l.stl", &v, &t);
    let p = scene(dir.path(), &mesh_keys("l.stl", "")).unwrap();
    let w = &p.world;
    let Shape::NonConvex(shape) = &w.shapes()[w.bodies().shape[0] as usize] else {
        panic!("not a non-convex particle")
    };
    // (2 × 0.6 + 0.6 × 0.6) × 0.5 = 0.78 file units³, scaled by 0.01³.
    let volume = shape.unit_mass_properties().volume;
    assert!((volume / 0.78e-6 - 1.0).abs() < 1e-6, "{volume}");
    assert_eq!(p.notes.len(), 1, "{:?}", p.notes);
    assert!(
        p.notes[0].starts_with("[shape.grain]") && p.notes[0].contains("welded"),
        "{}",
        p.notes[0]
    );
    // The same mesh without `nonconvex` is refused as not convex, with both ways out.
    let e = refused(
        dir.path(),
        "type = \"mesh\"\nfile = \"l.stl\"\nscale = 0.01",
    );
    assert!(
        e.contains("is not convex") && e.contains("nonconvex = true") && e.contains("convex_hull"),
        "{e}"
    );
}

#[test]
fn broken_meshes_are_refused_with_what_is_wrong_and_where() {
    let dir = tempfile::tempdir().unwrap();
    let (v, t) = l_mesh();

    // A hole: one triangle missing; its three edges are named.
    let mut open = t.clone();
    open.remove(0);
    write(dir.path(), "open.stl", &v, &open);
    let e = refused(dir.path(), &mesh_keys("open.stl", ""));
    assert!(e.contains("scene.toml:15: [shape.grain] file: "), "{e}");
    assert!(
        e.contains("open.stl: the mesh is not closed: 3 edge(s)"),
        "{e}"
    );
    assert!(e.contains("close the holes"), "{e}");

    // A fin: two triangles hanging off an edge (three or more triangles at it).
    let [a, b, _] = t[0];
    let mut fin_v = v.clone();
    fin_v.push(0.5 * (v[a] + v[b]) + DVec3::new(0.0, 0.0, -1.0));
    let tip = fin_v.len() - 1;
    let mut fin = t.clone();
    fin.push([a, b, tip]);
    fin.push([b, a, tip]);
    write(dir.path(), "fin.stl", &fin_v, &fin);
    let e = refused(dir.path(), &mesh_keys("fin.stl", ""));
    assert!(
        e.contains("not manifold") && e.contains("three or more"),
        "{e}"
    );

    // One triangle turned over: inconsistent; `reorient = true` repairs it.
    let mut turned = t.clone();
    turned[3].swap(1, 2);
    write(dir.path(), "turned.stl", &v, &turned);
    let e = refused(dir.path(), &mesh_keys("turned.stl", ""));
    assert!(
        e.contains("not consistently oriented") && e.contains("set reorient = true"),
        "{e}"
    );
    let p = scene(dir.path(), &mesh_keys("turned.stl", "reorient = true")).unwrap();
    assert!(
        p.notes
            .iter()
            .any(|n| n.contains("turned 1 triangles outward")),
        "{:?}",
        p.notes
    );

    // All turned over: inward; `reorient = true` turns it outward.
    let inward: Vec<[usize; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
    write(dir.path(), "inward.stl", &v, &inward);
    let e = refused(dir.path(), &mesh_keys("inward.stl", ""));
    assert!(
        e.contains("faces inward") && e.contains("reorient = true"),
        "{e}"
    );
    assert!(scene(dir.path(), &mesh_keys("inward.stl", "reorient = true")).is_ok());

    // Two L-shapes through each other, written as one mesh.
    let mut both_v = v.clone();
    both_v.extend(v.iter().map(|&x| x + DVec3::new(0.3, 0.1, 0.2)));
    let mut both = t.clone();
    both.extend(t.iter().map(|tri| tri.map(|i| i + v.len())));
    write(dir.path(), "crossing.stl", &both_v, &both);
    let e = refused(dir.path(), &mesh_keys("crossing.stl", ""));
    assert!(
        e.contains("intersects itself") && e.contains("triangle"),
        "{e}"
    );

    // Flat: a tetrahedron squashed into a plane.
    let flat = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, 0.0)];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    write(dir.path(), "flat.stl", &flat, &faces);
    let e = refused(dir.path(), &mesh_keys("flat.stl", ""));
    assert!(e.contains("encloses no volume"), "{e}");

    // `reorient` and `parts` belong to non-convex meshes.
    write(dir.path(), "l.stl", &v, &t);
    let e = refused(
        dir.path(),
        "type = \"mesh\"\nfile = \"l.stl\"\nreorient = true",
    );
    assert!(
        e.contains("reorient") && e.contains("set nonconvex = true"),
        "{e}"
    );
}

#[test]
fn convex_parts_must_fill_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let (v, t) = l_mesh();
    write(dir.path(), "l.stl", &v, &t);
    // The L centred on its box: x ∈ [−1, 1], y ∈ [−0.6, 0.6], z ∈ [−0.25, 0.25], arms 0.6 wide
    // along −y and −x.
    let part = |x: [f64; 2], y: [f64; 2]| {
        let corners: Vec<String> = (0..8)
            .map(|k| {
                format!(
                    "[{}, {}, {}]",
                    x[k & 1],
                    y[(k >> 1) & 1],
                    [-0.25, 0.25][(k >> 2) & 1]
                )
            })
            .collect();
        format!("[{}]", corners.join(", "))
    };
    let arm_x = part([-1.0, 1.0], [-0.6, 0.0]);
    let arm_y = part([-1.0, -0.4], [0.0, 0.6]);
    let p = scene(
        dir.path(),
        &mesh_keys("l.stl", &format!("parts = [{arm_x}, {arm_y}]")),
    )
    .unwrap();
    let w = &p.world;
    let Shape::NonConvex(shape) = &w.shapes()[0] else {
        panic!()
    };
    assert_eq!(shape.parts().len(), 2);
    // One part only: volumes do not add up.
    let e = refused(
        dir.path(),
        &mesh_keys("l.stl", &format!("parts = [{arm_x}]")),
    );
    assert!(
        e.contains("scene.toml:18: [shape.grain] parts: ") && e.contains("add up"),
        "{e}"
    );
    // A part sticking out of the body.
    let out = part([-1.0, 1.0], [-0.6, 0.6]);
    let e = refused(dir.path(), &mesh_keys("l.stl", &format!("parts = [{out}]")));
    assert!(e.contains("lies") && e.contains("outside the mesh"), "{e}");
}

#[test]
fn built_in_shapes_refuse_bad_parameters_by_key() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("type = \"jack\"\nlength = 0.01\nwidth = 0.02", "scene.toml:16: [shape.grain] width: width = 0.02 is not allowed: must be smaller than length = 0.01"),
        ("type = \"jack\"\nlength = 0.01\nwidth = -1.0", "width"),
        ("type = \"cross\"\nlength = 0.03\nwidth = 0.006\nthickness = 0.0", "thickness"),
        ("type = \"l_shape\"\nlength_x = 0.02\nlength_y = 0.005\nwidth = 0.006\nheight = 0.01", "must be smaller than length_y"),
        ("type = \"ring\"\nouter_radius = 0.01\ninner_radius = 0.02\nheight = 0.01", "inner_radius"),
        ("type = \"ring\"\nouter_radius = 0.02\ninner_radius = 0.01\nheight = 0.01\nsegments = 2", "segments = 2"),
        ("type = \"star\"\nspikes = 12\nradius = 0.01\nspike_length = 0.01", "spikes = 12"),
        ("type = \"screw\"\nradius = 0.005\ncore_radius = 0.006\nblade_width = 0.001\nlength = 0.02\nturns = 1.0", "core_radius = 0.006 is not allowed: must be smaller than radius"),
        ("type = \"jack\"\nlength = 0.02\nwidth = 0.004\ncolour = 3", "colour"),
    ];
    for (keys, expected) in cases {
        let e = refused(dir.path(), keys);
        assert!(e.contains(expected), "{keys}: {e}");
    }
    // And good ones build.
    for keys in [
        "type = \"jack\"\nlength = 0.02\nwidth = 0.004\nparts = true",
        "type = \"cross\"\nlength = 0.03\nwidth = 0.006\nthickness = 0.004",
        "type = \"ring\"\nouter_radius = 0.02\ninner_radius = 0.01\nheight = 0.01",
        "type = \"star\"\nspikes = 20\nradius = 0.01\nspike_length = 0.005\nparts = true",
        "type = \"screw\"\nradius = 0.005\ncore_radius = 0.002\nblade_width = 0.0015\nlength = 0.02\nturns = 1.5",
    ] {
        assert!(scene(dir.path(), keys).is_ok(), "{keys}");
    }
}
