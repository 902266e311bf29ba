//! The energy ledger's view of a world: what it holds now, and what a half kick with the
//! forces found between steps gives beyond the work the ledger books for it.

use super::World;
use crate::energy::EnergyReport;
use crate::integrate;
use crate::math::DVec3;

impl World {
    /// What a half kick with the forces held now (less `less`, a force and a torque per body)
    /// gives the bodies' kinetic energy beyond the work of those forces against the velocity it
    /// starts from: Σ |F + m g|² (dt/2)²/2m and τ·I⁻¹τ (dt/2)²/2 over the bodies.
    pub(super) fn half_kick_excess(&self, less: Option<&[(DVec3, DVec3)]>) -> f64 {
        let b = &self.bodies;
        let h = 0.5 * self.time_step;
        (0..b.len())
            .filter(|&i| b.counts(i))
            .map(|i| {
                let (force, torque) = less.map_or((DVec3::ZERO, DVec3::ZERO), |l| l[i]);
                let push = b.force[i] - force + b.mass[i] * self.gravity;
                let turn = b.orientation[i].inverse() * (b.torque[i] - torque);
                let translation = push.length_squared() * b.inv_mass[i];
                0.5 * h * h * (translation + (turn * turn).dot(b.inv_inertia[i]))
            })
            .sum()
    }

    /// The force and torque the contacts' normal and tangential dashpots put on each body, found
    /// before the first step: the contacts keep half of it for the next step to book (the force
    /// of a single half kick, `contact_law::History::damper_force`).
    pub(super) fn dashpot_loads(&self) -> Vec<(DVec3, DVec3)> {
        let b = &self.bodies;
        let mut loads = vec![(DVec3::ZERO, DVec3::ZERO); b.len()];
        for c in self.contacts().iter() {
            let force = 2.0 * c.history.damper_force.as_dvec3();
            let a = c.key.a as usize;
            loads[a].0 += force;
            loads[a].1 += (c.geometry.point - b.position[a]).cross(force);
            if let Some(j) = c.key.partner.body() {
                let j = j as usize;
                loads[j].0 -= force;
                loads[j].1 -= (c.geometry.point - b.position[j]).cross(force);
            }
        }
        loads
    }

    /// The energy ledger at the current state.
    pub fn energy(&self) -> EnergyReport {
        let world = self;
        let b = &world.bodies;
        let mut report = EnergyReport {
            dissipated: world.dissipated,
            removed: world.energy_removed,
            inserted: world.energy_inserted,
            wall_work: world.wall_loads().work,
            gravity_work: world.gravity_work,
            contacts: world
                .contacts()
                .iter()
                .filter(|c| b.counts(c.key.a as usize))
                .count(),
            ..EnergyReport::default()
        };
        for i in (0..b.len()).filter(|&i| b.counts(i)) {
            report.kinetic_translational += 0.5 * b.mass[i] * b.velocity[i].length_squared();
            report.kinetic_rotational += integrate::rotation::rotational_energy(
                b.orientation[i],
                b.angular_momentum[i],
                b.inv_inertia[i],
            );
            report.potential -= b.mass[i] * world.gravity.dot(b.position[i]);
        }
        for c in world.contacts().iter() {
            if !b.counts(c.key.a as usize) {
                continue;
            }
            report.elastic += c.report.elastic_energy;
            // The last step's dashpot work, which the next step books exactly; estimated here.
            report.dissipated += c.history.damper_work_estimate as f64;
        }
        report
    }
}
