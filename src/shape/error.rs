//! Why a polyhedral shape could not be built.

use crate::math::DVec3;
use thiserror::Error;

#[derive(Clone, Debug, Error, PartialEq)]
pub enum ShapeError {
    #[error("a polyhedron needs at least 4 points, got {count}")]
    TooFewPoints { count: usize },

    #[error("point {index} is {point}: every coordinate must be a finite number")]
    NonFinite { index: usize, point: DVec3 },

    #[error("all points coincide: they enclose no volume")]
    Coincident,

    #[error("all points lie on one line: they enclose no volume")]
    Collinear,

    #[error("all points lie in one plane: they enclose no volume")]
    Coplanar,

    #[error(
        "face {face} has zero area ({area:e} for a shape {size:e} across): \
         some points nearly coincide; merge or remove near-duplicate points"
    )]
    DegenerateFace { face: usize, area: f64, size: f64 },

    #[error(
        "coplanar hull triangles around triangle {triangle} do not form one convex polygon; \
         the points are too close to degenerate (nearly coincident or nearly coplanar)"
    )]
    MalformedFace { triangle: usize },

    #[error(
        "the mesh encloses a volume of {volume:e} for a size of {size:e}: it is flat, \
         or its triangles face inward (they must be counter-clockwise seen from outside)"
    )]
    NonPositiveVolume { volume: f64, size: f64 },

    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has {count} vertices")]
    VertexIndexOutOfRange {
        triangle: usize,
        vertex: usize,
        count: usize,
    },

    #[error("invalid shape parameter: {0}")]
    InvalidParameter(String),
}
