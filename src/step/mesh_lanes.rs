//! Four spheres on mesh walls at once: the general path of a touching sphere–mesh region
//! (`forces::LawInputs::respond` for a mesh partner, `contact_law::evaluate_point` or `evaluate`,
//! `Load::new`) in four lanes, as `step::plane_lanes` does for spheres on planes, from the contact
//! geometry the narrow phase left in the store at the start of the chunk
//! (`step::detect::set_spheres_on_mesh`).
//!
//! In drums, chutes and hoppers every sphere at the wall touches a mesh, and each of those
//! contacts took the general path one by one (`respond` and the work around it, some 5 % of the
//! step of the 10,000-sphere bed in a triangulated box, `perf record`). Each lane is the general path's arithmetic,
//! operation for operation and in the same order (the walls' motion subtracted where they move:
//! x − 0 is x to the bit where they do not), so the bits are the same (a property test below
//! holds them together).

use super::forces::LawInputs;
use super::plane_lanes::{padded, respond_to_wall, wall_law, WallContact};
use super::sphere_lanes::{Laws, MotionLanes};
use crate::contact::{EntryIds, EntryState, Partner};
use crate::wide::lanes::{each, F4, V3};

four_wide_kernel!(
    /// Response of the four touching sphere–mesh `entries` over the step `dt`: four at once
    /// where the CPU can, one by one through the general path (the same numbers) where it
    /// cannot.
    touching_meshes,
    one_by_one
);

/// The last one to three touching sphere–mesh entries of a run (`rest`), four-wide too: the
/// lanes left over repeat the last entry (see `four_wide_kernel`).
pub(crate) fn touching_meshes_rest(
    inputs: &LawInputs,
    ids: &EntryIds,
    state: &mut EntryState,
    rest: &[u32],
    dt: f64,
) {
    padded(rest, |four| touching_meshes(inputs, ids, state, four, dt));
}

/// The mesh wall of a sphere–mesh entry's key.
#[inline(always)]
fn wall(partner: Partner) -> usize {
    match partner {
        Partner::Mesh(w) => w as usize,
        _ => unreachable!("only sphere–mesh entries go through the mesh lanes"),
    }
}

/// The general path for one touching sphere–mesh entry `k` (the contact loop's, for a regional
/// entry that touches).
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(crate) fn one_by_one(
    inputs: &LawInputs,
    ids: &EntryIds,
    state: &mut EntryState,
    k: usize,
    dt: f64,
) {
    let g = state.geometry[k];
    respond_to_wall(inputs, ids, state, k, &g, dt);
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
    let w: [usize; 4] = each(|i| wall(ids.key[entries[i]].partner));
    let m = MotionLanes::gather(each(|i| &inputs.motion[a[i]]));
    let law = Laws::gather(each(|i| {
        let material = inputs.scene.walls[w[i]].material;
        inputs.laws.get(bodies.material[a[i]], material)
    }));
    let g = each(|i| state.geometry[entries[i]]);
    // How each wall moves at its contact point (LawInputs::respond), if any of the four moves.
    let states = each(|i| inputs.wall_states[w[i]].as_ref());
    let motion = states.iter().any(Option::is_some).then(|| {
        let zero = glam::DVec3::ZERO;
        let at = |f: &dyn Fn(usize, &[crate::wall::WallState; 2]) -> glam::DVec3| {
            V3::gather(|i| states[i].map_or(zero, |s| f(i, s)))
        };
        [
            at(&|i, [over_step, _]| over_step.surface_velocity(g[i].point, g[i].normal)),
            at(&|i, [_, at_end]| at_end.surface_velocity(g[i].point, g[i].normal)),
            at(&|_, [_, at_end]| at_end.angular_velocity),
        ]
    });
    let contact = WallContact {
        normal: V3::gather(|i| g[i].normal),
        overlap: F4::new(each(|i| g[i].overlap)),
        point: V3::gather(|i| g[i].point),
        motion,
    };
    wall_law(inputs, state, entries, a, &m, &law, &contact, dt);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactKey, PairKind};
    use crate::contact_law::SpinHistory;
    use crate::math::DVec3;
    use crate::narrow_phase::ContactPoint;
    use crate::step::sphere_lanes::tests::{
        rolls, run_entries, spin, tables, vec3, Lanes, TestSpheres, TABLES_COUNT,
    };
    use crate::step::Scene;
    use crate::wall::{MeshWall, WallMotion, WallState};
    use proptest::prelude::*;

    /// How a wall moves: translation velocity, rotation (rpm about an axis through a point),
    /// belt velocity.
    type Motion = (DVec3, f64, DVec3, DVec3);

    /// One sphere on a mesh wall: radius, the contact's normal, how deep the sphere sits (a
    /// share of its radius), its orientation, its velocities over the step and their change to
    /// its end, the sphere's and the wall's materials, the history it starts from, and the
    /// wall's motion (`None`: at rest).
    type Case = (
        f64,
        DVec3,
        f64,
        DVec3,
        [DVec3; 2],
        [DVec3; 2],
        (u32, u32),
        (DVec3, f64),
        SpinHistory,
        Option<Motion>,
    );

    fn case() -> impl Strategy<Value = Case> {
        let motion = (vec3(0.5), -60.0..60.0f64, vec3(1.0), vec3(0.3));
        (
            0.5e-3..2e-3f64,
            vec3(1.0).prop_filter("a direction", |d| d.length() > 1e-3),
            0.001..0.3f64,
            vec3(3.0),
            prop::array::uniform2(vec3(0.1)),
            prop::array::uniform2(vec3(0.01)),
            (0..2u32, 0..2u32),
            (
                prop_oneof![Just(DVec3::ZERO), vec3(1e-6), vec3(1e-4)],
                prop_oneof![Just(0.0), 1.0..1e4f64],
            ),
            spin(),
            prop::option::of(motion),
        )
    }

    /// The states of a wall over a step and at its end (times 0.1 s and 0.1 s + 20 µs).
    fn states((velocity, rpm, axis, belt): Motion) -> [WallState; 2] {
        let axis = if axis.length() > 1e-3 { axis } else { DVec3::Z };
        let motion = WallMotion::fixed()
            .with_velocity(velocity)
            .and_then(|m| m.with_rotation(DVec3::new(0.01, 0.0, -0.02), axis, rpm))
            .and_then(|m| m.with_surface_velocity(belt))
            .unwrap();
        [motion.state(0.1), motion.state(0.1 + 2e-5)]
    }

    proptest! {
        /// The four-wide kernel gives each lane exactly what the general path gives that sphere
        /// on its mesh wall: load, report and history, to the bit, for both normal laws, lanes
        /// of mixed materials, walls at rest and moving (translating, turning, with a belt) side
        /// by side, with and without friction and rolling friction, sticking and sliding, turned
        /// bodies with unequal inverse inertias.
        ///
        /// So do one to three entries padded to four (a run's rest), and the entries left out
        /// keep what they held.
        #[test]
        fn four_lanes_are_the_general_path_to_the_bit(
            cases in prop::array::uniform4(case()),
            law in 0..TABLES_COUNT,
            dt in prop_oneof![Just(0.0), 1e-6..1e-4f64],
            step in 1e-6..1e-4f64,
            rest in 1..4usize,
        ) {
            let laws = &tables()[law];
            let mut spheres = TestSpheres::default();
            let (mut walls, mut wall_states, mut geometry) = (Vec::new(), Vec::new(), Vec::new());
            let mut start_spin = Vec::new();
            for (i, &(r, normal, depth, turn, v, end, (ma, mw), (spring, kt), spin, moves)) in
                cases.iter().enumerate()
            {
                if rolls(law) {
                    start_spin.push(spin);
                }
                let normal = normal.normalize();
                let foot = DVec3::new(0.01, -0.02, 0.03) * (i as f64 + 1.0);
                let x = foot + normal * (r * (1.0 - depth));
                let overlap = r * depth;
                geometry.push(ContactPoint {
                    normal,
                    point: x - normal * (r - 0.5 * overlap),
                    overlap,
                });
                // A triangle under the contact (what it is made of is all the law reads).
                let (u, w) = (normal.any_orthonormal_vector(), normal.cross(normal.any_orthonormal_vector()));
                let corners = vec![foot - u * 0.01 - w * 0.01, foot + u * 0.01, foot + w * 0.01];
                walls.push(MeshWall::new(corners, vec![[0, 1, 2]], mw).unwrap());
                wall_states.push(moves.map(states));
                spheres.push(r, x, turn, v, end, ma, spring, kt);
            }
            let TestSpheres { bodies, shapes, motion, start } = spheres;
            let inputs = LawInputs {
                scene: Scene {
                    bodies: &bodies,
                    shapes: &shapes,
                    planes: &[],
                    walls: &walls,
                    law: Default::default(),
                },
                wall_states: &wall_states,
                laws,
                motion: &motion,
                near_triangles: crate::step::detect::NearTriangles::none(),
                inverse_step: 1.0 / step,
            };
            let key: Vec<ContactKey> = (0..4)
                .map(|i| ContactKey { a: i, partner: Partner::Mesh(i), region: 0 })
                .collect();
            let kind = [PairKind::SphereOnMesh; 4];
            let ids = EntryIds { key: &key, kind: &kind };
            let run = |lanes: Lanes| {
                run_entries(&start, &start_spin, &geometry, true, |state| {
                    run_lanes!(lanes, &inputs, &ids, state, dt, touching_meshes_rest)
                })
            };
            prop_assert_eq!(run(Lanes::Four), run(Lanes::OneByOne(4)));
            prop_assert_eq!(run(Lanes::Rest(rest)), run(Lanes::OneByOne(rest)));
        }
    }
}
