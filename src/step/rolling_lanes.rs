//! Rolling resistance of four point contacts at once: `contact_law::rolling::rolling_torque` (the
//! elastic–plastic rolling spring of EPSD2, capped at μ_r R* F_n) in four lanes, for the
//! four-wide kernels of sphere pairs (`step::sphere_lanes`) and of spheres on planes
//! (`step::plane_lanes`).
//!
//! Without it, every sphere contact of a world with rolling friction took the scalar path, and
//! such a world ran at half the speed of the same world without (the 10,000-sphere bed: 3.6 M
//! against 7.5 M particle-steps/s, docs/benchmarks.md). Each lane is the scalar law's arithmetic,
//! operation for operation and in the same order, its branches lane selects; the kernels'
//! property tests hold the bits together.
//!
//! A contact is a point contact here, so the twisting and rocking torques of
//! `contact_law::evaluate` (area contacts only) are zero and leave the twisting spring as it is.

use super::sphere_lanes::{rotate_into_plane, PointContacts};
use crate::contact::EntryState;
use crate::wide::lanes::{F4, V3};

/// The rolling law's response in four lanes (`contact_law::rolling::RollingTorque`).
pub(super) struct Rolling {
    /// Torque on body `a`.
    pub torque: V3,
    pub elastic_energy: F4,
    pub dissipated: F4,
}

/// The rolling torque of the four touching `entries` (`rolling_friction` their laws' μ_r;
/// `stiffness` and `total` the normal law's k_n and force) over the step `dt`: reads their
/// rolling springs, writes them back advanced, and returns the torque on body `a` with the
/// spring's energy and what the step dissipated. Lanes whose law has no rolling friction keep
/// their spring and give nothing, as the scalar law returns early for them.
#[inline(always)]
pub(super) fn rolling_torque(
    state: &mut EntryState,
    entries: [usize; 4],
    rolling_friction: F4,
    c: &PointContacts,
    (stiffness, total): (F4, F4),
    dt: F4,
) -> Rolling {
    let (zero, half) = (F4::splat(0.0), F4::splat(0.5));
    // Every lane's spring is read before any is written: the four entries may repeat one.
    let [sx, sy, sz, old_stiffness] = F4::transpose([
        state.spin[entries[0]].rolling_row(),
        state.spin[entries[1]].rolling_row(),
        state.spin[entries[2]].rolling_row(),
        state.spin[entries[3]].rolling_row(),
    ]);
    let spring = V3 {
        x: sx,
        y: sy,
        z: sz,
    };
    let (n, r) = (c.normal, c.effective_radius);
    // k_r = 2.25 μ_r² R*² k_n (`powi(2)` is the one product μ_r μ_r).
    let kr = F4::splat(2.25) * (rolling_friction * rolling_friction) * r * r * stiffness;
    let omega = c.relative_angular - n.scale(n.dot(c.relative_angular));
    let old = rotate_into_plane(spring, n);
    let old_energy = F4::select(
        old_stiffness.gt(zero),
        half * old.length_squared() / old_stiffness,
        zero,
    );
    let trial = old - omega.scale(kr).scale(dt);
    let limit = rolling_friction * r * total;
    let magnitude = trial.length_squared().sqrt();
    let torque = V3::select(magnitude.gt(limit), trial.scale(limit / magnitude), trial);
    let elastic_energy = half * torque.length_squared() / kr;
    let work_on_bodies = half * (old + torque).dot(omega) * dt;
    let dissipated = -work_on_bodies - (elastic_energy - old_energy);

    // No rolling friction: nothing, the spring kept. No stiffness: nothing, the spring let go.
    let off = rolling_friction.le(zero);
    let slack = kr.le(zero);
    let quiet = off | slack;
    let kept = V3::select(off, spring, V3::select(slack, V3::zero(), torque));
    let rows = F4::rows([kept.x, kept.y, kept.z, F4::select(quiet, old_stiffness, kr)]);
    for (i, &k) in entries.iter().enumerate() {
        rows[i].store(state.spin[k].rolling_row_mut());
    }
    Rolling {
        torque: V3::select(quiet, V3::zero(), torque),
        elastic_energy: F4::select(quiet, zero, elastic_energy),
        dissipated: F4::select(quiet, zero, dissipated),
    }
}
