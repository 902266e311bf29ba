//! Building the triangle-mesh walls of a scene (`[[mesh_wall]]`).

use super::format::{FacingSpec, WallGenerator};
use super::{KeyPath, Scene, SceneError};
use crate::math::{DQuat, DVec3};
use crate::wall::{generators, Ends, Facing, Hand, MeshWall, Screw, TriMesh};

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
        let wall = placed
            .into_wall(material)
            .map_err(|e| scene.error(key("file"), e.to_string()))?;
        walls.push(wall);
    }
    Ok(walls)
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
