//! What a contact's law gives each step, split by who reads it: the [`Load`] on the two bodies,
//! which the force sums read for every body and step, and the [`LawReport`] (normal force,
//! energies), which only the energy ledger and the outputs read. The sums then stream 72 bytes
//! per contact instead of the law's whole response and the contact point.

use crate::contact_law::Response;
use crate::math::DVec3;

/// The force and the moments a contact puts on its two bodies this step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Load {
    /// Force on body `a` [N]; the partner takes the opposite.
    pub force: DVec3,
    /// Moment on `a` about its centre [N m].
    pub torque_a: DVec3,
    /// Moment on the partner body about its centre [N m]; for a wall partner, the law's couple on
    /// `a` (the wall's moment follows from it, the force and the contact point).
    pub torque_b: DVec3,
}

impl Load {
    /// The load of the response `r` at the contact point `point`, between body `a` centred at
    /// `centre_a` and a partner body centred at `centre_b` (`None`: a wall).
    #[inline(always)]
    pub fn new(r: &Response, point: DVec3, centre_a: DVec3, centre_b: Option<DVec3>) -> Self {
        Load {
            force: r.force,
            torque_a: (point - centre_a).cross(r.force) + r.torque,
            torque_b: match centre_b {
                Some(centre) => -((point - centre).cross(r.force) + r.torque),
                None => r.torque,
            },
        }
    }

    /// The same load with the two bodies' roles exchanged.
    pub fn seen_from_partner(self) -> Self {
        Load {
            force: -self.force,
            torque_a: self.torque_b,
            torque_b: self.torque_a,
        }
    }
}

/// What else the law reports of a contact this step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LawReport {
    /// Normal force magnitude [N].
    pub normal_force: f64,
    /// Elastic energy the contact holds [J].
    pub elastic_energy: f64,
    /// Energy dissipated over the step [J].
    pub dissipated: f64,
}

impl LawReport {
    #[inline(always)]
    pub fn of(r: &Response) -> Self {
        LawReport {
            normal_force: r.normal_force,
            elastic_energy: r.elastic_energy,
            dissipated: r.dissipated,
        }
    }
}
