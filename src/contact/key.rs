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

    /// Where the partner sorts among a body's contacts: bodies by global id (`ids`, indexed by
    /// body), then planes, then mesh walls by index. Global ids do not depend on how the bodies
    /// are numbered (the space order, or one rank's share of them under MPI), so neither does this
    /// order, nor the force sums that follow it.
    #[inline]
    pub fn rank(self, ids: &[u64]) -> (u8, u64) {
        match self {
            Partner::Body(j) => (0, ids[j as usize]),
            Partner::Plane(p) => (1, p as u64),
            Partner::Mesh(w) => (2, w as u64),
        }
    }
}

/// How the narrow phase treats a pair; decided from the shapes when the pair becomes a candidate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum PairKind {
    /// Two spheres: centre distance against the sum of radii, nothing else.
    Spheres,
    /// Touches in one place at most: convex shapes with each other or with a plane.
    Single,
    /// May touch in several places at once (a non-convex body, a polyhedron on a mesh wall):
    /// the pair has `MAX_REGIONS` entries, matched to last step's by `contact::assign_regions`.
    Regional,
    /// A sphere on a mesh wall: regional as [`PairKind::Regional`], with
    /// [`SPHERE_MESH_REGIONS`] entries. A sphere touches a mesh once for each nearest point of
    /// the surface closer than its radius (`narrow_phase::sphere_mesh`): once on a flat or
    /// smooth surface, twice in a fold, three times in the corner of three walls.
    SphereOnMesh,
}

/// The slots of a sphere on a mesh wall ([`PairKind::SphereOnMesh`]): the three of a corner and
/// one to spare. Half of a polyhedron's eight, for the pair that outnumbers all other regional
/// pairs in drums, chutes and hoppers: every one of its slots is an entry that each stage passes
/// over at every step.
pub const SPHERE_MESH_REGIONS: usize = 4;

impl PairKind {
    /// The kind of a pair of `a` and `partner`, given whether each is a sphere and whether it
    /// may touch in several places (`None` for a wall partner).
    pub fn of(a: ShapeTraits, partner: Partner, b: Option<ShapeTraits>) -> Self {
        match (partner, b) {
            (Partner::Mesh(_), _) if a.sphere => PairKind::SphereOnMesh,
            (Partner::Mesh(_), _) => PairKind::Regional,
            _ if a.regional || b.is_some_and(|b| b.regional) => PairKind::Regional,
            (Partner::Body(_), Some(b)) if a.sphere && b.sphere => PairKind::Spheres,
            _ => PairKind::Single,
        }
    }

    /// Whether the pair may touch in several places, and has a store entry for each
    /// ([`PairKind::regions`]).
    #[inline(always)]
    pub fn is_regional(self) -> bool {
        matches!(self, PairKind::Regional | PairKind::SphereOnMesh)
    }

    /// The number of store entries (slots for contact regions) a pair of this kind has.
    #[inline(always)]
    pub fn regions(self) -> usize {
        match self {
            PairKind::Spheres | PairKind::Single => 1,
            PairKind::Regional => crate::narrow_phase::MAX_REGIONS,
            PairKind::SphereOnMesh => SPHERE_MESH_REGIONS,
        }
    }
}

/// What [`PairKind::of`] needs to know of a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeTraits {
    pub sphere: bool,
    pub regional: bool,
}

/// The identity of one contact, stable while the contact lasts: body `a` (for two bodies the one
/// with the smaller global id, `Bodies::id`), its partner, and which of the pair's contact regions
/// this is (0 for a pair that touches in one place). The store keeps its contacts in the order of
/// [`ContactKey::order`]: by `a`, then by partner and region in an order that does not depend on
/// how the bodies are numbered. So the force sums run in one order whatever the thread count, the
/// bodies' numbering or (under MPI) the rank count, and give the same bits.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct ContactKey {
    pub a: u32,
    pub partner: Partner,
    pub region: u8,
}

/// Where a contact sorts in the store: see [`ContactKey::order`].
pub type ContactOrder = (u32, (u8, u64), u8);

impl ContactKey {
    /// The store's order of contacts: by `a` (an index), then by [`Partner::rank`] (global ids),
    /// then by region.
    #[inline]
    pub fn order(&self, ids: &[u64]) -> ContactOrder {
        (self.a, self.partner.rank(ids), self.region)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_of_pair_gets_its_slots() {
        let sphere = ShapeTraits {
            sphere: true,
            regional: false,
        };
        let convex = ShapeTraits {
            sphere: false,
            regional: false,
        };
        let jack = ShapeTraits {
            sphere: false,
            regional: true,
        };
        let mesh = Partner::Mesh(0);
        let cases = [
            (sphere, Partner::Body(1), Some(sphere), PairKind::Spheres, 1),
            (sphere, Partner::Plane(0), None, PairKind::Single, 1),
            (convex, Partner::Body(1), Some(sphere), PairKind::Single, 1),
            (
                sphere,
                mesh,
                None,
                PairKind::SphereOnMesh,
                SPHERE_MESH_REGIONS,
            ),
            (
                convex,
                mesh,
                None,
                PairKind::Regional,
                crate::narrow_phase::MAX_REGIONS,
            ),
            (
                jack,
                mesh,
                None,
                PairKind::Regional,
                crate::narrow_phase::MAX_REGIONS,
            ),
            (sphere, Partner::Body(1), Some(jack), PairKind::Regional, 8),
        ];
        for (a, partner, b, kind, regions) in cases {
            assert_eq!(PairKind::of(a, partner, b), kind, "{a:?} {partner:?} {b:?}");
            assert_eq!(kind.regions(), regions);
            assert_eq!(kind.is_regional(), regions > 1);
        }
    }
}
