//! The volume contact of one region of a mesh wall, summed from the pieces of the body cut by
//! its triangles' cells (divergence-theorem sums over the pieces' boundary polygons).

use super::super::convex_convex::VolumeContact;
use super::{Class, Piece};
use crate::math::DVec3;

/// Divergence-theorem sums over boundary polygons, tetrahedra from a reference point `r`.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Sums {
    pub(super) six_volume: f64,
    pub(super) moment: DVec3,
    pub(super) vector_area: DVec3,
}

impl Sums {
    /// Adds a boundary polygon with outward unit `normal`; returns its area.
    pub(super) fn add(&mut self, polygon: &[DVec3], normal: DVec3, r: DVec3) -> f64 {
        let p0 = polygon[0] - r;
        let mut doubled = DVec3::ZERO;
        for w in polygon[1..].windows(2) {
            let (p1, p2) = (w[0] - r, w[1] - r);
            let v = p0.dot(p1.cross(p2));
            self.six_volume += v;
            self.moment += v * (p0 + p1 + p2);
            doubled += (p1 - p0).cross(p2 - p0);
        }
        // Only the polygon's own normal direction counts (exact direction, fan round-off dropped).
        let area = 0.5 * doubled.dot(normal);
        self.vector_area += area * normal;
        area
    }
}

/// The volume contact of one region: the sums of its pieces.
pub(super) fn region_contact(
    pieces: &[Piece],
    classes: &[Class],
    region: usize,
    x: DVec3,
    tolerance: f64,
) -> Option<VolumeContact> {
    let (mut volume, mut moment, mut area, mut potential) = (0.0, DVec3::ZERO, 0.0, 0.0);
    for piece in pieces.iter().filter(|p| classes[p.class].parent == region) {
        volume += piece.volume;
        moment += piece.moment;
        area += piece.area;
        potential += piece.potential;
    }
    if !(volume > 0.0 && area > 0.0) {
        return None;
    }
    let depth = volume / area;
    if depth.is_nan() || depth <= tolerance {
        return None;
    }
    let centroid = moment / volume;
    // Load Σ V n and its moment about the centroid, class by class: a flat region is one class,
    // whose load passes through the centroid exactly.
    let (mut load, mut couple, mut count) = (DVec3::ZERO, DVec3::ZERO, 0);
    for (c, class) in classes.iter().enumerate() {
        if class.parent != region || !class.touched {
            continue;
        }
        let (mut v, mut m) = (0.0, DVec3::ZERO);
        for piece in pieces.iter().filter(|p| p.class == c) {
            v += piece.volume;
            m += piece.moment;
        }
        load += v * class.face.normal;
        couple += (m - v * centroid).cross(class.face.normal);
        count += 1;
    }
    if count == 1 {
        couple = DVec3::ZERO;
    }
    let normal = load.try_normalize()?;
    Some(VolumeContact {
        volume,
        centroid: x + centroid,
        normal,
        area,
        depth,
        load,
        couple,
        potential,
    })
}
