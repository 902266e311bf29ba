//! Building the triangle-mesh walls of a scene (`[[mesh_wall]]`).

use super::format::{FacingSpec, MotionSpec, ScrewPartSpec, WallGenerator};
use super::{KeyPath, Scene, SceneError};
use crate::math::{DQuat, DVec3};
use crate::wall::{
    generators, Casing, Ends, Facing, Hand, MeshWall, MotionError, Screw, ScrewPart, TriMesh,
    WallMotion,
};

/// Every `[[mesh_wall]]` of the scene, placed.
pub fn build(scene: &Scene) -> Result<Vec<MeshWall>, SceneError> {
    let mut walls = Vec::new();
    for (n, spec) in scene.spec.mesh_walls.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("mesh_wall", n).key(k);
        let material = scene.material_index(&spec.material, key("material"))?;
        let mesh =
            match (&spec.file, &spec.generator) {
                (Some(file), None) => {
                    let path = super::shapes::scene_folder(scene).join(file);
                    let imported = crate::io::mesh::read_mesh(&path, 1.0)
                        .map_err(|e| scene.error(key("file"), e.to_string()))?;
                    TriMesh {
                        vertices: imported.vertices,
                        triangles: imported
                            .triangles
                            .iter()
                            .map(|&[a, b, c]| {
                                // Two corners swapped turn the triangle over.
                                let t = if spec.flip { [a, c, b] } else { [a, b, c] };
                                t.map(|i| i as u32)
                            })
                            .collect(),
                    }
                }
                (None, Some(_)) if spec.flip => return Err(scene.error(
                    key("flip"),
                    "`flip` turns the triangles of a mesh file; a generated wall faces the way \
                     its `facing` says",
                )),
                (None, Some(generator)) => {
                    generate(generator).map_err(|e| scene.error(key("generator"), e.0))?
                }
                _ => {
                    return Err(scene.error(
                        key("file"),
                        "give exactly one of `file` (an STL or OBJ mesh) and `generator`",
                    ))
                }
            };
        let placed = mesh.transformed(
            spec.scale,
            DQuat::from_scaled_axis(DVec3::from(spec.rotation)),
            DVec3::from(spec.translation),
        );
        let mut wall = placed
            .into_wall(material)
            .map_err(|e| scene.error(key("file"), e.to_string()))?;
        if let Some(m) = &spec.motion {
            if m.rpm.is_some() && turns_its_casing(spec.generator.as_ref()) {
                return Err(scene.error(
                    key("generator.part"),
                    "this screw's tube or trough would turn with it: set `part = \"screw\"` \
                     here and add the casing as a fixed [[mesh_wall]] with the same generator and \
                     `part = \"casing\"` (a tube that really turns with its screw: a separate \
                     `cylinder` wall with the same motion)",
                ));
            }
            wall.motion =
                motion(m).map_err(|(k, e)| scene.error(key(&format!("motion.{k}")), e))?;
        }
        walls.push(wall);
    }
    Ok(walls)
}

/// True for a screw generator that makes the flight and its casing in one wall.
fn turns_its_casing(generator: Option<&WallGenerator>) -> bool {
    matches!(
        generator,
        Some(WallGenerator::Screw {
            part: ScrewPartSpec::All,
            tube_clearance,
            trough_clearance,
            ..
        }) if tube_clearance.is_some() || trough_clearance.is_some()
    )
}

/// The motion of a `[mesh_wall.motion]` table, or the key at fault and why.
fn motion(m: &MotionSpec) -> Result<WallMotion, (&'static str, String)> {
    let mut motion = WallMotion::fixed();
    let fail = |k: &'static str| move |e: MotionError| (k, e.to_string());
    match (m.velocity, &m.velocity_table) {
        (Some(_), Some(_)) => {
            return Err((
                "velocity_table",
                "give either `velocity` (constant) or `velocity_table`, not both".into(),
            ))
        }
        (Some(v), None) => {
            motion = motion
                .with_velocity(DVec3::from(v))
                .map_err(fail("velocity"))?
        }
        (None, Some(rows)) => {
            let table = rows
                .iter()
                .map(|r| (r[0], DVec3::new(r[1], r[2], r[3])))
                .collect();
            motion = motion
                .with_velocity_table(table)
                .map_err(fail("velocity_table"))?;
        }
        (None, None) => {}
    }
    let rates = match (m.rpm, &m.rpm_table) {
        (Some(_), Some(_)) => {
            return Err((
                "rpm_table",
                "give either `rpm` (constant) or `rpm_table`, not both".into(),
            ))
        }
        (Some(rpm), None) => Some(("rpm", vec![(0.0, rpm)])),
        (None, Some(rows)) => Some(("rpm_table", rows.iter().map(|r| (r[0], r[1])).collect())),
        (None, None) => None,
    };
    match (rates, m.axis) {
        (Some((key, table)), Some(axis)) => {
            let point = DVec3::from(m.axis_point);
            motion = motion
                .with_rotation_table(point, DVec3::from(axis), table)
                .map_err(|e| match e {
                    MotionError::Axis => ("axis", e.to_string()),
                    MotionError::NonFinite => ("axis_point", e.to_string()),
                    e => (key, e.to_string()),
                })?
        }
        (Some(_), None) => {
            return Err((
                "axis",
                "a rotating wall needs its `axis` (and `axis_point`, default the origin)".into(),
            ))
        }
        (None, Some(_)) => {
            return Err((
                "rpm",
                "an `axis` is given without `rpm` or `rpm_table`: how fast does it turn?".into(),
            ))
        }
        (None, None) => {}
    }
    if let Some(v) = m.surface_velocity {
        motion = motion
            .with_surface_velocity(DVec3::from(v))
            .map_err(fail("surface_velocity"))?;
    }
    Ok(motion)
}

fn facing(f: FacingSpec) -> Facing {
    match f {
        FacingSpec::Inward => Facing::Inward,
        FacingSpec::Outward => Facing::Outward,
    }
}

fn ends(closed: bool) -> Ends {
    if closed {
        Ends::Closed
    } else {
        Ends::Open
    }
}

/// A screw's casing from its keys: a tube or a trough (whose sides reach, unless told, as high
/// above the axis as its radius), or none.
fn casing(
    flight_radius: f64,
    tube_clearance: Option<f64>,
    trough_clearance: Option<f64>,
    trough_height: Option<f64>,
) -> Result<Casing, generators::GeneratorError> {
    let error = |m: &str| Err(generators::GeneratorError(m.into()));
    match (tube_clearance, trough_clearance, trough_height) {
        (Some(_), Some(_), _) => error(
            "give either `tube_clearance` (a tube round the screw) or `trough_clearance` \
             (a trough open towards +y), not both",
        ),
        (_, None, Some(_)) => error("`trough_height` is given without `trough_clearance`"),
        (Some(clearance), None, None) => Ok(Casing::Tube { clearance }),
        (None, Some(clearance), height) => Ok(Casing::Trough {
            clearance,
            height: height.unwrap_or(flight_radius + clearance),
        }),
        (None, None, None) => Ok(Casing::None),
    }
}

fn generate(g: &WallGenerator) -> Result<TriMesh, generators::GeneratorError> {
    match *g {
        WallGenerator::Rectangle {
            origin,
            u,
            v,
            divisions,
        } => generators::rectangle(
            DVec3::from(origin),
            DVec3::from(u),
            DVec3::from(v),
            divisions[0],
            divisions[1],
        ),
        WallGenerator::Box {
            min,
            max,
            divisions,
            facing: f,
        } => generators::box_mesh(DVec3::from(min), DVec3::from(max), divisions, facing(f)),
        WallGenerator::Cylinder {
            radius,
            height,
            segments,
            rings,
            closed,
            facing: f,
        } => generators::cylinder(radius, height, segments, rings, ends(closed), facing(f)),
        WallGenerator::Frustum {
            bottom_radius,
            top_radius,
            height,
            segments,
            rings,
            closed,
            facing: f,
        } => generators::frustum(
            bottom_radius,
            top_radius,
            height,
            segments,
            rings,
            ends(closed),
            facing(f),
        ),
        WallGenerator::Screw {
            shaft_radius,
            flight_radius,
            pitch,
            turns,
            thickness,
            left_handed,
            segments_per_turn,
            radial_segments,
            shaft,
            tube_clearance,
            trough_clearance,
            trough_height,
            part,
        } => generators::screw(&Screw {
            shaft_radius,
            flight_radius,
            pitch,
            turns,
            thickness,
            hand: if left_handed { Hand::Left } else { Hand::Right },
            segments_per_turn,
            radial_segments,
            shaft,
            casing: casing(
                flight_radius,
                tube_clearance,
                trough_clearance,
                trough_height,
            )?,
            part: match part {
                ScrewPartSpec::All => ScrewPart::All,
                ScrewPartSpec::Screw => ScrewPart::Screw,
                ScrewPartSpec::Casing => ScrewPart::Casing,
            },
        }),
    }
}
