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
        let max_cells = (4 * boxes.len()).max(64);
        let mut cell = largest.max(f64::MIN_POSITIVE);
        // (A span of ∞ − ∞ gives a NaN product, never too many: see `cells_along`.)
        let too_many =
            |cell: f64| (span / cell + DVec3::ONE).floor().element_product() > max_cells as f64;
        while cell.is_finite() && too_many(cell) {
            cell *= 1.5;
        }
        let [nx, ny, nz] = (span / cell).to_array().map(|s| cells_along(s, max_cells));
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

/// The number of cells along an axis, given the span over the cell's width: at least one and at
/// most `max` (for finite boxes the loop above has already made it so). An infinite ratio takes
/// the most and a NaN one (a span of ∞ − ∞: bodies that all lie at an infinite coordinate, which
/// stops that loop at once) one, so that no count overflows and every box is filed.
fn cells_along(span_over_cell: f64, max: usize) -> usize {
    if span_over_cell.is_nan() {
        return 1;
    }
    // `as` saturates: an infinite ratio is `usize::MAX` before the clamp.
    (span_over_cell.floor().max(0.0) as usize).min(max - 1) + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxed(min: [f64; 3], max: [f64; 3]) -> Aabb {
        Aabb {
            min: DVec3::from_array(min),
            max: DVec3::from_array(max),
        }
    }

    /// Regression: bodies that all lie at an infinite x, one of them also at an infinite y, gave
    /// the grid an x span of ∞ − ∞ (NaN) and a y span of ∞: the loop that widens the cells
    /// stopped at once (a NaN product is never too large), the infinite count of y cells
    /// saturated to `u32::MAX`, one more wrapped it to zero, and filing the first box indexed a
    /// grid of no cells.
    #[test]
    fn boxes_at_infinity_are_filed_without_a_panic() {
        let inf = f64::INFINITY;
        let boxes = [
            boxed([inf, 0.0, 0.0], [inf, 1.0, 1.0]),
            boxed([inf, inf, 0.0], [inf, inf, 1.0]),
            boxed([inf, 0.5, 0.5], [inf, 1.5, 1.5]),
        ];
        let mut pairs = Vec::new();
        CellGrid::default().find_pairs(&boxes, &mut pairs);
        assert!(pairs
            .iter()
            .all(|&(i, j)| i < j && (j as usize) < boxes.len()));
    }
}
