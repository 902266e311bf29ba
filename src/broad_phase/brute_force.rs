use super::{BroadPhase, Pair};
use crate::math::Aabb;

/// Tests every pair: O(n²). The reference the other methods are checked against.
#[derive(Clone, Copy, Debug, Default)]
pub struct BruteForce;

impl BroadPhase for BruteForce {
    fn find_pairs(&mut self, boxes: &[Aabb], pairs: &mut Vec<Pair>) {
        pairs.clear();
        for (i, a) in boxes.iter().enumerate() {
            for (j, b) in boxes.iter().enumerate().skip(i + 1) {
                if a.overlaps(b) {
                    pairs.push((i as u32, j as u32));
                }
            }
        }
    }

    fn name(&self) -> &'static str {
        "brute_force"
    }
}
