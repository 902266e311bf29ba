//! Broad phase: which pairs of bodies are close enough to need collision detection.
//!
//! Every method answers the same question — the pairs whose axis-aligned boxes overlap — so they
//! are interchangeable and testable against each other; [`BruteForce`] is the reference.

mod brute_force;
mod cell_grid;

pub use brute_force::BruteForce;
pub use cell_grid::CellGrid;

use crate::math::Aabb;

/// A pair of body indices with `.0 < .1`.
pub type Pair = (u32, u32);

pub trait BroadPhase: Send {
    /// Replaces `pairs` with every pair of boxes that overlap (touching counts), each once with
    /// the smaller index first, in ascending order (so later stages are deterministic).
    fn find_pairs(&mut self, boxes: &[Aabb], pairs: &mut Vec<Pair>);

    fn name(&self) -> &'static str;
}

/// The methods a scene file can choose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    #[default]
    CellGrid,
    BruteForce,
}

impl Method {
    /// The method of a scene-file name (`cell_grid`, `brute_force`, ...).
    pub fn from_name(name: &str) -> Option<Self> {
        serde::Deserialize::deserialize(
            serde::de::value::StrDeserializer::<serde::de::value::Error>::new(name),
        )
        .ok()
    }

    pub fn build(self) -> Box<dyn BroadPhase> {
        match self {
            Method::CellGrid => Box::new(CellGrid::default()),
            Method::BruteForce => Box::new(BruteForce),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use proptest::prelude::*;

    fn boxes_from(spheres: &[(f64, f64, f64, f64)]) -> Vec<Aabb> {
        spheres
            .iter()
            .map(|&(x, y, z, r)| Aabb::around_sphere(DVec3::new(x, y, z), r))
            .collect()
    }

    proptest! {
        #[test]
        fn cell_grid_matches_brute_force(
            spheres in prop::collection::vec(
                (-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64, 0.05..1.0f64), 0..120)
        ) {
            let boxes = boxes_from(&spheres);
            let (mut expected, mut found) = (Vec::new(), Vec::new());
            BruteForce.find_pairs(&boxes, &mut expected);
            let mut grid = CellGrid::default();
            grid.find_pairs(&boxes, &mut found);
            prop_assert_eq!(&found, &expected);
            // A second call reuses the grid's buffers and must give the same answer.
            grid.find_pairs(&boxes, &mut found);
            prop_assert_eq!(found, expected);
        }
    }

    #[test]
    fn touching_boxes_are_a_pair() {
        let boxes = boxes_from(&[
            (0.0, 0.0, 0.0, 0.5),
            (1.0, 0.0, 0.0, 0.5),
            (3.0, 0.0, 0.0, 0.5),
        ]);
        let mut pairs = Vec::new();
        CellGrid::default().find_pairs(&boxes, &mut pairs);
        assert_eq!(pairs, vec![(0, 1)]);
    }
}
