//! What a contact's law gives each step, split by who reads it: the [`Load`] on the two bodies,
//! which the force sums read for every body and step, and the [`LawReport`] (normal force,
//! energies), which only the energy ledger and the outputs read. The sums then stream 72 bytes
//! per contact instead of the law's whole response and the contact point.

use crate::contact_law::Response;
use crate::math::DVec3;

/// The force and the moments a contact puts on its two bodies this step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
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
#[repr(C)]
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

// The layouts the four-wide sphere kernel writes (`Load::as_rows_mut`, `LawReport::as_array_mut`):
// nine and three `f64` in the order of the fields, no padding.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<Load>() == 72 && offset_of!(Load, torque_a) == 24);
    assert!(offset_of!(Load, torque_b) == 48);
    assert!(size_of::<LawReport>() == 24 && offset_of!(LawReport, elastic_energy) == 8);
    assert!(offset_of!(LawReport, dissipated) == 16);
};

impl Load {
    /// The load's nine numbers as rows of four, four and one: (force, torque_a.x),
    /// (torque_a.y, torque_a.z, torque_b.x, torque_b.y), torque_b.z.
    #[inline(always)]
    pub(crate) fn as_rows_mut(&mut self) -> (&mut [f64; 4], &mut [f64; 4], &mut f64) {
        let start = (self as *mut Load).cast::<f64>();
        // SAFETY: `Load` is `repr(C)`, nine `f64` with no padding (asserted above; glam's
        // `DVec3` is three `repr(C)` `f64`); the three parts do not overlap.
        unsafe {
            (
                &mut *start.cast::<[f64; 4]>(),
                &mut *start.add(4).cast::<[f64; 4]>(),
                &mut *start.add(8),
            )
        }
    }
}

impl LawReport {
    /// The report's three numbers in the order of the fields.
    #[inline(always)]
    pub(crate) fn as_array_mut(&mut self) -> &mut [f64; 3] {
        // SAFETY: `LawReport` is `repr(C)`, three `f64` with no padding (asserted above).
        unsafe { &mut *(self as *mut LawReport).cast::<[f64; 3]>() }
    }
}
