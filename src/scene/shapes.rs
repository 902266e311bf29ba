//! Building the named shapes of a scene (`[shape.NAME]`).

use super::format::ShapeSpec;
use super::{KeyPath, Scene, SceneError};
use crate::io::mesh::read_mesh;
use crate::math::{DQuat, DVec3};
use crate::shape::import::{convex_from_mesh, percent, MeshShapeError};
use crate::shape::mesh_check::CheckOptions;
use crate::shape::nonconvex::NonConvexError;
use crate::shape::nonconvex_generators::{self, NonConvexMesh};
use crate::shape::{
    generators, ConvexPolyhedron, MassProperties, NonConvexPolyhedron, Shape, ShapeError, Sphere,
};
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;
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
    /// What building it repaired or decided, for the user (welded vertices of a mesh, ...).
    pub note: Option<String>,
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

/// Why a shape could not be built: the key of its `[shape.NAME]` table to blame, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeBuildError {
    pub key: String,
    pub message: String,
}

impl ShapeBuildError {
    fn new(key: &str, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for ShapeBuildError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}: {}", self.key, self.message)
    }
}

pub fn build(scene: &Scene) -> Result<BTreeMap<String, BuiltShape>, SceneError> {
    let mut built = BTreeMap::new();
    for (name, spec) in &scene.spec.shapes {
        let shape = build_one(spec, scene_folder(scene)).map_err(|e| {
            scene.error(
                KeyPath::table(&format!("shape.{name}")).key(&e.key),
                e.message,
            )
        })?;
        built.insert(name.clone(), shape);
    }
    Ok(built)
}

/// The folder of the scene file: files a scene names (meshes) are relative to it.
pub(super) fn scene_folder(scene: &Scene) -> &Path {
    scene.file.parent().unwrap_or(Path::new(""))
}

/// Builds one shape; files it names are looked for relative to `folder`.
pub(super) fn build_one(spec: &ShapeSpec, folder: &Path) -> Result<BuiltShape, ShapeBuildError> {
    let positive = |what: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            // `edges[1]` is reported at the key `edges`.
            let key = what.split('[').next().unwrap_or(what);
            Err(ShapeBuildError::new(
                key,
                format!("{what} = {v} is not allowed: must be > 0 m"),
            ))
        }
    };
    let polyhedron = match spec {
        ShapeSpec::Sphere { radius } => {
            return Ok(BuiltShape {
                shape: Shape::Sphere(Sphere::new(positive("radius", *radius)?)),
                principal: DQuat::IDENTITY,
                centre: DVec3::ZERO,
                note: None,
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
                return Err(ShapeBuildError::new(
                    "sides",
                    format!("sides = {sides}: a prism needs at least 3 sides"),
                ));
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
                return Err(ShapeBuildError::new(
                    "vertices",
                    format!("vertices = {vertices}: a rock needs at least 4"),
                ));
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
        ShapeSpec::Mesh {
            file,
            scale,
            convex_hull: _,
            nonconvex: true,
            reorient,
            parts,
        } => return nonconvex_mesh_shape(folder, file, *scale, *reorient, parts.as_deref()),
        ShapeSpec::Mesh {
            file,
            scale,
            convex_hull,
            nonconvex: false,
            reorient,
            parts,
        } => {
            if *reorient || parts.is_some() {
                let key = if *reorient { "reorient" } else { "parts" };
                return Err(ShapeBuildError::new(
                    key,
                    format!("`{key}` applies to non-convex meshes only: set nonconvex = true"),
                ));
            }
            Ok(mesh_shape(folder, file, *scale, *convex_hull)?)
        }
        ShapeSpec::Jack {
            length,
            width,
            parts,
        } => {
            let (l, w) = (positive("length", *length)?, positive("width", *width)?);
            narrower("width", w, "length", l)?;
            return generated(nonconvex_generators::jack(l, w), *parts);
        }
        ShapeSpec::Cross {
            length,
            width,
            thickness,
            parts,
        } => {
            let (l, w) = (positive("length", *length)?, positive("width", *width)?);
            narrower("width", w, "length", l)?;
            let m = nonconvex_generators::cross(l, w, positive("thickness", *thickness)?);
            return generated(m, *parts);
        }
        ShapeSpec::LShape {
            length_x,
            length_y,
            width,
            height,
            parts,
        } => {
            let (a, b) = (
                positive("length_x", *length_x)?,
                positive("length_y", *length_y)?,
            );
            let w = positive("width", *width)?;
            narrower("width", w, "length_x", a)?;
            narrower("width", w, "length_y", b)?;
            let m = nonconvex_generators::l_shape(a, b, w, positive("height", *height)?);
            return generated(m, *parts);
        }
        ShapeSpec::Ring {
            outer_radius,
            inner_radius,
            height,
            segments,
            parts,
        } => {
            if *segments < 3 {
                return Err(ShapeBuildError::new(
                    "segments",
                    format!("segments = {segments}: a ring needs at least 3"),
                ));
            }
            let outer = positive("outer_radius", *outer_radius)?;
            let inner = positive("inner_radius", *inner_radius)?;
            narrower("inner_radius", inner, "outer_radius", outer)?;
            let m =
                nonconvex_generators::ring(outer, inner, positive("height", *height)?, *segments);
            return generated(m, *parts);
        }
        ShapeSpec::Screw {
            radius,
            core_radius,
            blade_width,
            length,
            turns,
            blades,
            segments,
        } => {
            let r = positive("radius", *radius)?;
            let c = positive("core_radius", *core_radius)?;
            narrower("core_radius", c, "radius", r)?;
            if !(2..=12).contains(blades) {
                return Err(ShapeBuildError::new(
                    "blades",
                    format!("blades = {blades}: a screw has 2 to 12 blades"),
                ));
            }
            if *segments < 4 {
                return Err(ShapeBuildError::new(
                    "segments",
                    format!("segments = {segments}: at least 4 per turn"),
                ));
            }
            if !(turns.is_finite() && *turns >= 0.0) {
                return Err(ShapeBuildError::new(
                    "turns",
                    format!("turns = {turns} is not allowed: must be ≥ 0"),
                ));
            }
            let m = nonconvex_generators::screw(
                r,
                c,
                positive("blade_width", *blade_width)?,
                positive("length", *length)?,
                *turns,
                *blades,
                *segments,
            );
            return generated(m, false);
        }
        ShapeSpec::Star {
            spikes,
            radius,
            spike_length,
            parts,
        } => {
            if *spikes != 8 && *spikes != 20 {
                return Err(ShapeBuildError::new(
                    "spikes",
                    format!("spikes = {spikes}: a star has 8 (on an octahedron) or 20 (on an icosahedron)"),
                ));
            }
            let m = nonconvex_generators::star(
                *spikes,
                positive("radius", *radius)?,
                positive("spike_length", *spike_length)?,
            );
            return generated(m, *parts);
        }
    };
    let (polyhedron, mass): (ConvexPolyhedron, MassProperties) = polyhedron.map_err(|e| {
        // A `hull` is blamed on its points; a mesh has said which key already.
        let key = match spec {
            ShapeSpec::Hull { .. } => "points",
            _ => "type",
        };
        ShapeBuildError::new(key, e.to_string())
    })?;
    Ok(BuiltShape {
        principal: mass.principal_rotation(),
        centre: mass.center_of_mass,
        shape: Shape::Convex(Arc::new(polyhedron)),
        note: None,
    })
}

fn nonconvex_shape(
    polyhedron: NonConvexPolyhedron,
    mass: MassProperties,
    note: Option<String>,
) -> BuiltShape {
    BuiltShape {
        principal: mass.principal_rotation(),
        centre: mass.center_of_mass,
        shape: Shape::NonConvex(Arc::new(polyhedron)),
        note,
    }
}

/// Refuses `small` ≥ `large`, blaming the key of `small`.
fn narrower(
    small_key: &str,
    small: f64,
    large_key: &str,
    large: f64,
) -> Result<(), ShapeBuildError> {
    if small < large {
        Ok(())
    } else {
        Err(ShapeBuildError::new(
            small_key,
            format!(
                "{small_key} = {small} is not allowed: must be smaller than {large_key} = {large}"
            ),
        ))
    }
}

/// A built-in non-convex shape, with its convex parts when `parts`.
fn generated(
    mesh: Result<NonConvexMesh, ShapeError>,
    parts: bool,
) -> Result<BuiltShape, ShapeBuildError> {
    let mesh = mesh.map_err(|e| ShapeBuildError::new("type", e.to_string()))?;
    let (polyhedron, mass) = mesh
        .build(parts)
        .map_err(|e| ShapeBuildError::new("type", e.to_string()))?;
    Ok(nonconvex_shape(polyhedron, mass, None))
}

/// Reads a mesh file as a non-convex particle (with its convex parts, if given); every message
/// names the file.
fn nonconvex_mesh_shape(
    folder: &Path,
    file: &str,
    scale: f64,
    reorient: bool,
    parts: Option<&[Vec<crate::scene::format::Vec3>]>,
) -> Result<BuiltShape, ShapeBuildError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(ShapeBuildError::new(
            "scale",
            format!("scale = {scale} is not allowed: must be > 0 (metres per unit of the file)"),
        ));
    }
    let path = folder.join(file);
    let mesh = read_mesh(&path, scale).map_err(|e| ShapeBuildError::new("file", e.to_string()))?;
    let name = path.display();
    let (polyhedron, mass, report) =
        NonConvexPolyhedron::from_mesh(&mesh.vertices, &mesh.triangles, CheckOptions { reorient })
            .map_err(|e| ShapeBuildError::new("file", format!("{name}: {e}")))?;
    let polyhedron = match parts {
        Some(parts) => {
            let points: Vec<Vec<DVec3>> = parts
                .iter()
                .map(|p| p.iter().map(|&x| DVec3::from(x) * scale).collect())
                .collect();
            polyhedron.with_parts(&mass, &points).map_err(|e| {
                let hint = match e {
                    NonConvexError::Part { .. } => "",
                    _ => " (part corners are in the file's units, like the mesh)",
                };
                ShapeBuildError::new("parts", format!("{e}{hint}"))
            })?
        }
        None => polyhedron,
    };
    let welded = mesh.info.welded;
    let mut repaired: Vec<String> = Vec::new();
    if welded > 0 {
        repaired.push(format!(
            "welded {welded} duplicate vertex records ({} not bit-identical)",
            mesh.info.near_duplicates
        ));
    }
    if mesh.info.degenerate_triangles > 0 {
        repaired.push(format!(
            "dropped {} triangles collapsed by welding",
            mesh.info.degenerate_triangles
        ));
    }
    repaired.extend(report.describe());
    let note = (!repaired.is_empty()).then(|| format!("{name}: {}", repaired.join("; ")));
    Ok(nonconvex_shape(polyhedron, mass, note))
}

/// Reads a mesh file and makes it a convex polyhedron; every message names the file.
fn mesh_shape(
    folder: &Path,
    file: &str,
    scale: f64,
    use_hull: bool,
) -> Result<(ConvexPolyhedron, MassProperties), ShapeBuildError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(ShapeBuildError::new(
            "scale",
            format!("scale = {scale} is not allowed: must be > 0 (metres per unit of the file)"),
        ));
    }
    let path = folder.join(file);
    let mesh = read_mesh(&path, scale).map_err(|e| ShapeBuildError::new("file", e.to_string()))?;
    let name = path.display();
    let hint = "set convex_hull = true to use the convex hull of its vertices";
    convex_from_mesh(&mesh.vertices, &mesh.triangles, use_hull)
        .map(|c| (c.polyhedron, c.mass))
        .map_err(|e| {
            let message = match e {
                MeshShapeError::NotConvex {
                    hull_excess,
                    deepest,
                } => {
                    let vertex = deepest
                        .map(|(index, p, depth)| {
                            format!(
                                "; vertex {index} at [{}, {}, {}] m lies {depth:.3e} m inside it",
                                p.x, p.y, p.z
                            )
                        })
                        .unwrap_or_default();
                    format!(
                        "{name} is not convex (its convex hull is {} % larger{vertex}): set \
                         nonconvex = true to use it as a non-convex particle, or convex_hull = \
                         true to use its hull",
                        percent(hull_excess)
                    )
                }
                MeshShapeError::Shape(ShapeError::TooFewPoints { count }) => format!(
                    "{name} has {count} distinct vertices (after welding those closer than {:e} \
                     of its size): a particle needs at least 4",
                    crate::geometry::weld::WELD_TOLERANCE
                ),
                MeshShapeError::Shape(
                    e @ (ShapeError::Coincident | ShapeError::Collinear | ShapeError::Coplanar),
                ) => format!("{name} has zero volume: {e}"),
                MeshShapeError::Shape(e) => format!("{name}: {e}"),
                e @ (MeshShapeError::NotClosed { .. } | MeshShapeError::Inconsistent { .. }) => {
                    format!("{name}: {e}; repair the mesh, or {hint}")
                }
                e @ MeshShapeError::SelfIntersecting { .. } => {
                    format!("{name}: {e}; repair the mesh, or {hint}")
                }
            };
            ShapeBuildError::new("file", message)
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
        let b = build_one(
            &ShapeSpec::Box {
                edges: [1.0, 2.0, 3.0],
            },
            Path::new(""),
        )
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
        let e = build_one(
            &ShapeSpec::Box {
                edges: [1.0, 0.0, 1.0],
            },
            Path::new(""),
        )
        .unwrap_err();
        assert_eq!(e.key, "edges");
        assert!(e.message.contains("edges[1]"));
        let e = build_one(
            &ShapeSpec::Hull {
                points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
            },
            Path::new(""),
        )
        .unwrap_err();
        assert_eq!(e.key, "points");
    }
}
