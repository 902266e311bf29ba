//! A scene with every kind of contact: spheres with rolling friction, cubes (the volume law),
//! non-convex stars and L-shapes (the vertex law with several regions per pair), a rotating drum
//! of triangles (regions on a moving mesh wall) and a plane; 144 bodies that fall into the drum,
//! which lifts them into a tumbling heap.

use polydem::scene::Scene;
use polydem::World;
use std::path::Path;

pub const DRUM: &str = r#"
[simulation]
time_step = "auto"
duration = 1.0
gravity = [0.0, 0.0, -9.81]

[[material]]
name = "grain"
density = 1200.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = 0.4
friction = 0.5
rolling_friction = 0.05

[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 1.0e6
poisson_ratio = 0.3
restitution = 0.4
friction = 0.4

[shape.star]
type = "star"
spikes = 8
radius = 0.003
spike_length = 0.004

[shape.ell]
type = "l_shape"
length_x = 0.009
length_y = 0.007
width = 0.003
height = 0.003

[shape.cube]
type = "box"
edges = [0.007, 0.007, 0.007]

# A drum 12 cm across and 6 cm deep turning about y, cut by a plane below its axis (a
# heap's floor).
[[mesh_wall]]
material = "steel"
generator = { type = "cylinder", radius = 0.06, height = 0.06, segments = 32, closed = true }
rotation = [1.5707963267948966, 0.0, 0.0]
translation = [0.0, 0.03, 0.0]
motion = { rpm = 40.0, axis = [0.0, 1.0, 0.0] }

[[plane]]
point = [0.0, 0.0, -0.054]
normal = [0.0, 0.0, 1.0]
material = "steel"

[[insert]]
method = "random"
material = "grain"
region_min = [-0.035, -0.026, -0.04]
region_max = [0.035, 0.026, 0.03]
count = 120
seed = 2
radius_distribution = { kind = "uniform", min = 0.002, max = 0.003 }

[[insert]]
method = "random"
shape = "cube"
material = "grain"
region_min = [-0.035, -0.023, -0.04]
region_max = [0.035, 0.023, 0.03]
count = 10
seed = 3

[[insert]]
method = "random"
shape = "star"
material = "grain"
region_min = [-0.035, -0.021, -0.04]
region_max = [0.035, 0.021, 0.03]
count = 8
seed = 4

[[insert]]
method = "random"
shape = "ell"
material = "grain"
region_min = [-0.035, -0.018, -0.04]
region_max = [0.035, 0.018, 0.03]
count = 6
seed = 5
"#;

pub fn drum() -> World {
    Scene::parse(Path::new("drum.toml"), DRUM.to_string())
        .expect("scene parses")
        .build()
        .expect("scene builds")
        .world
}
