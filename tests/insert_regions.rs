//! Insertion regions (issue #14): a box, or a cylinder along any axis; every body placed lies
//! wholly inside its region.

use polydem::math::DVec3;
use polydem::scene::Scene;

fn build(insert: &str) -> Result<polydem::scene::Prepared, String> {
    let text = format!(
        r#"
[simulation]
duration = 0.01
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.3
[[insert]]
material = "glass"
radius = 0.001
seed = 7
{insert}
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("regions.toml");
    std::fs::write(&file, text).unwrap();
    let scene = Scene::load(&file).map_err(|e| e.to_string())?;
    scene.build().map_err(|e| e.to_string())
}

#[test]
fn bodies_inserted_in_a_tilted_cylinder_lie_wholly_inside_it() {
    let (centre, axis) = (
        DVec3::new(0.01, -0.02, 0.05),
        DVec3::new(1.0, 1.0, 2.0).normalize(),
    );
    let (radius, length) = (0.008, 0.03);
    for method in ["random", "lattice"] {
        let prepared = build(&format!(
            "method = \"{method}\"\ncount = 40\n\
             cylinder = {{ centre = [0.01, -0.02, 0.05], axis = [1.0, 1.0, 2.0], radius = {radius}, length = {length} }}"
        ))
        .unwrap();
        let b = prepared.world.bodies();
        assert_eq!(b.len(), 40, "{method}");
        for i in 0..b.len() {
            let d = b.position[i] - centre;
            let along = d.dot(axis);
            let across = (d - axis * along).length();
            let r = b.bounding_radius[i];
            assert!(along.abs() <= 0.5 * length - r + 1e-12, "{method}: {along}");
            assert!(across <= radius - r + 1e-12, "{method}: {across}");
        }
        // They fill the cylinder, not only its middle: some reach near its rim and its ends.
        let reach = (0..b.len())
            .map(|i| {
                let d = b.position[i] - centre;
                (d - axis * d.dot(axis)).length()
            })
            .fold(0.0, f64::max);
        assert!(reach > 0.5 * radius, "{method}: {reach}");
    }
}

#[test]
fn a_region_is_a_box_or_a_cylinder_not_both_nor_neither() {
    let both = build(
        "method = \"random\"\ncount = 5\nregion_min = [0.0, 0.0, 0.0]\nregion_max = [0.1, 0.1, 0.1]\n\
         cylinder = { centre = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], radius = 0.01, length = 0.02 }",
    )
    .err()
    .unwrap();
    assert!(both.contains("one of the three"), "{both}");
    let neither = build("method = \"random\"\ncount = 5").err().unwrap();
    assert!(neither.contains("region_min"), "{neither}");
    let flat = build(
        "method = \"random\"\ncount = 5\n\
         cylinder = { centre = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 0.0], radius = 0.01, length = 0.02 }",
    )
    .err()
    .unwrap();
    assert!(flat.contains("cylinder.axis"), "{flat}");
}

/// A scene with an inlet and no gravity (bodies keep the inlet's velocity), run to its end;
/// returns the world at the end and every insertion's (time, bodies placed, shortfall).
fn stream(extra: &str, inlet: &str) -> (polydem::scene::Prepared, Vec<(f64, usize, bool)>) {
    stream_by("random", extra, inlet)
}

/// [`stream`], placing the bodies by `method`.
fn stream_by(
    method: &str,
    extra: &str,
    inlet: &str,
) -> (polydem::scene::Prepared, Vec<(f64, usize, bool)>) {
    let method = format!("method = \"{method}\"");
    let text = format!(
        r#"
[simulation]
duration = 0.05
output_interval = 0.01
gravity = [0.0, 0.0, 0.0]
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 5.0e6
poisson_ratio = 0.25
restitution = 0.5
friction = 0.3
{extra}
[[insert]]
material = "glass"
radius = 0.001
seed = 7
every = 0.01
{method}
{inlet}
"#
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("inlet.toml");
    std::fs::write(&file, text).unwrap();
    let mut prepared = Scene::load(&file).unwrap().build().unwrap();
    // The first layer is placed when the scene is built.
    let mut reports = vec![(0.0, prepared.world.bodies().len(), false)];
    polydem::run::run(&mut prepared, &dir.path().join("out"), |e| {
        if let polydem::run::RunEvent::Inserted(r) = e {
            reports.push((r.time, r.inserted, r.shortfall.is_some()));
        }
    })
    .unwrap();
    (prepared, reports)
}

fn no_two_overlap(b: &polydem::body::Bodies) -> bool {
    (0..b.len()).all(|i| {
        (i + 1..b.len()).all(|j| {
            (b.position[i] - b.position[j]).length()
                >= b.bounding_radius[i] + b.bounding_radius[j] - 1e-12
        })
    })
}

/// Issue #14: bodies stream in through a disc at the given rate, in front of it, with the given
/// speed along its normal, never overlapping each other or a wall that cuts the stream.
#[test]
fn bodies_stream_in_through_a_disc_inlet_at_its_rate_and_speed() {
    // A disc at z = 0.1 facing down; a plane at x = -0.005 (facing +x) cuts off a slice of it.
    let (prepared, reports) = stream(
        "[[plane]]\npoint = [-0.005, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\nmaterial = \"glass\"\n",
        "inlet = { centre = [0.0, 0.0, 0.1], normal = [0.0, 0.0, -2.0], radius = 0.01, speed = 0.5, rate = 2000.0 }",
    );
    // Every 0.01 s, 2000/s × 0.01 s = 20 bodies, all of them placed: the rate.
    let times: Vec<f64> = reports.iter().map(|r| r.0).collect();
    assert_eq!(reports.len(), 6, "{reports:?}");
    for (k, (t, n, short)) in reports.iter().enumerate() {
        assert!((t - 0.01 * k as f64).abs() < 1e-4, "{times:?}");
        assert_eq!((*n, *short), (20, false), "{reports:?}");
    }
    let b = prepared.world.bodies();
    assert_eq!(b.len(), 120);
    assert!(no_two_overlap(b), "bodies overlap");
    let face = DVec3::new(0.0, 0.0, 0.1);
    for i in 0..b.len() {
        // Along the normal at the inlet's speed, untouched (no gravity, no collisions).
        assert!(
            (b.velocity[i] - DVec3::new(0.0, 0.0, -0.5)).length() < 1e-12,
            "{}",
            b.velocity[i]
        );
        let d = b.position[i] - face;
        assert!(-d.z >= 0.001 - 1e-12, "behind the face: {d}");
        assert!(
            d.truncate().length() <= 0.009 + 1e-12,
            "outside the disc: {d}"
        );
        assert!(b.position[i].x >= -0.004 - 1e-12, "overlaps the plane: {d}");
    }
    // The last layer (inserted at the end) lies in the 5 mm the stream sweeps in 0.01 s.
    let nearest = (0..b.len())
        .map(|i| face.z - b.position[i].z)
        .fold(f64::MAX, f64::min);
    assert!((0.001 - 1e-12..0.004).contains(&nearest), "{nearest}");
    let farthest = (0..b.len())
        .map(|i| face.z - b.position[i].z)
        .fold(0.0, f64::max);
    assert!(farthest <= 0.05 * 0.5 + 0.004 + 1e-9, "{farthest}");
}

/// Placed on a lattice, the bodies of a layer sit on the layer's bounds (touching them): they
/// are placed all the same, and the stream is as with random placement.
#[test]
fn an_inlet_places_a_lattice_layer_too() {
    let (prepared, reports) = stream_by(
        "lattice",
        "",
        "inlet = { centre = [0.0, 0.0, 0.1], normal = [0.0, 0.0, -1.0], radius = 0.01, speed = 0.3, rate = 2000.0 }",
    );
    assert!(
        reports.iter().all(|r| (r.1, r.2) == (20, false)),
        "{reports:?}"
    );
    let b = prepared.world.bodies();
    assert!(no_two_overlap(b), "bodies overlap");
    for i in 0..b.len() {
        let d = b.position[i] - DVec3::new(0.0, 0.0, 0.1);
        assert!(
            -d.z >= 0.001 - 1e-12 && d.truncate().length() <= 0.009 + 1e-12,
            "{d}"
        );
    }
}

/// A tilted rectangle, with a rate that is not a whole number of bodies per layer: the layers
/// carry the remainder, so the mean rate is exact; bodies lie in front of the face and within
/// its sides, moving along its normal.
#[test]
fn a_tilted_rectangular_inlet_keeps_its_mean_rate() {
    let normal = DVec3::new(1.0, 0.0, 1.0).normalize();
    let (prepared, reports) = stream(
        "",
        "inlet = { centre = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 1.0], size = [0.03, 0.01], side = [0.0, 1.0, 0.0], speed = 0.4, rate = 1250.0 }",
    );
    // 12.5 bodies per layer: 12, 13, 12, 13, …
    let counts: Vec<usize> = reports.iter().map(|r| r.1).collect();
    assert_eq!(counts, vec![12, 13, 12, 13, 12, 13], "{reports:?}");
    let b = prepared.world.bodies();
    assert!(no_two_overlap(b), "bodies overlap");
    let side = DVec3::Y;
    let across = normal.cross(side);
    for i in 0..b.len() {
        assert!((b.velocity[i] - normal * 0.4).length() < 1e-12);
        let d = b.position[i];
        assert!(d.dot(normal) >= 0.001 - 1e-12, "behind the face: {d}");
        assert!(d.dot(side).abs() <= 0.015 - 0.001 + 1e-12, "{d}");
        assert!(d.dot(across).abs() <= 0.005 - 0.001 + 1e-12, "{d}");
    }
}

/// Inlets are checked like every other key: the message names the key and what to give.
#[test]
fn inlet_keys_are_checked() {
    let inlet = |keys: &str, more: &str| {
        build(&format!(
            "method = \"random\"\n{more}\ninlet = {{ centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], {keys} }}"
        ))
        .err()
        .unwrap_or_else(|| panic!("accepted: {keys} / {more}"))
    };
    let ok = "radius = 0.01, speed = 0.5, rate = 100.0";
    for (keys, more, expected) in [
        (ok, "", "give `every`"),
        (ok, "every = 0.01\ncount = 5", "leave out `count`"),
        (
            ok,
            "every = 0.01\nvelocity = [0.0, 0.0, 1.0]",
            "leave out `velocity`",
        ),
        (ok, "every = 0.001", "every ≥ 4.0000e-3 s"),
        (
            "speed = 0.5, rate = 100.0",
            "every = 0.01",
            "one of the three",
        ),
        (
            "radius = 0.01, size = [0.1, 0.1], speed = 0.5, rate = 100.0",
            "every = 0.01",
            "one of the three",
        ),
        (
            "radius = 0.01, speed = 0.0, rate = 100.0",
            "every = 0.01",
            "inlet.speed",
        ),
        (
            "radius = 0.01, speed = 0.5, rate = -1.0",
            "every = 0.01",
            "inlet.rate",
        ),
        (
            "radius = 0.0005, speed = 0.5, rate = 100.0",
            "every = 0.01",
            "inlet.radius",
        ),
        (
            "size = [0.1, 0.1], side = [0.0, 0.0, 3.0], speed = 0.5, rate = 100.0",
            "every = 0.01",
            "parallel to the normal",
        ),
        (
            "radius = 0.01, speed = 0.5, rate = 1.0e7",
            "every = 0.01",
            "inlet.rate",
        ),
    ] {
        let message = inlet(keys, more);
        assert!(message.contains(expected), "{keys} / {more}: {message}");
        assert!(message.contains("insert"), "{message}");
    }
    let zero = build(
        "method = \"random\"\nevery = 0.01\ninlet = { centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 0.0], radius = 0.01, speed = 0.5, rate = 100.0 }",
    )
    .err()
    .unwrap();
    assert!(zero.contains("inlet.normal"), "{zero}");
    let both = build(
        "method = \"random\"\nevery = 0.01\nregion_min = [0.0, 0.0, 0.0]\nregion_max = [0.1, 0.1, 0.1]\n\
         inlet = { centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], radius = 0.01, speed = 0.5, rate = 100.0 }",
    )
    .err()
    .unwrap();
    assert!(both.contains("one of the three"), "{both}");
}

/// An ASCII STL of `triangles` (corners as given).
fn stl(triangles: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("solid face\n");
    for t in triangles {
        s.push_str("facet normal 0 0 0\n outer loop\n");
        for v in t {
            s.push_str(&format!("  vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        s.push_str(" endloop\nendfacet\n");
    }
    s + "endsolid face\n"
}

/// An L-shaped flat face at height `z`, wound counter-clockwise seen from above: three squares of
/// 1 cm, the one at (1, 1) cm left out.
fn l_shape(z: f64) -> Vec<[[f64; 3]; 3]> {
    let mut t = Vec::new();
    for (i, j) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
        let p = |a: f64, b: f64| [0.01 * (i + a), 0.01 * (j + b), z];
        t.push([p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)]);
        t.push([p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]);
    }
    t
}

/// Issue #14: an inlet face from a mesh file (an L, not convex), turned to face down: bodies
/// appear only over the L, at least their radius inside its outline, and leave it downwards.
#[test]
fn an_inlet_face_from_a_mesh_file_streams_bodies_over_its_shape() {
    let dir = tempfile::tempdir().unwrap();
    let face = dir.path().join("face.stl");
    std::fs::write(&face, stl(&l_shape(0.1))).unwrap();
    let inlet = format!(
        "inlet = {{ file = {:?}, flip = true, speed = 0.5, rate = 1000.0 }}",
        face.display().to_string()
    );
    let (prepared, reports) = stream("", &inlet);
    assert!(
        reports.iter().all(|r| (r.1, r.2) == (10, false)),
        "{reports:?}"
    );
    let b = prepared.world.bodies();
    assert_eq!(b.len(), 60);
    assert!(no_two_overlap(b), "bodies overlap");
    let r = 0.001;
    for i in 0..b.len() {
        let p = b.position[i];
        assert!((b.velocity[i] - DVec3::new(0.0, 0.0, -0.5)).length() < 1e-12);
        assert!(p.z <= 0.1 - r + 1e-12, "behind the face: {p}");
        let on_l = (r - 1e-12..=0.02 - r + 1e-12).contains(&p.x)
            && (r - 1e-12..=0.02 - r + 1e-12).contains(&p.y)
            && !(p.x > 0.01 - r + 1e-12 && p.y > 0.01 - r + 1e-12);
        assert!(on_l, "not over the L, inside its outline: {p}");
    }
    // Some come over each arm of the L, not only its corner square.
    assert!((0..b.len()).any(|i| b.position[i].x > 0.012));
    assert!((0..b.len()).any(|i| b.position[i].y > 0.012));

    // A face that is not flat, or one given a centre besides its file, is refused.
    let mut bent = l_shape(0.1);
    bent[5][2][2] = 0.105;
    let bent_file = dir.path().join("bent.stl");
    std::fs::write(&bent_file, stl(&bent)).unwrap();
    let refused = build(&format!(
        "method = \"random\"\nevery = 0.01\ninlet = {{ file = {:?}, speed = 0.5, rate = 100.0 }}",
        bent_file.display().to_string()
    ))
    .err()
    .unwrap();
    assert!(
        refused.contains("inlet.file") && refused.contains("not flat"),
        "{refused}"
    );
    let refused = build(&format!(
        "method = \"random\"\nevery = 0.01\ninlet = {{ file = {:?}, centre = [0.0, 0.0, 0.0], speed = 0.5, rate = 100.0 }}",
        face.display().to_string()
    ))
    .err()
    .unwrap();
    assert!(refused.contains("leave out `centre`"), "{refused}");
}
