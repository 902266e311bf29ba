//! What a world is built from (`World::new`).

use crate::broad_phase;
use crate::material::{Material, PairTable};
use crate::math::DVec3;
use crate::wall::Plane;

/// Everything about a world except its bodies and the parts it may lack (see `World::with_*`).
pub struct WorldConfig {
    pub time_step: f64,
    pub gravity: DVec3,
    pub materials: Vec<Material>,
    pub pair_laws: PairTable,
    pub planes: Vec<Plane>,
    pub broad_phase: broad_phase::Method,
    /// Extra distance [m] by which the broad phase's boxes are enlarged so that its pair list
    /// can be reused over several steps; `None` picks a default from the body sizes
    /// ([`World::default_skin`]).
    pub skin: Option<f64>,
    /// Worker threads for the parallel loops (0: one per core).
    pub threads: usize,
}

/// A world for tests: spheres of 1 cm at `positions` (material of density 1000 kg/m³, E 1 MPa,
/// Hertz), among the mesh walls `walls`, no gravity, a step of 10 µs, one thread.
#[cfg(test)]
pub(crate) fn spheres_among_walls(
    walls: Vec<crate::wall::MeshWall>,
    positions: &[DVec3],
) -> super::World {
    let material = Material {
        name: "m".into(),
        density: 1000.0,
        youngs_modulus: 1e6,
        poisson_ratio: 0.3,
        restitution: 0.5,
        friction: 0.5,
        rolling_friction: 0.0,
    };
    let laws = PairTable::new(
        std::slice::from_ref(&material),
        crate::contact_law::NormalLaw::Hertz,
        1.0,
        &[],
    );
    let mut world = super::World::new(WorldConfig {
        time_step: 1e-5,
        gravity: DVec3::ZERO,
        materials: vec![material],
        pair_laws: laws,
        planes: Vec::new(),
        broad_phase: Default::default(),
        skin: None,
        threads: 1,
    })
    .unwrap()
    .with_mesh_walls(walls);
    for &position in positions {
        world.add_body(crate::body::BodyInit {
            shape: crate::shape::Shape::Sphere(crate::shape::Sphere::new(0.01)),
            material: 0,
            position,
            orientation: crate::math::DQuat::IDENTITY,
            velocity: DVec3::ZERO,
            angular_velocity: DVec3::ZERO,
        });
    }
    world
}
