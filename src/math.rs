//! Vector, quaternion and matrix types used throughout polydem.
//!
//! We use `glam`'s `f64` types directly: they are small, `Copy`, and SIMD-friendly. Pinned to the
//! same minor version as `parry3d-f64` so that later geometry code can share them.

pub use glam::{DMat3, DQuat, DVec3};

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    pub fn around_sphere(centre: DVec3, radius: f64) -> Self {
        let r = DVec3::splat(radius);
        Self::new(centre - r, centre + r)
    }

    /// Closed-interval overlap test: boxes that only touch count as overlapping, so that
    /// bodies exactly in contact are never missed by a broad phase.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.x <= other.max.x
            && other.min.x <= self.max.x
            && self.min.y <= other.max.y
            && other.min.y <= self.max.y
            && self.min.z <= other.max.z
            && other.min.z <= self.max.z
    }

    pub fn enlarged(&self, margin: f64) -> Self {
        let m = DVec3::splat(margin);
        Self::new(self.min - m, self.max + m)
    }

    /// True when `p` is inside or on the box.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    pub fn union(&self, other: &Aabb) -> Self {
        Self::new(self.min.min(other.min), self.max.max(other.max))
    }
}

/// True when every component is finite (no NaN, no infinity).
pub fn is_finite_vec(v: DVec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// Puts `values` in a new order in place: element `k` becomes what element `order[k]` was
/// (`order` a permutation). Follows the permutation's cycles, so it needs no second copy of the
/// values, only one flag per element (`done`, working memory).
pub fn permute_in_place<T: Copy>(values: &mut [T], order: &[u32], done: &mut Vec<bool>) {
    debug_assert_eq!(values.len(), order.len());
    done.clear();
    done.resize(values.len(), false);
    for start in 0..values.len() {
        if done[start] {
            continue;
        }
        let first = values[start];
        let mut k = start;
        loop {
            done[k] = true;
            let from = order[k] as usize;
            if from == start {
                values[k] = first;
                break;
            }
            values[k] = values[from];
            k = from;
        }
    }
}

#[cfg(test)]
mod permute_tests {
    use super::permute_in_place;
    use proptest::prelude::*;

    proptest! {
        /// In-place permutation gives what gathering into a new vector gives.
        #[test]
        fn permuting_in_place_is_gathering(keys in prop::collection::vec(any::<u32>(), 0..200)) {
            // The order that sorts `keys` (ties by position): any permutation.
            let mut order: Vec<u32> = (0..keys.len() as u32).collect();
            order.sort_by_key(|&k| (keys[k as usize], k));
            let values: Vec<u64> = (0..keys.len() as u64).map(|v| v * 7 + 3).collect();
            let gathered: Vec<u64> = order.iter().map(|&k| values[k as usize]).collect();
            let mut permuted = values.clone();
            permute_in_place(&mut permuted, &order, &mut Vec::new());
            prop_assert_eq!(permuted, gathered);
        }
    }
}
