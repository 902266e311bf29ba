//! The one rule by which a contact region found this step is matched to last step's, so that its
//! history (friction spring, rolling and twisting springs) follows it.
//!
//! A pair that can touch in several places at once — a non-convex body on anything, any body on a
//! mesh wall (a corner, the arms of a jack on a triangulated floor) — has [`MAX_REGIONS`] slots in
//! the contact store. Each step its regions are found anew, in no particular identity; this rule
//! gives each a slot:
//! 1. regions are taken in the order the narrow phase gives them (deterministic);
//! 2. a region takes the slot of the unclaimed contact of last step that is nearest to it, if that
//!    one's contact point is within `reach` and its normal within 60° (the region moved a little
//!    and turned a little: the same contact, its history carries on);
//! 3. the other regions are new contacts: each takes the lowest slot that was free last step, or,
//!    if every slot was in use, the lowest slot whose contact ended this step (its history is
//!    dropped, never inherited).

use crate::math::DVec3;
pub use crate::narrow_phase::MAX_REGIONS;
use crate::narrow_phase::{ContactPoint, Geometry};

/// Normals of the same contact on consecutive steps differ by less than 60°.
const SAME_NORMAL_COS: f64 = 0.5;

/// What the rule reads of a contact region: where it is and which way it points. A region is a
/// [`Geometry`] (with the overlap's volume, for polyhedra) or, for a sphere on a mesh wall, a
/// [`ContactPoint`]: the rule gives both the same slots.
pub trait Region: Copy {
    fn normal(&self) -> DVec3;
    fn point(&self) -> DVec3;
}

impl Region for Geometry {
    #[inline(always)]
    fn normal(&self) -> DVec3 {
        self.normal
    }

    #[inline(always)]
    fn point(&self) -> DVec3 {
        self.point
    }
}

impl Region for ContactPoint {
    #[inline(always)]
    fn normal(&self) -> DVec3 {
        self.normal
    }

    #[inline(always)]
    fn point(&self) -> DVec3 {
        self.point
    }
}

/// What the rule gives one slot this step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Assigned<G = Geometry> {
    /// The region in this slot; `None`: the slot is free this step.
    pub geometry: Option<G>,
    /// The region is a new contact (not last step's region of this slot): it starts with empty
    /// history.
    pub fresh: bool,
}

impl<G> Default for Assigned<G> {
    fn default() -> Self {
        Assigned {
            geometry: None,
            fresh: false,
        }
    }
}

/// Assigns the regions `found` (at most [`MAX_REGIONS`] are taken) to the `N` slots of a pair
/// whose contacts last step were `previous` (by slot; `None` where the slot was free): a
/// polyhedron's [`MAX_REGIONS`], a sphere's four on a mesh wall (what it is given does not
/// depend on `N` beyond the slots it has).
pub fn assign_regions<G: Region, const N: usize>(
    previous: &[Option<G>; N],
    found: &[G],
    reach: f64,
) -> [Assigned<G>; N] {
    const { assert!(N <= MAX_REGIONS) };
    let mut out = [Assigned::default(); N];
    let mut claimed = [false; N];
    let mut waiting = [None; MAX_REGIONS];
    let mut waiting_count = 0;
    for g in found.iter().take(MAX_REGIONS) {
        let matched = previous
            .iter()
            .enumerate()
            .filter(|&(slot, _)| !claimed[slot])
            .filter_map(|(slot, p)| p.map(|p| (slot, p)))
            .filter(|(_, p)| p.normal().dot(g.normal()) > SAME_NORMAL_COS)
            .map(|(slot, p)| (slot, (p.point() - g.point()).length()))
            .filter(|&(_, d)| d <= reach)
            .min_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        match matched {
            Some((slot, _)) => {
                claimed[slot] = true;
                out[slot] = Assigned {
                    geometry: Some(*g),
                    fresh: false,
                };
            }
            None => {
                waiting[waiting_count] = Some(*g);
                waiting_count += 1;
            }
        }
    }
    let slots = N;
    let was_free = |slot: usize| previous[slot].is_none();
    for g in waiting.iter().take(waiting_count).flatten() {
        let slot = (0..slots)
            .find(|&s| !claimed[s] && was_free(s))
            .or_else(|| (0..slots).find(|&s| !claimed[s]));
        let Some(slot) = slot else { break };
        claimed[slot] = true;
        out[slot] = Assigned {
            geometry: Some(*g),
            fresh: true,
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    fn at(x: f64, n: DVec3) -> Geometry {
        Geometry {
            normal: n,
            point: DVec3::new(x, 0.0, 0.0),
            overlap: 1e-3,
            volume: None,
        }
    }

    fn slots_of(assigned: &[Assigned; MAX_REGIONS]) -> Vec<(usize, f64, bool)> {
        assigned
            .iter()
            .enumerate()
            .filter_map(|(s, a)| a.geometry.map(|g| (s, g.point.x, a.fresh)))
            .collect()
    }

    fn as_previous(assigned: &[Assigned; MAX_REGIONS]) -> [Option<Geometry>; MAX_REGIONS] {
        assigned.map(|a| a.geometry)
    }

    #[test]
    fn regions_keep_their_slots() {
        let none = [None; MAX_REGIONS];
        let first = assign_regions(&none, &[at(0.0, DVec3::Z), at(1.0, DVec3::Z)], 0.1);
        assert_eq!(
            slots_of(&first),
            vec![(0, 0.0, true), (1, 1.0, true)],
            "new regions take the lowest free slots"
        );
        // Next step the regions come in the other order and have moved a little; a third appears.
        let found = [at(1.01, DVec3::Z), at(5.0, DVec3::Z), at(0.01, DVec3::Z)];
        let second = assign_regions(&as_previous(&first), &found, 0.1);
        assert_eq!(
            slots_of(&second),
            vec![(0, 0.01, false), (1, 1.01, false), (2, 5.0, true)]
        );
        // A region whose normal turned over is a new contact, in a slot free last step.
        let third = assign_regions(&as_previous(&second), &[at(1.01, -DVec3::Z)], 0.1);
        assert_eq!(slots_of(&third), vec![(3, 1.01, true)]);
        // Out of reach: a new contact too.
        let fourth = assign_regions(&as_previous(&second), &[at(1.5, DVec3::Z)], 0.1);
        assert_eq!(slots_of(&fourth), vec![(3, 1.5, true)]);
    }

    #[test]
    fn a_full_pair_reuses_an_ended_slot_as_new() {
        let full: Vec<Geometry> = (0..MAX_REGIONS).map(|k| at(k as f64, DVec3::Z)).collect();
        let previous = as_previous(&assign_regions(&[None; MAX_REGIONS], &full, 0.1));
        // All but slot 2 continue; a region far away takes slot 2, fresh.
        let mut found: Vec<Geometry> = full.clone();
        found[2] = at(100.0, DVec3::Z);
        let next = assign_regions(&previous, &found, 0.1);
        assert_eq!(next[2].geometry.unwrap().point.x, 100.0);
        assert!(next[2].fresh);
        assert!(next.iter().enumerate().all(|(s, a)| a.fresh == (s == 2)));
    }
}
