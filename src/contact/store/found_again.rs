//! What the store does not keep of a touching entry, found again when it is read between steps:
//! the contact point of a sphere pair (in a world of spheres and planes, of every contact), and
//! in such a world the law's report too (see `StoreLayout`). Between steps the bodies are where
//! the last evaluation found them (the closing half kick moves none), so the same operations on
//! the same numbers give the bits the contact law used.

use super::{ContactStore, Placement};
use crate::contact::key::{PairKind, Partner};
use crate::contact::load::LawReport;
use crate::contact_law::{effective_radius_and_mass, normal};
use crate::narrow_phase::{self, ContactPoint};

impl ContactStore {
    /// The contact point of touching entry `k`: the one kept, or for a sphere pair (and in a
    /// world that keeps no geometry, a sphere on a plane) found again from the bodies `at` by the
    /// narrow phase's own operations, so that between steps it has the bits the contact law used.
    pub fn contact_point(&self, k: usize, at: Placement) -> ContactPoint {
        let key = self.entries.key[k];
        if let Some(g) = self.entries.geometry.get(k) {
            if self.entries.kind[k] != PairKind::Spheres {
                return *g;
            }
        }
        let (a, b) = (key.a as usize, at.bodies);
        match key.partner {
            Partner::Body(j) => {
                let j = j as usize;
                let radius = &b.bounding_radius;
                narrow_phase::overlapping_spheres(
                    b.position[a],
                    radius[a],
                    b.position[j],
                    radius[j],
                )
            }
            Partner::Plane(p) => {
                let plane = &at.planes[p as usize];
                let radius = at.shapes[b.shape[a] as usize].bounding_radius();
                narrow_phase::touching_sphere_plane(
                    b.position[a],
                    radius,
                    plane.point,
                    plane.normal,
                )
            }
            Partner::Mesh(_) => unreachable!("a world with mesh walls keeps their geometry"),
        }
    }

    /// The law's report of touching entry `k`, whose contact point is `point`
    /// ([`ContactStore::contact_point`]): the one kept, or in a world that keeps none (spheres
    /// and planes under point laws) found again from the bodies `at`:
    ///
    /// - the elastic energy as the point law sums it: the normal law's at the overlap and R*
    ///   the law used, plus the tangential spring's as the history keeps it (½ k_t |ξ|², the
    ///   numbers the law wrote), plus in a world with rolling friction the rolling spring's
    ///   (½ |M_r|²/k_r, likewise; a point contact has no twisting spring, so `stored_energy`'s
    ///   twisting term is the zero the law adds in its place): the same bits;
    /// - the normal force as the load's force along the normal, F·n: the law's F = n F_n + F_t
    ///   with F_t ⊥ n, so F_n to rounding (a few units in the last place). A contact whose normal
    ///   force was cut off at zero has no friction either, F = 0, and reads 0.
    pub fn report(&self, k: usize, point: &ContactPoint, at: Placement) -> LawReport {
        if let Some(r) = self.report.get(k) {
            return *r;
        }
        let key = self.entries.key[k];
        let (a, b) = (key.a as usize, at.bodies);
        // R* and the partner's material as the contact loop takes them (`step::sphere_lanes`,
        // `step::plane_lanes`, `step::forces::LawInputs::respond`).
        let (effective_radius, material) = match key.partner {
            Partner::Body(j) => {
                let j = j as usize;
                let radius = (b.bounding_radius[a], b.bounding_radius[j]);
                let (radius, _) = effective_radius_and_mass(radius, (b.mass[a], b.mass[j]));
                (radius, b.material[j])
            }
            Partner::Plane(p) => (b.equivalent_radius[a], at.planes[p as usize].material),
            Partner::Mesh(_) => unreachable!("a world with mesh walls keeps its reports"),
        };
        let law = at.laws.get(b.material[a], material);
        let (_, _, normal_energy, _) = normal::elastic(law, point.overlap, effective_radius);
        let elastic_energy = normal_energy + self.entries.history[k].stored_energy();
        LawReport {
            normal_force: self.load[k].force.dot(point.normal).max(0.0),
            elastic_energy: match self.entries.spin.get(k) {
                Some(spin) => elastic_energy + spin.stored_energy(),
                None => elastic_energy,
            },
        }
    }

    /// The elastic energy held by the touching contacts that a renumbering by `new_index` drops
    /// ([`ContactStore::renumber`]: those of removed bodies), of those whose body `a` is
    /// `counted`, in store order; the bodies `at` are still numbered as before.
    pub fn dropped_energy(
        &self,
        new_index: &[u32],
        counted: impl Fn(usize) -> bool,
        at: Placement,
    ) -> f64 {
        let e = &self.entries;
        let removed = |i: u32| new_index[i as usize] == u32::MAX;
        (0..e.key.len())
            .filter(|&k| {
                let key = e.key[k];
                let partner_removed = key.partner.body().is_some_and(removed);
                e.touching[k] && (removed(key.a) || partner_removed) && counted(key.a as usize)
            })
            .map(|k| {
                self.report(k, &self.contact_point(k, at), at)
                    .elastic_energy
            })
            .fold(0.0, |lost, energy| lost + energy)
    }
}
