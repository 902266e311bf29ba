//! A body's contacts as plain data keyed by global ids, for a share of a decomposed world that
//! takes the body over from another (`decomposition`): the receiving share holds the same
//! contacts under its own indices, and takes the sender's history, which is the exact one.

use super::ContactStore;
use crate::body::Bodies;
use crate::contact::{LawReport, Partner, PartnerLoad};
use crate::contact_law::{History, OverlapVolume, SpinHistory};
use crate::narrow_phase::ContactPoint;
use std::collections::HashMap;

/// A contact's partner by what names it in every share: a body by global id, a wall by index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum PartnerId {
    Body(u64),
    Plane(u32),
    Mesh(u32),
}

/// One contact-store entry as plain data.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EntryRecord {
    /// Global id of body `a`.
    pub a: u64,
    pub partner: PartnerId,
    pub region: u8,
    pub touching: bool,
    pub geometry: ContactPoint,
    pub history: History,
    pub spin: Option<SpinHistory>,
    pub volume: Option<OverlapVolume>,
    pub load: PartnerLoad,
    pub report: LawReport,
}

/// A body's entry that a share could not place: it touches, but the share has no such candidate.
#[derive(Debug, thiserror::Error)]
#[error(
    "the contact of body {a} with {partner:?} (region {region}) touches, but this share has no \
     such candidate: its ghost layer is too thin for the bodies' motion"
)]
pub struct UnplacedContact {
    pub a: u64,
    pub partner: PartnerId,
    pub region: u8,
}

impl ContactStore {
    /// Every entry of body `i`, as `a` or as partner, in store order.
    pub fn records_of(&self, bodies: &Bodies, i: usize) -> Vec<EntryRecord> {
        let incoming = self.incoming(i).iter().map(|&e| e as usize);
        self.records(bodies, self.own(i).chain(incoming))
    }

    /// The entries of body `i` as `a` (each entry of a store is one body's as `a`).
    pub fn own_records(&self, bodies: &Bodies, i: usize) -> Vec<EntryRecord> {
        self.records(bodies, self.own(i))
    }

    fn records(&self, bodies: &Bodies, entries: impl Iterator<Item = usize>) -> Vec<EntryRecord> {
        entries
            .map(|e| {
                let key = self.entries.key[e];
                EntryRecord {
                    a: bodies.id[key.a as usize],
                    partner: match key.partner {
                        Partner::Body(j) => PartnerId::Body(bodies.id[j as usize]),
                        Partner::Plane(p) => PartnerId::Plane(p),
                        Partner::Mesh(w) => PartnerId::Mesh(w),
                    },
                    region: key.region,
                    touching: self.entries.touching[e],
                    // None kept for a sphere pair, nor in a world of spheres and planes: the
                    // receiving share finds it again from the bodies.
                    geometry: self.entries.geometry.get(e).copied().unwrap_or_default(),
                    history: self.entries.history[e],
                    spin: self.entries.spin.get(e).copied(),
                    volume: self.volume.get(e).copied().flatten(),
                    load: self.load[e],
                    report: self.report.get(e).copied().unwrap_or_default(),
                }
            })
            .collect()
    }

    /// Makes body `i`'s entries what `records` (its every entry in another share) say: each of
    /// its entries is first cleared (touching nothing, no history), then each record is put into
    /// the entry of its key. `index` gives the local index of a global id. A record whose key
    /// has no entry here must not touch (it is then a candidate there only); one that touches
    /// is an error.
    pub fn adopt(
        &mut self,
        i: usize,
        index: &HashMap<u64, usize>,
        records: &[EntryRecord],
    ) -> Result<(), UnplacedContact> {
        let entries: Vec<usize> = self
            .own(i)
            .chain(self.incoming(i).iter().map(|&e| e as usize))
            .collect();
        for e in entries {
            self.clear_entry(e);
        }
        records.iter().try_for_each(|r| self.place(index, r))
    }

    /// Makes every entry what `records` say (each entry of the whole store once, as gathered from
    /// every share of a decomposed world; see [`ContactStore::adopt`]): every entry is cleared,
    /// then each record put into the entry of its key.
    pub fn adopt_all(
        &mut self,
        index: &HashMap<u64, usize>,
        records: &[EntryRecord],
    ) -> Result<(), UnplacedContact> {
        for e in 0..self.entries.key.len() {
            self.clear_entry(e);
        }
        records.iter().try_for_each(|r| self.place(index, r))
    }

    /// Entry `e` touching nothing, with no history and no load.
    fn clear_entry(&mut self, e: usize) {
        self.entries.touching[e] = false;
        if let Some(g) = self.entries.geometry.get_mut(e) {
            *g = ContactPoint::default();
        }
        self.entries.history[e] = History::default();
        if let Some(spin) = self.entries.spin.get_mut(e) {
            *spin = SpinHistory::default();
        }
        if let Some(volume) = self.volume.get_mut(e) {
            *volume = None;
        }
        self.load[e] = PartnerLoad::default();
        if let Some(report) = self.report.get_mut(e) {
            *report = LawReport::default();
        }
    }

    /// Puts record `r` into the entry of its key (`index`: local index by global id); a record
    /// with no such entry must not touch.
    fn place(
        &mut self,
        index: &HashMap<u64, usize>,
        r: &EntryRecord,
    ) -> Result<(), UnplacedContact> {
        let local = |id: u64| index.get(&id).map(|&j| j as u32);
        let partner = match r.partner {
            PartnerId::Body(id) => local(id).map(Partner::Body),
            PartnerId::Plane(p) => Some(Partner::Plane(p)),
            PartnerId::Mesh(w) => Some(Partner::Mesh(w)),
        };
        let found = local(r.a).zip(partner).and_then(|(a, partner)| {
            self.own(a as usize).find(|&e| {
                let key = self.entries.key[e];
                key.partner == partner && key.region == r.region
            })
        });
        let Some(e) = found else {
            if r.touching {
                return Err(UnplacedContact {
                    a: r.a,
                    partner: r.partner,
                    region: r.region,
                });
            }
            return Ok(());
        };
        self.entries.touching[e] = r.touching;
        if let Some(g) = self.entries.geometry.get_mut(e) {
            *g = r.geometry;
        }
        self.entries.history[e] = r.history;
        if let (Some(spin), Some(r)) = (self.entries.spin.get_mut(e), r.spin) {
            *spin = r;
        }
        if let Some(volume) = self.volume.get_mut(e) {
            *volume = r.volume;
        }
        self.load[e] = r.load;
        if let Some(report) = self.report.get_mut(e) {
            *report = r.report;
        }
        Ok(())
    }
}
