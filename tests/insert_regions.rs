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
    assert!(both.contains("one of the two"), "{both}");
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
