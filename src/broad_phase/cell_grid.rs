use super::{BroadPhase, Pair};
use crate::math::{Aabb, DVec3};

/// Linked-cell list (Allen & Tildesley 1987, §5.3): space is cut into cubic cells at least as
/// large as the largest box, each box is filed under the cell of its lower corner, and a box can
/// only overlap boxes filed in its own or the 26 neighbouring cells. Cost O(n) for bodies of
/// similar size; wide size ranges make cells large and the method slow (the LLL's strength).
#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    /// Bodies sorted by cell (counting sort), and where each cell's run starts.
    sorted: Vec<u32>,
    cell_start: Vec<u32>,
    cell_of: Vec<u32>,
    fill: Vec<u32>,
}

impl BroadPhase for CellGrid {
    fn find_pairs(&mut self, boxes: &[Aabb], pairs: &mut Vec<Pair>) {
        pairs.clear();
        if boxes.len() < 2 {
            return;
        }
        let mut bounds = boxes[0];
        let mut largest: f64 = 0.0;
        for b in boxes {
            bounds = bounds.union(b);
            largest = largest.max(b.extent().max_element());
        }
        let span = bounds.extent();
        // Cells no smaller than the largest box, and no more cells than a few per body so memory
        // stays O(n) however dilute the scene.
        let max_cells = (4 * boxes.len()).max(64) as f64;
        let mut cell = largest.max(f64::MIN_POSITIVE);
        while (span / cell + DVec3::ONE).floor().element_product() > max_cells {
            cell *= 1.5;
        }
        let dims = (span / cell).floor().as_uvec3() + glam::UVec3::ONE;
        let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
        let index = |p: DVec3| -> (usize, usize, usize) {
            let c = ((p - bounds.min) / cell).floor();
            (
                (c.x as usize).min(nx - 1),
                (c.y as usize).min(ny - 1),
                (c.z as usize).min(nz - 1),
            )
        };

        self.cell_start.clear();
        self.cell_start.resize(nx * ny * nz + 1, 0);
        self.cell_of.clear();
        for b in boxes {
            let (x, y, z) = index(b.min);
            let id = (z * ny + y) * nx + x;
            self.cell_of.push(id as u32);
            self.cell_start[id + 1] += 1;
        }
        for c in 1..self.cell_start.len() {
            self.cell_start[c] += self.cell_start[c - 1];
        }
        self.sorted.clear();
        self.sorted.resize(boxes.len(), 0);
        self.fill.clone_from(&self.cell_start);
        for (body, &c) in self.cell_of.iter().enumerate() {
            self.sorted[self.fill[c as usize] as usize] = body as u32;
            self.fill[c as usize] += 1;
        }

        for (i, a) in boxes.iter().enumerate() {
            let (x, y, z) = index(a.min);
            for cz in z.saturating_sub(1)..=(z + 1).min(nz - 1) {
                for cy in y.saturating_sub(1)..=(y + 1).min(ny - 1) {
                    for cx in x.saturating_sub(1)..=(x + 1).min(nx - 1) {
                        let c = (cz * ny + cy) * nx + cx;
                        let run = self.cell_start[c] as usize..self.cell_start[c + 1] as usize;
                        for &j in &self.sorted[run] {
                            if (j as usize) > i && a.overlaps(&boxes[j as usize]) {
                                pairs.push((i as u32, j));
                            }
                        }
                    }
                }
            }
        }
        pairs.sort_unstable();
    }

    fn name(&self) -> &'static str {
        "cell_grid"
    }
}
