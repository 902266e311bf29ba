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
    debug_assert!(rest.len() < 4, "a rest of at most three entries");
    if let Some(&last) = rest.last() {
        let four = std::array::from_fn(|i| rest.get(i).copied().unwrap_or(last) as usize);
        touching_planes(inputs, ids, state, four, dt);
    }
}

/// The general path for one touching sphere–plane entry `k`.
fn one_by_one(inputs: &LawInputs, ids: &EntryIds, state: &mut EntryState, k: usize, dt: f64) {
    let key = ids.key[k];
    let g = super::detect::detect_single(inputs.scene, &key, k, state)
        .expect("a sphere–plane entry sorted as touching touches");
    let mut none = crate::contact_law::SpinHistory::default();
    let spin = state.spin.get_mut(k).unwrap_or(&mut none);
    let history = (&mut state.history[k], spin);
    let r = inputs.respond(key, ids.kind[k], &g, None, history, dt);
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
    use crate::body::{Bodies, BodyInit};
    use crate::contact::{ContactKey, LawReport, OwnLoad, PairKind, PartnerLoad};
    use crate::contact_law::{History, SpinHistory};
    use crate::integrate::BodyMotion;
    use crate::math::{DQuat, DVec3};
    use crate::shape::{Shape, Sphere};
    use crate::step::sphere_lanes::tests::{rolls, spin, tables, vec3, TABLES_COUNT};
    use crate::step::Scene;
    use glam::Vec3;
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
            let (mut bodies, mut shapes, mut motion, mut planes) =
                (Bodies::default(), Vec::new(), Vec::new(), Vec::new());
            let (mut start, mut start_spin) = (Vec::new(), Vec::new());
            for (i, &(r, normal, depth, turn, v, end, (ma, mp), spring, kt, spin)) in cases.iter().enumerate() {
                if rolls(law) {
                    start_spin.push(spin);
                }
                let normal = normal.normalize();
                let point = DVec3::new(0.01, -0.02, 0.03) * (i as f64 + 1.0);
                let x = point + normal * (r * (1.0 - depth)) + normal.any_orthonormal_vector() * 0.004;
                planes.push(Plane { point, normal, material: mp });
                shapes.push(Shape::Sphere(Sphere { radius: r }));
                let orientation = DQuat::from_scaled_axis(turn);
                let init = BodyInit {
                    shape: shapes[i].clone(),
                    material: ma,
                    position: x,
                    orientation,
                    velocity: DVec3::ZERO,
                    angular_velocity: DVec3::ZERO,
                };
                let mass = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
                // Unequal moments, as of a body that is not a solid sphere.
                let inertia = DVec3::new(0.4, 0.3, 0.5) * mass * r * r;
                bodies.push(i as u64, i as u32, ma, r, r, mass, inertia, &init);
                motion.push(BodyMotion {
                    position: x,
                    radius: r,
                    velocity: v[0],
                    angular_velocity: v[1] * 100.0,
                    velocity_end: v[0] + end[0],
                    angular_velocity_end: (v[1] + end[1]) * 100.0,
                });
                start.push(History {
                    tangential_spring: spring,
                    tangential_stiffness: kt,
                    damper_force: (spring * 1e4).as_vec3() + Vec3::X * 1e-3,
                    damper_work_estimate: 1e-7,
                });
            }
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
            let run = |four_wide: bool, count: usize| {
                let mut touching = [false; 4];
                let mut history: [History; 4] = std::array::from_fn(|i| start[i]);
                let (mut load, mut report) = ([PartnerLoad::default(); 4], [LawReport::default(); 4]);
                let mut own = [OwnLoad::default(); 4];
                let mut dissipated = [0.0; 4];
                let mut spin = start_spin.clone();
                let mut state = EntryState {
                    touching: &mut touching,
                    geometry: &mut [],
                    volume: &mut [],
                    history: &mut history,
                    spin: &mut spin,
                    load: &mut load,
                    own: &mut own,
                    report: &mut report,
                    dissipated: &mut dissipated,
                };
                if four_wide && count < 4 {
                    let rest: Vec<u32> = (0..count as u32).collect();
                    touching_planes_rest(&inputs, &ids, &mut state, &rest, dt);
                } else if four_wide {
                    #[cfg(target_arch = "x86_64")]
                    {
                        if !std::arch::is_x86_feature_detected!("avx") {
                            println!("no AVX here: the kernel is not used on this CPU");
                        } else {
                            // SAFETY: the CPU has AVX.
                            unsafe { with_avx(&inputs, &ids, &mut state, [0, 1, 2, 3], dt) };
                        }
                    }
                    #[cfg(not(target_arch = "x86_64"))]
                    kernel(&inputs, &ids, &mut state, [0, 1, 2, 3], dt);
                } else {
                    for k in 0..count {
                        one_by_one(&inputs, &ids, &mut state, k, dt);
                    }
                }
                format!("{touching:?} {history:?} {spin:?} {load:?} {own:?} {report:?} {dissipated:?}")
            };
            prop_assert_eq!(run(true, 4), run(false, 4));
            prop_assert_eq!(run(true, rest), run(false, rest));
        }
    }
}
