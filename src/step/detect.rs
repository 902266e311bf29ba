//! Stage 2 of the contact pipeline: the narrow phase. For every candidate in the contact store, its
//! contact geometry this step (normal, point, overlap, and for polyhedra the overlap's volume), by
//! `narrow_phase` per pair of shape kinds; pairs that can touch in several places get their regions
//! matched to last step's by the one rule of `contact::assign_regions`.

use crate::body::Bodies;
use crate::contact::{
    assign_regions, Assigned, ContactKey, ContactStore, EntryState, Partner, StorePass,
    MAX_REGIONS, SPHERE_MESH_REGIONS,
};
use crate::contact_law::PolyhedralLaw;
use crate::math::{Aabb, DVec3};
use crate::narrow_phase::{
    self, ClipScratch, ContactPoint, ConvexMeshScratch, Geometry, MeshContact, MeshScratch, Posed,
    RegionScratch,
};
use crate::shape::Shape;
use crate::step::prefetch::prefetch;
use crate::wall::{MeshWall, Plane};
use rayon::prelude::*;
use std::cell::RefCell;
use std::ops::Range;

/// Working memory of the narrow phase, one per worker thread for the life of the thread (kept in a
/// thread-local, so parallel jobs do not build it afresh).
#[derive(Default)]
struct Scratch {
    clip: ClipScratch,
    regions: RegionScratch,
    mesh: MeshScratch,
    mesh_contacts: Vec<MeshContact>,
    convex_mesh: ConvexMeshScratch,
    found: Vec<Geometry>,
    points: Vec<ContactPoint>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// The world as the narrow phase sees it.
#[derive(Clone, Copy)]
pub struct Scene<'a> {
    pub bodies: &'a Bodies,
    pub shapes: &'a [Shape],
    pub planes: &'a [Plane],
    pub walls: &'a [MeshWall],
    pub law: PolyhedralLaw,
}

impl<'a> Scene<'a> {
    fn shape(&self, i: u32) -> &'a Shape {
        &self.shapes[self.bodies.shape[i as usize] as usize]
    }

    fn posed(&self, i: u32) -> Posed<'a> {
        Posed {
            shape: self.shape(i),
            position: self.bodies.position[i as usize],
            orientation: self.bodies.orientation[i as usize],
        }
    }
}

/// How many spheres on mesh walls ahead [`set_spheres_on_mesh`] asks for their slots.
const PREFETCH_AHEAD: usize = 2;

/// Regions matched to their slots, per polyhedral pair with several entries (reused from step
/// to step), and the triangles each sphere on a mesh wall may touch while the neighbour list
/// lasts.
#[derive(Default)]
pub struct RegionOutput {
    assigned: Vec<[Assigned; MAX_REGIONS]>,
    near: NearTriangles,
}

impl RegionOutput {
    /// The triangles near each sphere on a mesh wall, for [`set_spheres_on_mesh`].
    pub fn near_triangles(&self) -> &NearTriangles {
        &self.near
    }
}

/// The triangles near each sphere on a mesh wall (`near[first[h]..first[h + 1]]` for the
/// sphere whose entries start at the store's `spheres_on_mesh()[h]`), made for the store's list
/// `list` (`ContactStore::list_id`) and the skin `skin`: those within the sphere's radius and
/// twice its margin and half a skin of where it was then.
#[derive(Default)]
pub struct NearTriangles {
    list: u64,
    skin: f64,
    first: Vec<u32>,
    near: Vec<u32>,
}

impl NearTriangles {
    /// No lists (a world without spheres on mesh walls).
    #[cfg(test)]
    pub fn none() -> &'static NearTriangles {
        static NONE: NearTriangles = NearTriangles {
            list: 0,
            skin: 0.0,
            first: Vec::new(),
            near: Vec::new(),
        };
        &NONE
    }

    /// Makes the lists again if the store holds another list of candidates than they were made
    /// for. A list stays while no body has moved beyond its margin since it was made (`margin`,
    /// per body; half the skin where empty), nor any wall more than half the skin
    /// (`candidates::NeighbourSearch`): a sphere then stays within its margin and half a skin of
    /// where it was, in its wall's placement, and within twice that of where it is now, whenever
    /// within the list's life this is done (right after the list is made, or after a restart).
    /// The distance to a triangle changes no faster than the sphere moves, so the triangles
    /// within the radius and that reach hold every triangle it can reach before the next list
    /// (`narrow_phase::triangles_within`; fewer than those whose boxes come that near).
    fn update(&mut self, scene: Scene, store: &ContactStore, (skin, margin): (f64, &[f64])) {
        if self.list == store.list_id() && store.list_id() != 0 && self.skin == skin {
            return;
        }
        let keys = store.keys();
        let lists: Vec<Vec<u32>> = store
            .spheres_on_mesh()
            .par_iter()
            .with_min_len(64)
            .map(|&first| {
                let key = &keys[first as usize];
                let (x, r, wall) = sphere_and_wall(scene, key);
                let margin = margin.get(key.a as usize).copied().unwrap_or(0.5 * skin);
                let mut near = Vec::new();
                narrow_phase::triangles_within(x, r + 2.0 * margin + skin, wall, &mut near);
                near
            })
            .collect();
        self.first.clear();
        self.near.clear();
        for list in &lists {
            self.first.push(self.near.len() as u32);
            self.near.extend_from_slice(list);
        }
        self.first.push(self.near.len() as u32);
        (self.list, self.skin) = (store.list_id(), skin);
    }

    /// The triangles near the `h`-th sphere on a mesh wall.
    fn of(&self, h: usize) -> &[u32] {
        &self.near[self.first[h] as usize..self.first[h + 1] as usize]
    }
}

/// The sphere of a sphere-on-mesh entry `key`: its centre in its wall's reference placement, its
/// radius, and the wall.
#[inline]
fn sphere_and_wall<'a>(scene: Scene<'a>, key: &ContactKey) -> (DVec3, f64, &'a MeshWall) {
    let (Partner::Mesh(w), Shape::Sphere(sphere)) = (key.partner, scene.shape(key.a)) else {
        unreachable!("a sphere-on-mesh entry is a sphere and a mesh wall")
    };
    let wall = &scene.walls[w as usize];
    let x = wall
        .pose()
        .to_reference(scene.bodies.position[key.a as usize]);
    (x, sphere.radius, wall)
}

/// The geometry of every polyhedral pair that may touch in several places, matched to last
/// step's regions, and the triangles near each sphere on a mesh wall (whose slots the contact
/// loop sets, [`set_spheres_on_mesh`]). Returns the energy held by the history of region
/// contacts that ended or gave their slot to a new contact (dissipated). `reach`: the neighbour
/// search's skin and each body's margin (see [`NearTriangles::update`]).
pub fn detect_regions(
    scene: Scene,
    store: &mut ContactStore,
    regions: &mut RegionOutput,
    reach: (f64, &[f64]),
) -> f64 {
    regions.near.update(scene, store, reach);
    if store.regional().is_empty() {
        return 0.0;
    }
    let (touching, geometry) = (store.touching(), store.geometry());
    let keys = store.keys();
    store
        .regional()
        .par_iter()
        .with_min_len(8)
        .map(|&first| {
            let first = first as usize;
            let previous: [Option<Geometry>; MAX_REGIONS] = std::array::from_fn(|k| {
                touching[first + k].then(|| geometry[first + k].with_volume(None))
            });
            SCRATCH.with_borrow_mut(|s| {
                let (found, reach) = several(scene, &keys[first], s);
                assign_regions(&previous, found, reach)
            })
        })
        .collect_into_vec(&mut regions.assigned);
    store.set_regions(&regions.assigned, scene.bodies)
}

/// The contacts of the spheres on mesh walls `spheres` (indices into the store's
/// `spheres_on_mesh`, whose first entries are `first_entries`) among the triangles `near`
/// lists for them, matched to last step's by the rule of `contact::assign_regions` on contact
/// points alone (a sphere's contacts have no volume) and set in their four slots, in `pass`: a
/// chunk of the contact loop, whose first entry is the store's `chunk_first`. Done there rather
/// than in a stage of its own, the most numerous regional pairs' slots are set while in the
/// cache, in parallel with the rest of the chunk's work. Returns the energy the histories that
/// ended or gave their slot to a new contact held (dissipated), added up in store order.
pub(crate) fn set_spheres_on_mesh(
    scene: Scene,
    near: &NearTriangles,
    (first_entries, spheres): (&[u32], Range<usize>),
    pass: &mut StorePass,
    chunk_first: usize,
) -> f64 {
    let mut lost = 0.0;
    if spheres.is_empty() {
        return lost;
    }
    // The chunk's entries are read here for the first time this step: ask for the slots of the
    // sphere some spheres ahead while this one's triangles are searched.
    let in_chunk = &first_entries[..spheres.end];
    let ask_for = |h: usize, pass: &StorePass| {
        if let Some(&first) = in_chunk.get(h) {
            let k = first as usize - chunk_first;
            prefetch(&pass.geometry[k]);
            prefetch(&pass.geometry[k + SPHERE_MESH_REGIONS - 1]);
            prefetch(&pass.touching[k]);
        }
    };
    for h in spheres.start..spheres.start + PREFETCH_AHEAD {
        ask_for(h, pass);
    }
    SCRATCH.with_borrow_mut(|s| {
        for h in spheres {
            ask_for(h + PREFETCH_AHEAD, pass);
            let k = first_entries[h] as usize - chunk_first;
            let previous: [Option<ContactPoint>; SPHERE_MESH_REGIONS] =
                std::array::from_fn(|i| pass.touching[k + i].then(|| pass.geometry[k + i]));
            let (found, reach) = sphere_on_mesh(scene, &pass.key[k], near.of(h), s);
            let assigned = assign_regions(&previous, found, reach);
            let slots = assigned.iter().map(|a| (a.geometry, None, a.fresh));
            pass.set_pair(k, slots, scene.bodies, &mut lost);
        }
    });
    lost
}

/// The narrow phase of entry `k`, a pair that touches in one place at most (regional entries are
/// set by [`detect_regions`]; sphere pairs find their contact with their law, see
/// `step::spheres`): whether it touches, and its geometry and volume where the store keeps them.
/// Returns the contact point found. Contacts that end are booked by the contact laws.
pub(crate) fn detect_single(
    scene: Scene,
    key: &ContactKey,
    k: usize,
    state: &mut EntryState,
) -> Option<ContactPoint> {
    let found = single(scene, key);
    state.touching[k] = found.is_some();
    let found = found?;
    if let Some(g) = state.geometry.get_mut(k) {
        *g = found.contact_point();
    }
    if let Some(v) = state.volume.get_mut(k) {
        *v = found.volume;
    }
    Some(found.contact_point())
}

/// The contact of a pair that touches in one place at most.
fn single(scene: Scene, key: &ContactKey) -> Option<Geometry> {
    let a = scene.posed(key.a);
    match key.partner {
        // Only two bodies may need the thread's clipping scratch: reaching it costs a
        // thread-local lookup and a borrow, which a sphere on a plane (the most common single
        // contact) spent more time on than on its contact.
        Partner::Body(j) => SCRATCH.with_borrow_mut(|s| {
            narrow_phase::body_body(a, scene.posed(j), scene.law, &mut s.clip)
        }),
        Partner::Plane(p) => {
            let plane = &scene.planes[p as usize];
            narrow_phase::body_plane(a, plane.point, plane.normal, scene.law)
        }
        Partner::Mesh(_) => unreachable!("mesh walls are regional"),
    }
}

/// The contact regions of a pair that may touch in several places, and how far a region may move
/// in a step and still be the same contact.
fn several<'s>(scene: Scene, key: &ContactKey, s: &'s mut Scratch) -> (&'s [Geometry], f64) {
    let a = scene.posed(key.a);
    let radius = |i: u32| scene.bodies.equivalent_radius[i as usize];
    let found = &mut s.found;
    found.clear();
    let reach = match key.partner {
        Partner::Body(j) => {
            narrow_phase::body_body_regions(a, scene.posed(j), scene.law, &mut s.regions, found);
            0.5 * radius(key.a).min(radius(j))
        }
        Partner::Plane(p) => {
            let plane = &scene.planes[p as usize];
            narrow_phase::body_plane_regions(
                a,
                plane.point,
                plane.normal,
                scene.law,
                &mut s.regions,
                found,
            );
            0.5 * radius(key.a)
        }
        Partner::Mesh(w) => {
            mesh_contacts(a, &scene.walls[w as usize], scene.law, s);
            0.5 * radius(key.a)
        }
    };
    (&s.found, reach)
}

/// The contacts of the sphere of `key.a` with mesh wall `key.partner`, as [`mesh_contacts`]
/// finds them, among the triangles `near` ([`NearTriangles`]), and how far one may move in a
/// step and still be the same contact (as [`several`]).
fn sphere_on_mesh<'s>(
    scene: Scene,
    key: &ContactKey,
    near: &[u32],
    s: &'s mut Scratch,
) -> (&'s [ContactPoint], f64) {
    let (x, r, wall) = sphere_and_wall(scene, key);
    s.points.clear();
    if wall.bounds().overlaps(&Aabb::around_sphere(x, r)) {
        let (scratch, contacts) = (&mut s.mesh, &mut s.mesh_contacts);
        narrow_phase::sphere_mesh_contacts_among(x, r, wall, near, scratch, contacts);
        let pose = wall.pose();
        let found = s.mesh_contacts.iter();
        s.points
            .extend(found.map(|c| c.geometry.contact_point().moved(&pose)));
    }
    (
        &s.points,
        0.5 * scene.bodies.equivalent_radius[key.a as usize],
    )
}

/// A body's contacts with a mesh wall, into `s.found`. A moving wall is searched in its reference
/// placement, with the body taken there; the contacts are brought back to the world.
fn mesh_contacts(body: Posed, wall: &MeshWall, law: PolyhedralLaw, s: &mut Scratch) {
    let pose = wall.pose();
    let x = pose.to_reference(body.position);
    let q = pose.rotation.inverse() * body.orientation;
    match body.shape {
        Shape::Sphere(sphere) => {
            if wall
                .bounds()
                .overlaps(&Aabb::around_sphere(x, sphere.radius))
            {
                narrow_phase::sphere_mesh_contacts(
                    x,
                    sphere.radius,
                    wall,
                    &mut s.mesh,
                    &mut s.mesh_contacts,
                );
                s.found.extend(s.mesh_contacts.iter().map(|c| c.geometry));
            }
        }
        Shape::Convex(p) => {
            narrow_phase::convex_mesh_contacts(p, x, q, wall, law, &mut s.convex_mesh, &mut s.found)
        }
        // The vertex law on its mesh, whether or not it has parts.
        Shape::NonConvex(p) => {
            narrow_phase::nonconvex_mesh_contacts(p, x, q, wall, &mut s.convex_mesh, &mut s.found)
        }
    }
    for g in &mut s.found {
        *g = g.moved(&pose);
    }
}
