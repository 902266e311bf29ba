//! What the contact loops read of a body, packed once per step.

use super::{last_level_cache, rotation};
use crate::body::Bodies;
use crate::math::{DQuat, DVec3};
use rayon::prelude::*;

/// A body's position and motion in two cache lines: one random access per body and contact
/// instead of one per quantity. Position and radius come first, in the first line: the test of
/// whether two spheres touch, made for every candidate pair at every step, reads only that line.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub struct BodyMotion {
    pub position: DVec3,
    /// Bounding radius (a sphere's radius).
    pub radius: f64,
    /// Velocity and angular velocity over the step just taken (half-step values).
    pub velocity: DVec3,
    pub angular_velocity: DVec3,
    /// The same predicted at the end of the step.
    pub velocity_end: DVec3,
    pub angular_velocity_end: DVec3,
}

// The layout `BodyMotion::as_rows` reads: sixteen `f64` in the order of the fields, no padding.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<BodyMotion>() == 128 && size_of::<DVec3>() == 24);
    assert!(offset_of!(BodyMotion, position) == 0 && offset_of!(BodyMotion, radius) == 24);
    assert!(offset_of!(BodyMotion, velocity) == 32);
    assert!(offset_of!(BodyMotion, angular_velocity) == 56);
    assert!(offset_of!(BodyMotion, velocity_end) == 80);
    assert!(offset_of!(BodyMotion, angular_velocity_end) == 104);
};

impl BodyMotion {
    /// The sixteen numbers in memory order (position, radius, velocity, angular velocity, the
    /// same two at the end of the step) as four rows of four: what the four-wide sphere kernel
    /// loads whole and transposes into lanes (`step::sphere_lanes`).
    #[inline(always)]
    pub fn as_rows(&self) -> &[[f64; 4]; 4] {
        // SAFETY: `BodyMotion` is `repr(C)`, sixteen `f64` with no padding (asserted above; glam's
        // `DVec3` is three `repr(C)` `f64`), and `[[f64; 4]; 4]` has its size and a weaker
        // alignment.
        unsafe { &*(self as *const BodyMotion).cast::<[[f64; 4]; 4]>() }
    }

    /// The motion of a body at `position` with half-step velocities `velocity` and
    /// `angular_velocity`, and those at the end of the step predicted from the last forces, which
    /// the closing half kick will add again to first order: v_{n+1} ≈ v_{n+½} + (F_n/m + g) h and
    /// L_{n+1} ≈ L_{n+½} + τ_n h. `rotation` is (orientation, angular momentum, inverse inertia),
    /// `load` (acceleration F/m + g, torque τ).
    #[inline]
    pub fn predict(
        position: DVec3,
        velocity: DVec3,
        angular_velocity: DVec3,
        rotation: (DQuat, DVec3, DVec3),
        load: (DVec3, DVec3),
        h: f64,
        radius: f64,
    ) -> Self {
        let (q, l, inv_i) = rotation;
        let (acceleration, torque) = load;
        BodyMotion {
            position,
            velocity,
            angular_velocity,
            velocity_end: velocity + acceleration * h,
            angular_velocity_end: rotation::angular_velocity(q, l + torque * h, inv_i),
            radius,
        }
    }
}

/// Writes `m` to `dst`; with `stream`, by streaming stores, which write whole cache lines to
/// memory without first reading them in (the caller must end its pass with [`end_streaming`]).
///
/// Why: the opening kick and drift write every body's packed motion, two cache lines a body, at
/// every step. In a large world the lines have left the cache since the contact loops read them,
/// and a plain store first reads each line back from memory to write over it: on the 65,000-
/// sphere bed these reads were the pass's hottest instructions (the stores into the motion took
/// a fifth of its samples, `perf annotate`), and streaming stores cut the pass by a fifth. In a
/// world whose arrays stay in the cache between the two passes, a plain store finds its line
/// there, and a streaming one would send to memory what the contact loops read next: see
/// [`streams_motion`].
#[inline(always)]
pub(crate) fn write(dst: &mut BodyMotion, m: BodyMotion, stream: bool) {
    #[cfg(target_arch = "x86_64")]
    if stream {
        use std::arch::x86_64::{_mm_loadu_pd, _mm_stream_pd};
        let to = (dst as *mut BodyMotion).cast::<f64>();
        let from = m.as_rows().as_flattened();
        for k in (0..16).step_by(2) {
            // SAFETY: SSE2 is part of x86-64; `dst` is one `BodyMotion`, sixteen `f64` aligned to
            // 64 bytes (see the layout asserted above), so every pair of them is aligned to 16
            // and lies within it.
            unsafe { _mm_stream_pd(to.add(k), _mm_loadu_pd(from[k..].as_ptr())) };
        }
        return;
    }
    let _ = stream;
    *dst = m;
}

/// Ends a pass of [`write`]s: streaming stores are not ordered with the stores that follow them,
/// so the fence makes them visible before the pass hands its work on (to another thread, say).
#[inline]
pub(crate) fn end_streaming(stream: bool) {
    #[cfg(target_arch = "x86_64")]
    if stream {
        // SAFETY: SSE2 is part of x86-64.
        unsafe { std::arch::x86_64::_mm_sfence() };
    }
    let _ = stream;
}

/// Whether a world of `bodies` bodies writes its packed motion by streaming stores ([`write`]):
/// when its step's working set does not fit the last-level cache, so that the motion's lines have
/// left the cache by the time the kick-drift writes them. Measured on the spheres' benchmark (one
/// thread, steps 5,000–5,800; docs/benchmarks.md, "The packed motion written by streaming
/// stores"): with a 32 MB cache (that of one AMD EPYC chiplet), the opening pass a fifth shorter
/// at 65,000 and no gain at 10,000; with a 480 MB cache (an Intel Xeon), where the 65,000-sphere
/// bed's step stays in the cache, streaming stores made the whole step 3 % slower.
pub fn streams_motion(bodies: usize) -> bool {
    last_level_cache::outgrown_by(bodies)
}

/// Packs every body's motion as it is, for an evaluation outside the step (the first one, or
/// after bodies were added or removed): the end velocities are the current ones.
pub fn pack(b: &Bodies, motion: &mut Vec<BodyMotion>) {
    crate::tight::resize_tight(motion, b.len(), BodyMotion::default());
    motion
        .par_iter_mut()
        .enumerate()
        .with_min_len(1024)
        .for_each(|(i, m)| {
            *m = BodyMotion {
                position: b.position[i],
                velocity: b.velocity[i],
                angular_velocity: b.angular_velocity[i],
                velocity_end: b.velocity[i],
                angular_velocity_end: b.angular_velocity[i],
                radius: b.bounding_radius[i],
            };
        });
}
