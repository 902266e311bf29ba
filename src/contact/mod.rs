//! Contacts: who touches whom, the geometry of each contact this step, and the history it carries
//! from step to step (see [`ContactStore`]).

mod key;
mod load;
mod regions;
mod store;
mod view;

pub use key::{ContactKey, ContactOrder, PairKind, Partner, ShapeTraits, SPHERE_MESH_REGIONS};
pub use load::{LawReport, Load, OwnLoad, PartnerLoad};
pub use regions::{assign_regions, Assigned, MAX_REGIONS};
pub(crate) use store::{finish, Chunks, EntryIds, EntryState, StorePass};
pub use store::{
    Candidate, ContactRef, ContactStore, EntryRecord, PartnerId, Placement, StoreLayout,
    UnplacedContact, CHUNK_ENTRIES,
};
pub use view::Contacts;
