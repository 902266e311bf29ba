//! A scene with every kind of contact: spheres with rolling friction, cubes (the volume law),
//! non-convex stars and L-shapes (the vertex law with several regions per pair), a rotating drum
//! of triangles (regions on a moving mesh wall) and a plane; 144 bodies that fall into the drum,
//! which lifts them into a tumbling heap.

use polydem::scene::Scene;
use polydem::World;
use std::path::Path;

pub const DRUM: &str = include_str!("../data/drum.toml");

pub fn drum() -> World {
    Scene::parse(Path::new("drum.toml"), DRUM.to_string())
        .expect("scene parses")
        .build()
        .expect("scene builds")
        .world
}
