//! Whether the CPU has AVX-512VL, for which the four-wide sphere kernel has a second copy
//! (`step::sphere_lanes`).
//!
//! AVX-512VL gives the compiler 32 vector registers instead of 16; the kernel keeps many values
//! live and spills them to the stack with 16. Only the registers and the instructions' encoding
//! change: every operation is the same IEEE one (Rust never contracts a multiply and an add,
//! whatever the CPU has), so both copies give the same bits, on any machine (a test below holds a
//! world's steps to it).
//!
//! Only a function marked `#[target_feature]` and what is inlined into it by `#[inline(always)]`
//! get the wider registers: a closure called from such a function stays a function of its own,
//! compiled for the baseline (tried for the per-body loops, it changed nothing).
//!
//! [`lanes`] has the four-wide value types those paths compute with.

pub mod lanes;

/// Whether the CPU has AVX-512VL (and the kernel's wide copy is used).
#[inline(always)]
pub(crate) fn available() -> bool {
    #[cfg(test)]
    if tests::BASELINE.load(std::sync::atomic::Ordering::Relaxed) {
        return false;
    }
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx512vl");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

#[cfg(test)]
mod tests {
    use crate::body::BodyInit;
    use crate::contact_law::NormalLaw;
    use crate::material::{Material, PairTable};
    use crate::math::{DQuat, DVec3};
    use crate::rng::SplitMix64;
    use crate::shape::{Shape, Sphere};
    use crate::wall::Plane;
    use crate::{World, WorldConfig};
    use std::sync::atomic::{AtomicBool, Ordering};

    /// Set while the test steps its baseline world: the kernel then takes its AVX copy.
    pub(super) static BASELINE: AtomicBool = AtomicBool::new(false);

    /// Spheres poured into a box of planes (sphere pairs through the four-wide kernel and the
    /// scalar path, plane contacts through the general one).
    fn pour() -> World {
        let material = Material {
            name: "grain".into(),
            density: 2500.0,
            youngs_modulus: 1e8,
            poisson_ratio: 0.25,
            restitution: 0.5,
            friction: 0.5,
            rolling_friction: 0.0,
        };
        let laws = PairTable::new(
            std::slice::from_ref(&material),
            NormalLaw::Hertz,
            2.0 / 7.0,
            &[],
        );
        let (spacing, n) = (0.011, 6);
        let width = spacing * n as f64;
        let wall = |point: DVec3, normal: DVec3| Plane {
            point,
            normal,
            material: 0,
        };
        let mut world = World::new(WorldConfig {
            time_step: 2e-5,
            gravity: DVec3::new(0.0, 0.0, -9.81),
            materials: vec![material],
            pair_laws: laws,
            planes: vec![
                wall(DVec3::ZERO, DVec3::Z),
                wall(DVec3::ZERO, DVec3::X),
                wall(DVec3::new(width, 0.0, 0.0), -DVec3::X),
                wall(DVec3::ZERO, DVec3::Y),
                wall(DVec3::new(0.0, width, 0.0), -DVec3::Y),
            ],
            broad_phase: Default::default(),
            skin: None,
            threads: 1,
        })
        .unwrap();
        let mut rng = SplitMix64::new(7);
        let mut random = || {
            DVec3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            )
        };
        for k in 0..n * n * n {
            let cell = DVec3::new((k % n) as f64, ((k / n) % n) as f64, (k / (n * n)) as f64);
            world.add_body(BodyInit {
                shape: Shape::Sphere(Sphere::new(0.0055 + 0.0005 * random().x)),
                material: 0,
                position: (cell + 0.5) * spacing + random() * 0.0003,
                orientation: DQuat::IDENTITY,
                velocity: random() * 0.5 - DVec3::Z,
                angular_velocity: random() * 50.0,
            });
        }
        world
    }

    fn state(world: &World) -> String {
        let b = world.bodies();
        format!(
            "{:?}",
            (
                &b.position,
                &b.velocity,
                &b.angular_velocity,
                &b.orientation
            )
        )
    }

    #[test]
    fn the_wide_copy_of_the_kernel_gives_the_baseline_bits() {
        if !super::available() {
            eprintln!("this CPU has no AVX-512VL: only the AVX copy runs here");
        }
        let (mut baseline, mut wide) = (pour(), pour());
        BASELINE.store(true, Ordering::Relaxed);
        for _ in 0..400 {
            baseline.step();
        }
        BASELINE.store(false, Ordering::Relaxed);
        for _ in 0..400 {
            wide.step();
        }
        assert!(
            wide.contacts()
                .iter()
                .filter(|c| c.report.normal_force > 0.0)
                .count()
                > 100
        );
        assert_eq!(state(&baseline), state(&wide));
    }
}
