//! Helpers shared by the integration tests.

use polydem::math::DVec3;
use polydem::rng::SplitMix64;
use polydem::shape::Shape;
use polydem::World;

/// Kicks every body to a random velocity of `speed` (range, m/s) in a random direction and a
/// random spin of up to `spin` rad/s about a random axis.
pub fn kick(w: &mut World, rng: &mut SplitMix64, speed: (f64, f64), spin: f64) {
    for i in 0..w.bodies.len() {
        let direction = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
        w.bodies.velocity[i] = direction * rng.uniform(speed.0, speed.1);
        let omega = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize()
            * rng.uniform(0.0, spin);
        // L = R I Rᵀ ω (principal moments in the body frame).
        let q = w.bodies.orientation[i];
        w.bodies.angular_momentum[i] = q * (w.bodies.inertia[i] * (q.inverse() * omega));
        w.bodies.angular_velocity[i] = omega;
    }
}

/// How far the farthest vertex of any polyhedron pokes out of the box [0, size]³; panics,
/// naming the body and `what`, if a body's centre has left it.
pub fn deepest_outside_box(w: &World, size: f64, what: &str) -> f64 {
    let mut deepest = 0.0f64;
    for i in 0..w.bodies.len() {
        let x = w.bodies.position[i];
        assert!(
            x.cmpgt(DVec3::ZERO).all() && x.cmplt(DVec3::splat(size)).all(),
            "{what}: body {i} left the box: {x:?}"
        );
        let vertices = match &w.shapes[w.bodies.shape[i] as usize] {
            Shape::Convex(p) => p.vertices(),
            Shape::NonConvex(p) => p.vertices(),
            Shape::Sphere(_) => &[],
        };
        for &v in vertices {
            let y = x + w.bodies.orientation[i] * v;
            let out = (-y.min_element()).max((y - DVec3::splat(size)).max_element());
            deepest = deepest.max(out);
        }
    }
    deepest
}
