//! Broad phase: which pairs of bodies are close enough to need collision detection.
//!
//! Every method answers the same question — the pairs whose axis-aligned boxes overlap — so they
//! are interchangeable and testable against each other; [`BruteForce`] is the reference.

mod brute_force;
mod cell_grid;
mod sweep_and_prune;

pub use brute_force::BruteForce;
pub use cell_grid::CellGrid;
pub use sweep_and_prune::SweepAndPrune;

use crate::math::Aabb;

/// A pair of body indices with `.0 < .1`.
pub type Pair = (u32, u32);

pub trait BroadPhase: Send + Sync {
    /// Replaces `pairs` with every pair of boxes that overlap (touching counts), each once with
    /// the smaller index first, in ascending order (so later stages are deterministic).
    fn find_pairs(&mut self, boxes: &[Aabb], pairs: &mut Vec<Pair>);

    /// The bodies were renumbered: body `i` is now body `new_index[i]`, or left the world where
    /// it is [`GONE`] (the kept ones numbered `0..kept`). Returns whether the method follows, so
    /// that its next call repairs its state rather than starting afresh; if not, the caller
    /// builds a new one.
    fn renumber(&mut self, new_index: &[u32]) -> bool {
        let _ = new_index;
        false
    }

    /// `added` bodies were appended after the others. Returns whether the method follows (see
    /// [`BroadPhase::renumber`]).
    fn append(&mut self, added: usize) -> bool {
        let _ = added;
        false
    }

    fn name(&self) -> &'static str;
}

/// In a renumbering ([`BroadPhase::renumber`]), the new index of a body that left.
pub const GONE: u32 = u32::MAX;

/// The methods a scene file can choose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Insertion-sorted endpoint lists (Schinner's LLL), see [`SweepAndPrune`]. The default: it
    /// measures faster than the cell grid on dense packings and dilute gases alike, and much
    /// faster with wide size ranges (`docs/benchmarks.md`).
    #[default]
    SweepAndPrune,
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
            Method::SweepAndPrune => Box::new(SweepAndPrune::default()),
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

    /// A body on a coarse grid (multiples of 0.25) so that coincident coordinates and exactly
    /// touching boxes are common: centre in [0, 10]³, half extents per axis mostly 0–0.5 but up
    /// to 5 (size ratios 1:20 and more; 0 gives flat boxes and points).
    fn grid_body() -> impl Strategy<Value = ([i32; 3], [i32; 3])> {
        let half = prop_oneof![3 => 0..=2i32, 1 => 1..=20i32];
        (
            prop::array::uniform3(0..=40i32),
            prop::array::uniform3(half),
        )
    }

    #[derive(Clone, Debug)]
    enum Motion {
        /// Small move of one body along one axis, by -2..=2 grid steps.
        Jitter(prop::sample::Index, usize, i32),
        /// Jump anywhere (a "teleport").
        Jump(prop::sample::Index, [i32; 3]),
        Resize(prop::sample::Index, [i32; 3]),
        Add(([i32; 3], [i32; 3])),
        /// `swap_remove`, which also renumbers the last body.
        Remove(prop::sample::Index),
    }

    fn motion() -> impl Strategy<Value = Motion> {
        prop_oneof![
            12 => (any::<prop::sample::Index>(), 0..3usize, -2..=2i32)
                .prop_map(|(i, a, d)| Motion::Jitter(i, a, d)),
            1 => (any::<prop::sample::Index>(), prop::array::uniform3(0..=40i32))
                .prop_map(|(i, c)| Motion::Jump(i, c)),
            1 => (any::<prop::sample::Index>(), grid_body())
                .prop_map(|(i, (_, h))| Motion::Resize(i, h)),
            1 => grid_body().prop_map(Motion::Add),
            1 => any::<prop::sample::Index>().prop_map(Motion::Remove),
        ]
    }

    fn grid_boxes(bodies: &[([i32; 3], [i32; 3])]) -> Vec<Aabb> {
        let v = |a: [i32; 3]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64) * 0.25;
        bodies
            .iter()
            .map(|&(c, h)| Aabb::new(v(c) - v(h), v(c) + v(h)))
            .collect()
    }

    proptest! {
        /// Every method against brute force at every call of a run of motions: jitter, jumps,
        /// size changes, bodies added and removed (each with its own reused state).
        #[test]
        fn methods_match_brute_force_through_motion(
            initial in prop::collection::vec(grid_body(), 0..200),
            steps in prop::collection::vec(prop::collection::vec(motion(), 0..80), 1..12),
        ) {
            let mut bodies = initial;
            let mut methods: Vec<Box<dyn BroadPhase>> = vec![
                Box::new(SweepAndPrune::default()),
                Box::new(CellGrid::default()),
                // Many small regions (boxes up to 10 wide span up to 20 per axis) and regions
                // of a few boxes: frequent region changes, pairs shared by several regions.
                Box::new(SweepAndPrune::with_region_side(0.5)),
                Box::new(SweepAndPrune::with_region_side(1.75)),
                Box::new(SweepAndPrune::with_bodies_per_region(6)),
            ];
            let (mut expected, mut found) = (Vec::new(), Vec::new());
            for (call, step) in std::iter::once(&Vec::new()).chain(&steps).enumerate() {
                for m in step {
                    let n = bodies.len();
                    match m {
                        Motion::Jitter(i, a, d) if n > 0 => bodies[i.index(n)].0[*a] += d,
                        Motion::Jump(i, c) if n > 0 => bodies[i.index(n)].0 = *c,
                        Motion::Resize(i, h) if n > 0 => bodies[i.index(n)].1 = *h,
                        Motion::Add(b) => bodies.push(*b),
                        Motion::Remove(i) if n > 0 => {
                            bodies.swap_remove(i.index(n));
                        }
                        _ => {}
                    }
                }
                let boxes = grid_boxes(&bodies);
                BruteForce.find_pairs(&boxes, &mut expected);
                for (k, method) in methods.iter_mut().enumerate() {
                    method.find_pairs(&boxes, &mut found);
                    prop_assert_eq!(&found, &expected, "{} #{} at call {}", method.name(), k, call);
                }
            }
        }
    }

    #[test]
    fn sweep_and_prune_is_a_scene_method() {
        let m = Method::from_name("sweep_and_prune");
        assert_eq!(m, Some(Method::SweepAndPrune));
        assert_eq!(m.unwrap().build().name(), "sweep_and_prune");
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
