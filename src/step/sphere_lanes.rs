//! Four touching sphere pairs at once: the sphere fast path (`step::spheres`) in four lanes.
//!
//! Most of a granular run's time goes into sphere contacts, and their arithmetic is a long chain
//! of dependent operations (three square roots and two divisions among them) that one contact at
//! a time leaves the floating-point units idle waiting on. Four contacts side by side in [`F4`]
//! lanes fill them: the contact loop gathers the touching sphere pairs of a chunk four by four,
//! runs this kernel, and scatters the results into the store; what is left over (fewer than four)
//! goes through the scalar path.
//!
//! Each lane is the scalar path's arithmetic, operation for operation and in the same order
//! (`narrow_phase::overlapping_spheres`, `step::forces::kinematics`,
//! `contact_law::evaluate_point` with `normal::elastic`, `tangential::tangential_force` and
//! `book_dampers`; in a world with rolling friction `contact_law::evaluate`, whose rolling torque
//! `step::rolling_lanes` adds; then `Load::new`); branches become lane selects of both sides. So it gives the
//! same bits, which a property test below holds, and results stay the same whichever entries
//! happen to share a group, for any thread count and on any machine.

use super::forces::LawInputs;
use super::spheres;
use crate::contact::{EntryIds, EntryState};
use crate::contact_law::{History, NormalLaw, PairLaw, DASHPOT_BOUND, TANGENTIAL_MASS_SHARE};
use crate::integrate::BodyMotion;
use crate::math::DVec3;
use crate::wide::lanes::{each, F4, M4, V3};

four_wide_kernel!(
    /// Contact and response of the four touching sphere pairs `entries` (their partners bodies)
    /// over the step `dt`: four at once where the CPU can, one by one through the scalar path
    /// (the same numbers) where it cannot.
    touching_pairs,
    one_by_one
);

/// The scalar path for one touching sphere pair `k`.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn one_by_one(inputs: &LawInputs, ids: &EntryIds, state: &mut EntryState, k: usize, dt: f64) {
    spheres::touching_pair(inputs, ids.key[k], state.entry(k), dt);
}

/// The law's numbers of the four lanes.
pub(super) struct Laws {
    hertz: M4,
    /// E* under Hertz; the spring's stiffness under the linear law.
    youngs_modulus: F4,
    linear_stiffness: F4,
    shear_modulus: F4,
    damping: F4,
    tangential_damping_ratio: F4,
    tangential_stiffness_ratio: F4,
    friction: F4,
    rolling_friction: F4,
}

impl Laws {
    #[inline(always)]
    pub(super) fn gather(law: [&PairLaw; 4]) -> Self {
        // Most groups share one law (a scene has few materials): its numbers are then loaded
        // once each and broadcast, not gathered lane by lane and shuffled together, which keeps
        // about fifty loads and shuffles off the kernel's vector units.
        let shared = law[1..].iter().all(|&l| std::ptr::eq(l, law[0]));
        let lanes = |f: fn(&PairLaw) -> f64| {
            if shared {
                F4::splat(f(law[0]))
            } else {
                F4::new(each(|i| f(law[i])))
            }
        };
        let is_hertz = |l: &PairLaw| {
            if l.normal == NormalLaw::Hertz {
                1.0
            } else {
                0.0
            }
        };
        Laws {
            hertz: lanes(is_hertz).gt(F4::splat(0.0)),
            youngs_modulus: lanes(|l| l.effective_youngs_modulus),
            linear_stiffness: lanes(|l| match l.normal {
                NormalLaw::Linear { stiffness } => stiffness,
                NormalLaw::Hertz => 0.0,
            }),
            shear_modulus: lanes(|l| l.effective_shear_modulus),
            damping: lanes(|l| l.damping),
            tangential_damping_ratio: lanes(|l| l.tangential_damping_ratio),
            tangential_stiffness_ratio: lanes(|l| l.tangential_stiffness_ratio),
            friction: lanes(|l| l.friction),
            rolling_friction: lanes(|l| l.rolling_friction),
        }
    }
}

/// The packed motion of four bodies, lane by lane: each body's two cache lines loaded whole and
/// transposed (the numbers themselves, so the same bits as gathering them one by one).
pub(super) struct MotionLanes {
    pub position: V3,
    pub velocity: V3,
    pub angular_velocity: V3,
    pub velocity_end: V3,
    pub angular_velocity_end: V3,
    pub radius: F4,
}

impl MotionLanes {
    #[inline(always)]
    pub(super) fn gather(motion: [&BodyMotion; 4]) -> Self {
        let columns = |row: usize| F4::transpose(motion.map(|m| &m.as_rows()[row]));
        let [x, y, z, radius] = columns(0);
        let [vx, vy, vz, wx] = columns(1);
        let [wy, wz, ex, ey] = columns(2);
        let [ez, fx, fy, fz] = columns(3);
        MotionLanes {
            position: V3 { x, y, z },
            velocity: V3 {
                x: vx,
                y: vy,
                z: vz,
            },
            angular_velocity: V3 {
                x: wx,
                y: wy,
                z: wz,
            },
            velocity_end: V3 {
                x: ex,
                y: ey,
                z: ez,
            },
            angular_velocity_end: V3 {
                x: fx,
                y: fy,
                z: fz,
            },
            radius,
        }
    }
}

/// As `tangential::rotate_into_plane`, lane by lane.
#[inline(always)]
pub(super) fn rotate_into_plane(v: V3, n: V3) -> V3 {
    let zero = F4::splat(0.0);
    let length_squared = v.length_squared();
    let projected = v - n.scale(n.dot(v));
    let projected_squared = projected.length_squared();
    let rotated = projected.scale((length_squared / projected_squared).sqrt());
    let rotated = V3::select(projected_squared.eq(zero), V3::zero(), rotated);
    V3::select(length_squared.eq(zero), v, rotated)
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
    let pair: [(usize, usize); 4] = each(|i| spheres::bodies(ids.key[entries[i]]));
    let (motion, mass) = (inputs.motion, &bodies.mass);
    let a = MotionLanes::gather(each(|i| &motion[pair[i].0]));
    let b = MotionLanes::gather(each(|i| &motion[pair[i].1]));
    let scalars = |f: &dyn Fn(usize) -> f64| F4::new(each(f));
    let (xa, xb) = (a.position, b.position);
    let (ra, rb) = (a.radius, b.radius);
    let law = Laws::gather(each(|i| {
        let (p, q) = pair[i];
        inputs.laws.get(bodies.material[p], bodies.material[q])
    }));
    let (zero, half) = (F4::splat(0.0), F4::splat(0.5));

    // The narrow phase (narrow_phase::overlapping_spheres).
    let d = xa - xb;
    let distance = d.length_squared().sqrt();
    let normal = V3::select(
        distance.gt(zero),
        d.scale(F4::splat(1.0) / distance),
        V3::splat(DVec3::Z),
    );
    let overlap = ra + rb - distance;
    let point = xb + normal.scale(rb - half * overlap);

    // The contact points' velocities over the step and at its end (spheres::touching_pair).
    let (arm_a, arm_b) = (point - xa, point - xb);
    let va = a.velocity + a.angular_velocity.cross(arm_a);
    let va_end = a.velocity_end + a.angular_velocity_end.cross(arm_a);
    let vb = b.velocity + b.angular_velocity.cross(arm_b);
    let vb_end = b.velocity_end + b.angular_velocity_end.cross(arm_b);
    // R* and m* with one division (contact_law::effective_radius_and_mass).
    let (mass_a, mass_b) = (scalars(&|i| mass[pair[i].0]), scalars(&|i| mass[pair[i].1]));
    let (radius_sum, mass_sum) = (ra + rb, mass_a + mass_b);
    let inverse = F4::splat(1.0) / (radius_sum * mass_sum);
    let effective_radius = ra * rb * mass_sum * inverse;
    let effective_mass = mass_a * mass_b * radius_sum * inverse;
    // The dashpots' bounds (DashpotLimit::of_spheres, on the world's step whatever `dt` the
    // histories advance by).
    let tangential_mass = F4::splat(TANGENTIAL_MASS_SHARE) * effective_mass;
    let contacts = PointContacts {
        normal,
        overlap,
        relative: va - vb,
        relative_end: va_end - vb_end,
        relative_angular: a.angular_velocity - b.angular_velocity,
        effective_radius,
        effective_mass,
        limit: [
            dashpot_limit(inputs, effective_mass),
            dashpot_limit(inputs, tangential_mass),
        ],
    };
    let (force, torque) = point_law(state, entries, &law, &contacts, dt);
    // Load::new: each body's moment of the force, and the law's torque on `a` (its rolling
    // resistance; none without rolling friction).
    let torque_a = arm_a.cross(force) + torque;
    let torque_b = -(arm_b.cross(force) + torque);
    store_loads(state, entries, force, torque_a, torque_b);
}

/// `DASHPOT_BOUND` m/Δt: the bound on a dashpot pushing mass `m` (`DashpotLimit::of_masses`),
/// Δt the world's step.
///
/// (The kernels call it, and every other lane operation, outside closures: a closure is not
/// compiled with its function's target features, so each lane operation in it became a call.)
#[inline(always)]
pub(super) fn dashpot_limit(inputs: &LawInputs, mass: F4) -> F4 {
    F4::splat(DASHPOT_BOUND) * mass * F4::splat(inputs.inverse_step)
}

/// Four point contacts as the law sees them (`forces::kinematics`, lane by lane).
pub(super) struct PointContacts {
    pub normal: V3,
    pub overlap: F4,
    /// The contact points' relative velocity over the step and predicted at its end.
    pub relative: V3,
    pub relative_end: V3,
    /// The bodies' relative angular velocity over the step (the rolling law's).
    pub relative_angular: V3,
    pub effective_radius: F4,
    pub effective_mass: F4,
    /// The bounds on the normal and tangential dashpots (`contact_law::DashpotLimit`).
    pub limit: [F4; 2],
}

/// The point law (`contact_law::evaluate_point` with `normal::elastic`,
/// `tangential::tangential_force` and `book_dampers`) of the four touching `entries` over the
/// step `dt`: writes their histories, reports and touching flags, and returns the force on body
/// `a` and the law's torque on it (the caller writes the loads, whose moments depend on the
/// partner).
///
/// In a world that keeps spin histories (one with rolling friction) the law is
/// `contact_law::evaluate` instead: the same with the rolling resistance
/// ([`rolling_lanes`](super::rolling_lanes)), whose torque is then the law's (otherwise none) and
/// whose energies join the sums in `evaluate`'s order.
#[inline(always)]
pub(super) fn point_law(
    state: &mut EntryState,
    entries: [usize; 4],
    law: &Laws,
    c: &PointContacts,
    dt: f64,
) -> (V3, V3) {
    let scalars = |f: &dyn Fn(usize) -> f64| F4::new(each(f));
    let history: [&History; 4] = each(|i| &state.history[entries[i]]);
    let old_spring = V3::gather(|i| history[i].tangential_spring);
    let old_kt = scalars(&|i| history[i].tangential_stiffness);
    let previous_damper = V3::gather(|i| history[i].damper_force.as_dvec3());
    let (zero, half, dt4) = (F4::splat(0.0), F4::splat(0.5), F4::splat(dt));
    let (normal, overlap, effective_mass) = (c.normal, c.overlap, c.effective_mass);

    // Kinematics (forces::kinematics).
    let (relative, relative_end) = (c.relative, c.relative_end);
    let (normal_speed, normal_speed_end) = (relative.dot(normal), relative_end.dot(normal));
    let overlap_rate = -normal_speed_end;
    let tangential_velocity = relative - normal.scale(normal_speed);
    let tangential_velocity_end = relative_end - normal.scale(normal_speed_end);
    let velocity_start = relative.scale(F4::splat(2.0)) - relative_end;

    // The normal law (normal::elastic; normal::bounded_dashpot).
    let contact_radius = (c.effective_radius * overlap).sqrt();
    let (e, k) = (law.youngs_modulus, law.linear_stiffness);
    let elastic = F4::select(
        law.hertz,
        F4::splat(4.0 / 3.0) * e * overlap * contact_radius,
        k * overlap,
    );
    let stiffness = F4::select(law.hertz, F4::splat(2.0) * e * contact_radius, k);
    let elastic_energy = F4::select(
        law.hertz,
        F4::splat(8.0 / 15.0) * e * overlap * overlap * contact_radius,
        half * k * overlap * overlap,
    );
    let contact_radius = F4::select(law.hertz, contact_radius, zero);
    let damping_coefficient = (law.damping * (effective_mass * stiffness).sqrt()).min(c.limit[0]);
    let total = (elastic + damping_coefficient * overlap_rate).max(zero);

    // The tangential law (tangential::tangential_force).
    let kt = F4::select(
        law.hertz,
        F4::splat(8.0) * law.shear_modulus * contact_radius,
        law.tangential_stiffness_ratio * stiffness,
    );
    let frictionless = kt.le(zero) | law.friction.le(zero);
    let old_xi = rotate_into_plane(old_spring, normal);
    let gamma = (damping_coefficient * law.tangential_damping_ratio).min(c.limit[1]);
    let damping = tangential_velocity_end.scale(-gamma);
    let trial_xi = old_xi + tangential_velocity.scale(dt4);
    let trial = trial_xi.scale(-kt) + damping;
    let limit = law.friction * total;
    let trial_squared = trial.length_squared();
    let sticks = trial_squared.le(limit * limit);
    let sliding = trial.scale(limit / trial_squared.sqrt());
    let force_t = V3::select(sticks, trial, sliding);
    let xi = V3::select(sticks, trial_xi, sliding.scale(F4::splat(-1.0) / kt));
    let damper_t = V3::select(sticks, damping, V3::zero());
    let elastic_t = half * kt * xi.length_squared();
    let spring_work = half * (old_xi.scale(old_kt) + xi.scale(kt)).dot(tangential_velocity) * dt4;
    let old_energy = half * old_kt * old_xi.length_squared();
    let dissipated_t = spring_work - (elastic_t - old_energy);
    // Without friction or stiffness there is no tangential force, and the spring is let go.
    let force_t = V3::select(frictionless, V3::zero(), force_t);
    let damper_t = V3::select(frictionless, V3::zero(), damper_t);
    let elastic_t = F4::select(frictionless, zero, elastic_t);
    let dissipated_t = F4::select(frictionless, zero, dissipated_t);
    let xi = V3::select(frictionless, V3::zero(), xi);
    let kt = F4::select(frictionless, old_kt, kt);

    // The dashpots' work of the last step and this step's (contact_law::book_dampers). Forces
    // found again between steps (dt = 0, the same for every lane) keep the mean of the last
    // step's dashpot force and theirs, and the last step's estimate.
    let normal_damper = total - elastic;
    let damper_force = normal.scale(normal_damper) + damper_t;
    let (damper_work, damper_force, damper_estimate) = if dt == 0.0 {
        let kept = F4::new(each(|i| history[i].damper_work_estimate as f64));
        (zero, (previous_damper + damper_force).scale(half), kept)
    } else {
        let estimate = (normal_damper * overlap_rate - damper_t.dot(tangential_velocity_end)) * dt4;
        let work = -previous_damper.dot(velocity_start) * dt4;
        (work, damper_force, estimate)
    };

    // The response (evaluate_point; evaluate, whose twisting and rocking terms are zero for a
    // point contact: `+ zero` where they are added).
    let force = normal.scale(total) + force_t;
    let (torque, elastic_energy, dissipated) = if state.spin.is_empty() {
        let elastic_energy = elastic_energy + elastic_t;
        (
            V3::zero(),
            elastic_energy,
            damper_work + dissipated_t + zero,
        )
    } else {
        let rolling = super::rolling_lanes::rolling_torque(
            state,
            entries,
            law.rolling_friction,
            c,
            (stiffness, total),
            dt4,
        );
        (
            rolling.torque + V3::zero(),
            elastic_energy + elastic_t + rolling.elastic_energy + zero,
            damper_work + dissipated_t + rolling.dissipated + zero + zero,
        )
    };

    // Each entry's history and report are written whole, row by row: the lanes are turned into
    // rows in registers (the same numbers, so the same bits) and stored 32 bytes at a time,
    // where writing them number by number cost a store and a reload each.
    let spring = F4::rows([xi.x, xi.y, xi.z, kt]);
    let damper = F4::rows([
        damper_force.x,
        damper_force.y,
        damper_force.z,
        damper_estimate,
    ]);
    let dissipated = dissipated.to_array();
    for (i, &k) in entries.iter().enumerate() {
        state.touching[k] = true;
        let (history_spring, history_damper) = state.history[k].as_rows_mut();
        spring[i].store(history_spring);
        damper[i].store_f32(history_damper);
        state.dissipated[k] = dissipated[i];
    }
    // A world of spheres and planes keeps no reports: they are found again when read.
    if !state.report.is_empty() {
        let report = F4::rows([total, elastic_energy, zero, zero]);
        for (i, &k) in entries.iter().enumerate() {
            report[i].store2(state.report[k].as_array_mut());
        }
    }
    (force, torque)
}

/// Writes the loads (`Load::new`) of the four `entries`: the force on body `a` and its moment
/// (the contact loop's scratch), and the force and the partner's moment (for a wall, the law's
/// couple on `a`: the store's), as rows.
#[inline(always)]
pub(super) fn store_loads(
    state: &mut EntryState,
    entries: [usize; 4],
    force: V3,
    torque_a: V3,
    torque_b: V3,
) {
    let own_first = F4::rows([force.x, force.y, force.z, torque_a.x]);
    let partner_first = F4::rows([force.x, force.y, force.z, torque_b.x]);
    // (torque_a.y, torque_a.z) in the low halves, (torque_b.y, torque_b.z) in the high ones.
    let rest = F4::rows([torque_a.y, torque_a.z, torque_b.y, torque_b.z]);
    for (i, &k) in entries.iter().enumerate() {
        let (first, second) = state.own[k].as_rows_mut();
        own_first[i].store(first);
        rest[i].store2(second);
        let (first, second) = state.load[k].as_rows_mut();
        partner_first[i].store(first);
        rest[i].store_high2(second);
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::body::{Bodies, BodyInit};
    use crate::contact::{ContactKey, LawReport, OwnLoad, PairKind, Partner, PartnerLoad};
    use crate::contact_law::{NormalLaw, SpinHistory};
    use crate::integrate::BodyMotion;
    use crate::material::{Material, PairTable};
    use crate::math::DQuat;
    use crate::shape::{Shape, Sphere};
    use glam::Vec3;
    use proptest::prelude::*;

    pub(in crate::step) fn vec3(r: f64) -> impl Strategy<Value = DVec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// Two materials (so lanes mix laws), both normal laws, without and with friction, without
    /// and with rolling friction (table `k` has it if `k & 4`; then material "b" has none, so
    /// that the pairs' laws have μ_r 0.05, 0.025 and 0); made once, as the restitution's damping
    /// is found by integrating a collision.
    pub(in crate::step) fn tables() -> &'static [PairTable] {
        static TABLES: std::sync::OnceLock<Vec<PairTable>> = std::sync::OnceLock::new();
        TABLES.get_or_init(|| {
            (0..TABLES_COUNT)
                .map(|k| {
                    let material = |name: &str, restitution: f64, friction: f64| Material {
                        name: name.into(),
                        density: 2500.0,
                        youngs_modulus: 5e6,
                        poisson_ratio: 0.25,
                        restitution,
                        friction: if k & 2 != 0 { friction } else { 0.0 },
                        rolling_friction: if k & 4 != 0 && name == "a" { 0.05 } else { 0.0 },
                    };
                    let normal = if k & 1 != 0 {
                        NormalLaw::Hertz
                    } else {
                        NormalLaw::Linear { stiffness: 1e3 }
                    };
                    let materials = [material("a", 0.3, 0.4), material("b", 0.0, 0.7)];
                    PairTable::new(&materials, normal, 2.0 / 7.0, &[])
                })
                .collect()
        })
    }

    /// How many [`tables`] there are.
    pub(in crate::step) const TABLES_COUNT: usize = 8;

    /// Whether table `k` has rolling friction: a world that keeps spin histories.
    /// The spheres of a wall kernel's test (`plane_lanes`, `mesh_lanes`), one per lane, and the
    /// histories their entries start from.
    #[derive(Default)]
    pub(in crate::step) struct TestSpheres {
        pub bodies: crate::body::Bodies,
        pub shapes: Vec<crate::shape::Shape>,
        pub motion: Vec<BodyMotion>,
        pub start: Vec<History>,
    }

    impl TestSpheres {
        /// A sphere of radius `r` at `x`, turned by `turn` (axis × angle), of material
        /// `material`, with unequal moments (as of a body that is not a solid sphere), its
        /// velocities `v` (and ω/100) over the step and `v + end` at its end, and an entry history
        /// with `spring` and stiffness `kt`.
        #[allow(clippy::too_many_arguments)]
        pub(in crate::step) fn push(
            &mut self,
            r: f64,
            x: DVec3,
            turn: DVec3,
            v: [DVec3; 2],
            end: [DVec3; 2],
            material: u32,
            spring: DVec3,
            kt: f64,
        ) {
            let i = self.shapes.len();
            let shape = crate::shape::Shape::Sphere(crate::shape::Sphere { radius: r });
            self.shapes.push(shape.clone());
            let init = crate::body::BodyInit {
                shape,
                material,
                position: x,
                orientation: crate::math::DQuat::from_scaled_axis(turn),
                velocity: DVec3::ZERO,
                angular_velocity: DVec3::ZERO,
            };
            let mass = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
            let inertia = DVec3::new(0.4, 0.3, 0.5) * mass * r * r;
            self.bodies
                .push(i as u64, i as u32, material, r, r, mass, inertia, &init);
            self.motion.push(BodyMotion {
                position: x,
                radius: r,
                velocity: v[0],
                angular_velocity: v[1] * 100.0,
                velocity_end: v[0] + end[0],
                angular_velocity_end: (v[1] + end[1]) * 100.0,
            });
            self.start.push(History {
                tangential_spring: spring,
                tangential_stiffness: kt,
                damper_force: (spring * 1e4).as_vec3() + glam::Vec3::X * 1e-3,
                damper_work_estimate: 1e-7,
            });
        }
    }

    /// How a wall kernel's test runs its four entries (`plane_lanes`, `mesh_lanes`): four-wide
    /// (the kernel, or a rest of fewer padded to four) or one by one on the general path.
    pub(in crate::step) enum Lanes {
        Four,
        Rest(usize),
        OneByOne(usize),
    }

    /// Four entries' state from the histories `start` (and spin histories `start_spin`, the
    /// geometry `geometry`, touching or not), given to `run`; what it leaves, as text to compare.
    pub(in crate::step) fn run_entries(
        start: &[History],
        start_spin: &[SpinHistory],
        geometry: &[crate::narrow_phase::ContactPoint],
        touching: bool,
        run: impl FnOnce(&mut EntryState),
    ) -> String {
        let mut touching = [touching; 4];
        let mut geometry = geometry.to_vec();
        let mut history: [History; 4] = std::array::from_fn(|i| start[i]);
        let (mut load, mut report) = ([PartnerLoad::default(); 4], [LawReport::default(); 4]);
        let mut own = [OwnLoad::default(); 4];
        let mut dissipated = [0.0; 4];
        let mut spin = start_spin.to_vec();
        let mut state = EntryState {
            touching: &mut touching,
            geometry: &mut geometry,
            volume: &mut [],
            history: &mut history,
            spin: &mut spin,
            load: &mut load,
            own: &mut own,
            report: &mut report,
            dissipated: &mut dissipated,
        };
        run(&mut state);
        format!("{touching:?} {history:?} {spin:?} {load:?} {own:?} {report:?} {dissipated:?}")
    }

    pub(in crate::step) fn rolls(k: usize) -> bool {
        k & 4 != 0
    }

    /// A rolling spring to start from: none, one the step's turn changes, or one past the
    /// rolling limit; its stiffness none or some.
    pub(in crate::step) fn spin() -> impl Strategy<Value = SpinHistory> {
        (
            prop_oneof![Just(DVec3::ZERO), vec3(1e-9), vec3(1e-5)],
            prop_oneof![Just(0.0), 1e-7..1e-4f64],
        )
            .prop_map(|(rolling_torque, rolling_stiffness)| SpinHistory {
                rolling_torque,
                rolling_stiffness,
                twisting_torque: 1e-9,
                twisting_stiffness: 1e-6,
            })
    }

    /// One pair's setup: radii, direction and overlap, the bodies' motions, the materials, and
    /// the history it starts from (a spring, a stiffness, a dashpot force; a rolling spring).
    type Pair = (
        f64,
        f64,
        DVec3,
        f64,
        [DVec3; 4],
        [DVec3; 4],
        (u32, u32),
        DVec3,
        f64,
        SpinHistory,
    );

    fn pair() -> impl Strategy<Value = Pair> {
        (
            0.5e-3..2e-3f64,
            0.5e-3..2e-3f64,
            vec3(1.0).prop_filter("a direction", |d| d.length() > 1e-3),
            0.6..0.999f64,
            prop::array::uniform4(vec3(0.1)),
            prop::array::uniform4(vec3(0.01)),
            (0..2u32, 0..2u32),
            // Springs from none to far past the Coulomb limit.
            prop_oneof![Just(DVec3::ZERO), vec3(1e-6), vec3(1e-4)],
            prop_oneof![Just(0.0), 1.0..1e4f64],
            spin(),
        )
    }

    proptest! {
        /// The four-wide kernel gives each lane exactly what the scalar path gives that pair:
        /// load, report and history, to the bit, for both normal laws, lanes of mixed
        /// materials, with and without friction, sticking and sliding, and with rolling
        /// friction (lanes with and without it, springs held and capped) in a world that
        /// keeps spin histories.
        #[test]
        fn four_lanes_are_the_scalar_path_to_the_bit(
            pairs in prop::array::uniform4(pair()),
            law in 0..TABLES_COUNT,
            // Histories advance by `dt`; the dashpots are bounded on the world's step, which
            // differs when forces are found between steps (dt = 0).
            dt in prop_oneof![Just(0.0), 1e-6..1e-4f64],
            step in 1e-6..1e-4f64,
        ) {
            let inverse_step = 1.0 / step;
            let laws = &tables()[law];
            let (mut bodies, mut shapes, mut motion) = (Bodies::default(), Vec::new(), Vec::new());
            let (mut start, mut start_spin) = (Vec::new(), Vec::new());
            for (p, &(ra, rb, direction, gap, v, end, (ma, mb), spring, kt, spin)) in pairs.iter().enumerate() {
                if rolls(law) {
                    start_spin.push(spin);
                }
                let xa = DVec3::new(0.01, 0.02, 0.03) * (p as f64 + 1.0);
                let xb = xa + direction.normalize() * gap * (ra + rb);
                for (side, (r, x, material)) in [(ra, xa, ma), (rb, xb, mb)].into_iter().enumerate() {
                    let i = bodies.len();
                    shapes.push(Shape::Sphere(Sphere { radius: r }));
                    let init = BodyInit {
                        shape: shapes[i].clone(),
                        material,
                        position: x,
                        orientation: DQuat::IDENTITY,
                        velocity: DVec3::ZERO,
                        angular_velocity: DVec3::ZERO,
                    };
                    let mass = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
                    let inertia = DVec3::splat(0.4 * mass * r * r);
                    bodies.push(i as u64, i as u32, material, r, r, mass, inertia, &init);
                    motion.push(BodyMotion {
                        position: x,
                        velocity: v[2 * side],
                        angular_velocity: v[2 * side + 1] * 100.0,
                        velocity_end: v[2 * side] + end[2 * side],
                        angular_velocity_end: (v[2 * side + 1] + end[2 * side + 1]) * 100.0,
                        radius: r,
                    });
                }
                start.push(History {
                    tangential_spring: spring,
                    tangential_stiffness: kt,
                    damper_force: (spring * 1e4).as_vec3() + Vec3::X * 1e-3,
                    damper_work_estimate: 1e-7,
                });
            }
            let inputs = LawInputs::of_bodies(&bodies, &shapes, laws, &motion, inverse_step);
            let key: Vec<ContactKey> = (0..4)
                .map(|p| ContactKey { a: 2 * p, partner: Partner::Body(2 * p + 1), region: 0 })
                .collect();
            let kind = [PairKind::Spheres; 4];
            let ids = EntryIds { key: &key, kind: &kind };
            // Both paths, each on its own copy of the store's four entries.
            let run = |four_wide: bool| {
                // Debug prints the shortest string that reads back to the same bits.
                run_entries(&start, &start_spin, &[], false, |state| {
                    for (k, &key) in key.iter().enumerate() {
                        assert!(spheres::overlaps(&inputs, key), "pair {k} must touch");
                    }
                    if four_wide {
                        #[cfg(target_arch = "x86_64")]
                        {
                            if !std::arch::is_x86_feature_detected!("avx") {
                                println!("no AVX here: the kernel is not used on this CPU");
                            } else {
                                // SAFETY: the CPU has AVX.
                                unsafe { with_avx(&inputs, &ids, state, [0, 1, 2, 3], dt) };
                            }
                        }
                        #[cfg(not(target_arch = "x86_64"))]
                        kernel(&inputs, &ids, state, [0, 1, 2, 3], dt);
                    } else {
                        for (k, &key) in key.iter().enumerate() {
                            spheres::touching_pair(&inputs, key, state.entry(k), dt);
                        }
                    }
                })
            };
            prop_assert_eq!(run(true), run(false));
        }
    }
}
