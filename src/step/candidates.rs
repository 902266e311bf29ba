//! Stage 1 of the contact pipeline: the candidate contacts, i.e. the bodies and partners (other
//! bodies, planes, mesh walls) that are close enough to touch before the list is made again.
//!
//! The list is made with a skin: boxes enlarged by half the skin on each side. It stays valid until
//! some body has moved more than half the skin, or a moving mesh wall has (Verlet 1967's neighbour
//! list idea): until then no two bodies outside each other's enlarged boxes can touch, nor a body
//! and a wall more than a skin apart. Body pairs come from the broad phase (the Linked Linear List
//! by default).

use crate::body::Bodies;
use crate::broad_phase::{self, BroadPhase, Pair};
use crate::contact::{Candidate, PairKind, Partner, ShapeTraits};
use crate::math::{Aabb, DVec3};
use crate::shape::Shape;
use crate::wall::{MeshWall, Plane, WallPose};
use rayon::prelude::*;

/// The neighbour search's state between steps.
pub struct NeighbourSearch {
    method: broad_phase::Method,
    broad_phase: Box<dyn BroadPhase>,
    /// The skin [m]: see [`crate::WorldConfig::skin`].
    skin: f64,
    /// Where the bodies were when the list was made.
    reference_position: Vec<DVec3>,
    /// Where the mesh walls were when the list was made.
    reference_pose: Vec<WallPose>,
    valid: bool,
    boxes: Vec<Aabb>,
    pairs: Vec<Pair>,
    /// Which of `pairs` come within a skin (working memory of the search).
    keep: Vec<bool>,
    wall_candidates: Vec<(u32, Partner)>,
    /// The candidates, in the store's order ([`Candidate::order`]).
    list: Vec<Candidate>,
    /// Working memory of the list's counting sort: each body's first candidate, and the next
    /// free place of each body's run.
    first: Vec<u32>,
    next: Vec<u32>,
    /// Times the list was made (for diagnostics and tests).
    pub rebuilds: u64,
}

/// The part of [`NeighbourSearch`] that decides when the list is made again.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SearchState {
    skin: f64,
    reference_position: Vec<DVec3>,
    reference_pose: Vec<WallPose>,
    valid: bool,
    rebuilds: u64,
}

impl NeighbourSearch {
    pub fn new(method: broad_phase::Method, skin: f64) -> Self {
        Self {
            method,
            broad_phase: method.build(),
            skin,
            reference_position: Vec::new(),
            reference_pose: Vec::new(),
            valid: false,
            boxes: Vec::new(),
            pairs: Vec::new(),
            keep: Vec::new(),
            wall_candidates: Vec::new(),
            list: Vec::new(),
            first: Vec::new(),
            next: Vec::new(),
            rebuilds: 0,
        }
    }

    pub fn skin(&self) -> f64 {
        self.skin
    }

    /// What decides when the list is made again, for a checkpoint.
    pub fn state(&self) -> SearchState {
        SearchState {
            skin: self.skin,
            reference_position: self.reference_position.clone(),
            reference_pose: self.reference_pose.clone(),
            valid: self.valid,
            rebuilds: self.rebuilds,
        }
    }

    /// Continues from `state` with a fresh broad phase: it finds the same candidates when the
    /// list is next made (only its cost differs), and the list itself lives on in the contact
    /// store's entries.
    pub fn restore(&mut self, state: SearchState) {
        self.broad_phase = self.method.build();
        self.skin = state.skin;
        self.reference_position = state.reference_position;
        self.reference_pose = state.reference_pose;
        self.valid = state.valid;
        self.rebuilds = state.rebuilds;
    }

    pub fn set_skin(&mut self, skin: f64) {
        self.skin = skin;
        self.valid = false;
    }

    /// Where the bodies were when the list was made (`None` when it must be made anew anyway).
    pub fn reference_positions(&self) -> Option<&[DVec3]> {
        self.valid.then_some(&self.reference_position[..])
    }

    /// Makes the list again at the next update, as if a body had moved half a skin (the broad
    /// phase goes on from its state).
    pub fn expire(&mut self) {
        self.valid = false;
    }

    /// Bodies were added or removed: indices changed, so the search starts afresh.
    pub fn invalidate(&mut self) {
        self.valid = false;
        self.broad_phase = self.method.build();
    }

    /// Makes the list again if it may have gone stale; returns the new list, or `None` when the
    /// old one still holds.
    pub fn update(
        &mut self,
        bodies: &Bodies,
        shapes: &[Shape],
        planes: &[Plane],
        walls: &[MeshWall],
    ) -> Option<&[Candidate]> {
        let half_skin = 0.5 * self.skin;
        if self.valid && !self.moved_too_far(bodies, walls, half_skin) {
            return None;
        }
        self.boxes.clear();
        self.boxes.par_extend(
            bodies
                .position
                .par_iter()
                .zip(&bodies.bounding_radius)
                .map(|(&x, &r)| Aabb::around_sphere(x, r + half_skin)),
        );
        self.broad_phase.find_pairs(&self.boxes, &mut self.pairs);
        // Boxes overlap more often than the bounding spheres come within a skin of each other
        // (by about 6/π): keep only the pairs that can touch before the next search. Which ones is
        // found in parallel (a distance each, the bodies read at random), the list then closed up
        // in order.
        let (x, r) = (&bodies.position, &bodies.bounding_radius);
        let skin = self.skin;
        self.keep.clear();
        self.keep.par_extend(self.pairs.par_iter().map(|&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            let reach = r[i] + r[j] + skin;
            (x[i] - x[j]).length_squared() <= reach * reach
        }));
        let mut keep = self.keep.iter();
        self.pairs.retain(|_| keep.next() == Some(&true));
        self.find_wall_candidates(bodies, planes, walls);
        self.merge(bodies, shapes);
        self.reference_position.clone_from(&bodies.position);
        self.reference_pose.clear();
        self.reference_pose.extend(walls.iter().map(MeshWall::pose));
        self.valid = true;
        self.rebuilds += 1;
        Some(&self.list)
    }

    fn moved_too_far(&self, bodies: &Bodies, walls: &[MeshWall], half_skin: f64) -> bool {
        let limit = half_skin * half_skin;
        let wall_moved = walls.iter().zip(&self.reference_pose).any(|(w, then)| {
            !w.motion.keeps_place() && wall_displacement(w, then, &w.pose()) > half_skin
        });
        wall_moved
            || bodies
                .position
                .par_iter()
                .zip(self.reference_position.par_iter())
                .any(|(x, x0)| (*x - *x0).length_squared() > limit)
    }

    /// Planes within half a skin of a body's bounding sphere (planes do not move), and mesh walls
    /// with a triangle whose box comes within a skin of it (body and wall may each move half a
    /// skin before the list is made again).
    fn find_wall_candidates(&mut self, bodies: &Bodies, planes: &[Plane], walls: &[MeshWall]) {
        let half_skin = 0.5 * self.skin;
        let skin = self.skin;
        self.wall_candidates.clear();
        if planes.is_empty() && walls.is_empty() {
            return;
        }
        self.wall_candidates.par_extend(
            (0..bodies.len() as u32)
                .into_par_iter()
                .with_min_len(256)
                .flat_map_iter(|i| {
                    let x = bodies.position[i as usize];
                    let r = bodies.bounding_radius[i as usize];
                    let near_planes = planes
                        .iter()
                        .enumerate()
                        .filter(move |(_, p)| (x - p.point).dot(p.normal) < r + half_skin)
                        .map(move |(p, _)| (i, Partner::Plane(p as u32)));
                    let near_walls = walls
                        .iter()
                        .enumerate()
                        .filter(move |(_, w)| {
                            let reach = Aabb::around_sphere(w.pose().to_reference(x), r + skin);
                            w.bounds().overlaps(&reach) && w.has_triangles_near(&reach)
                        })
                        .map(move |(w, _)| (i, Partner::Mesh(w as u32)));
                    near_planes.chain(near_walls)
                }),
        );
    }

    /// One list in the store's order ([`Candidate::order`]) from the body pairs and the wall
    /// candidates: each body pair oriented by global id (body `a` the one with the smaller id, so
    /// that the pair is seen from the same side however the bodies are numbered), placed by `a`
    /// (a counting sort), then each body's short run sorted by its partners' rank.
    fn merge(&mut self, bodies: &Bodies, shapes: &[Shape]) {
        let ids = &bodies.id;
        let traits = |i: u32| {
            let shape = &shapes[bodies.shape[i as usize] as usize];
            ShapeTraits {
                sphere: matches!(shape, Shape::Sphere(_)),
                regional: shape.has_regions(),
            }
        };
        let oriented = |&(i, j): &Pair| {
            if ids[i as usize] < ids[j as usize] {
                (i, j)
            } else {
                (j, i)
            }
        };
        let first = &mut self.first;
        first.clear();
        first.resize(bodies.len() + 1, 0);
        for pair in &self.pairs {
            first[oriented(pair).0 as usize + 1] += 1;
        }
        for &(a, _) in &self.wall_candidates {
            first[a as usize + 1] += 1;
        }
        for i in 0..bodies.len() {
            first[i + 1] += first[i];
        }
        let unset = Candidate {
            a: 0,
            partner: Partner::Body(0),
            kind: PairKind::Single,
        };
        self.list.clear();
        self.list.resize(first[bodies.len()] as usize, unset);
        let next = &mut self.next;
        next.clear();
        next.extend_from_slice(&first[..bodies.len()]);
        let mut place = |c: Candidate| {
            let slot = &mut next[c.a as usize];
            self.list[*slot as usize] = c;
            *slot += 1;
        };
        for pair in &self.pairs {
            let (a, b) = oriented(pair);
            let partner = Partner::Body(b);
            place(Candidate {
                a,
                partner,
                kind: PairKind::of(traits(a), partner, Some(traits(b))),
            });
        }
        for &(a, partner) in &self.wall_candidates {
            place(Candidate {
                a,
                partner,
                kind: PairKind::of(traits(a), partner, None),
            });
        }
        // Each body's run (the bodies' runs in parallel: the list is grouped by body `a`).
        self.list
            .par_chunk_by_mut(|x, y| x.a == y.a)
            .for_each(|run| run.sort_unstable_by_key(|c| c.partner.rank(ids)));
    }
}

/// The farthest any point of the wall's bounding box has moved between two poses: |(R₁ − R₀)p +
/// t₁ − t₀| is convex in p, so its maximum over the box is at a corner.
fn wall_displacement(wall: &MeshWall, then: &WallPose, now: &WallPose) -> f64 {
    let b = wall.bounds();
    (0..8)
        .map(|k| {
            let corner = DVec3::new(
                if k & 1 == 0 { b.min.x } else { b.max.x },
                if k & 2 == 0 { b.min.y } else { b.max.y },
                if k & 4 == 0 { b.min.z } else { b.max.z },
            );
            (now.to_world(corner) - then.to_world(corner)).length()
        })
        .fold(0.0, f64::max)
}
