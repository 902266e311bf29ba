//! A uniform grid of a triangle mesh's triangles, queried by boxes: "which triangles are near this
//! body". Used by [`TriangleMesh`](super::triangle_mesh::TriangleMesh).

use super::compressed_rows::compressed_rows;
use crate::math::{Aabb, DVec3};

/// The bounding box of triangle `tri`.
pub fn triangle_bounds(vertices: &[DVec3], tri: &[u32; 3]) -> Aabb {
    let [a, b, c] = tri.map(|i| vertices[i as usize]);
    Aabb::new(a.min(b).min(c), a.max(b).max(c))
}

/// A uniform grid over the mesh's bounding box; each cell lists the triangles whose bounding box
/// overlaps it. The cell width is the mean largest extent of a triangle's bounding box (at least
/// 1/256 of the largest extent of the mesh, so the grid has at most 256 cells along an axis).
#[derive(Clone, Debug)]
pub struct TriangleGrid {
    origin: DVec3,
    inverse_cell: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
    /// Each triangle's bounding box: a query returns only the triangles whose box meets it, not
    /// every triangle of the cells it covers (cells are as large as the largest triangles, so on
    /// a mesh of mixed sizes a cell can hold many small ones far from the query).
    boxes: Vec<Aabb>,
}

impl TriangleGrid {
    const MAX_CELLS_PER_AXIS: usize = 256;

    /// The grid of `triangles` (indices into `vertices`), all inside `bounds`.
    pub fn new(vertices: &[DVec3], triangles: &[[u32; 3]], bounds: Aabb) -> Self {
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| triangle_bounds(vertices, t))
            .collect();
        let mean = boxes.iter().map(|b| b.extent().max_element()).sum::<f64>() / boxes.len() as f64;
        let extent = bounds.extent();
        let largest = extent.max_element();
        let cell = mean
            .max(largest / Self::MAX_CELLS_PER_AXIS as f64)
            .max(f64::MIN_POSITIVE);
        let dims = [extent.x, extent.y, extent.z]
            .map(|e| ((e / cell).floor() as usize + 1).min(Self::MAX_CELLS_PER_AXIS));
        let mut grid = Self {
            origin: bounds.min,
            inverse_cell: 1.0 / cell,
            dims,
            start: Vec::new(),
            items: Vec::new(),
            boxes: Vec::new(),
        };
        let count = dims[0] * dims[1] * dims[2];
        let pairs: Vec<(u32, u32)> = boxes
            .iter()
            .enumerate()
            .flat_map(|(t, b)| {
                let (lo, hi) = grid
                    .cell_range(b)
                    .expect("a triangle lies inside the mesh bounds");
                let dims = grid.dims;
                (lo[2]..=hi[2]).flat_map(move |k| {
                    (lo[1]..=hi[1]).flat_map(move |j| {
                        (lo[0]..=hi[0])
                            .map(move |i| (((k * dims[1] + j) * dims[0] + i) as u32, t as u32))
                    })
                })
            })
            .collect();
        let (start, items) = compressed_rows(count, pairs.iter().copied());
        grid.start = start;
        grid.items = items;
        grid.boxes = boxes;
        grid
    }

    /// The cells a box covers (clamped to the grid), or `None` if it misses the grid.
    fn cell_range(&self, b: &Aabb) -> Option<([usize; 3], [usize; 3])> {
        let lo = (b.min - self.origin) * self.inverse_cell;
        let hi = (b.max - self.origin) * self.inverse_cell;
        let mut out_lo = [0usize; 3];
        let mut out_hi = [0usize; 3];
        for a in 0..3 {
            let n = self.dims[a] as f64;
            // Closed intervals: a box touching the grid's far face still meets the last cell.
            if !(hi[a] >= 0.0 && lo[a] <= n) {
                return None;
            }
            out_lo[a] = (lo[a].max(0.0).floor() as usize).min(self.dims[a] - 1);
            out_hi[a] = (hi[a].max(0.0).floor() as usize).min(self.dims[a] - 1);
        }
        Some((out_lo, out_hi))
    }

    /// Appends to `out` the triangles whose boxes overlap `b`, then sorts `out` and drops repeats.
    pub fn query(&self, b: &Aabb, out: &mut Vec<u32>) {
        let Some((lo, hi)) = self.cell_range(b) else {
            return;
        };
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    let c = (k * self.dims[1] + j) * self.dims[0] + i;
                    out.extend(
                        self.items[self.start[c] as usize..self.start[c + 1] as usize]
                            .iter()
                            .filter(|&&t| self.boxes[t as usize].overlaps(b)),
                    );
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Whether any triangle's box overlaps `b` (as [`TriangleGrid::query`] without the list).
    pub fn any(&self, b: &Aabb) -> bool {
        let Some((lo, hi)) = self.cell_range(b) else {
            return false;
        };
        (lo[2]..=hi[2]).any(|k| {
            (lo[1]..=hi[1]).any(|j| {
                (lo[0]..=hi[0]).any(|i| {
                    let c = (k * self.dims[1] + j) * self.dims[0] + i;
                    self.items[self.start[c] as usize..self.start[c + 1] as usize]
                        .iter()
                        .any(|&t| self.boxes[t as usize].overlaps(b))
                })
            })
        })
    }
}
