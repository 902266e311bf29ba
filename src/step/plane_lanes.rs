//! Four spheres on plane walls at once: the general path of a sphere touching a plane
//! (`narrow_phase::sphere_plane`, `forces::LawInputs::respond`, `contact_law::evaluate_point`,
//! `Load::new`) in four lanes, as `step::sphere_lanes` does for sphere pairs.
//!
//! In a box or a chute a tenth of the spheres or more rest on a plane, and each of those contacts
//! took the general path one by one: about 100 ns each, a twelfth of the settled 10,000-sphere
//! step. Each lane is the general path's arithmetic, operation for operation and in the same
//! order, so the bits are the same (a property test below holds them together). Used in worlds of
//! spheres and planes, where every single-contact entry with a plane partner is a sphere on a
//! plane and takes the point law (with rolling resistance, `step::rolling_lanes`, where some law
//! has rolling friction).

use super::forces::LawInputs;
use super::sphere_lanes::{self, dashpot_limit, Laws, MotionLanes, PointContacts};
use crate::contact::{EntryIds, EntryState, Partner};
use crate::wall::Plane;
use crate::wide::lanes::{each, F4, V3};

/// Whether the sphere of body `a` touches plane `partner` (the test of
/// `narrow_phase::sphere_plane`; a NaN position counts as touching, so that a blow-up shows).
#[inline(always)]
pub(crate) fn touches(inputs: &LawInputs, a: u32, partner: Partner) -> bool {
    let plane = plane(inputs, partner);
    let m = &inputs.motion[a as usize];
    let height = (m.position - plane.point).dot(plane.normal);
    let overlap = m.radius - height;
    !(overlap <= 0.0 || height <= -m.radius)
}

/// The plane of a wall entry's key.
#[inline(always)]
fn plane<'a>(inputs: &LawInputs<'a>, partner: Partner) -> &'a Plane {
    match partner {
        Partner::Plane(p) => &inputs.scene.planes[p as usize],
        _ => unreachable!("only sphere–plane entries go through the plane lanes"),
    }
}

four_wide_kernel!(
    /// Contact and response of the four touching sphere–plane `entries` over the step `dt`: four
    /// at once where the CPU can, one by one through the general path (the same numbers) where
    /// it cannot.
    touching_planes,
    one_by_one
);

/// The last one to three touching sphere–plane entries of a run (`rest`), four-wide too: the
/// lanes left over repeat the last entry (see `four_wide_kernel`). A run of 256 entries of the
/// 65,000-sphere bed has some seven spheres on a plane, so the rest was a fifth of them, and one
/// by one it had cost two thirds as much as the other four fifths (1.8 % of the step against
/// 2.7 %, `perf record`).
pub(crate) fn touching_planes_rest(
    inputs: &LawInputs,
    ids: &EntryIds,
    state: &mut EntryState,
    rest: &[u32],
    dt: f64,
) {
    padded(rest, |four| touching_planes(inputs, ids, state, four, dt));
}

/// Runs `four` on the one to three entries `rest` padded to four by repeating the last (none
/// when `rest` is empty).
#[inline(always)]
pub(super) fn padded(rest: &[u32], four: impl FnOnce([usize; 4])) {
    debug_assert!(rest.len() < 4, "a rest of at most three entries");
    if let Some(&last) = rest.last() {
        four(std::array::from_fn(|i| {
            rest.get(i).copied().unwrap_or(last) as usize
        }));
    }
}

/// The general path for one touching sphere–plane entry `k`.
fn one_by_one(inputs: &LawInputs, ids: &EntryIds, state: &mut EntryState, k: usize, dt: f64) {
    let key = ids.key[k];
    let g = super::detect::detect_single(inputs.scene, &key, k, state)
        .expect("a sphere–plane entry sorted as touching touches");
    respond_to_wall(inputs, ids, state, k, &g, dt);
}

/// The general path's response of touching sphere–wall entry `k` at contact `g`: the law
/// (`LawInputs::respond`), the load with no partner body, the report and the energy lost.
pub(super) fn respond_to_wall(
    inputs: &LawInputs,
    ids: &EntryIds,
    state: &mut EntryState,
    k: usize,
    g: &crate::narrow_phase::ContactPoint,
    dt: f64,
) {
    let key = ids.key[k];
    let mut none = crate::contact_law::SpinHistory::default();
    let spin = state.spin.get_mut(k).unwrap_or(&mut none);
    let history = (&mut state.history[k], spin);
    let r = inputs.respond(key, ids.kind[k], g, None, history, dt);
    let centre = inputs.motion[key.a as usize].position;
    state.set_load(k, crate::contact::Load::new(&r, g.point, centre, None));
    if let Some(report) = state.report.get_mut(k) {
        *report = crate::contact::LawReport::of(&r);
    }
    state.dissipated[k] = r.dissipated;
}

#[inline(always)]
fn kernel(
    inputs: &LawInputs,
    ids: &EntryIds,
    state: &mut EntryState,
    entries: [usize; 4],
    dt: f64,
) {
    let bodies = inputs.scene.bodies;
    let a: [usize; 4] = each(|i| ids.key[entries[i]].a as usize);
    let planes: [&Plane; 4] = each(|i| plane(inputs, ids.key[entries[i]].partner));
    let m = MotionLanes::gather(each(|i| &inputs.motion[a[i]]));
    let law = Laws::gather(each(|i| {
        inputs.laws.get(bodies.material[a[i]], planes[i].material)
    }));
    let normal = V3::gather(|i| planes[i].normal);
    let half = F4::splat(0.5);

    // The narrow phase (narrow_phase::touching_sphere_plane).
    let x = m.position;
    let overlap = m.radius - (x - V3::gather(|i| planes[i].point)).dot(normal);
    let point = x - normal.scale(m.radius - half * overlap);
    let contact = WallContact {
        normal,
        overlap,
        point,
        // The plane does not move: v − 0 and ω − 0 are v and ω to the bit.
        motion: None,
    };
    wall_law(inputs, state, entries, a, &m, &law, &contact, dt);
}

/// The contact of four spheres with their walls, and how the walls move at the contact points.
pub(super) struct WallContact {
    pub normal: V3,
    pub overlap: F4,
    pub point: V3,
    /// The walls' velocities at the points over the step and at its end, and their angular
    /// velocities; `None` for walls at rest.
    pub motion: Option<[V3; 3]>,
}

/// The response of four spheres (bodies `a`, motions `m`, laws `law`) to their walls at
/// `contact`, into entries `entries`: `LawInputs::respond` for a wall partner,
/// `contact_law::evaluate_point` (or `evaluate` with rolling resistance) and `Load::new` with no
/// partner body, lane by lane, operation for operation.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn wall_law(
    inputs: &LawInputs,
    state: &mut EntryState,
    entries: [usize; 4],
    a: [usize; 4],
    m: &MotionLanes,
    law: &Laws,
    contact: &WallContact,
    dt: f64,
) {
    let bodies = inputs.scene.bodies;
    let scalars = |f: &dyn Fn(usize) -> f64| F4::new(each(f));
    let WallContact {
        normal,
        overlap,
        point,
        motion,
    } = *contact;
    let zero = F4::splat(0.0);
    let x = m.position;

    // The contact point's velocity over the step and at its end (LawInputs::point_velocity),
    // less the wall's.
    let arm = point - x;
    let mut relative = m.velocity + m.angular_velocity.cross(arm);
    let mut relative_end = m.velocity_end + m.angular_velocity_end.cross(arm);
    let mut relative_angular = m.angular_velocity;
    if let Some([wall, wall_end, wall_spin]) = motion {
        relative = relative - wall;
        relative_end = relative_end - wall_end;
        relative_angular = relative_angular - wall_spin;
    }

    // The masses a push along the normal and along the worst tangent move (forces::dashpot_mass
    // for one body): (r × n)·I⁻¹(r × n) with r × n turned into the body's frame by the inverse
    // of its orientation (glam's `DQuat::mul_vec3` on the conjugate, term for term).
    let q = each(|i| bodies.orientation[a[i]]);
    let (w, b) = (
        F4::new(each(|i| q[i].w)),
        V3::gather(|i| -glam::DVec3::new(q[i].x, q[i].y, q[i].z)),
    );
    let r = arm.cross(normal);
    let turn = r.scale(w * w - b.dot(b))
        + b.scale(r.dot(b) * F4::splat(2.0))
        + b.cross(r).scale(w * F4::splat(2.0));
    let inv_mass = scalars(&|i| bodies.inv_mass[a[i]]);
    let inv_inertia = V3::gather(|i| bodies.inv_inertia[a[i]]);
    let turn_squared = V3 {
        x: turn.x * turn.x,
        y: turn.y * turn.y,
        z: turn.z * turn.z,
    };
    let normal_compliance = zero + (inv_mass + turn_squared.dot(inv_inertia));
    // glam's `max_element`: max(x, max(y, z)) with max(p, q) = p if p > q, else q.
    let (ix, iy, iz) = (inv_inertia.x, inv_inertia.y, inv_inertia.z);
    let larger_yz = F4::select(iy.gt(iz), iy, iz);
    let largest = F4::select(ix.gt(larger_yz), ix, larger_yz);
    let tangential_compliance = zero + (inv_mass + arm.length_squared() * largest);
    let one = F4::splat(1.0);
    let limit = [
        dashpot_limit(inputs, one / normal_compliance),
        dashpot_limit(inputs, one / tangential_compliance),
    ];

    let contacts = PointContacts {
        normal,
        overlap,
        relative,
        relative_end,
        relative_angular,
        effective_radius: scalars(&|i| bodies.equivalent_radius[a[i]]),
        effective_mass: scalars(&|i| bodies.mass[a[i]]),
        limit,
    };
    let (force, torque) = sphere_lanes::point_law(state, entries, law, &contacts, dt);
    // Load::new with no partner body: the moment on `a` and the law's torque, and for the
    // wall the law's torque (its rolling resistance; none without rolling friction).
    let torque_a = arm.cross(force) + torque;
    sphere_lanes::store_loads(state, entries, force, torque_a, torque);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactKey, PairKind};
    use crate::contact_law::SpinHistory;
    use crate::math::DVec3;
    use crate::step::sphere_lanes::tests::{
        rolls, run_entries, spin, tables, vec3, Lanes, TestSpheres, TABLES_COUNT,
    };
    use crate::step::Scene;
    use proptest::prelude::*;

    /// One sphere on a plane: radius, the plane's normal, how deep the sphere sits (a share of
    /// its radius), its orientation, its velocities over the step and their change to its end,
    /// the sphere's and the plane's materials, and the history it starts from.
    type Case = (
        f64,
        DVec3,
        f64,
        DVec3,
        [DVec3; 2],
        [DVec3; 2],
        (u32, u32),
        DVec3,
        f64,
        SpinHistory,
    );

    fn case() -> impl Strategy<Value = Case> {
        (
            0.5e-3..2e-3f64,
            vec3(1.0).prop_filter("a direction", |d| d.length() > 1e-3),
            0.001..0.3f64,
            vec3(3.0),
            prop::array::uniform2(vec3(0.1)),
            prop::array::uniform2(vec3(0.01)),
            (0..2u32, 0..2u32),
            prop_oneof![Just(DVec3::ZERO), vec3(1e-6), vec3(1e-4)],
            prop_oneof![Just(0.0), 1.0..1e4f64],
            spin(),
        )
    }

    proptest! {
        /// The four-wide kernel gives each lane exactly what the general path gives that sphere
        /// on its plane: load, report and history, to the bit, for both normal laws, lanes of
        /// mixed materials and planes, with and without friction and rolling friction, sticking
        /// and sliding, turned bodies with unequal inverse inertias.
        ///
        /// So do one to three entries padded to four (a run's rest, `touching_planes_rest`),
        /// and the entries left out keep what they held.
        #[test]
        fn four_lanes_are_the_general_path_to_the_bit(
            cases in prop::array::uniform4(case()),
            law in 0..TABLES_COUNT,
            dt in prop_oneof![Just(0.0), 1e-6..1e-4f64],
            step in 1e-6..1e-4f64,
            rest in 1..4usize,
        ) {
            let laws = &tables()[law];
            let (mut spheres, mut planes) = (TestSpheres::default(), Vec::new());
            let mut start_spin = Vec::new();
            for (i, &(r, normal, depth, turn, v, end, (ma, mp), spring, kt, spin)) in cases.iter().enumerate() {
                if rolls(law) {
                    start_spin.push(spin);
                }
                let normal = normal.normalize();
                let point = DVec3::new(0.01, -0.02, 0.03) * (i as f64 + 1.0);
                let x = point + normal * (r * (1.0 - depth)) + normal.any_orthonormal_vector() * 0.004;
                planes.push(Plane { point, normal, material: mp });
                spheres.push(r, x, turn, v, end, ma, spring, kt);
            }
            let TestSpheres { bodies, shapes, motion, start } = spheres;
            let inputs = LawInputs {
                scene: Scene {
                    bodies: &bodies,
                    shapes: &shapes,
                    planes: &planes,
                    walls: &[],
                    law: Default::default(),
                },
                wall_states: &[],
                laws,
                motion: &motion,
                near_triangles: crate::step::detect::NearTriangles::none(),
                inverse_step: 1.0 / step,
            };
            let key: Vec<ContactKey> = (0..4)
                .map(|i| ContactKey { a: i, partner: Partner::Plane(i), region: 0 })
                .collect();
            let kind = [PairKind::Single; 4];
            let ids = EntryIds { key: &key, kind: &kind };
            for k in &key {
                prop_assert!(touches(&inputs, k.a, k.partner), "{:?} must touch", k);
            }
            let geometry = Vec::<crate::narrow_phase::ContactPoint>::new();
            let run = |lanes: Lanes| {
                run_entries(&start, &start_spin, &geometry, false, |state| {
                    run_lanes!(lanes, &inputs, &ids, state, dt, touching_planes_rest)
                })
            };
            prop_assert_eq!(run(Lanes::Four), run(Lanes::OneByOne(4)));
            prop_assert_eq!(run(Lanes::Rest(rest)), run(Lanes::OneByOne(rest)));
        }
    }
}
