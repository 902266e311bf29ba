//! The opening half kick and drift of isotropic bodies (spheres, cubes, regular polyhedra), four
//! at a time.
//!
//! For an isotropic body ω = L/I needs no change of frame, and the drift is one exact rotation
//! (`rotation::drift_isotropic`): a short chain of arithmetic per body, which one body at a time
//! leaves the floating-point units waiting on. Four bodies side by side in [`F4`] lanes fill
//! them. Each lane is the scalar path's arithmetic, operation for operation and in the same order
//! (`integrate::kick_drift`'s isotropic branch, `rotation::drift_isotropic`,
//! `rotation::rotation_by`, glam's quaternion product and `rotation::renormalize`), so the results
//! are the same bits whichever bodies share a group, on any machine (a test below holds it).

use super::rotation::SERIES_LIMIT;
use super::{motion, BodyMotion, Kick};
use crate::math::{DQuat, DVec3};
use crate::wide::lanes::{each, F4, V3};

/// One task's bodies, as slices of the bodies' arrays: what the pass reads and writes of them.
pub(super) struct Arrays<'a> {
    pub position: &'a mut [DVec3],
    pub velocity: &'a mut [DVec3],
    pub orientation: &'a mut [DQuat],
    pub angular_momentum: &'a mut [DVec3],
    pub angular_velocity: &'a mut [DVec3],
    pub motion: &'a mut [BodyMotion],
    pub inv_mass: &'a [f64],
    pub inv_inertia: &'a [DVec3],
    pub force: &'a [DVec3],
    pub torque: &'a [DVec3],
    pub bounding_radius: &'a [f64],
    /// Whether the packed motion is written by streaming stores ([`motion::write`]).
    pub stream_motion: bool,
}

/// The closing half kick left to this pass (if any; see `integrate::kick_drift`), the opening
/// half kick and the drift of the four isotropic bodies `k..k + 4` of `arrays`. Returns
/// false, with nothing written, if one of them turns too far in the step for the series of
/// `rotation::rotation_by` (the caller then takes them one by one).
///
/// # Safety
/// Only on a CPU with AVX (see [`F4`]), from code compiled for it.
#[inline(always)]
pub(super) unsafe fn four(
    arrays: &mut Arrays,
    k: usize,
    closing: Option<Kick>,
    kick: Kick,
    dt: f64,
) -> bool {
    let inv_inertia = vectors(k, arrays.inv_inertia);
    let (h, dt) = (F4::splat(kick.h), F4::splat(dt));
    let (force, torque) = (vectors(k, arrays.force), vectors(k, arrays.torque));
    let inv_mass = lane(k, arrays.inv_mass);
    let (mut velocity, mut angular_momentum) = (
        vectors(k, arrays.velocity),
        vectors(k, arrays.angular_momentum),
    );
    if let Some(closing) = closing {
        // Kick::apply, as `step::accumulate` would have given it (ω follows from L below).
        let closing_h = F4::splat(closing.h);
        let acceleration = force.scale(inv_mass) + V3::splat(closing.gravity);
        velocity = velocity + acceleration.scale(closing_h);
        angular_momentum = angular_momentum + torque.scale(closing_h);
    }
    let acceleration = force.scale(inv_mass) + V3::splat(kick.gravity);
    let velocity = velocity + acceleration.scale(h);
    let angular_momentum = angular_momentum + torque.scale(h);
    let position = vectors(k, arrays.position) + velocity.scale(dt);
    // rotation::drift_isotropic: the mean of the three (equal) inverse moments.
    let inv_i = (inv_inertia.x + inv_inertia.y + inv_inertia.z) / F4::splat(3.0);
    let turn = angular_momentum.scale(inv_i * dt);
    // rotation::rotation_by, the series branch.
    let t2 = turn.length_squared();
    if F4::splat(SERIES_LIMIT).le(t2).any() {
        return false;
    }
    let sin_half_over_angle =
        c(0.5) - t2 * (c(1.0 / 48.0) - t2 * (c(1.0 / 3840.0) - t2 * c(1.0 / 645_120.0)));
    let cos_half = c(1.0) - t2 * (c(1.0 / 8.0) - t2 * (c(1.0 / 384.0) - t2 * c(1.0 / 46_080.0)));
    let axis = turn.scale(sin_half_over_angle);
    let (x0, y0, z0, w0) = (axis.x, axis.y, axis.z, cos_half);
    let q: [DQuat; 4] = each(|j| arrays.orientation[k + j]);
    let x1 = F4::new(q.map(|q| q.x));
    let y1 = F4::new(q.map(|q| q.y));
    let z1 = F4::new(q.map(|q| q.z));
    let w1 = F4::new(q.map(|q| q.w));
    // glam's DQuat::mul_quat, term for term.
    let x = w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1;
    let y = w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1;
    let z = w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1;
    let w = w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1;
    // rotation::renormalize.
    let scale = c(1.5) - c(0.5) * (x * x + y * y + z * z + w * w);
    let (x, y, z, w) = (
        (x * scale).to_array(),
        (y * scale).to_array(),
        (z * scale).to_array(),
        (w * scale).to_array(),
    );
    let inv_i_x = inv_inertia.x;
    let angular_velocity = angular_momentum.scale(inv_i_x);
    let velocity_end = velocity + acceleration.scale(h);
    let angular_velocity_end = (angular_momentum + torque.scale(h)).scale(inv_i_x);
    let (position, velocity) = (position.lanes(), velocity.lanes());
    let (angular_momentum, angular_velocity) = (angular_momentum.lanes(), angular_velocity.lanes());
    let (velocity_end, angular_velocity_end) = (velocity_end.lanes(), angular_velocity_end.lanes());
    for j in 0..4 {
        let i = k + j;
        arrays.position[i] = position[j];
        arrays.velocity[i] = velocity[j];
        arrays.angular_momentum[i] = angular_momentum[j];
        arrays.angular_velocity[i] = angular_velocity[j];
        arrays.orientation[i] = DQuat::from_xyzw(x[j], y[j], z[j], w[j]);
        let m = BodyMotion {
            position: position[j],
            velocity: velocity[j],
            angular_velocity: angular_velocity[j],
            velocity_end: velocity_end[j],
            angular_velocity_end: angular_velocity_end[j],
            radius: arrays.bounding_radius[i],
        };
        motion::write(&mut arrays.motion[i], m, arrays.stream_motion);
    }
    true
}

// Helpers of `four` that compute with `F4` are functions, not closures: a closure would be
// compiled apart from the `#[target_feature]` code that inlines `four` (see `wide`), and its AVX
// operations would become calls. Closures that only load numbers (`each`, `map`) are harmless.

/// Lanes `k..k + 4` of `values`.
#[inline(always)]
fn lane(k: usize, values: &[f64]) -> F4 {
    F4::new([values[k], values[k + 1], values[k + 2], values[k + 3]])
}

/// Vectors `k..k + 4` of `values`, one per lane.
#[inline(always)]
fn vectors(k: usize, values: &[DVec3]) -> V3 {
    V3::gather(|j| values[k + j])
}

/// `v` in every lane.
#[inline(always)]
fn c(v: f64) -> F4 {
    F4::splat(v)
}

#[cfg(test)]
mod tests {
    use super::super::{kick_drift_bodies, Kick};
    use super::*;
    use crate::rng::SplitMix64;
    use proptest::prelude::*;

    /// The bodies' arrays, owned.
    #[derive(Clone, Debug, PartialEq)]
    struct Owned {
        position: Vec<DVec3>,
        velocity: Vec<DVec3>,
        orientation: Vec<DQuat>,
        angular_momentum: Vec<DVec3>,
        angular_velocity: Vec<DVec3>,
        motion: Vec<[f64; 16]>,
        inv_mass: Vec<f64>,
        inv_inertia: Vec<DVec3>,
        force: Vec<DVec3>,
        torque: Vec<DVec3>,
        bounding_radius: Vec<f64>,
    }

    /// `count` bodies of 1 mm or so, moving and turning as in a DEM run; `spin` scales their
    /// angular momentum (large enough, some turn beyond the series in a step). Every fifth is
    /// not isotropic.
    fn bodies(seed: u64, count: usize, spin: f64) -> Owned {
        let mut rng = SplitMix64::new(seed);
        let mut vector = |scale: f64| DVec3::new(rng.normal(), rng.normal(), rng.normal()) * scale;
        let position = (0..count).map(|_| vector(1e-2)).collect();
        let velocity = (0..count).map(|_| vector(1.0)).collect();
        let angular_momentum = (0..count).map(|_| vector(1e-9 * spin)).collect();
        let force = (0..count).map(|_| vector(1e-4)).collect();
        let torque = (0..count).map(|_| vector(1e-7)).collect();
        let orientation = (0..count)
            .map(|_| {
                let axis = vector(1.0);
                DQuat::from_scaled_axis(axis).normalize()
            })
            .collect();
        let inv_inertia = (0..count)
            .map(|i| {
                let m = 1e11 * (1.0 + (i % 3) as f64);
                if i % 5 == 4 {
                    DVec3::new(m, 1.3 * m, 0.7 * m)
                } else {
                    DVec3::splat(m)
                }
            })
            .collect();
        Owned {
            position,
            velocity,
            orientation,
            angular_momentum,
            angular_velocity: vec![DVec3::ZERO; count],
            motion: vec![[0.0; 16]; count],
            inv_mass: (0..count).map(|i| 1e5 * (1.0 + i as f64)).collect(),
            inv_inertia,
            force,
            torque,
            bounding_radius: (0..count).map(|i| 1e-3 * (1.0 + i as f64)).collect(),
        }
    }

    /// The pass over `owned`, four-wide or one by one, the motion written by streaming stores
    /// or plain ones; with a closing half kick of the last step left to it if `closing`.
    fn run(owned: &Owned, by_fours: bool, stream_motion: bool, closing: bool) -> Owned {
        let mut out = owned.clone();
        let mut motion = vec![BodyMotion::default(); out.position.len()];
        let mut arrays = Arrays {
            position: &mut out.position,
            velocity: &mut out.velocity,
            orientation: &mut out.orientation,
            angular_momentum: &mut out.angular_momentum,
            angular_velocity: &mut out.angular_velocity,
            motion: &mut motion,
            inv_mass: &owned.inv_mass,
            inv_inertia: &owned.inv_inertia,
            force: &owned.force,
            torque: &owned.torque,
            bounding_radius: &owned.bounding_radius,
            stream_motion,
        };
        let kick = Kick {
            gravity: DVec3::new(0.3, 0.0, -9.81),
            h: 1e-5,
        };
        // The last step's gravity other than this one's (as under a gravity table).
        let closing = closing.then_some(Kick {
            gravity: DVec3::new(0.0, 0.2, -9.7),
            h: 1e-5,
        });
        // SAFETY: four-wide only on a CPU with AVX (on x86-64; elsewhere lanes are arrays).
        unsafe { kick_drift_bodies(&mut arrays, closing, kick, 2e-5, by_fours) };
        motion::end_streaming(stream_motion);
        out.motion = motion
            .iter()
            .map(|m| *m.as_rows().as_flattened().first_chunk().unwrap())
            .collect();
        out
    }

    fn bits(owned: &Owned) -> String {
        format!("{owned:?}")
    }

    fn has_avx() -> bool {
        #[cfg(target_arch = "x86_64")]
        return std::arch::is_x86_feature_detected!("avx");
        #[cfg(not(target_arch = "x86_64"))]
        return true;
    }

    proptest! {
        /// Four bodies at once give every body's new state and packed motion to the bit of one
        /// at a time, with bodies that are not isotropic and bodies that turn beyond the series
        /// among them, and a count that leaves a rest; and so do both with the motion written
        /// by streaming stores (as in large worlds); with or without the last step's closing
        /// half kick left to the pass.
        #[test]
        fn four_at_a_time_is_one_at_a_time(
            seed in any::<u64>(),
            count in 1usize..23,
            fast in any::<bool>(),
            closing in any::<bool>(),
        ) {
            prop_assume!(has_avx());
            let owned = bodies(seed, count, if fast { 20.0 } else { 1.0 });
            let one_by_one = bits(&run(&owned, false, false, closing));
            prop_assert_eq!(bits(&run(&owned, true, false, closing)), one_by_one.clone());
            prop_assert_eq!(bits(&run(&owned, true, true, closing)), one_by_one.clone());
            prop_assert_eq!(bits(&run(&owned, false, true, closing)), one_by_one);
        }
    }

    /// The test above does reach both sides of the series' limit.
    #[test]
    fn the_spins_drawn_reach_both_sides_of_the_series() {
        let turn = |spin: f64| {
            let b = bodies(1, 20, spin);
            let t2: Vec<f64> = (0..20)
                .map(|i| (b.angular_momentum[i] * (b.inv_inertia[i].x * 2e-5)).length_squared())
                .collect();
            (
                t2.iter().cloned().fold(0.0, f64::max),
                t2.iter().cloned().fold(f64::INFINITY, f64::min),
            )
        };
        assert!(turn(1.0).0 < SERIES_LIMIT);
        let (most, least) = turn(20.0);
        assert!(
            most > SERIES_LIMIT && least < SERIES_LIMIT,
            "{most} {least}"
        );
    }
}
