//! Welding: merging the near-duplicate vertices of a triangle mesh, so that triangles that meet
//! share vertex indices (mesh files repeat every corner per triangle, generators build meshes
//! from separate pieces). Whatever reads or builds a mesh, and whatever needs its adjacency,
//! welds it here.

use super::point_in_polyhedron::bounds_of;
use crate::math::{Aabb, DVec3};
use std::collections::HashMap;

/// Vertices closer than this, relative to the diagonal of the mesh's bounding box, are welded.
pub const WELD_TOLERANCE: f64 = 1e-9;

/// A mesh with near-duplicate vertices merged.
#[derive(Clone, Debug, PartialEq)]
pub struct Welded {
    /// The vertices kept, in order of first use.
    pub vertices: Vec<DVec3>,
    /// The triangles with at least three distinct corners left, re-indexed.
    pub triangles: Vec<[usize; 3]>,
    /// Vertices merged into a kept one that they were not bit-identical to.
    pub near_duplicates: usize,
}

/// Merges each vertex into the first earlier one closer than `relative_tolerance` × the diagonal
/// of the bounding box of all `vertices`, and drops triangles left with a repeated corner.
/// Vertices no triangle uses are dropped too.
///
/// A uniform grid of cells as wide as the tolerance finds the candidates: a vertex's match lies in
/// its own cell or one of the 26 around it. Merging into the first match (not clustering) keeps
/// every kept vertex where the file put it and makes the result independent of hashing order.
pub fn weld(vertices: &[DVec3], triangles: &[[usize; 3]], relative_tolerance: f64) -> Welded {
    let Aabb { min: lo, max: hi } = bounds_of(vertices, triangles);
    let tolerance = relative_tolerance * (hi - lo).length();
    // With a zero tolerance (all points equal, or none) only exact copies merge: one cell.
    let cell_of = |v: DVec3| -> [i64; 3] {
        if tolerance > 0.0 {
            let c = ((v - lo) / tolerance).floor();
            [c.x as i64, c.y as i64, c.z as i64]
        } else {
            [0; 3]
        }
    };
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut kept: Vec<DVec3> = Vec::new();
    let mut new_index: HashMap<usize, usize> = HashMap::new();
    let mut near_duplicates = 0;
    let mut welded_triangles = Vec::with_capacity(triangles.len());
    for triangle in triangles {
        let mut corners = [0; 3];
        for (k, &old) in triangle.iter().enumerate() {
            if let Some(&new) = new_index.get(&old) {
                corners[k] = new;
                continue;
            }
            let v = vertices[old];
            let cell = cell_of(v);
            // The earliest kept vertex within the tolerance, wherever the cells are stored.
            let mut found: Option<usize> = None;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let near = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                        for &candidate in grid.get(&near).into_iter().flatten() {
                            let distance = (kept[candidate] - v).length();
                            if (distance < tolerance || kept[candidate] == v)
                                && found.is_none_or(|f| candidate < f)
                            {
                                found = Some(candidate);
                            }
                        }
                    }
                }
            }
            let new = match found {
                Some(candidate) => {
                    if kept[candidate] != v {
                        near_duplicates += 1;
                    }
                    candidate
                }
                None => {
                    kept.push(v);
                    grid.entry(cell).or_default().push(kept.len() - 1);
                    kept.len() - 1
                }
            };
            new_index.insert(old, new);
            corners[k] = new;
        }
        if corners[0] != corners[1] && corners[1] != corners[2] && corners[0] != corners[2] {
            welded_triangles.push(corners);
        }
    }
    // Drop vertices that only degenerate triangles used, keeping the order of first use.
    let mut used = vec![false; kept.len()];
    for &i in welded_triangles.iter().flatten() {
        used[i] = true;
    }
    if used.iter().all(|&u| u) {
        return Welded {
            vertices: kept,
            triangles: welded_triangles,
            near_duplicates,
        };
    }
    let mut renumber = vec![usize::MAX; kept.len()];
    let mut vertices_out = Vec::new();
    for (i, v) in kept.iter().enumerate() {
        if used[i] {
            renumber[i] = vertices_out.len();
            vertices_out.push(*v);
        }
    }
    Welded {
        vertices: vertices_out,
        triangles: welded_triangles
            .iter()
            .map(|t| t.map(|i| renumber[i]))
            .collect(),
        near_duplicates,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_merges_near_copies_and_drops_collapsed_triangles() {
        let e = 1e-12;
        let vertices = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(e, 0.0, 0.0), // a near copy of 0
            DVec3::X,                // an exact copy of 1
            DVec3::Z,
            DVec3::new(0.5, 0.5, 0.5), // used only by a collapsed triangle
        ];
        let triangles = [[0, 1, 2], [3, 4, 5], [0, 3, 6]];
        let w = weld(&vertices, &triangles, WELD_TOLERANCE);
        assert_eq!(w.vertices, vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]);
        assert_eq!(w.triangles, vec![[0, 1, 2], [0, 1, 3]]);
        assert_eq!(w.near_duplicates, 1);
        // Points farther apart than the tolerance stay apart.
        let apart = weld(&vertices, &triangles, 1e-13);
        assert_eq!(apart.vertices.len(), 6);
    }
}
