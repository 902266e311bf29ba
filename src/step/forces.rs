//! Stages 3 and 4 of the contact pipeline: the contact laws give every touching contact its force,
//! moment and energy figures (one loop over the store, in parallel chunks of whole bodies, each
//! contact writing only its own response, each chunk adding up its bodies' own contacts), and the
//! sums are completed with the contacts whose partner each body is (in parallel over bodies, in
//! store order, so the sums are bit-identical for any thread count).

use crate::body::Bodies;
use crate::contact::{
    Chunks, ContactKey, ContactStore, EntryIds, EntryState, LawReport, Load, OwnLoad, PairKind,
    Partner, PartnerLoad, StorePass,
};
use crate::contact_law::{
    self, DashpotLimit, History, Kinematics, OverlapVolume, Response, SpinHistory,
};
use crate::integrate::{BodyMotion, ForceSums, Kick, KickedBody};
use crate::material::PairTable;
use crate::math::DVec3;
use crate::narrow_phase::{self, ContactPoint};
use crate::step::detect;
use crate::step::lookahead::{Lookahead, Moves};
use crate::step::mesh_lanes;
use crate::step::plane_lanes;
use crate::step::prefetch::prefetch;
use crate::step::sphere_lanes;
use crate::step::spheres::{self, EntryOut};
use crate::step::Scene;
use crate::wall::WallState;
use rayon::prelude::*;

/// What the contact laws read besides the contacts.
#[derive(Clone, Copy)]
pub struct LawInputs<'a> {
    /// The bodies, their shapes and the walls.
    pub scene: Scene<'a>,
    /// Each mesh wall's motion over the step and at its end; `None` for a fixed wall.
    pub wall_states: &'a [Option<[WallState; 2]>],
    pub laws: &'a PairTable,
    /// Each body's motion packed for the contact loops ([`pack_motion`]).
    pub motion: &'a [BodyMotion],
    /// The triangles near each sphere on a mesh wall, among which the contact loop finds its
    /// contacts ([`detect::set_spheres_on_mesh`]).
    pub near_triangles: &'a detect::NearTriangles,
    /// 1/Δt, Δt the world's time step: the interval the forces found will act over, on which
    /// the dashpots are bounded (`contact_law::DashpotLimit`), whatever interval the histories
    /// advance by (none when the forces are found again between steps). Computed once per step,
    /// it leaves a product per contact instead of a division (a tenth of a sphere contact's
    /// time, measured).
    pub inverse_step: f64,
}

impl EntryState<'_> {
    /// What the step writes of entry `k`.
    #[inline(always)]
    pub(crate) fn entry(&mut self, k: usize) -> EntryOut<'_> {
        EntryOut {
            touching: &mut self.touching[k],
            history: &mut self.history[k],
            spin: self.spin.get_mut(k),
            load: &mut self.load[k],
            own: &mut self.own[k],
            report: self.report.get_mut(k),
            dissipated: &mut self.dissipated[k],
        }
    }
}

#[cfg(test)]
impl<'a> LawInputs<'a> {
    /// The inputs of a world of bodies with no walls (the sphere paths' tests).
    pub(crate) fn of_bodies(
        bodies: &'a crate::body::Bodies,
        shapes: &'a [crate::shape::Shape],
        laws: &'a PairTable,
        motion: &'a [BodyMotion],
        inverse_step: f64,
    ) -> Self {
        LawInputs {
            scene: Scene {
                bodies,
                shapes,
                planes: &[],
                walls: &[],
                law: Default::default(),
            },
            wall_states: &[],
            laws,
            motion,
            near_triangles: detect::NearTriangles::none(),
            inverse_step,
        }
    }
}

impl LawInputs<'_> {
    /// Velocity of the body point at `point` over the step just taken (the half-step velocity),
    /// and predicted at the end of the step.
    #[inline]
    fn point_velocity(&self, body: usize, point: DVec3) -> (DVec3, DVec3) {
        let m = &self.motion[body];
        let arm = point - m.position;
        let now = m.velocity + m.angular_velocity.cross(arm);
        let end = m.velocity_end + m.angular_velocity_end.cross(arm);
        (now, end)
    }

    /// The law's response for the touching contact of body `a` and `partner`.
    pub(crate) fn respond(
        &self,
        key: ContactKey,
        kind: PairKind,
        g: &ContactPoint,
        volume: Option<OverlapVolume>,
        (history, spin): (&mut History, &mut SpinHistory),
        dt: f64,
    ) -> Response {
        let (b, shapes) = (self.scene.bodies, self.scene.shapes);
        let a = key.a as usize;
        let (va, va_end) = self.point_velocity(a, g.point);
        // The partner's velocity at the contact point over the step and at its end, its angular
        // velocity, its material; R* and m* of the pair.
        let (vb, vb_end, wb, material, effective_radius, effective_mass) = match key.partner {
            Partner::Body(j) => {
                let j = j as usize;
                let (vb, vb_end) = self.point_velocity(j, g.point);
                // R* from the volume-equivalent radii (the sphere's radius on a polyhedron), as
                // the laws and the time-step estimate define it; the bounding radius of a
                // polyhedron would soften every contact (by 1.4 for a cube).
                let (radius, mass) = if kind == PairKind::Spheres {
                    let (ra, rb) = (self.motion[a].radius, self.motion[j].radius);
                    contact_law::effective_radius_and_mass((ra, rb), (b.mass[a], b.mass[j]))
                } else {
                    let radius = narrow_phase::effective_radius(
                        &shapes[b.shape[a] as usize],
                        &shapes[b.shape[j] as usize],
                    );
                    (radius, b.mass[a] * b.mass[j] / (b.mass[a] + b.mass[j]))
                };
                let w = self.motion[j].angular_velocity;
                (vb, vb_end, w, b.material[j], radius, mass)
            }
            Partner::Plane(p) => {
                let material = self.scene.planes[p as usize].material;
                let zero = DVec3::ZERO;
                (
                    zero,
                    zero,
                    zero,
                    material,
                    b.equivalent_radius[a],
                    b.mass[a],
                )
            }
            Partner::Mesh(w) => {
                let w = w as usize;
                let (v, v_end, omega) = match &self.wall_states[w] {
                    None => (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO),
                    Some([over_step, at_end]) => (
                        over_step.surface_velocity(g.point, g.normal),
                        at_end.surface_velocity(g.point, g.normal),
                        at_end.angular_velocity,
                    ),
                };
                let material = self.scene.walls[w].material;
                (v, v_end, omega, material, b.equivalent_radius[a], b.mass[a])
            }
        };
        let mut k = kinematics(
            g,
            volume,
            va - vb,
            va_end - vb_end,
            self.motion[a].angular_velocity - wb,
            effective_radius,
            effective_mass,
            self.inverse_step,
        );
        // Two spheres keep m* and 2/7 m*, as on the fast path (`step::spheres`), to the bit.
        if kind != PairKind::Spheres {
            let partner = key.partner.body().map(|j| j as usize);
            let (normal, tangential) = dashpot_mass(b, a, partner, g.point, g.normal);
            k.dashpot_limit = DashpotLimit::of_masses(normal, tangential, self.inverse_step);
        }
        let law = self.laws.get(b.material[a], material);
        // A point contact without rolling friction (a sphere on a wall, say) needs only the
        // normal and tangential laws: the same bits without the terms that are zero there.
        if volume.is_none() && law.rolling_friction <= 0.0 {
            contact_law::evaluate_point(law, &k, history, dt)
        } else {
            contact_law::evaluate(law, &k, history, spin, dt)
        }
    }
}

/// Evaluates the contact law of every touching contact of chunk `c` of `chunks` (`pass`, the
/// entries of whole bodies) over the step `dt` (sphere pairs find their contact here too, see
/// [`spheres`](super::spheres), and spheres on mesh walls theirs first, see
/// [`detect::set_spheres_on_mesh`]). A contact that ended forgets its history; the energy its
/// springs held is booked as dissipated. Returns the energy the chunk's contacts dissipated over
/// the step: the spheres on mesh walls' ended regions first, then each run's entries', summed in
/// eight stripes ([`striped_sum`]; those of a ghost's contacts left to its owner).
///
/// The laws write each load's partner side into the store, for [`accumulate`], and body `a`'s
/// side into the thread's scratch, which is added into `own` (the chunk's bodies' sums) after
/// each run, in store order, while still in the cache (the order `accumulate` once added them
/// in, so the same bits). The energy each entry dissipated goes to the scratch too, and is added
/// up after each run in a fixed order of the run's entries ([`striped_sum`]).
///
/// Relies on what the store keeps true between steps: an entry that does not touch holds no
/// history, a zero load and a zero report. A sphere pair that was apart and stays apart is then
/// left as it is, with nothing read of it but its flag and nothing written.
pub(crate) fn evaluate(
    inputs: LawInputs,
    mut pass: StorePass,
    mut own: OwnSums,
    (chunks, c): (Chunks, usize),
    dt: f64,
) -> f64 {
    own.force.fill(DVec3::ZERO);
    own.torque.fill(DVec3::ZERO);
    let first_body = chunks.bodies[c] as usize;
    let mut evaluate_runs = |scratch: &mut Scratch| {
        let Scratch {
            sorted,
            own_loads,
            dissipated: lost,
        } = scratch;
        let mut dissipated = detect::set_spheres_on_mesh(
            inputs.scene,
            inputs.near_triangles,
            (chunks.spheres_on_mesh, chunks.spheres_on_mesh(c)),
            &mut pass,
            chunks.first_entry(c),
        );
        let (keys, count) = (pass.key, pass.len());
        for start in (0..count).step_by(RUN) {
            let run = start..(start + RUN).min(count);
            let lost = &mut lost[..run.len()];
            lost.fill(0.0);
            let (ids, mut state) = pass.run(run.clone(), &mut own_loads[..run.len()], lost);
            sorted.sort(&inputs, &ids, &state, &keys[start..]);
            evaluate_sorted(&inputs, &ids, &mut state, sorted, dt);
            dissipated += booked(&inputs, &ids, &state);
            add_own_loads(&ids, &state, &mut own, first_body);
        }
        dissipated
    };
    SCRATCH.with(|scratch| match scratch.try_borrow_mut() {
        Ok(mut scratch) => evaluate_runs(&mut scratch),
        // A pass nested in another on this thread (none is today): scratch of its own.
        Err(_) => evaluate_runs(&mut Scratch::new()),
    })
}

/// Body `a`'s side of a run's loads added to the sums `own` (of the bodies from `first_body`
/// on), in store order. An entry that does not touch has a zero load, which would leave the sum
/// as it is (a sum that starts at +0 stays bit for bit the same when ±0 is added): it is masked
/// out rather than branched on (whether a candidate touches is a coin toss), and its scratch
/// need not be cleared.
#[inline(always)]
fn add_own_loads(ids: &EntryIds, state: &EntryState, own: &mut OwnSums, first_body: usize) {
    let masked = |v: DVec3, mask: u64| {
        DVec3::new(
            f64::from_bits(v.x.to_bits() & mask),
            f64::from_bits(v.y.to_bits() & mask),
            f64::from_bits(v.z.to_bits() & mask),
        )
    };
    for ((key, load), &touching) in ids.key.iter().zip(state.own.iter()).zip(&*state.touching) {
        let mask = (touching as u64).wrapping_neg();
        let i = key.a as usize - first_body;
        own.force[i] += masked(load.force, mask);
        own.torque[i] += masked(load.torque_a, mask);
    }
}

/// The contact loop's working memory, one per thread, kept from step to step: the sorted lists
/// of a run, body `a`'s side of its loads, and the energy its entries dissipated.
struct Scratch {
    sorted: Sorted,
    own_loads: [OwnLoad; RUN],
    dissipated: [f64; RUN],
}

impl Scratch {
    fn new() -> Box<Self> {
        Box::new(Scratch {
            sorted: Sorted::default(),
            own_loads: [OwnLoad::default(); RUN],
            dissipated: [0.0; RUN],
        })
    }
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Box<Scratch>> = std::cell::RefCell::new(Scratch::new());
}

/// The sums of a run of bodies' own contacts (those where the body is `a`): the bodies' force and
/// torque arrays, which [`accumulate`] completes with the contacts whose partner they are.
pub struct OwnSums<'a> {
    pub force: &'a mut [DVec3],
    pub torque: &'a mut [DVec3],
}

impl OwnSums<'_> {
    /// The same sums, borrowed for a shorter while.
    pub(crate) fn reborrow(&mut self) -> OwnSums<'_> {
        OwnSums {
            force: self.force,
            torque: self.torque,
        }
    }

    /// The bodies before `mid` and from `mid` on.
    pub(crate) fn split_at(self, mid: usize) -> (Self, Self) {
        let (force, force_rest) = self.force.split_at_mut(mid);
        let (torque, torque_rest) = self.torque.split_at_mut(mid);
        (
            OwnSums { force, torque },
            OwnSums {
                force: force_rest,
                torque: torque_rest,
            },
        )
    }
}

/// Entries the contact loop sorts at a time (the length of a parallel work item).
const RUN: usize = crate::contact::CHUNK_ENTRIES;

/// A run's entries sorted by what they need: sphere pairs that touch, spheres that touch a plane
/// (in worlds where they take the four-wide path, see [`plane_lanes`]), spheres that touch a mesh
/// wall ([`mesh_lanes`]), sphere pairs and spheres on planes that touched and no longer do, and
/// the others (those that stay apart need nothing, nor do the regions that do not touch, see
/// `StorePass::set_region`). Whether a candidate touches is a coin toss, so the sort is done
/// without a branch on it: every entry is written at the end of each list, and the list's
/// length grows by one where it belongs there.
struct Sorted {
    touching: [u32; RUN],
    planes: [u32; RUN],
    meshes: [u32; RUN],
    ended: [u32; RUN],
    other: [u32; RUN],
    lengths: [usize; 5],
}

impl Default for Sorted {
    fn default() -> Self {
        Sorted {
            touching: [0; RUN],
            planes: [0; RUN],
            meshes: [0; RUN],
            ended: [0; RUN],
            other: [0; RUN],
            lengths: [0; 5],
        }
    }
}

impl Sorted {
    /// Sorts the entries of a run (at most [`RUN`]); `ahead`, the keys from the run's first on
    /// to the chunk's end, tells what to ask for in advance. A function of its own: inlined into
    /// the contact loop, its counters had to share the registers of the loop's other paths, and
    /// one went to the stack and back at every entry.
    #[inline(never)]
    fn sort(
        &mut self,
        inputs: &LawInputs,
        ids: &EntryIds,
        state: &EntryState,
        ahead: &[ContactKey],
    ) {
        let [mut touching, mut planes, mut meshes, mut ended, mut other] = [0; 5];
        // In a world of spheres and planes (no geometry kept), every single-contact entry is a
        // sphere on a plane under the point law (with rolling resistance if it keeps spins).
        let planes_in_lanes = state.geometry.is_empty();
        for k in 0..ids.key.len() {
            let key = ids.key[k];
            if let Some(ahead) = ahead.get(k + SORT_PREFETCH_AHEAD) {
                prefetch_partner(inputs, ahead.partner);
            }
            if let Some(h) = state.history.get(k + SORT_PREFETCH_AHEAD) {
                prefetch(&h.tangential_spring.x);
            }
            let kind = ids.kind[k];
            if kind == PairKind::Spheres {
                let touches = spheres::overlaps(inputs, key);
                self.touching[touching] = k as u32;
                touching += touches as usize;
                self.ended[ended] = k as u32;
                ended += (!touches & state.touching[k]) as usize;
            } else if planes_in_lanes && kind == PairKind::Single {
                let touches = plane_lanes::touches(inputs, key.a, key.partner);
                self.planes[planes] = k as u32;
                planes += touches as usize;
                self.ended[ended] = k as u32;
                ended += (!touches & state.touching[k]) as usize;
            } else {
                // A regional entry that does not touch was left as an entry apart is left (see
                // `StorePass::set_region`): nothing to do.
                let on_mesh = kind == PairKind::SphereOnMesh;
                self.meshes[meshes] = k as u32;
                meshes += (on_mesh & state.touching[k]) as usize;
                self.other[other] = k as u32;
                other += (!on_mesh & (!kind.is_regional() | state.touching[k])) as usize;
            }
        }
        self.lengths = [touching, planes, meshes, ended, other];
    }

    fn touching(&self) -> &[u32] {
        &self.touching[..self.lengths[0]]
    }

    fn planes(&self) -> &[u32] {
        &self.planes[..self.lengths[1]]
    }

    fn meshes(&self) -> &[u32] {
        &self.meshes[..self.lengths[2]]
    }

    fn ended(&self) -> &[u32] {
        &self.ended[..self.lengths[3]]
    }

    fn other(&self) -> &[u32] {
        &self.other[..self.lengths[4]]
    }
}

/// The contact laws of the sorted entries (each entry's result is its own, whatever the order).
#[inline(always)]
fn evaluate_sorted(
    inputs: &LawInputs,
    ids: &EntryIds,
    state: &mut EntryState,
    sorted: &Sorted,
    dt: f64,
) {
    // Touching sphere pairs, and spheres on planes, go through the four-wide kernels in groups
    // of four (with rolling resistance in a world that keeps spin histories).
    let mut fours = sorted.touching().chunks_exact(4);
    for four in &mut fours {
        let four = std::array::from_fn(|i| four[i] as usize);
        sphere_lanes::touching_pairs(inputs, ids, state, four, dt);
    }
    for &k in fours.remainder() {
        let k = k as usize;
        spheres::touching_pair(inputs, ids.key[k], state.entry(k), dt);
    }
    let mut fours = sorted.planes().chunks_exact(4);
    for four in &mut fours {
        let four = std::array::from_fn(|i| four[i] as usize);
        plane_lanes::touching_planes(inputs, ids, state, four, dt);
    }
    plane_lanes::touching_planes_rest(inputs, ids, state, fours.remainder(), dt);
    let mut fours = sorted.meshes().chunks_exact(4);
    for four in &mut fours {
        let four = std::array::from_fn(|i| four[i] as usize);
        mesh_lanes::touching_meshes(inputs, ids, state, four, dt);
    }
    mesh_lanes::touching_meshes_rest(inputs, ids, state, fours.remainder(), dt);
    for &k in sorted.ended() {
        spheres::apart(state.entry(k as usize));
    }
    for &k in sorted.other() {
        let (k, key) = (k as usize, ids.key[k as usize]);
        // The narrow phase of a pair that touches in one place; a regional pair's regions were
        // found before the loop (a world with regional pairs keeps their geometry).
        let g = match ids.kind[k] {
            PairKind::Single => detect::detect_single(inputs.scene, &key, k, state),
            _ => state.touching[k].then(|| state.geometry[k]),
        };
        let history = &mut state.history[k];
        let spin = state.spin.get_mut(k);
        let r = match &g {
            Some(g) => {
                let volume = state.volume.get(k).copied().flatten();
                let mut none = SpinHistory::default();
                let spin = spin.unwrap_or(&mut none);
                inputs.respond(key, ids.kind[k], g, volume, (history, spin), dt)
            }
            None => ended(history, spin),
        };
        // Apart, the load is zero whatever the point (the last one kept, if any).
        let point = g
            .or_else(|| state.geometry.get(k).copied())
            .unwrap_or_default()
            .point;
        let centre_b = key
            .partner
            .body()
            .map(|j| inputs.motion[j as usize].position);
        let centre_a = inputs.motion[key.a as usize].position;
        state.set_load(k, Load::new(&r, point, centre_a, centre_b));
        if let Some(report) = state.report.get_mut(k) {
            *report = LawReport::of(&r);
        }
        state.dissipated[k] = r.dissipated;
    }
}

/// The energy a run's entries dissipated this step, from the loop's scratch (a ghost's contacts
/// are left to its owner: they add a zero). An entry the laws left as it is (apart, and apart
/// before) adds a zero.
#[inline(always)]
fn booked(inputs: &LawInputs, ids: &EntryIds, state: &EntryState) -> f64 {
    let ghost = &inputs.scene.bodies.ghost;
    let lost = &*state.dissipated;
    if ghost.is_empty() {
        striped_sum(lost, |_| true)
    } else {
        striped_sum(lost, |k| !ghost[ids.key[k].a as usize])
    }
}

/// Accumulators of [`striped_sum`].
const STRIPES: usize = 8;

/// The sum of the `values` whose index is `counted`, in a fixed order that does not wait on
/// each addition: value `k` goes to accumulator `k % 8`, and the eight are added pairwise. One
/// running sum was a chain of dependent additions as long as the run (256 entries: a 1.5 %
/// share of the settled 10,000-sphere step, all waiting on the adder); eight chains fill the
/// adders. The order depends on the values' count alone, so the sum is the same for any thread
/// count. A value not counted adds a zero, which leaves an accumulator as it is.
#[inline(always)]
fn striped_sum(values: &[f64], counted: impl Fn(usize) -> bool) -> f64 {
    let mut stripes = [0.0f64; STRIPES];
    let mut eights = values.chunks_exact(STRIPES);
    for (c, eight) in (&mut eights).enumerate() {
        for (j, (stripe, &v)) in stripes.iter_mut().zip(eight).enumerate() {
            *stripe += if counted(c * STRIPES + j) { v } else { 0.0 };
        }
    }
    let start = values.len() - eights.remainder().len();
    for (j, (stripe, &v)) in stripes.iter_mut().zip(eights.remainder()).enumerate() {
        *stripe += if counted(start + j) { v } else { 0.0 };
    }
    let [a, b, c, d, e, f, g, h] = stripes;
    ((a + b) + (c + d)) + ((e + f) + (g + h))
}

/// How many entries ahead the contact loop asks for the partner's motion, and the force sums for
/// the loads of a body's incoming entries: enough to cover a miss to memory with the work between.
const PREFETCH_AHEAD: usize = 8;

/// How many entries ahead the sort of a chunk asks for the partner's motion: its work per entry
/// is a few nanoseconds, so it must ask further ahead than the force sums.
const SORT_PREFETCH_AHEAD: usize = 24;

/// Asks for what the contact loop reads of body partner `partner` ([`prefetch`]): its motion,
/// and its mass and material, which the laws of a touching pair read.
#[inline(always)]
fn prefetch_partner(inputs: &LawInputs, partner: Partner) {
    let Some(j) = partner.body().map(|j| j as usize) else {
        return;
    };
    let bodies = inputs.scene.bodies;
    if let (Some(m), Some(mass), Some(material)) = (
        inputs.motion.get(j),
        bodies.mass.get(j),
        bodies.material.get(j),
    ) {
        prefetch(m);
        prefetch(mass);
        prefetch(material);
    }
}

/// The response of a contact that does not touch: none, and if it touched before, its history is
/// dropped and the energy its springs held is booked as dissipated.
#[inline(always)]
pub(crate) fn ended(history: &mut History, spin: Option<&mut SpinHistory>) -> Response {
    let mut lost = 0.0;
    if *history != History::default() {
        // The springs' energy, and the last step's dashpot work, which no next step will book.
        lost = history.stored_energy() + history.damper_work_estimate as f64;
        *history = History::default();
    }
    if let Some(spin) = spin.filter(|s| **s != SpinHistory::default()) {
        lost += spin.stored_energy();
        *spin = SpinHistory::default();
    }
    Response {
        dissipated: lost,
        ..Response::default()
    }
}

/// Completes the bodies' force and moment sums, which hold their own contacts' (as `a`, added by
/// [`evaluate`]), with those of the contacts whose partner they are, in store order, unless the
/// contact loop did (see `ContactStore::completes_sums`); then gives
/// each body the step's closing half `kick`, if any, while its sums are at hand, and, given
/// `ahead` (a share of a decomposed world), returns what it finds of the owned bodies' next move
/// ([`Moves`]; [`Moves::NONE`] without it or without a kick).
pub fn accumulate(
    bodies: &mut Bodies,
    store: &ContactStore,
    kick: Option<Kick>,
    ahead: Option<Lookahead>,
) -> Moves {
    let sums = IncomingSums(store);
    let needed = sums.needed();
    let Bodies {
        position,
        orientation,
        velocity,
        angular_momentum,
        angular_velocity,
        inv_mass,
        inv_inertia,
        force,
        torque,
        ghost,
        ..
    } = bodies;
    let (position, orientation, ghost) = (&*position, &*orientation, &*ghost);
    let (inv_mass, inv_inertia) = (&*inv_mass, &*inv_inertia);
    let count = force.len();
    force
        .par_iter_mut()
        .zip(torque.par_iter_mut())
        .zip(velocity.par_iter_mut())
        .zip(angular_momentum.par_iter_mut())
        .zip(angular_velocity.par_iter_mut())
        .enumerate()
        .with_min_len(256)
        .fold(
            || Moves::NONE,
            |moves, (i, ((((force, torque), v), l), w))| {
                if needed {
                    if i + PREFETCH_AHEAD < count {
                        sums.prefetch(i + PREFETCH_AHEAD);
                    }
                    (*force, *torque) = sums.complete(i, *force, *torque);
                }
                let (f, t) = (*force, *torque);
                let Some(kick) = kick else {
                    return moves;
                };
                let body = KickedBody {
                    velocity: v,
                    angular_momentum: l,
                    angular_velocity: w,
                    orientation: &orientation[i],
                    inv_mass: inv_mass[i],
                    inv_inertia: &inv_inertia[i],
                };
                kick.apply(body, f, t);
                match &ahead {
                    Some(ahead) if !ghost.get(i).copied().unwrap_or(false) => {
                        moves.with_body(ahead, &kick, i, (position[i], *v, f, inv_mass[i]))
                    }
                    _ => moves,
                }
            },
        )
        .reduce(|| Moves::NONE, Moves::merge)
}

/// The loads of the contacts whose partner a body is, from the store: what completes the sums
/// of its own contacts that [`evaluate`] left, in the order of the body's incoming index list
/// (its partners' ids), so the same bits for any thread count and numbering.
pub struct IncomingSums<'a>(pub &'a ContactStore);

impl ForceSums for IncomingSums<'_> {
    #[inline(always)]
    fn complete(&self, body: usize, force: DVec3, torque: DVec3) -> (DVec3, DVec3) {
        // Entries that do not touch hold a zero load, so every entry is added without a test
        // (whether a candidate touches is a coin toss, and a mispredicted branch per entry cost
        // more than the addition): a sum that starts at +0 stays bit for bit the same when ±0
        // is added.
        let load = self.0.loads();
        let incoming = self.0.incoming(body).iter().map(|&e| &load[e as usize]);
        add_incoming((force, torque), incoming)
    }

    #[inline(always)]
    fn prefetch(&self, body: usize) {
        let load = self.0.loads();
        for &e in self.0.incoming(body) {
            prefetch(&load[e as usize]);
        }
    }

    fn needed(&self) -> bool {
        !self.0.completes_sums()
    }
}

/// A body's force and moment `sums` of its own contacts completed with the `loads` of the
/// entries whose partner it is, in the order given: one rule, so that the pass over the bodies
/// ([`IncomingSums`]) and the contact loop (`step::complete_sums`) give the same bits.
#[inline(always)]
pub(crate) fn add_incoming<'a>(
    sums: (DVec3, DVec3),
    loads: impl Iterator<Item = &'a PartnerLoad>,
) -> (DVec3, DVec3) {
    let (mut f, mut t) = sums;
    for load in loads {
        f -= load.force;
        t += load.torque_b;
    }
    (f, t)
}

/// Relative motion at a contact, from the relative velocities of the contact points; the dashpots'
/// limits those of two spheres under a step of 1/`inverse_step`.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn kinematics(
    g: &ContactPoint,
    volume: Option<OverlapVolume>,
    relative_velocity: DVec3,
    relative_velocity_end: DVec3,
    relative_angular_velocity: DVec3,
    effective_radius: f64,
    effective_mass: f64,
    inverse_step: f64,
) -> Kinematics {
    let normal_speed = relative_velocity.dot(g.normal);
    let normal_speed_end = relative_velocity_end.dot(g.normal);
    Kinematics {
        normal: g.normal,
        overlap: g.overlap,
        overlap_rate: -normal_speed_end,
        tangential_velocity: relative_velocity - g.normal * normal_speed,
        tangential_velocity_end: relative_velocity_end - g.normal * normal_speed_end,
        velocity_start: 2.0 * relative_velocity - relative_velocity_end,
        relative_angular_velocity,
        effective_radius,
        effective_mass,
        overlap_volume: volume,
        dashpot_limit: DashpotLimit::of_spheres(effective_mass, inverse_step),
    }
}

/// The masses a push at `point` along `normal` and (at most) along a tangent moves, for body `a`
/// and its partner `b` (`None`: a wall, which does not move): see `contact_law::DashpotLimit`.
fn dashpot_mass(
    bodies: &Bodies,
    a: usize,
    b: Option<usize>,
    point: DVec3,
    normal: DVec3,
) -> (f64, f64) {
    let (mut normal_compliance, mut tangential_compliance) = (0.0, 0.0);
    for i in std::iter::once(a).chain(b) {
        let arm = point - bodies.position[i];
        let inv_inertia = bodies.inv_inertia[i];
        // (r × n)·I⁻¹(r × n), with I⁻¹ diagonal in the body's frame.
        let turn = bodies.orientation[i].inverse() * arm.cross(normal);
        normal_compliance += bodies.inv_mass[i] + (turn * turn).dot(inv_inertia);
        // Along the worst tangent: |r|² times the largest inverse principal moment.
        tangential_compliance +=
            bodies.inv_mass[i] + arm.length_squared() * inv_inertia.max_element();
    }
    (1.0 / normal_compliance, 1.0 / tangential_compliance)
}

#[cfg(test)]
mod tests {
    use super::{striped_sum, STRIPES};
    use proptest::prelude::*;

    proptest! {
        /// The striped sum adds value `k` into accumulator `k % 8` and the eight pairwise
        /// (checked against that order written one value at a time), leaves out the values not
        /// counted as if they were zeros, and is the exact sum to within the rounding of
        /// `n` additions.
        #[test]
        fn striped_sums_keep_their_order_and_their_accuracy(
            values in prop::collection::vec(-1e3..1e3f64, 0..300),
            skip in 1usize..7,
        ) {
            let mut stripes = [0.0f64; STRIPES];
            for (k, &v) in values.iter().enumerate() {
                stripes[k % STRIPES] += v;
            }
            let s = stripes;
            let ordered = ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
            prop_assert_eq!(striped_sum(&values, |_| true).to_bits(), ordered.to_bits());

            let counted = |k: usize| !k.is_multiple_of(skip);
            let zeroed: Vec<f64> = values
                .iter()
                .enumerate()
                .map(|(k, &v)| if counted(k) { v } else { 0.0 })
                .collect();
            prop_assert_eq!(
                striped_sum(&values, counted).to_bits(),
                striped_sum(&zeroed, |_| true).to_bits()
            );

            // Error of recursive summation: at most (n - 1) ε Σ|x| (Higham, Accuracy and
            // Stability of Numerical Algorithms, §4.2); the exact sum from integers, every value
            // being a multiple of 2^-40 here after rounding to it.
            let grid = |v: f64| (v * 2f64.powi(40)).round();
            let on_grid: Vec<f64> = values.iter().map(|&v| grid(v) / 2f64.powi(40)).collect();
            let exact: i128 = on_grid.iter().map(|&v| (v * 2f64.powi(40)) as i128).sum();
            let exact = exact as f64 / 2f64.powi(40);
            let magnitude: f64 = on_grid.iter().map(|v| v.abs()).sum();
            let bound = values.len() as f64 * f64::EPSILON * magnitude + f64::MIN_POSITIVE;
            let sum = striped_sum(&on_grid, |_| true);
            prop_assert!((sum - exact).abs() <= bound, "{sum} against {exact} (bound {bound})");
        }
    }
}
