//! What a world is built from (`World::new`), and the parts a world may lack (`World::with_*`).

use super::World;
use crate::broad_phase;
use crate::contact_law::PolyhedralLaw;
use crate::flow::FlowMeter;
use crate::material::{Material, PairTable};
use crate::math::{Aabb, DVec3};
use crate::time_table::TimeTable;
use crate::wall::{MeshWall, Plane};

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

/// The parts a world may lack, each added to a world built by [`World::new`].
impl World {
    /// The world with these triangle-mesh walls (fixed or moving).
    pub fn with_mesh_walls(mut self, walls: Vec<MeshWall>) -> Self {
        self.mesh_walls = walls;
        self.structure_changed();
        self
    }

    /// The world with this contact law for polyhedra (the volume law by default).
    pub fn with_polyhedral_law(mut self, law: PolyhedralLaw) -> Self {
        self.polyhedral_law = law;
        self.structure_changed();
        self
    }

    /// The world with gravity following `table` (see [`World::follow_gravity`]).
    pub fn with_gravity_table(mut self, table: TimeTable<DVec3>) -> Self {
        self.gravity = table.value(self.time + 0.5 * self.time_step);
        self.gravity_table = Some(table);
        self
    }

    /// The world with these flow meters.
    pub fn with_flow_meters(mut self, meters: Vec<FlowMeter>) -> Self {
        self.flow_meters = meters;
        self
    }

    /// The world with an open boundary: bodies whose centre leaves `domain` are removed.
    pub fn with_domain(mut self, domain: Aabb) -> Self {
        self.domain = Some(domain);
        self
    }

    /// A fifth of the smallest bounding radius: small enough that the extra candidate pairs cost
    /// little, large enough that the list lasts many steps at the speeds DEM time steps allow.
    pub fn default_skin(smallest_radius: f64) -> f64 {
        0.2 * smallest_radius
    }
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
