//! The benchmark scenes (`bench/*.toml`) build as `polydem bench scene` builds them, and the
//! weak-scaling bed (`bench/spheres_130k.toml`, issue #17) is the 65k bed twice: the same
//! spheres, material, step and walls, in a box twice as long, with the same fill density, so
//! that two ranks of it each hold what one rank of the 65k bed holds.

use polydem::math::DVec3;
use polydem::scene::Scene;
use polydem::World;
use std::path::Path;

fn build(name: &str) -> World {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("bench")
        .join(name);
    let scene = Scene::load(&file).unwrap_or_else(|e| panic!("{name}: {e}"));
    scene
        .build()
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .world
}

#[test]
fn every_benchmark_scene_builds() {
    for (name, bodies) in [("spheres_10k.toml", 10_000), ("cubes_1k.toml", 1_000)] {
        assert_eq!(build(name).bodies().len(), bodies, "{name}");
    }
}

#[test]
fn the_rolling_bed_is_the_10k_bed_with_rolling_friction() {
    let (plain, rolling) = (build("spheres_10k.toml"), build("spheres_10k_rolling.toml"));
    assert_eq!(plain.bodies().position, rolling.bodies().position);
    assert_eq!(plain.time_step(), rolling.time_step());
    assert_eq!(plain.pair_laws().get(0, 0).rolling_friction, 0.0);
    assert_eq!(rolling.pair_laws().get(0, 0).rolling_friction, 0.05);
    assert_eq!(
        plain.pair_laws().get(0, 0).friction,
        rolling.pair_laws().get(0, 0).friction
    );
}

/// The mesh bed is the 10k bed with its five planes given as one triangle mesh (from
/// bench/open_box_60mm.stl, which bench/open_box_stl.py writes): the same bodies, step and
/// material, and every plane of the box covered by the mesh's triangles, whose normals point
/// into the box.
#[test]
fn the_mesh_bed_is_the_10k_bed_in_a_triangulated_box() {
    let (plain, mesh) = (build("spheres_10k.toml"), build("spheres_10k_mesh.toml"));
    assert_eq!(plain.bodies().position, mesh.bodies().position);
    assert_eq!(plain.time_step(), mesh.time_step());
    assert_eq!(plain.pair_laws().get(0, 0), mesh.pair_laws().get(0, 0));
    assert!(mesh.planes().is_empty());
    let [wall] = mesh.mesh_walls() else {
        panic!("one mesh wall")
    };
    assert_eq!(wall.triangles().len(), 360);
    for plane in plain.planes() {
        // The triangles in this plane (the STL's single-precision coordinates are within 2e-9 m
        // of the plane's), facing the way it faces, cover its 60 mm × 60 mm.
        let area: f64 = (0..360)
            .map(|t| wall.corners(t))
            .filter(|c| {
                c.iter()
                    .all(|&v| (v - plane.point).dot(plane.normal).abs() < 2e-9)
            })
            .map(|[a, b, c]| {
                let n = (b - a).cross(c - a);
                assert!(n.normalize().dot(plane.normal) > 1.0 - 1e-12);
                0.5 * n.length()
            })
            .sum();
        assert!((area - 0.06 * 0.06).abs() < 1e-9, "{plane:?}: {area}");
    }
}

#[test]
fn the_weak_scaling_bed_is_the_65k_bed_twice() {
    let (single, double) = (build("spheres_65k.toml"), build("spheres_130k.toml"));
    assert_eq!(single.bodies().len(), 65_000);
    assert_eq!(double.bodies().len(), 130_000);
    assert_eq!(single.time_step(), double.time_step());
    assert_eq!(single.planes().len(), double.planes().len());
    let b = double.bodies();
    assert_eq!(single.bodies().mass[0], b.mass[0]);
    assert_eq!(single.bodies().bounding_radius[0], b.bounding_radius[0]);
    // The box is 300 mm × 150 mm; every sphere lies in it, and each half holds half of them (the
    // fill is uniform: a binomial count of 130,000 with p = 1/2 has a standard deviation of 181,
    // so ±1,000 is more than five of them).
    let inside = |x: &DVec3| {
        let r = 0.001;
        (r..=0.30 - r).contains(&x.x) && (r..=0.15 - r).contains(&x.y) && x.z >= r
    };
    assert!(b.position.iter().all(inside));
    let first_half = b.position.iter().filter(|x| x.x < 0.15).count();
    assert!(
        first_half.abs_diff(65_000) < 1_000,
        "{first_half} in the first half"
    );
}
