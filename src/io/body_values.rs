//! What the outputs say about each body beyond its state: speed, coordination number, walls
//! touching, and the name of its shape — worked out once per frame from the world, then written
//! with the particle points and with the faces of polyhedra alike.

use super::vtk::BodyFields;
use crate::shape::Shape;
use crate::world::World;

/// The names of the scene's shapes, numbered as written in the `shape` arrays: 0 is `sphere`
/// (spheres given by a radius), then the scene's `[shape.NAME]`s by name.
#[derive(Clone, Debug, Default)]
pub struct ShapeNames {
    named: Vec<(String, Shape)>,
}

impl ShapeNames {
    pub fn new(named: Vec<(String, Shape)>) -> Self {
        Self { named }
    }

    /// All names, by number.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        std::iter::once("sphere").chain(self.named.iter().map(|(n, _)| n.as_str()))
    }

    /// The number of `shape`'s name: the named shape it is (polyhedra by identity, spheres by
    /// radius), else 0.
    pub fn index_of(&self, shape: &Shape) -> u32 {
        self.named
            .iter()
            .position(|(_, s)| s == shape)
            .map_or(0, |k| k as u32 + 1)
    }

    /// Whether any named shape is a polyhedron (so the run writes `polyhedra.pvd` from its first
    /// frame on, even before the first polyhedron arrives).
    pub fn has_polyhedra(&self) -> bool {
        self.named
            .iter()
            .any(|(_, s)| !matches!(s, Shape::Sphere(_)))
    }
}

/// Per-body values computed for one frame.
pub struct BodyValues {
    pub speeds: Vec<f64>,
    pub coordination: Vec<u32>,
    pub wall_contacts: Vec<u32>,
    pub shapes: Vec<u32>,
}

impl BodyValues {
    pub fn of(world: &World, names: &ShapeNames) -> Self {
        let b = world.bodies();
        let n = b.len();
        let mut coordination = vec![0u32; n];
        let mut wall_contacts = vec![0u32; n];
        // Contacts come sorted by (a, partner, region): a pair touching in several regions is
        // one neighbour.
        let mut previous = None;
        for c in world.contacts().iter() {
            let pair = (c.key.a, c.key.partner);
            if previous.replace(pair) == Some(pair) {
                continue;
            }
            match c.key.partner.body() {
                Some(j) => {
                    coordination[c.key.a as usize] += 1;
                    coordination[j as usize] += 1;
                }
                None => wall_contacts[c.key.a as usize] += 1,
            }
        }
        let by_entry: Vec<u32> = world.shapes().iter().map(|s| names.index_of(s)).collect();
        Self {
            speeds: b.velocity.iter().map(|v| v.length()).collect(),
            coordination,
            wall_contacts,
            shapes: b.shape.iter().map(|&s| by_entry[s as usize]).collect(),
        }
    }

    /// The fields of every body, in body order.
    pub fn fields<'a>(&'a self, world: &'a World) -> BodyFields<'a> {
        let b = world.bodies();
        BodyFields {
            velocities: &b.velocity,
            speeds: &self.speeds,
            angular_velocities: &b.angular_velocity,
            forces: &b.force,
            torques: &b.torque,
            coordination: &self.coordination,
            wall_contacts: &self.wall_contacts,
            materials: &b.material,
            shapes: &self.shapes,
        }
    }
}

/// The same fields with one entry per face of a body's surface: `of_body[k]` is face k's body.
pub struct FaceValues {
    velocities: Vec<crate::math::DVec3>,
    speeds: Vec<f64>,
    angular_velocities: Vec<crate::math::DVec3>,
    forces: Vec<crate::math::DVec3>,
    torques: Vec<crate::math::DVec3>,
    coordination: Vec<u32>,
    wall_contacts: Vec<u32>,
    materials: Vec<u32>,
    shapes: Vec<u32>,
}

impl FaceValues {
    pub fn gather(bodies: &BodyFields, of_body: &[usize]) -> Self {
        fn pick<T: Copy>(values: &[T], of_body: &[usize]) -> Vec<T> {
            of_body.iter().map(|&i| values[i]).collect()
        }
        Self {
            velocities: pick(bodies.velocities, of_body),
            speeds: pick(bodies.speeds, of_body),
            angular_velocities: pick(bodies.angular_velocities, of_body),
            forces: pick(bodies.forces, of_body),
            torques: pick(bodies.torques, of_body),
            coordination: pick(bodies.coordination, of_body),
            wall_contacts: pick(bodies.wall_contacts, of_body),
            materials: pick(bodies.materials, of_body),
            shapes: pick(bodies.shapes, of_body),
        }
    }

    pub fn fields(&self) -> BodyFields<'_> {
        BodyFields {
            velocities: &self.velocities,
            speeds: &self.speeds,
            angular_velocities: &self.angular_velocities,
            forces: &self.forces,
            torques: &self.torques,
            coordination: &self.coordination,
            wall_contacts: &self.wall_contacts,
            materials: &self.materials,
            shapes: &self.shapes,
        }
    }
}
