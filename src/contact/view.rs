//! The contacts as outside code reads them (`World::contacts`): the store, and where the bodies
//! and planes are, from which it finds again the geometry it does not keep (a sphere pair's; in
//! a world of spheres and planes alone, every contact's: see `StoreLayout::geometry`).

use super::store::{ContactRef, ContactStore, Placement};
use super::Partner;

/// The touching contacts of a world, read between steps.
#[derive(Clone, Copy)]
pub struct Contacts<'a> {
    store: &'a ContactStore,
    at: Placement<'a>,
}

impl<'a> Contacts<'a> {
    pub fn new(store: &'a ContactStore, at: Placement<'a>) -> Self {
        Contacts { store, at }
    }

    /// The store itself: its entries, candidates as well as contacts.
    pub fn store(&self) -> &'a ContactStore {
        self.store
    }

    /// The contacts that touch, in store order.
    pub fn iter(&self) -> impl Iterator<Item = ContactRef<'a>> + 'a {
        self.store.touching_contacts(self.at)
    }

    /// Contacts between two bodies.
    pub fn between_bodies(&self) -> impl Iterator<Item = ContactRef<'a>> + 'a {
        self.iter()
            .filter(|c| matches!(c.key.partner, Partner::Body(_)))
    }

    /// Contacts of bodies with plane walls.
    pub fn with_planes(&self) -> impl Iterator<Item = ContactRef<'a>> + 'a {
        self.iter()
            .filter(|c| matches!(c.key.partner, Partner::Plane(_)))
    }

    /// Contacts of bodies with mesh walls.
    pub fn with_mesh_walls(&self) -> impl Iterator<Item = ContactRef<'a>> + 'a {
        self.iter()
            .filter(|c| matches!(c.key.partner, Partner::Mesh(_)))
    }

    /// Number of contacts that touch.
    pub fn len(&self) -> usize {
        self.store.len()
    }

    pub fn is_empty(&self) -> bool {
        self.store.is_empty()
    }

    /// Number of entries (candidate contacts).
    pub fn entries(&self) -> usize {
        self.store.entries()
    }
}
