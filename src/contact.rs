//! The list of current contacts and the history each carries from step to step.

use crate::contact_law::{History, Response};
use crate::narrow_phase::Geometry;

/// One contact between body `a` and body (or wall) `b`.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    pub a: u32,
    pub b: u32,
    /// Which of the pair's contacts this is, when a pair can touch in several regions at once
    /// (a non-convex body): each region keeps its slot, and so its history, from step to step.
    /// 0 for a pair with one contact.
    pub slot: u16,
    pub geometry: Geometry,
    pub history: History,
    /// What the law gave in the latest evaluation.
    pub response: Response,
}

/// Contacts sorted by `(a, b)`. Sorting makes every later loop run in a fixed order, which is what
/// makes the results independent of the thread count, and lets the update below carry history by a
/// linear merge instead of a hash lookup.
#[derive(Clone, Debug, Default)]
pub struct ContactList {
    pub contacts: Vec<Contact>,
    previous: Vec<Contact>,
}

impl ContactList {
    /// Replaces the contacts by `found` (sorted by `(a, b)`), keeping the history of every pair
    /// that was already in contact; a new contact starts with empty history. Returns the energy
    /// the history springs of the contacts that ended still held (see [`History::stored_energy`]).
    pub fn update(&mut self, found: &[(u32, u32, Geometry)]) -> f64 {
        self.update_keyed(found.iter().map(|&(a, b, g)| (a, b, 0, g)))
    }

    /// As [`ContactList::update`] for pairs with several contacts: `found` sorted by
    /// `(a, b, slot)`; the history follows the slot.
    pub fn update_slots(&mut self, found: &[(u32, u32, u16, Geometry)]) -> f64 {
        self.update_keyed(found.iter().copied())
    }

    fn update_keyed(&mut self, found: impl Iterator<Item = (u32, u32, u16, Geometry)>) -> f64 {
        std::mem::swap(&mut self.contacts, &mut self.previous);
        self.contacts.clear();
        let mut lost = 0.0;
        let mut old = self.previous.iter().peekable();
        for (a, b, slot, geometry) in found {
            while let Some(ended) = old.next_if(|c| (c.a, c.b, c.slot) < (a, b, slot)) {
                lost += ended.history.stored_energy();
            }
            let history = match old.next_if(|c| (c.a, c.b, c.slot) == (a, b, slot)) {
                Some(c) => c.history,
                None => History::default(),
            };
            self.contacts.push(Contact {
                a,
                b,
                slot,
                geometry,
                history,
                response: Response::default(),
            });
        }
        lost + old.map(|ended| ended.history.stored_energy()).sum::<f64>()
    }

    /// After bodies were removed: renumbers the contacts by `new_index` (`u32::MAX` for a removed
    /// body) and drops those of removed bodies. `b_is_body` says whether `b` is a body index (or a
    /// wall's). The renumbering keeps the order, so the list stays sorted. Returns the elastic
    /// energy the dropped contacts held.
    pub fn renumber(&mut self, new_index: &[u32], b_is_body: bool) -> f64 {
        let mut lost = 0.0;
        self.contacts.retain_mut(|c| {
            let a = new_index[c.a as usize];
            let b = if b_is_body {
                new_index[c.b as usize]
            } else {
                c.b
            };
            if a == u32::MAX || b == u32::MAX {
                lost += c.response.elastic_energy;
                return false;
            }
            (c.a, c.b) = (a, b);
            true
        });
        lost
    }

    /// The contacts of the pair (a, b) in the list, found from `cursor` on (the list is sorted;
    /// callers walking pairs in order pass the cursor back in to make the walk linear).
    pub fn of_pair(&self, a: u32, b: u32, cursor: &mut usize) -> &[Contact] {
        let c = &self.contacts;
        while *cursor < c.len() && (c[*cursor].a, c[*cursor].b) < (a, b) {
            *cursor += 1;
        }
        let start = *cursor;
        let mut end = start;
        while end < c.len() && (c[end].a, c[end].b) == (a, b) {
            end += 1;
        }
        &c[start..end]
    }

    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }
}

/// Gives each of a pair's regions found this step a slot, following last step's contacts of the
/// pair: a region takes the slot of the unclaimed previous contact nearest to it, if that one is
/// within `reach` [m] and its normal within 60°; the others take the lowest slots that no
/// previous contact of the pair held (so that none inherits an ended contact's history). Regions
/// are taken in the order given, so the result is deterministic. Appends `(slot, geometry)` to
/// `out`, sorted by slot.
pub fn assign_slots(
    previous: &[Contact],
    regions: impl Iterator<Item = Geometry>,
    reach: f64,
    out: &mut Vec<(u16, Geometry)>,
) {
    let first = out.len();
    let mut used: u64 = 0;
    let mut pending: [Option<Geometry>; 64] = [None; 64];
    let mut waiting = 0;
    for g in regions {
        let matched = previous
            .iter()
            .filter(|c| c.slot < 64 && used & (1 << c.slot) == 0)
            .filter(|c| c.geometry.normal.dot(g.normal) > 0.5)
            .map(|c| (c.slot, (c.geometry.point - g.point).length()))
            .filter(|&(_, d)| d <= reach)
            .min_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        match matched {
            Some((slot, _)) => {
                used |= 1 << slot;
                out.push((slot, g));
            }
            None if waiting < pending.len() => {
                pending[waiting] = Some(g);
                waiting += 1;
            }
            None => {}
        }
    }
    let mut taken = used;
    for c in previous.iter().filter(|c| c.slot < 64) {
        taken |= 1 << c.slot;
    }
    for g in pending.iter().take(waiting).flatten() {
        let slot = (!taken).trailing_zeros() as u16;
        taken |= 1 << slot;
        out.push((slot, *g));
    }
    out[first..].sort_by_key(|&(slot, _)| slot);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    fn geometry() -> Geometry {
        Geometry {
            normal: DVec3::Z,
            point: DVec3::ZERO,
            overlap: 1e-3,
            volume: None,
        }
    }

    #[test]
    fn history_survives_while_the_contact_lasts() {
        let mut list = ContactList::default();
        list.update(&[(0, 1, geometry()), (1, 2, geometry())]);
        list.contacts[1].history.tangential_spring = DVec3::X;
        list.update(&[(0, 2, geometry()), (1, 2, geometry())]);
        assert_eq!(list.contacts[0].history, History::default());
        assert_eq!(list.contacts[1].history.tangential_spring, DVec3::X);
        // A contact that ends forgets its history, and gives back the energy its springs held.
        list.contacts[1].history.tangential_stiffness = 4.0;
        let lost = list.update(&[(0, 2, geometry())]);
        assert_eq!(lost, 0.5 * 4.0);
        list.update(&[(0, 2, geometry()), (1, 2, geometry())]);
        assert_eq!(list.contacts[1].history, History::default());
    }

    #[test]
    fn regions_keep_their_slots_and_history() {
        let at = |x: f64, n: DVec3| Geometry {
            normal: n,
            point: DVec3::new(x, 0.0, 0.0),
            ..geometry()
        };
        let mut list = ContactList::default();
        let mut slots = Vec::new();
        assign_slots(
            &[],
            [at(0.0, DVec3::Z), at(1.0, DVec3::Z)].into_iter(),
            0.1,
            &mut slots,
        );
        assert_eq!(slots.iter().map(|s| s.0).collect::<Vec<_>>(), vec![0, 1]);
        let found: Vec<_> = slots.iter().map(|&(s, g)| (0, 1, s, g)).collect();
        list.update_slots(&found);
        list.contacts[1].history.tangential_spring = DVec3::X;
        // Next step the regions come in the other order and have moved a little; a third appears.
        let mut cursor = 0;
        let previous = list.of_pair(0, 1, &mut cursor).to_vec();
        let mut slots = Vec::new();
        let regions = [at(1.01, DVec3::Z), at(5.0, DVec3::Z), at(0.01, DVec3::Z)];
        assign_slots(&previous, regions.into_iter(), 0.1, &mut slots);
        let points: Vec<(u16, f64)> = slots.iter().map(|&(s, g)| (s, g.point.x)).collect();
        assert_eq!(points, vec![(0, 0.01), (1, 1.01), (2, 5.0)]);
        let found: Vec<_> = slots.iter().map(|&(s, g)| (0, 1, s, g)).collect();
        list.update_slots(&found);
        assert_eq!(list.contacts[1].history.tangential_spring, DVec3::X);
        assert_eq!(list.contacts[2].history, History::default());
        // A region whose normal turned over is a new contact.
        let previous = list.of_pair(0, 1, &mut 0).to_vec();
        let mut slots = Vec::new();
        assign_slots(
            &previous,
            [at(1.01, -DVec3::Z)].into_iter(),
            0.1,
            &mut slots,
        );
        assert_eq!(slots[0].0, 3);
    }
}
