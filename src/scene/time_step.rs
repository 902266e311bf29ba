//! Choosing a scene's time step: the stable estimate for the bodies placed at the start and those
//! its insertions will bring, checked against the step the user asked for. Done before the world
//! is built, so that the world starts with the step it runs with.

use super::format::TimeStep;
use super::{insert, KeyPath, Scene, SceneError, ScheduledInsertion};
use crate::body::BodyInit;
use crate::contact_law::NormalLaw;
use crate::material::Material;
use crate::math::DVec3;
use crate::shape::{Shape, Sphere};
use crate::timestep;
use crate::wall::{MeshWall, Plane};

/// What the time step depends on, built before the world.
pub(super) struct StepInputs<'a> {
    pub bodies: &'a [(BodyInit, KeyPath)],
    pub schedule: &'a [ScheduledInsertion],
    pub materials: &'a [Material],
    pub planes: &'a [Plane],
    pub mesh_walls: &'a [MeshWall],
    pub law: NormalLaw,
    pub gravity: DVec3,
}

/// More steps than any run can take: refused, as a sign of a scale error in the scene.
const MAX_STEPS: f64 = 1e11;

/// The deepest overlap an expected impact may bring, as a fraction of the body's radius.
pub const MAX_OVERLAP: f64 = 0.5;

impl Scene {
    /// The time step to run with, the stable estimate, and whether the step was chosen
    /// automatically; an error if there is nothing to simulate or the user's step is above the
    /// estimate (unless forced).
    pub(super) fn time_step(
        &self,
        inputs: StepInputs,
    ) -> Result<(f64, timestep::Estimate, bool), SceneError> {
        let spec = &self.spec;
        let time_key = KeyPath::table("simulation").key("time_step");
        // The step must also suit bodies that arrive later: each scheduled insertion's smallest.
        let candidate = |shape: &Shape, mass: f64, material: u32| timestep::Candidate {
            radius: shape.bounding_radius(),
            mass,
            material,
            polyhedron: shape
                .largest_face_area()
                .map(|area| (shape.equivalent_radius(), area)),
            vertex_springs: shape.largest_face_corners(),
        };
        // As `World::add_body` will weigh them.
        let mass = |shape: &Shape, material: u32| {
            inputs.materials[material as usize].density * shape.unit_mass_properties().volume
        };
        let present = inputs.bodies.iter().map(|(init, _)| {
            candidate(&init.shape, mass(&init.shape, init.material), init.material)
        });
        let arriving = inputs.schedule.iter().map(|s| {
            let shape = match &s.shape {
                Some(built) => built.shape.clone(),
                None => Shape::Sphere(Sphere::new(insert::smallest_radius(&s.spec, None))),
            };
            candidate(&shape, mass(&shape, s.material), s.material)
        });
        let wall_materials: Vec<u32> = inputs
            .planes
            .iter()
            .map(|p| p.material)
            .chain(inputs.mesh_walls.iter().map(|w| w.material))
            .collect();
        let conditions = timestep::Conditions {
            materials: inputs.materials,
            wall_materials: &wall_materials,
            law: inputs.law,
            impact_speed: self.impact_speed(inputs.gravity, inputs.bodies, inputs.mesh_walls),
        };
        let estimate =
            timestep::estimate(present.chain(arriving), &conditions).ok_or_else(|| {
                self.error(
                time_key.clone(),
                "the scene has no particles: nothing to simulate (add [[particle]] or [[insert]])",
            )
            })?;
        let (dt, automatic) = match spec.simulation.time_step {
            TimeStep::Auto => (estimate.seconds, true),
            TimeStep::Seconds(dt) => (dt, false),
        };
        self.check_step_count(dt, &estimate)?;
        self.check_overlaps(&estimate, inputs.materials)?;
        match spec.simulation.time_step {
            TimeStep::Auto => Ok((dt, estimate, automatic)),
            TimeStep::Seconds(dt) => {
                if dt > estimate.seconds && !spec.simulation.force_time_step {
                    return Err(self.error(
                        time_key,
                        format!(
                            "{dt:e} s is above the stable estimate {:.4e} s ({}); use a smaller \
                             step, time_step = \"auto\", or set force_time_step = true to run \
                             anyway",
                            estimate.seconds, estimate.reason
                        ),
                    ));
                }
                Ok((dt, estimate, false))
            }
        }
    }

    /// A step that is no step (zero, not finite: degenerate radii, densities or moduli make the
    /// estimate so), a duration shorter than half a step (nothing would be simulated, yet a whole
    /// step would run), or more steps than any run can take, are refused with the reason.
    fn check_step_count(&self, dt: f64, estimate: &timestep::Estimate) -> Result<(), SceneError> {
        let sim = KeyPath::table("simulation");
        if !(dt.is_finite() && dt > 0.0) {
            return Err(self.error(
                sim.key("time_step"),
                format!(
                    "the time step comes out as {dt:e} s ({}), which cannot be run: check the \
                     particles' sizes, densities and the materials' moduli for values out of any \
                     physical range",
                    estimate.reason
                ),
            ));
        }
        let duration = self.spec.simulation.duration;
        if duration < 0.5 * dt {
            return Err(self.error(
                sim.key("duration"),
                format!(
                    "{duration:e} s is shorter than half the time step ({dt:e} s): nothing would be \
                     simulated; give a duration of at least one step"
                ),
            ));
        }
        let steps = duration / dt;
        if steps > MAX_STEPS {
            return Err(self.error(
                sim.key("duration"),
                format!(
                    "{duration:e} s at a step of {dt:e} s is {steps:.3e} steps, more than the \
                     {MAX_STEPS:e} any run could take (a thousand hours even at 10⁸ steps an hour); \
                     shorten the duration or check the scene's scale"
                ),
            ));
        }
        Ok(())
    }

    /// Bodies so soft for their size and speed that an expected impact would overlap them by
    /// more than [`MAX_OVERLAP`] of their radius are refused: no contact law holds there, bodies
    /// pass through each other, and the energy ledger cannot close (issue #11, point 4).
    fn check_overlaps(
        &self,
        estimate: &timestep::Estimate,
        materials: &[Material],
    ) -> Result<(), SceneError> {
        let Some(deep) = &estimate.deepest else {
            return Ok(());
        };
        if deep.ratio <= MAX_OVERLAP {
            return Ok(());
        }
        let material = &materials[deep.material as usize];
        // The stiffness that brings the overlap down to a tenth of the radius.
        let target = 0.1;
        let (key, advice) = match deep.modulus_power {
            Some(power) => (
                KeyPath::entry("material", deep.material as usize).key("youngs_modulus"),
                format!(
                    "give '{}' a youngs_modulus of at least {:.1e} Pa (now {:.1e} Pa)",
                    material.name,
                    material.youngs_modulus * (deep.ratio / target).powf(power),
                    material.youngs_modulus
                ),
            ),
            None => (
                KeyPath::table("contact").key("stiffness"),
                format!(
                    "raise [contact] stiffness {:.0}-fold",
                    (deep.ratio / target).powi(2).ceil()
                ),
            ),
        };
        Err(self.error(
            key,
            format!(
                "too soft for these bodies at these speeds: {} would overlap by {:.0}% of the \
                 radius (a contact law holds for overlaps of a few percent; beyond about half the \
                 radius bodies pass through each other and the energy is no longer conserved). \
                 The speed is the fastest the scene can bring (initial and insertion speeds, a fall \
                 across its height, its walls' surfaces); {advice}, or lower the speeds",
                deep.what,
                100.0 * deep.ratio
            ),
        ))
    }

    /// The largest impact speed to expect: the fastest initial or insertion speed plus a free
    /// fall across the whole height of the scene (bodies and insertion regions, along gravity).
    pub(super) fn impact_speed(
        &self,
        gravity: DVec3,
        bodies: &[(BodyInit, KeyPath)],
        mesh_walls: &[MeshWall],
    ) -> f64 {
        let g = gravity.length();
        let down = if g > 0.0 { gravity / g } else { DVec3::ZERO };
        let mut speed: f64 = bodies
            .iter()
            .map(|(b, _)| b.velocity.length())
            .fold(0.0, f64::max);
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        for (b, _) in bodies {
            let (h, radius) = (b.position.dot(down), b.shape.bounding_radius());
            low = low.min(h - radius);
            high = high.max(h + radius);
        }
        for i in &self.spec.insertions {
            speed = speed.max(DVec3::from(i.initial_velocity()).length());
            let (lo, hi) = i.bounds();
            let (lo, hi) = (DVec3::from(lo), DVec3::from(hi));
            for corner in 0..8 {
                let pick = |bit: usize, a: f64, b: f64| if corner & bit == 0 { a } else { b };
                let p = DVec3::new(
                    pick(1, lo.x, hi.x),
                    pick(2, lo.y, hi.y),
                    pick(4, lo.z, hi.z),
                );
                low = low.min(p.dot(down));
                high = high.max(p.dot(down));
            }
        }
        // A floor: bodies fall onto it from wherever they are.
        if low <= high {
            for p in &self.spec.planes {
                let normal = DVec3::from(p.normal).normalize_or_zero();
                if normal.dot(down) < -0.5 {
                    high = high.max(DVec3::from(p.point).dot(down));
                }
            }
        }
        let height = if high > low { high - low } else { 0.0 };
        // A body met by a moving wall: the wall's fastest surface point on top.
        let wall_speed = mesh_walls
            .iter()
            .map(|w| w.motion.max_surface_speed(w.vertices()))
            .fold(0.0, f64::max);
        speed + (2.0 * g * height).sqrt() + wall_speed
    }
}
