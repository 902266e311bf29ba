//! Building the triangle-mesh walls of a scene (`[[mesh_wall]]`).

use super::format::{FacingSpec, MotionSpec, WallGenerator};
use super::{KeyPath, Scene, SceneError};
use crate::math::{DQuat, DVec3};
use crate::wall::{
    generators, Ends, Facing, Hand, MeshWall, MotionError, Screw, TriMesh, WallMotion,
};

/// Every `[[mesh_wall]]` of the scene, placed.
pub fn build(scene: &Scene) -> Result<Vec<MeshWall>, SceneError> {
    let mut walls = Vec::new();
    for (n, spec) in scene.spec.mesh_walls.iter().enumerate() {
        let key = |k: &str| KeyPath::entry("mesh_wall", n).key(k);
        let material = scene.material_index(&spec.material, key("material"))?;
        let mesh = match (&spec.file, &spec.generator) {
            (Some(file), None) => {
                let path = super::shapes::scene_folder(scene).join(file);
                let imported = crate::io::mesh::read_mesh(&path, 1.0)
                    .map_err(|e| scene.error(key("file"), e.to_string()))?;
                TriMesh {
                    vertices: imported.vertices,
                    triangles: imported
                        .triangles
                        .iter()
                        .map(|t| t.map(|i| i as u32))
                        .collect(),
                }
            }
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
            wall.motion =
                motion(m).map_err(|(k, e)| scene.error(key(&format!("motion.{k}")), e))?;
        }
        walls.push(wall);
    }
    Ok(walls)
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
    match (m.rpm, m.axis) {
        (Some(rpm), Some(axis)) => {
            motion = motion
                .with_rotation(DVec3::from(m.axis_point), DVec3::from(axis), rpm)
                .map_err(fail("axis"))?
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
                "an `axis` is given without `rpm`: how fast does it turn?".into(),
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
            tube_clearance,
        }),
    }
}
