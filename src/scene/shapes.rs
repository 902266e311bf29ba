//! Building the named shapes of a scene (`[shape.NAME]`).

use super::format::ShapeSpec;
use super::{KeyPath, Scene, SceneError};
use crate::math::{DQuat, DVec3};
use crate::shape::{generators, ConvexPolyhedron, MassProperties, Shape, Sphere};
use std::collections::BTreeMap;
use std::sync::Arc;

/// A shape ready to place. Polyhedra live in their principal frame; `principal` and `centre` say
/// where that frame sits in the frame the user described the shape in, so that a particle placed
/// with no rotation looks as the user wrote it (a box with `edges = [1, 2, 3]` keeps its long side
/// along z, whatever order the principal axes come in).
#[derive(Clone, Debug)]
pub struct BuiltShape {
    pub shape: Shape,
    /// Principal (body) frame → user frame.
    pub principal: DQuat,
    /// Centre of mass in the user frame.
    pub centre: DVec3,
}

impl BuiltShape {
    /// Pose of the body for a shape placed at `position` with `rotation` (user frame → world).
    pub fn pose(&self, position: DVec3, rotation: DQuat) -> (DVec3, DQuat) {
        (
            position + rotation * self.centre,
            (rotation * self.principal).normalize(),
        )
    }
}

pub fn build(scene: &Scene) -> Result<BTreeMap<String, BuiltShape>, SceneError> {
    let mut built = BTreeMap::new();
    for (name, spec) in &scene.spec.shapes {
        let key = KeyPath::table(&format!("shape.{name}")).key("type");
        let shape = build_one(spec).map_err(|e| scene.error(key, e))?;
        built.insert(name.clone(), shape);
    }
    Ok(built)
}

pub(super) fn build_one(spec: &ShapeSpec) -> Result<BuiltShape, String> {
    let positive = |what: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(format!("{what} = {v} is not allowed: must be > 0 m"))
        }
    };
    let polyhedron = match spec {
        ShapeSpec::Sphere { radius } => {
            return Ok(BuiltShape {
                shape: Shape::Sphere(Sphere::new(positive("radius", *radius)?)),
                principal: DQuat::IDENTITY,
                centre: DVec3::ZERO,
            })
        }
        ShapeSpec::Box { edges } => generators::cuboid(
            positive("edges[0]", edges[0])?,
            positive("edges[1]", edges[1])?,
            positive("edges[2]", edges[2])?,
        ),
        ShapeSpec::Tetrahedron { edge } => {
            generators::regular_tetrahedron(positive("edge", *edge)?)
        }
        ShapeSpec::Octahedron { edge } => generators::regular_octahedron(positive("edge", *edge)?),
        ShapeSpec::Dodecahedron { edge } => {
            generators::regular_dodecahedron(positive("edge", *edge)?)
        }
        ShapeSpec::Icosahedron { edge } => {
            generators::regular_icosahedron(positive("edge", *edge)?)
        }
        ShapeSpec::Prism {
            sides,
            circumradius,
            height,
        } => {
            if *sides < 3 {
                return Err(format!("sides = {sides}: a prism needs at least 3 sides"));
            }
            generators::regular_prism(
                *sides,
                positive("circumradius", *circumradius)?,
                positive("height", *height)?,
            )
        }
        ShapeSpec::Hull { points } => {
            let points: Vec<DVec3> = points.iter().map(|&p| DVec3::from(p)).collect();
            ConvexPolyhedron::from_points(&points)
        }
        ShapeSpec::Rock {
            vertices,
            size,
            elongation,
            seed,
        } => {
            if *vertices < 4 {
                return Err(format!("vertices = {vertices}: a rock needs at least 4"));
            }
            for (axis, &e) in elongation.iter().enumerate() {
                positive(&format!("elongation[{axis}]"), e)?;
            }
            generators::random_rock(
                *seed,
                *vertices,
                DVec3::from(*elongation),
                positive("size", *size)?,
            )
        }
    };
    let (polyhedron, mass): (ConvexPolyhedron, MassProperties) =
        polyhedron.map_err(|e| e.to_string())?;
    Ok(BuiltShape {
        principal: mass.principal_rotation(),
        centre: mass.center_of_mass,
        shape: Shape::Convex(Arc::new(polyhedron)),
    })
}

/// A rotation drawn uniformly (Shoemake 1992, "Uniform random rotations", Graphics Gems III).
pub fn random_rotation(rng: &mut crate::rng::SplitMix64) -> DQuat {
    let (u1, u2, u3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let tau = std::f64::consts::TAU;
    DQuat::from_xyzw(
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    )
    .normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_keeps_the_users_axes() {
        let b = build_one(&ShapeSpec::Box {
            edges: [1.0, 2.0, 3.0],
        })
        .unwrap();
        let Shape::Convex(p) = &b.shape else { panic!() };
        let (x, q) = b.pose(DVec3::new(5.0, 0.0, 0.0), DQuat::IDENTITY);
        let world: Vec<DVec3> = p.vertices().iter().map(|&v| x + q * v).collect();
        let extent = |axis: usize| {
            let values = world.iter().map(|v| v[axis]);
            values.clone().fold(f64::MIN, f64::max) - values.fold(f64::MAX, f64::min)
        };
        assert!((extent(0) - 1.0).abs() < 1e-12);
        assert!((extent(1) - 2.0).abs() < 1e-12);
        assert!((extent(2) - 3.0).abs() < 1e-12);
        assert!((x - DVec3::new(5.0, 0.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn random_rotations_are_unit_and_spread() {
        let mut rng = crate::rng::SplitMix64::new(1);
        let mut mean = DVec3::ZERO;
        for _ in 0..20000 {
            let q = random_rotation(&mut rng);
            assert!((q.length() - 1.0).abs() < 1e-12);
            mean += q * DVec3::Z;
        }
        // A uniform rotation sends z anywhere on the sphere: the mean direction tends to 0.
        assert!((mean / 20000.0).length() < 0.02);
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(build_one(&ShapeSpec::Box {
            edges: [1.0, 0.0, 1.0]
        })
        .unwrap_err()
        .contains("edges[1]"));
        assert!(build_one(&ShapeSpec::Hull {
            points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]
        })
        .is_err());
    }
}
