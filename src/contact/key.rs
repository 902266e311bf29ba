//! Which contact a contact is: the body, its partner and the region.

/// What a body touches: another body, a plane wall or a mesh wall (by index in the world's lists).
/// The order (bodies, then planes, then mesh walls) is the order of a body's contacts in the store.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum Partner {
    Body(u32),
    Plane(u32),
    Mesh(u32),
}

impl Partner {
    /// The partner's index when it is a body.
    pub fn body(self) -> Option<u32> {
        match self {
            Partner::Body(j) => Some(j),
            _ => None,
        }
    }

    pub fn is_wall(self) -> bool {
        !matches!(self, Partner::Body(_))
    }
}

/// How the narrow phase treats a pair; decided from the shapes when the pair becomes a candidate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PairKind {
    /// Two spheres: centre distance against the sum of radii, nothing else.
    Spheres,
    /// Touches in one place at most: convex shapes with each other or with a plane.
    Single,
    /// May touch in several places at once (a non-convex body, a mesh wall): the pair has
    /// `MAX_REGIONS` entries, matched to last step's by `contact::assign_regions`.
    Regional,
}

impl PairKind {
    /// The kind of a pair of `a` and `partner`, given whether each is a sphere and whether it
    /// may touch in several places (`None` for a wall partner).
    pub fn of(a: ShapeTraits, partner: Partner, b: Option<ShapeTraits>) -> Self {
        match (partner, b) {
            (Partner::Mesh(_), _) => PairKind::Regional,
            _ if a.regional || b.is_some_and(|b| b.regional) => PairKind::Regional,
            (Partner::Body(_), Some(b)) if a.sphere && b.sphere => PairKind::Spheres,
            _ => PairKind::Single,
        }
    }
}

/// What [`PairKind::of`] needs to know of a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeTraits {
    pub sphere: bool,
    pub regional: bool,
}

/// The identity of one contact, stable while the contact lasts: body `a` (for two bodies the smaller
/// index), its partner, and which of the pair's contact regions this is (0 for a pair that touches
/// in one place). Keys sort by `(a, partner, region)`; the store keeps its contacts in that order,
/// which is what makes every later loop run in a fixed order whatever the thread count.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct ContactKey {
    pub a: u32,
    pub partner: Partner,
    pub region: u8,
}
