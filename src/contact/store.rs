//! The contact store: every contact of the world, with bodies, planes and mesh walls alike, under
//! one key, with its geometry of this step and the history it carries from step to step.
//!
//! The store holds an entry for every *candidate* contact: a body and a partner close enough to
//! touch before the neighbour search runs again (one entry, or [`MAX_REGIONS`] for a pair that can
//! touch in several places). Entries keep their places between neighbour searches, so a step
//! writes each entry's geometry and response in place, in parallel, with no per-step sorting or
//! merging; a new neighbour list carries the history over by one merge of sorted keys
//! ([`ContactStore::set_candidates`]). Per-body index lists make the force sums parallel and still
//! bit-identical for any thread count: each body adds up its own contacts in store order.
//!
//! Persistent state (key, history) is kept apart from what a step recomputes (touching, geometry,
//! response).

use super::key::{ContactKey, ContactOrder, PairKind, Partner};
use super::load::{LawReport, Load, OwnLoad, PartnerLoad};
use super::regions::{Assigned, MAX_REGIONS};
use crate::body::Bodies;
use crate::contact_law::{History, OverlapVolume, SpinHistory};
use crate::groups::{for_each_group_mut, sort_short_by_key};
use crate::material::PairTable;
use crate::math::{permute_in_place, DVec3};
use crate::narrow_phase::{ContactPoint, Geometry};
use crate::shape::Shape;
use crate::tight::resize_tight;
use crate::wall::Plane;

pub(crate) mod finish;
mod found_again;
mod pass;
mod relocate;
mod transfer;
pub use pass::CHUNK_ENTRIES;
pub(crate) use pass::{Chunks, StorePass};
use relocate::GONE;
pub use transfer::{EntryRecord, PartnerId, UnplacedContact};

/// A body and a partner that may touch before the next neighbour search.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Candidate {
    pub a: u32,
    pub partner: Partner,
    /// How the narrow phase treats the pair; a regional pair gets an entry for each of its
    /// regions ([`PairKind::regions`]).
    pub kind: PairKind,
}

impl Candidate {
    /// The store's order ([`ContactKey::order`]) of the candidate's first entry.
    pub fn order(&self, ids: &[u64]) -> ContactOrder {
        (self.a, self.partner.rank(ids), 0)
    }

    /// The number of store entries the candidate gets: one per region ([`PairKind::regions`]).
    pub fn entries(&self) -> usize {
        self.kind.regions()
    }

    /// The keys of the candidate's entries, with its kind, in the store's order.
    fn keys(&self) -> impl DoubleEndedIterator<Item = (ContactKey, PairKind)> + '_ {
        (0..self.entries() as u8).map(move |region| {
            let key = ContactKey {
                a: self.a,
                partner: self.partner,
                region,
            };
            (key, self.kind)
        })
    }
}

/// Where the bodies and planes are, and the laws between them: what the store finds again the
/// geometry and the law reports it does not keep from ([`StoreLayout::geometry`],
/// [`StoreLayout::reports`]).
#[derive(Clone, Copy)]
pub struct Placement<'a> {
    pub bodies: &'a Bodies,
    pub shapes: &'a [Shape],
    pub planes: &'a [Plane],
    pub laws: &'a PairTable,
}

/// One contact as outside code sees it.
#[derive(Clone, Copy, Debug)]
pub struct ContactRef<'a> {
    pub key: ContactKey,
    pub geometry: Geometry,
    pub history: &'a History,
    /// The rolling and twisting springs, in worlds that keep them (see [`SpinHistory`]).
    pub spin: Option<&'a SpinHistory>,
    pub load: &'a PartnerLoad,
    /// Normal force and elastic energy: kept, or found again (see [`StoreLayout::reports`]).
    pub report: LawReport,
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
struct Persistent {
    key: Vec<ContactKey>,
    kind: Vec<PairKind>,
    touching: Vec<bool>,
    /// Empty in a world of spheres and planes alone; else one per entry, but never written for
    /// a sphere pair (see [`ContactStore::contact_point`]).
    geometry: Vec<ContactPoint>,
    history: Vec<History>,
    /// Empty in a world without rolling friction and polyhedra.
    spin: Vec<SpinHistory>,
}

impl Persistent {
    /// Energy held in the springs of entry `k`.
    fn stored_energy(&self, k: usize) -> f64 {
        self.history[k].stored_energy() + self.spin.get(k).map_or(0.0, SpinHistory::stored_energy)
    }
}

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ContactStore {
    /// Per entry, sorted by key: key, whether it touches this step, its geometry (valid while
    /// touching; kept to match regions next step) and its history.
    entries: Persistent,
    /// Per entry: what the contact law gave this step (zero when not touching), the partner's
    /// side of the load apart from the rest (body `a`'s side went straight into its sum).
    load: Vec<PartnerLoad>,
    /// Per entry, in a world that keeps them (see [`StoreLayout::reports`]), else empty.
    report: Vec<LawReport>,
    /// Per entry, only in a world with polyhedra (else empty): the overlap volume of polyhedral
    /// contacts under the volume law.
    volume: Vec<Option<OverlapVolume>>,
    /// First entry of each pair with [`MAX_REGIONS`] entries ([`PairKind::Regional`]).
    regional: Vec<u32>,
    /// First entry of each sphere on a mesh wall ([`PairKind::SphereOnMesh`]).
    #[serde(default)]
    spheres_on_mesh: Vec<u32>,
    /// Which list of candidates the store holds: a number no other list in the process has,
    /// 0 for none yet (see [`ContactStore::list_id`]).
    #[serde(skip, default = "new_list_id")]
    list_id: u64,
    /// `own[i]..own[i + 1]`: the entries of body `i` as `a`.
    own: Vec<u32>,
    /// `incoming[incoming_first[i]..incoming_first[i + 1]]`: the entries whose partner is body `i`,
    /// in store order.
    incoming_first: Vec<u32>,
    incoming: Vec<u32>,
    /// The first body of each chunk of the contact loop, and the count of bodies (see
    /// [`Chunks`]); made again from `own` when empty, with the two below.
    #[serde(skip)]
    chunks: Vec<u32>,
    /// `finishing[finishing_first[r]..finishing_first[r + 1]]`: the bodies whose force sums the
    /// contact loop completes once the chunks of its range `r` are done (see `finish`).
    #[serde(skip)]
    finishing_first: Vec<u32>,
    #[serde(skip)]
    finishing: Vec<u32>,
    /// Whether the contact loop completes the force sums (`Some`), or it is left to the size of
    /// the world against the last-level cache (`None`, see [`ContactStore::set_sums_in_loop`]).
    #[serde(skip)]
    sums_in_loop: Option<bool>,
    /// Whether the last contact loop completed the bodies' force sums (see
    /// [`ContactStore::completes_sums`]).
    #[serde(skip)]
    sums_completed: bool,
    /// Entries whose partner is a wall, in store order.
    wall_entries: Vec<u32>,
    /// Working memory of [`ContactStore::set_candidates`], empty between merges: each
    /// candidate's first entry (when some have several), where each old entry goes, and where
    /// the kept ones go, in order.
    #[serde(skip)]
    first_entry: Vec<u32>,
    #[serde(skip)]
    fates: Vec<u32>,
    #[serde(skip)]
    targets: Vec<u32>,
}

/// Which arrays a world's store keeps beside those every entry has: what its bodies and walls can
/// need. Fixed by the scene (its shapes, walls and laws).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StoreLayout {
    /// The contact geometry (normal, point, overlap) of every entry but sphere pairs: in a world
    /// with polyhedra or mesh walls, whose contacts cost a narrow phase to find and whose regions
    /// are matched to last step's by it. A world of spheres and planes alone keeps none (56 bytes
    /// an entry): a contact of two spheres, or of a sphere and a plane, is found again from the
    /// bodies when it is read ([`ContactStore::contact_point`]).
    pub geometry: bool,
    /// The overlap volume of polyhedral contacts under the volume law (a world with polyhedra).
    pub volumes: bool,
    /// Rolling and twisting springs (a world with rolling friction or polyhedra).
    pub spins: bool,
    /// The law's report (normal force, elastic energy) of every entry: in a world with
    /// polyhedra or mesh walls. A world of spheres and planes (point laws, with or without
    /// rolling resistance) keeps none (16 bytes an entry): its reports are found again when read,
    /// from the geometry, the load and the histories (`ContactStore::report`).
    pub reports: bool,
}

impl StoreLayout {
    /// The layout of a world of bodies of `shapes`, with mesh walls or not, with rolling friction
    /// in some pair law or not.
    pub fn of(shapes: &[Shape], mesh_walls: bool, rolling_friction: bool) -> Self {
        let polyhedra = shapes.iter().any(|s| !matches!(s, Shape::Sphere(_)));
        StoreLayout {
            geometry: polyhedra || mesh_walls,
            volumes: polyhedra,
            spins: polyhedra || rolling_friction,
            reports: polyhedra || mesh_walls,
        }
    }
}

/// A list number no store in the process has had (see [`ContactStore::list_id`]).
fn new_list_id() -> u64 {
    static LISTS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    LISTS.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

impl ContactStore {
    /// Makes `candidates` (sorted by `(a, partner)`, each once) the entries, carrying every
    /// continuing entry's state over. Returns the energy the history springs of touching contacts
    /// that are no longer candidates still held (none in a consistent neighbour search; booked as
    /// dissipated by the caller; a ghost's contacts are left to its owner, see `Bodies::ghost`).
    ///
    /// `layout`: which arrays besides the keys and histories the entries keep.
    ///
    /// The merge is done in place, with no second copy of the entries, in two parallel passes
    /// (`store/relocate.rs`): where each old entry goes, found block by block; then each array
    /// moved there (the arrays side by side).
    pub fn set_candidates(
        &mut self,
        candidates: &[Candidate],
        bodies: &Bodies,
        layout: StoreLayout,
    ) -> f64 {
        let ids = &bodies.id;
        debug_assert!(candidates
            .windows(2)
            .all(|w| w[0].order(ids) < w[1].order(ids)));
        // The new keys, in order, are made on the fly from the candidates (a list of them would
        // cost 20 bytes an entry at the store's peak).
        self.regional.clear();
        self.spheres_on_mesh.clear();
        self.list_id = new_list_id();
        self.first_entry.clear();
        let mut count = 0;
        for c in candidates {
            match c.kind {
                PairKind::Regional => self.regional.push(count as u32),
                PairKind::SphereOnMesh => self.spheres_on_mesh.push(count as u32),
                PairKind::Spheres | PairKind::Single => {}
            }
            count += c.entries();
        }
        if !self.regional.is_empty() || !self.spheres_on_mesh.is_empty() {
            let mut next = 0;
            self.first_entry.extend(candidates.iter().map(|c| {
                let first = next;
                next += c.entries() as u32;
                first
            }));
        }
        let e = &mut self.entries;
        let old = e.key.len();
        // An array the layout now asks for starts with defaults for the old entries.
        if layout.spins {
            e.spin.resize(old, SpinHistory::default());
        } else {
            e.spin.clear();
        }
        if layout.geometry {
            e.geometry.resize(old, ContactPoint::default());
        } else {
            e.geometry.clear();
        }
        // What the last evaluation gave goes along with its entry (read between steps: the
        // ledger, the outputs), so the store tells the same story after a new list as before.
        self.load.resize(old, PartnerLoad::default());
        if layout.reports {
            self.report.resize(old, LawReport::default());
        } else if !self.report.is_empty() {
            // Kept by a store of an older version, read from a checkpoint.
            self.report = Vec::new();
        }
        if layout.volumes {
            self.volume.resize(old, None);
        } else {
            self.volume.clear();
        }
        // 1. Where each old entry goes; the energy held by those that go.
        let fates = &mut self.fates;
        relocate::find_fates(&e.key, candidates, &self.first_entry, ids, fates);
        let mut lost = 0.0;
        for (o, _) in fates.iter().enumerate().filter(|(_, &f)| f == GONE) {
            if e.touching[o] && bodies.counts(e.key[o].a as usize) {
                lost += e.stored_energy(o);
            }
        }
        self.targets.clear();
        self.targets
            .extend(fates.iter().copied().filter(|&f| f != GONE));
        // 2. The keys and kinds written from the candidates, every other array moved to its
        // entries' new places, the arrays side by side.
        let (fates, targets) = (&self.fates[..], &self.targets[..]);
        let Persistent {
            key,
            kind,
            touching,
            geometry,
            history,
            spin,
        } = e;
        let (load, report, volume) = (&mut self.load, &mut self.report, &mut self.volume);
        rayon::scope(|s| {
            s.spawn(|_| relocate::relocate(load, fates, targets, count, PartnerLoad::default()));
            s.spawn(|_| relocate::relocate(history, fates, targets, count, History::default()));
            s.spawn(|_| {
                if layout.reports {
                    relocate::relocate(report, fates, targets, count, LawReport::default());
                }
                relocate::relocate(touching, fates, targets, count, false);
                let unset = ContactKey {
                    a: 0,
                    partner: Partner::Body(0),
                    region: 0,
                };
                resize_tight(key, count, unset);
                resize_tight(kind, count, PairKind::Single);
                let new = candidates.iter().flat_map(Candidate::keys);
                for ((key, kind), (new_key, new_kind)) in
                    key.iter_mut().zip(kind.iter_mut()).zip(new)
                {
                    *key = new_key;
                    *kind = new_kind;
                }
            });
            if layout.geometry {
                s.spawn(|_| {
                    relocate::relocate(geometry, fates, targets, count, ContactPoint::default())
                });
            }
            if layout.spins {
                s.spawn(|_| {
                    relocate::relocate(spin, fates, targets, count, SpinHistory::default())
                });
            }
            if layout.volumes {
                s.spawn(|_| relocate::relocate(volume, fates, targets, count, None));
            }
        });
        // Made anew at the next merge: not held until then, when the neighbour search's lists
        // are (see `step::candidates`).
        self.fates = Vec::new();
        self.targets = Vec::new();
        self.first_entry = Vec::new();
        self.index(ids);
        lost
    }

    /// Builds the per-body index lists (counting sorts, linear in the entries), each body's
    /// incoming entries sorted by the global id of their `a` (short lists).
    fn index(&mut self, ids: &[u64]) {
        let bodies = ids.len();
        let keys = &self.entries.key;
        self.own.clear();
        self.own.resize(bodies + 1, 0);
        self.incoming_first.clear();
        self.incoming_first.resize(bodies + 1, 0);
        self.wall_entries.clear();
        for (e, k) in keys.iter().enumerate() {
            self.own[k.a as usize + 1] += 1;
            match k.partner {
                Partner::Body(j) => self.incoming_first[j as usize + 1] += 1,
                _ => self.wall_entries.push(e as u32),
            }
        }
        for i in 0..bodies {
            self.own[i + 1] += self.own[i];
            self.incoming_first[i + 1] += self.incoming_first[i];
        }
        self.incoming.clear();
        self.incoming
            .resize(self.incoming_first[bodies] as usize, 0);
        let mut next: Vec<u32> = self.incoming_first[..bodies].to_vec();
        for (e, k) in keys.iter().enumerate() {
            if let Partner::Body(j) = k.partner {
                let slot = &mut next[j as usize];
                self.incoming[*slot as usize] = e as u32;
                *slot += 1;
            }
        }
        // Each body's list (the bodies' lists in parallel).
        for_each_group_mut(&mut self.incoming, &self.incoming_first, |_, list| {
            sort_short_by_key(list, |&e| {
                (ids[keys[e as usize].a as usize], keys[e as usize].region)
            })
        });
        self.make_chunks();
    }

    /// After bodies were removed: renumbers the entries by `new_index` (`u32::MAX` for a removed
    /// body) and drops those of removed bodies; the order, and so the sorting, is kept (the
    /// energy the dropped contacts held: [`ContactStore::dropped_energy`], before). The per-body
    /// index lists are stale until the next [`ContactStore::set_candidates`].
    pub fn renumber(&mut self, new_index: &[u32]) {
        let mut kept = 0;
        let e = &mut self.entries;
        for k in 0..e.key.len() {
            let key = e.key[k];
            let a = new_index[key.a as usize];
            let partner = match key.partner {
                Partner::Body(j) => Partner::Body(new_index[j as usize]),
                wall => wall,
            };
            if a == u32::MAX || partner == Partner::Body(u32::MAX) {
                continue;
            }
            e.key[kept] = ContactKey { a, partner, ..key };
            e.kind[kept] = e.kind[k];
            e.touching[kept] = e.touching[k];
            if !e.geometry.is_empty() {
                e.geometry[kept] = e.geometry[k];
            }
            e.history[kept] = e.history[k];
            if !e.spin.is_empty() {
                e.spin[kept] = e.spin[k];
            }
            self.load[kept] = self.load[k];
            if !self.report.is_empty() {
                self.report[kept] = self.report[k];
            }
            if !self.volume.is_empty() {
                self.volume[kept] = self.volume[k];
            }
            kept += 1;
        }
        e.key.truncate(kept);
        e.kind.truncate(kept);
        e.touching.truncate(kept);
        e.geometry.truncate(kept);
        e.history.truncate(kept);
        e.spin.truncate(kept.min(e.spin.len()));
        self.load.truncate(kept);
        self.report.truncate(kept);
        if !self.volume.is_empty() {
            self.volume.truncate(kept);
        }
        self.regional.clear();
        self.spheres_on_mesh.clear();
        self.own.clear();
        self.chunks.clear();
        self.finishing_first.clear();
        self.finishing.clear();
        self.incoming_first.clear();
        self.incoming.clear();
        self.wall_entries.clear();
    }

    /// After the bodies were put in a new order (`new_index[old] = new`, see
    /// `step::space_order`; `ids` the bodies' global ids in the new order): renumbers the entries
    /// and sorts them again. Body pairs are oriented by global id, so renumbering never turns one;
    /// a pair oriented the other way (from a checkpoint of an older version, which oriented by
    /// index) is seen from its other side: its normal, tangential spring, dashpot force, rolling
    /// torque, force and moments change sign. Nothing else changes; the per-body index lists are
    /// stale until the next [`ContactStore::set_candidates`].
    /// `positions`: the bodies' centres, in the new order.
    pub fn permute(&mut self, new_index: &[u32], ids: &[u64], positions: &[DVec3]) {
        let e = &mut self.entries;
        // The keys are renamed in place, then the entries sorted through an index array (4 bytes
        // an entry: this runs on a full store, and its working memory adds to the peak).
        for k in 0..e.key.len() {
            let key = e.key[k];
            let a = new_index[key.a as usize];
            let key = match key.partner {
                Partner::Body(j) if ids[new_index[j as usize] as usize] < ids[a as usize] => {
                    if let Some(g) = e.geometry.get_mut(k) {
                        g.normal = -g.normal;
                    }
                    let h = &mut e.history[k];
                    h.tangential_spring = -h.tangential_spring;
                    h.damper_force = -h.damper_force;
                    if let Some(spin) = e.spin.get_mut(k) {
                        spin.rolling_torque = -spin.rolling_torque;
                    }
                    let centres = (
                        positions[a as usize],
                        positions[new_index[j as usize] as usize],
                    );
                    self.load[k] = self.load[k].seen_from_partner(centres);
                    if let Some(Some(v)) = self.volume.get_mut(k) {
                        v.couple = -v.couple;
                    }
                    ContactKey {
                        a: new_index[j as usize],
                        partner: Partner::Body(a),
                        ..key
                    }
                }
                Partner::Body(j) => ContactKey {
                    a,
                    partner: Partner::Body(new_index[j as usize]),
                    ..key
                },
                wall => ContactKey {
                    a,
                    partner: wall,
                    ..key
                },
            };
            e.key[k] = key;
        }
        let mut from: Vec<u32> = (0..e.key.len() as u32).collect();
        from.sort_unstable_by_key(|&k| e.key[k as usize].order(ids));
        let done = &mut Vec::new();
        permute_in_place(&mut e.key, &from, done);
        permute_in_place(&mut e.kind, &from, done);
        permute_in_place(&mut e.touching, &from, done);
        if !e.geometry.is_empty() {
            permute_in_place(&mut e.geometry, &from, done);
        }
        permute_in_place(&mut e.history, &from, done);
        if !e.spin.is_empty() {
            permute_in_place(&mut e.spin, &from, done);
        }
        permute_in_place(&mut self.load, &from, done);
        if !self.report.is_empty() {
            permute_in_place(&mut self.report, &from, done);
        }
        if !self.volume.is_empty() {
            permute_in_place(&mut self.volume, &from, done);
        }
        self.regional.clear();
        self.spheres_on_mesh.clear();
        self.own.clear();
        self.chunks.clear();
        self.finishing_first.clear();
        self.finishing.clear();
        self.incoming_first.clear();
        self.incoming.clear();
        self.wall_entries.clear();
    }

    /// Whether every body pair is oriented by global id and the entries are in the store's order
    /// ([`ContactKey::order`]).
    pub fn in_order(&self, ids: &[u64]) -> bool {
        let keys = &self.entries.key;
        let oriented = keys.iter().all(|k| match k.partner {
            Partner::Body(j) => ids[k.a as usize] < ids[j as usize],
            _ => true,
        });
        oriented && keys.windows(2).all(|w| w[0].order(ids) < w[1].order(ids))
    }

    /// Number of entries (candidate contacts).
    pub fn entries(&self) -> usize {
        self.entries.key.len()
    }

    pub fn keys(&self) -> &[ContactKey] {
        &self.entries.key
    }

    pub fn touching(&self) -> &[bool] {
        &self.entries.touching
    }

    /// The geometry kept per entry: empty in a world that keeps none, and never written for a
    /// sphere pair (see [`ContactStore::contact_point`]).
    pub fn geometry(&self) -> &[ContactPoint] {
        &self.entries.geometry
    }

    pub fn loads(&self) -> &[PartnerLoad] {
        &self.load
    }

    /// First entries of the pairs with [`MAX_REGIONS`] entries ([`PairKind::Regional`]).
    pub fn regional(&self) -> &[u32] {
        &self.regional
    }

    /// First entries of the spheres on mesh walls ([`PairKind::SphereOnMesh`]).
    pub fn spheres_on_mesh(&self) -> &[u32] {
        &self.spheres_on_mesh
    }

    /// A number that names the list of candidates the store holds, new with every list (and
    /// for a store read from a checkpoint), no two alike in the process; 0 before the first.
    /// What is worked out once per list and kept beside the store (the triangles near each
    /// sphere on a mesh wall, `step::detect`) tells by it when it is stale.
    pub fn list_id(&self) -> u64 {
        self.list_id
    }

    /// Whether the last contact loop (`step::detect_and_evaluate`) left the bodies' force sums
    /// complete: in a world whose step outgrows the last-level cache, where the loads of a body's
    /// incoming entries, read a whole step after they were written, would each be a miss; else
    /// the sums are completed by the pass over the bodies that follows (`step::IncomingSums`),
    /// where the loads are cache hits. Either way each sum is added up in the same order, so the
    /// same bits.
    pub fn completes_sums(&self) -> bool {
        self.sums_completed
    }

    /// Sets where the force sums are completed from the next step on: in the contact loop
    /// (`Some(true)`), in the pass over the bodies (`Some(false)`), or by the world's size
    /// against the last-level cache (`None`, the default). The results are the same bits.
    pub fn set_sums_in_loop(&mut self, choice: Option<bool>) {
        self.sums_in_loop = choice;
        self.chunks.clear();
    }

    pub(crate) fn set_sums_completed(&mut self, completed: bool) {
        self.sums_completed = completed;
    }

    /// Entries of body `i` as `a`.
    pub fn own(&self, i: usize) -> std::ops::Range<usize> {
        self.own[i] as usize..self.own[i + 1] as usize
    }

    /// Entries whose partner is body `i`.
    pub fn incoming(&self, i: usize) -> &[u32] {
        &self.incoming[self.incoming_first[i] as usize..self.incoming_first[i + 1] as usize]
    }

    /// Entries whose partner is a wall, in store order.
    pub fn wall_entries(&self) -> &[u32] {
        &self.wall_entries
    }

    /// Sets what the pairs with [`MAX_REGIONS`] entries touch this step: `assigned[g]` for the
    /// pair whose entries start at `regional()[g]` (spheres on mesh walls are set in the contact
    /// loop's chunks, `step::detect::set_spheres_on_mesh`). Returns the energy the dropped
    /// histories held (see [`StorePass::set_region`]), added up in store order.
    pub(crate) fn set_regions(
        &mut self,
        assigned: &[[Assigned; MAX_REGIONS]],
        bodies: &Bodies,
    ) -> f64 {
        debug_assert_eq!(assigned.len(), self.regional.len());
        let mut lost = 0.0;
        let regional = std::mem::take(&mut self.regional);
        let mut pass = self.entries_mut();
        for (&first, slots) in regional.iter().zip(assigned) {
            let slots = slots.iter().map(|a| {
                let point = a.geometry.as_ref().map(Geometry::contact_point);
                (point, a.geometry.and_then(|g| g.volume), a.fresh)
            });
            pass.set_pair(first as usize, slots, bodies, &mut lost);
        }
        self.regional = regional;
        lost
    }

    /// Sets what entry `e` touches this step (see [`StorePass::set_region`]).
    #[cfg(test)]
    pub(crate) fn set_region(
        &mut self,
        e: usize,
        point: Option<ContactPoint>,
        volume: Option<OverlapVolume>,
        fresh: bool,
    ) -> f64 {
        self.entries_mut().set_region(e, point, volume, fresh)
    }

    /// The contacts that touch, in store order (see [`Contacts`](super::Contacts)).
    pub(crate) fn touching_contacts<'a>(
        &'a self,
        at: Placement<'a>,
    ) -> impl Iterator<Item = ContactRef<'a>> + 'a {
        let e = &self.entries;
        (0..e.key.len()).filter(|&k| e.touching[k]).map(move |k| {
            let point = self.contact_point(k, at);
            ContactRef {
                key: e.key[k],
                geometry: point.with_volume(self.volume.get(k).copied().flatten()),
                history: &e.history[k],
                spin: e.spin.get(k),
                load: &self.load[k],
                report: self.report(k, &point, at),
            }
        })
    }

    /// Number of contacts that touch.
    pub fn len(&self) -> usize {
        self.entries.touching.iter().filter(|&&t| t).count()
    }

    pub fn is_empty(&self) -> bool {
        !self.entries.touching.iter().any(|&t| t)
    }
}

/// Keys and kinds of a run of entries.
pub(crate) struct EntryIds<'a> {
    pub key: &'a [ContactKey],
    pub kind: &'a [PairKind],
}

/// What a step writes of a run of entries.
pub(crate) struct EntryState<'a> {
    pub touching: &'a mut [bool],
    pub geometry: &'a mut [ContactPoint],
    /// Empty in a world without polyhedra.
    pub volume: &'a mut [Option<OverlapVolume>],
    pub history: &'a mut [History],
    /// Empty in a world without rolling friction and polyhedra.
    pub spin: &'a mut [SpinHistory],
    /// The partner's side of each entry's load, kept by the store for the force sums.
    pub load: &'a mut [PartnerLoad],
    /// Body `a`'s side of each touching entry's load, in the contact loop's scratch (what it
    /// holds for an entry that does not touch is not read).
    pub own: &'a mut [OwnLoad],
    /// Empty in a world that keeps no reports (see [`StoreLayout::reports`]).
    pub report: &'a mut [LawReport],
    /// The energy each entry dissipated over the step, in the contact loop's scratch: zero
    /// before the laws run, and for an entry they leave as it is.
    pub dissipated: &'a mut [f64],
}

impl EntryState<'_> {
    /// Makes `load` entry `k`'s load.
    #[inline(always)]
    pub(crate) fn set_load(&mut self, k: usize, load: Load) {
        self.load[k] = load.partner_side();
        self.own[k] = load.own_side();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::SPHERE_MESH_REGIONS;
    use crate::math::DVec3;

    fn touching_at(z: f64) -> ContactPoint {
        ContactPoint {
            normal: DVec3::Z,
            point: DVec3::new(0.0, 0.0, z),
            overlap: 1e-3,
        }
    }

    /// `n` bodies with ids `0..n`, none a ghost: what the store reads of bodies.
    fn numbered(n: u64) -> Bodies {
        Bodies {
            id: (0..n).collect(),
            ..Bodies::default()
        }
    }

    /// A layout that keeps every entry's geometry and report (these tests' pairs are not
    /// spheres).
    fn kept(volumes: bool, spins: bool) -> StoreLayout {
        StoreLayout {
            geometry: true,
            volumes,
            spins,
            reports: true,
        }
    }

    /// Where bodies `bodies` are, with no walls, for a store whose entries all keep their
    /// geometry and reports (nothing else is read).
    fn placement(bodies: &Bodies) -> Placement<'_> {
        static LAWS: std::sync::OnceLock<PairTable> = std::sync::OnceLock::new();
        let laws = LAWS.get_or_init(|| {
            let linear = crate::contact_law::NormalLaw::Linear { stiffness: 1.0 };
            PairTable::new(&[], linear, 1.0, &[])
        });
        Placement {
            bodies,
            shapes: &[],
            planes: &[],
            laws,
        }
    }

    /// The touching contacts of a store whose entries all keep their geometry and reports.
    fn touching(store: &ContactStore) -> Vec<ContactRef<'_>> {
        static BODIES: std::sync::OnceLock<Bodies> = std::sync::OnceLock::new();
        let bodies = BODIES.get_or_init(Bodies::default);
        store.touching_contacts(placement(bodies)).collect()
    }

    fn candidate(a: u32, partner: Partner) -> Candidate {
        Candidate {
            a,
            partner,
            kind: PairKind::Single,
        }
    }

    fn touch(store: &mut ContactStore, a: u32, partner: Partner) -> usize {
        let e = store
            .keys()
            .iter()
            .position(|k| k.a == a && k.partner == partner)
            .unwrap();
        store.set_region(e, Some(touching_at(0.0)), None, false);
        e
    }

    #[test]
    fn history_survives_a_new_neighbour_list_while_the_contact_lasts() {
        let mut store = ContactStore::default();
        let first = [
            candidate(0, Partner::Body(1)),
            candidate(1, Partner::Body(2)),
            candidate(1, Partner::Plane(0)),
        ];
        store.set_candidates(&first, &numbered(3), kept(false, false));
        let e = touch(&mut store, 1, Partner::Body(2));
        store.entries.history[e].tangential_spring = DVec3::X;
        store.entries.history[e].tangential_stiffness = 4.0;
        // A new list: (0, 2) is new, (1, 2) continues, (0, 1) is gone.
        let second = [
            candidate(0, Partner::Body(2)),
            candidate(1, Partner::Body(2)),
            candidate(1, Partner::Plane(0)),
        ];
        assert_eq!(
            store.set_candidates(&second, &numbered(3), kept(false, false)),
            0.0
        );
        let history = |s: &ContactStore, k: usize| s.entries.history[k];
        assert_eq!(history(&store, 0), History::default());
        assert_eq!(history(&store, 1).tangential_spring, DVec3::X);
        assert!(store.touching()[1]);
        // A touching contact that drops out gives back the energy its springs held.
        let lost = store.set_candidates(
            &[candidate(0, Partner::Body(2))],
            &numbered(3),
            kept(false, false),
        );
        assert_eq!(lost, 0.5 * 4.0);
    }

    /// Issue #18's memory target: the merge's working memory is let go of after it (it would
    /// otherwise be held through the next neighbour search, where the run's memory peaks).
    #[test]
    fn the_store_holds_no_merge_memory_between_lists() {
        let mut store = ContactStore::default();
        let pairs = [
            candidate(0, Partner::Body(1)),
            candidate(1, Partner::Body(2)),
        ];
        for _ in 0..2 {
            store.set_candidates(&pairs, &numbered(3), kept(false, false));
            let working = [&store.fates, &store.targets, &store.first_entry];
            assert!(working.iter().all(|v| v.capacity() == 0));
            assert_eq!(store.keys().len(), 2);
        }
    }

    /// The rolling and twisting springs, kept only where asked for, follow their contact like the
    /// tangential one and count in the energy a dropped contact gives back.
    #[test]
    fn spin_history_survives_a_new_neighbour_list_and_only_where_kept() {
        let mut store = ContactStore::default();
        let pairs = [
            candidate(0, Partner::Body(1)),
            candidate(1, Partner::Body(2)),
        ];
        store.set_candidates(&pairs, &numbered(3), kept(false, false));
        assert!(touching(&store).into_iter().all(|c| c.spin.is_none()));
        store.set_candidates(&pairs, &numbered(3), kept(false, true));
        let e = touch(&mut store, 1, Partner::Body(2));
        store.entries.spin[e] = SpinHistory {
            rolling_torque: DVec3::Y,
            rolling_stiffness: 0.25,
            ..SpinHistory::default()
        };
        let more = [pairs[0], candidate(0, Partner::Body(2)), pairs[1]];
        assert_eq!(
            store.set_candidates(&more, &numbered(3), kept(false, true)),
            0.0
        );
        let c = touching(&store).into_iter().find(|c| c.key.a == 1).unwrap();
        assert_eq!(c.spin.unwrap().rolling_torque, DVec3::Y);
        let lost = store.set_candidates(&more[..2], &numbered(3), kept(false, true));
        assert_eq!(lost, 0.5 / 0.25);
    }

    proptest::proptest! {
        /// The in-place merge of a new candidate list gives what a merge into fresh arrays
        /// gives: every continuing key keeps its state, new keys start afresh, dropped touching
        /// contacts give back their springs' energy; over random sequences of lists.
        #[test]
        fn in_place_merge_matches_a_fresh_merge(
            lists in proptest::collection::vec(
                proptest::collection::btree_set((0u32..6, 0u32..8, 0u8..3), 0..30),
                1..6,
            ),
            spins in proptest::bool::ANY,
        ) {
            use std::collections::BTreeMap;
            let mut store = ContactStore::default();
            // The model: key -> (kind, touching, spring, rolling torque).
            let mut model: BTreeMap<ContactKey, (PairKind, bool, DVec3, DVec3)> = BTreeMap::new();
            for (round, list) in lists.iter().enumerate() {
                let candidates: Vec<Candidate> = list
                    .iter()
                    .map(|&(a, p, kind)| Candidate {
                        a,
                        partner: if p < 6 { Partner::Body(p) } else { Partner::Plane(p - 6) },
                        kind: [PairKind::Single, PairKind::Spheres, PairKind::Regional][kind as usize],
                    })
                    .map(|c| ((c.a, c.partner), c))
                    .collect::<std::collections::BTreeMap<_, _>>()
                    .into_values()
                    .collect();
                let mut fresh = BTreeMap::new();
                for c in &candidates {
                    let regions = if c.kind == PairKind::Regional { MAX_REGIONS as u8 } else { 1 };
                    for region in 0..regions {
                        let key = ContactKey { a: c.a, partner: c.partner, region };
                        let state = model.get(&key).map_or(
                            (c.kind, false, DVec3::ZERO, DVec3::ZERO),
                            |&(_, t, x, r)| (c.kind, t, x, r),
                        );
                        fresh.insert(key, state);
                    }
                }
                let expected_lost: f64 = model
                    .iter()
                    .filter(|(k, s)| s.1 && !fresh.contains_key(k))
                    .map(|(_, s)| 0.5 * s.2.length_squared() + if spins { s.3.length_squared() } else { 0.0 })
                    .sum();
                let lost = store.set_candidates(&candidates, &numbered(6), kept(false, spins));
                model = fresh;
                proptest::prop_assert!((lost - expected_lost).abs() <= 1e-12 * (1.0 + expected_lost));
                let keys: Vec<ContactKey> = model.keys().copied().collect();
                proptest::prop_assert_eq!(store.keys(), &keys[..]);
                for (k, (key, &(kind, touching, spring, rolling))) in model.iter().enumerate() {
                    proptest::prop_assert_eq!(store.entries.kind[k], kind, "{:?}", key);
                    proptest::prop_assert_eq!(store.entries.touching[k], touching);
                    proptest::prop_assert_eq!(store.entries.history[k].tangential_spring, spring);
                    if spins {
                        proptest::prop_assert_eq!(store.entries.spin[k].rolling_torque, rolling);
                    } else {
                        proptest::prop_assert!(store.entries.spin.is_empty());
                    }
                }
                // Give some entries a state for the next round: touching, with springs of known
                // energy (stiffness 1: energy |ξ|²/2; rolling stiffness 0.5: energy |M|²).
                for (k, (_, state)) in model.iter_mut().enumerate() {
                    if (k + round) % 3 == 0 {
                        let spring = DVec3::new(k as f64 + 1.0, round as f64, 0.5);
                        store.entries.touching[k] = true;
                        store.entries.history[k] = History {
                            tangential_spring: spring,
                            tangential_stiffness: 1.0,
                            ..History::default()
                        };
                        state.1 = true;
                        state.2 = spring;
                        if spins {
                            let rolling = DVec3::new(0.0, 1.0, k as f64);
                            store.entries.spin[k] = SpinHistory {
                                rolling_torque: rolling,
                                rolling_stiffness: 0.5,
                                ..SpinHistory::default()
                            };
                            state.3 = rolling;
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn index_lists_name_each_bodys_contacts() {
        let mut store = ContactStore::default();
        let list = [
            candidate(0, Partner::Body(2)),
            candidate(0, Partner::Plane(0)),
            candidate(1, Partner::Body(2)),
            Candidate {
                a: 1,
                partner: Partner::Mesh(0),
                kind: PairKind::Regional,
            },
        ];
        store.set_candidates(&list, &numbered(3), kept(true, true));
        assert_eq!(store.entries(), 3 + MAX_REGIONS);
        assert_eq!(store.own(0), 0..2);
        assert_eq!(store.own(1), 2..3 + MAX_REGIONS);
        assert_eq!(store.own(2), 3 + MAX_REGIONS..3 + MAX_REGIONS);
        assert_eq!(store.incoming(2), &[0, 2]);
        assert!(store.incoming(0).is_empty());
        assert_eq!(store.regional(), &[3]);
        assert_eq!(store.wall_entries().len(), 1 + MAX_REGIONS);
    }

    /// A sphere on a mesh wall has four slots, a polyhedron eight; each kind has its list of
    /// first entries. `set_regions` sets the polyhedra's, booking the energy of the histories
    /// that end in store order; the spheres' are left to the contact loop's chunks.
    #[test]
    fn regional_pairs_and_spheres_on_meshes_are_listed_apart() {
        let mut store = ContactStore::default();
        let regional = |a, partner, kind| Candidate { a, partner, kind };
        let list = [
            regional(0, Partner::Mesh(0), PairKind::SphereOnMesh),
            regional(1, Partner::Body(2), PairKind::Regional),
            regional(1, Partner::Mesh(0), PairKind::Regional),
            regional(1, Partner::Mesh(1), PairKind::Regional),
            regional(2, Partner::Mesh(0), PairKind::SphereOnMesh),
        ];
        store.set_candidates(&list, &numbered(3), kept(true, true));
        let (four, eight) = (SPHERE_MESH_REGIONS, MAX_REGIONS);
        assert_eq!(store.entries(), 2 * four + 3 * eight);
        assert_eq!(
            store.spheres_on_mesh(),
            &[0, four as u32 + 3 * eight as u32]
        );
        assert_eq!(
            store.regional(),
            &[
                four as u32,
                (four + eight) as u32,
                (four + 2 * eight) as u32
            ]
        );
        // Every pair touches in its last slot, with a spring holding 2 J (the spheres), and
        // 2^53, 1 and 1 J (the polyhedra, in store order): added in another order, the sum
        // rounds otherwise.
        let lasts = [
            four - 1,
            four + eight - 1,
            four + 2 * eight - 1,
            four + 3 * eight - 1,
            2 * four + 3 * eight - 1,
        ];
        let springs = [
            (4.0, 1.0),
            (4.0, 2f64.powi(26)),
            (2.0, 1.0),
            (2.0, 1.0),
            (4.0, 1.0),
        ];
        for (&e, &(stiffness, spring)) in lasts.iter().zip(&springs) {
            store.set_region(e, Some(touching_at(0.0)), None, false);
            let history = &mut store.entries.history[e];
            history.tangential_stiffness = stiffness;
            history.tangential_spring = DVec3::X * spring;
        }
        // Next step no polyhedron touches: their energies come back as one sum in store order.
        let none = vec![[Assigned::default(); MAX_REGIONS]; 3];
        let lost = store.set_regions(&none, &numbered(3));
        let in_order = (2f64.powi(53) + 1.0) + 1.0;
        assert_ne!(in_order, 2f64.powi(53) + (1.0 + 1.0));
        assert_eq!(lost.to_bits(), in_order.to_bits());
        assert!(lasts[1..4].iter().all(|&e| !store.touching()[e]));
        assert!(store.touching()[lasts[0]] && store.touching()[lasts[4]]);
    }

    /// Regression (the contact loop passes by regional entries that do not touch): a region
    /// that ends gives up its load and report when its slot is set free, not when the laws run.
    /// A non-convex body's stale load would go on pushing its partner (the force sums add every
    /// incoming load, touching or not).
    #[test]
    fn a_region_that_ends_gives_up_its_load_and_report() {
        let mut store = ContactStore::default();
        let list = [Candidate {
            a: 0,
            partner: Partner::Body(1),
            kind: PairKind::Regional,
        }];
        store.set_candidates(&list, &numbered(2), kept(true, false));
        store.set_region(2, Some(touching_at(0.0)), None, true);
        store.load[2].force = DVec3::X;
        store.load[2].torque_b = DVec3::Y;
        store.report[2] = LawReport {
            normal_force: 1.0,
            elastic_energy: 2.0,
        };
        // Still touching: what the laws wrote stays until they write again.
        store.set_region(2, Some(touching_at(1e-6)), None, false);
        assert_eq!(store.load[2].force, DVec3::X);
        store.set_region(2, None, None, false);
        assert_eq!(store.load[2], PartnerLoad::default());
        assert_eq!(store.report[2], LawReport::default());
        assert!(!store.touching()[2]);
    }

    /// A store whose body pairs are seen from the lower index (as checkpoints of older versions
    /// keep them) is turned to the order of ids: each pair seen from the body of smaller id,
    /// with its springs and load seen from that side (the new partner's moment from the balance
    /// of moments), and sorted by partner id.
    #[test]
    fn a_store_oriented_by_index_is_turned_to_the_order_of_ids() {
        let mut store = ContactStore::default();
        let list = [
            candidate(0, Partner::Body(1)),
            candidate(0, Partner::Body(2)),
            candidate(1, Partner::Body(2)),
        ];
        store.set_candidates(&list, &numbered(3), kept(false, false));
        let e = touch(&mut store, 0, Partner::Body(2));
        store.entries.history[e].tangential_spring = DVec3::X;
        // Body 0 at the origin pushed along y at (1, 0, 0) by body 2 at (2, 0, 0): both turn
        // about +z.
        store.load[e].force = DVec3::Y;
        store.load[e].torque_b = DVec3::Z;
        let positions = [DVec3::ZERO, DVec3::ONE, DVec3::new(2.0, 0.0, 0.0)];
        // The same bodies with ids in the other order: every pair is now seen from the wrong side.
        let reversed = Bodies {
            id: vec![2, 1, 0],
            ..Bodies::default()
        };
        assert!(store.in_order(&numbered(3).id));
        assert!(!store.in_order(&reversed.id));
        store.permute(&[0, 1, 2], &reversed.id, &positions);
        assert!(store.in_order(&reversed.id));
        let keys: Vec<_> = store.keys().iter().map(|k| (k.a, k.partner)).collect();
        assert_eq!(
            keys,
            vec![
                (1, Partner::Body(0)),
                (2, Partner::Body(1)),
                (2, Partner::Body(0)),
            ]
        );
        let turned = store
            .keys()
            .iter()
            .position(|k| k.a == 2 && k.partner == Partner::Body(0));
        let turned = turned.unwrap();
        assert_eq!(store.entries.history[turned].tangential_spring, -DVec3::X);
        assert_eq!(store.load[turned].force, -DVec3::Y);
        assert_eq!(store.load[turned].torque_b, DVec3::Z);
        assert_eq!(store.entries.geometry[turned].normal, -DVec3::Z);
    }

    #[test]
    fn renumbering_drops_the_contacts_of_removed_bodies_and_keeps_order() {
        let mut store = ContactStore::default();
        let list = [
            candidate(0, Partner::Body(1)),
            candidate(0, Partner::Body(2)),
            candidate(2, Partner::Plane(0)),
        ];
        let bodies = numbered(3);
        store.set_candidates(&list, &bodies, kept(true, true));
        let e = touch(&mut store, 0, Partner::Body(1));
        store.report[e].elastic_energy = 2.0;
        let new_index = [0, u32::MAX, 1];
        let lost = store.dropped_energy(&new_index, |_| true, placement(&bodies));
        assert_eq!(lost, 2.0);
        store.renumber(&new_index);
        let keys: Vec<_> = store.keys().iter().map(|k| (k.a, k.partner)).collect();
        assert_eq!(keys, vec![(0, Partner::Body(1)), (1, Partner::Plane(0))]);
    }
}
