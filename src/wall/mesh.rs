//! Triangle-mesh walls: triangle meshes that bodies collide with, fixed or moving.
//!
//! A [`MeshWall`] is a [`TriangleMesh`] (triangles, normals, adjacency, grid: `geometry::
//! triangle_mesh`) with what makes it a wall: its material, its prescribed motion and where that
//! motion has put it now. The mesh is kept in the wall's reference placement (time 0); the
//! contact routines take a body into that placement by the wall's pose.

use super::motion::{WallMotion, WallPose};
use crate::geometry::triangle_mesh::{TriangleMesh, TriangleMeshError};
use crate::material::MaterialId;
use crate::math::{is_finite_vec, DQuat, DVec3};
use std::ops::Deref;
use thiserror::Error;

/// Why a mesh wall could not be built.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MeshWallError {
    #[error("mesh wall {0}")]
    Mesh(#[from] TriangleMeshError),
    #[error("scale = {scale} is not allowed: must be a finite number > 0")]
    Scale { scale: f64 },
    #[error("the rotation of a mesh wall must be a finite unit quaternion")]
    Rotation,
    #[error("the translation of a mesh wall must be finite")]
    Translation,
}

/// A wall made of triangles. Its geometric queries are those of its [`TriangleMesh`], reached
/// through `Deref` (`wall.corners(t)`, `wall.triangles_near(..)`): a wall *is* its surface, plus
/// a material and a motion.
#[derive(Clone, Debug)]
pub struct MeshWall {
    surface: TriangleMesh,
    pub material: MaterialId,
    /// How the wall moves; its triangles are in the placement of time 0.
    pub motion: WallMotion,
    /// Where the wall is now (see [`MeshWall::set_time`]).
    pose: WallPose,
}

impl Deref for MeshWall {
    type Target = TriangleMesh;

    fn deref(&self) -> &TriangleMesh {
        &self.surface
    }
}

impl MeshWall {
    /// Builds a fixed wall from vertices and triangles (indices into `vertices`, counter-clockwise
    /// seen from the side bodies live on); see [`TriangleMesh::new`].
    pub fn new(
        vertices: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        material: MaterialId,
    ) -> Result<Self, MeshWallError> {
        Ok(Self {
            surface: TriangleMesh::new(vertices, triangles)?,
            material,
            motion: WallMotion::fixed(),
            pose: WallPose::IDENTITY,
        })
    }

    /// The wall with every vertex x moved to `rotation * (scale * x) + translation`.
    pub fn transformed(
        &self,
        scale: f64,
        rotation: DQuat,
        translation: DVec3,
    ) -> Result<Self, MeshWallError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(MeshWallError::Scale { scale });
        }
        if !(rotation.is_finite() && (rotation.length() - 1.0).abs() < 1e-9) {
            return Err(MeshWallError::Rotation);
        }
        if !is_finite_vec(translation) {
            return Err(MeshWallError::Translation);
        }
        Ok(Self {
            surface: self.surface.transformed(scale, rotation, translation)?,
            material: self.material,
            motion: self.motion.clone(),
            pose: WallPose::IDENTITY,
        })
    }

    /// See [`TriangleMesh::smooth_angle`].
    pub fn set_smooth_angle(&mut self, angle: f64) {
        self.surface.set_smooth_angle(angle);
    }

    /// Where the wall is now: reference placement → world.
    pub fn pose(&self) -> WallPose {
        self.pose
    }

    /// Moves the wall to where its motion puts it at time `t`.
    pub fn set_time(&mut self, t: f64) {
        self.pose = self.motion.pose(t);
    }

    /// The vertices where the wall is now.
    pub fn current_vertices(&self) -> impl Iterator<Item = DVec3> + '_ {
        let pose = self.pose;
        self.vertices().iter().map(move |&v| pose.to_world(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        (
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn a_wall_keeps_its_material() {
        let (v, t) = square();
        let w = MeshWall::new(v, t, 3).unwrap();
        assert_eq!(w.material, 3);
    }

    #[test]
    fn errors_name_the_mesh_wall() {
        let (v, _) = square();
        let err = MeshWall::new(v, vec![[0, 1, 2], [0, 1, 1]], 0).unwrap_err();
        assert_eq!(
            err,
            MeshWallError::Mesh(TriangleMeshError::RepeatedCorner {
                triangle: 1,
                index: 1
            })
        );
        assert_eq!(err.to_string(), "mesh wall triangle 1 uses vertex 1 twice");
    }

    #[test]
    fn transformed_scales_rotates_translates() {
        let (v, t) = square();
        let w = MeshWall::new(v, t, 0).unwrap();
        let q = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let moved = w.transformed(2.0, q, DVec3::new(0.0, 0.0, 5.0)).unwrap();
        assert!((moved.vertices()[2] - DVec3::new(2.0, 0.0, 7.0)).length() < 1e-12);
        assert!((moved.normals()[0] - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12);
        assert!((moved.area() - 4.0).abs() < 1e-12);
        assert!(w.transformed(0.0, q, DVec3::ZERO).is_err());
        assert!(w
            .transformed(1.0, DQuat::from_xyzw(0.0, 0.0, 0.0, 2.0), DVec3::ZERO)
            .is_err());
    }
}
