//! The list of current contacts and the history each carries from step to step.

use crate::contact_law::{History, Response};
use crate::narrow_phase::Geometry;

/// One contact between body `a` and body (or wall) `b`.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    pub a: u32,
    pub b: u32,
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
        std::mem::swap(&mut self.contacts, &mut self.previous);
        self.contacts.clear();
        let mut lost = 0.0;
        let mut old = self.previous.iter().peekable();
        for &(a, b, geometry) in found {
            while let Some(ended) = old.next_if(|c| (c.a, c.b) < (a, b)) {
                lost += ended.history.stored_energy();
            }
            let history = match old.next_if(|c| (c.a, c.b) == (a, b)) {
                Some(c) => c.history,
                None => History::default(),
            };
            self.contacts.push(Contact {
                a,
                b,
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

    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }
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
}
