//! What a contact's law gives each step, split by who reads it: the [`Load`] on the two bodies,
//! and the [`LawReport`] (normal force, energies), which only the energy ledger and the outputs
//! read. Of the load, the store keeps only the partner's side ([`PartnerLoad`], 48 bytes): body
//! `a`'s side is added to `a`'s sum by the contact loop itself, while the chunk's loads are still
//! in the cache (`step::forces::evaluate`), so the force sums read 48 bytes per contact, and
//! only for the partner.

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

    /// What the partner takes: the opposite force, and its moment (for a wall, the couple).
    #[inline(always)]
    pub fn partner_side(&self) -> PartnerLoad {
        PartnerLoad {
            force: self.force,
            torque_b: self.torque_b,
        }
    }
}

/// What the store keeps of a contact's [`Load`] between the contact loop and the force sums: the
/// partner's side. (Body `a`'s moment is added to `a`'s sum in the contact loop.)
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct PartnerLoad {
    /// Force on body `a` [N]; the partner takes the opposite.
    pub force: DVec3,
    /// Moment on the partner body about its centre [N m]; for a wall partner, the law's couple
    /// on `a`.
    pub torque_b: DVec3,
}

impl PartnerLoad {
    /// The load of a body pair with the two bodies' roles exchanged, `centres` those of `a` and
    /// of the partner: the new partner's moment is `a`'s, which the moments' balance gives,
    /// τ_a + τ_b = (c_b − c_a) × F.
    pub fn seen_from_partner(self, centres: (DVec3, DVec3)) -> Self {
        let torque_a = (centres.1 - centres.0).cross(self.force) - self.torque_b;
        PartnerLoad {
            force: -self.force,
            torque_b: torque_a,
        }
    }
}

/// What else the law reports of a contact this step, kept by the store for the outputs and the
/// energy ledger. The energy a contact dissipated over the step is not kept: the contact loop
/// adds it up from its scratch while the run is in the cache (`step::forces::evaluate`), so that
/// no pass reads 8 bytes of every entry to book it.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct LawReport {
    /// Normal force magnitude [N].
    pub normal_force: f64,
    /// Elastic energy the contact holds [J].
    pub elastic_energy: f64,
}

impl LawReport {
    #[inline(always)]
    pub fn of(r: &Response) -> Self {
        LawReport {
            normal_force: r.normal_force,
            elastic_energy: r.elastic_energy,
        }
    }
}

/// Body `a`'s side of a contact's [`Load`], which the contact loop adds to `a`'s sums in the
/// cache (see `step::forces::evaluate`) and the store does not keep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct OwnLoad {
    /// Force on body `a` [N].
    pub force: DVec3,
    /// Moment on `a` about its centre [N m].
    pub torque_a: DVec3,
}

impl Load {
    /// What body `a` takes.
    #[inline(always)]
    pub fn own_side(&self) -> OwnLoad {
        OwnLoad {
            force: self.force,
            torque_a: self.torque_a,
        }
    }
}

// The layouts the four-wide kernels write (`as_rows_mut`, `LawReport::as_array_mut`): six and
// two `f64` in the order of the fields, no padding.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<PartnerLoad>() == 48 && offset_of!(PartnerLoad, torque_b) == 24);
    assert!(size_of::<OwnLoad>() == 48 && offset_of!(OwnLoad, torque_a) == 24);
    assert!(size_of::<LawReport>() == 16 && offset_of!(LawReport, elastic_energy) == 8);
};

/// The six numbers of a force and a moment, `repr(C)` with no padding (asserted above), as rows
/// of four and two: (force, moment.x), (moment.y, moment.z).
///
/// # Safety
/// `T` must be six `f64` in a row.
#[inline(always)]
unsafe fn six_as_rows<T>(value: &mut T) -> (&mut [f64; 4], &mut [f64; 2]) {
    let start = (value as *mut T).cast::<f64>();
    // SAFETY: the caller's promise; the two parts do not overlap.
    unsafe {
        (
            &mut *start.cast::<[f64; 4]>(),
            &mut *start.add(4).cast::<[f64; 2]>(),
        )
    }
}

impl PartnerLoad {
    /// The six numbers as rows: (force, torque_b.x), (torque_b.y, torque_b.z).
    #[inline(always)]
    pub(crate) fn as_rows_mut(&mut self) -> (&mut [f64; 4], &mut [f64; 2]) {
        // SAFETY: `PartnerLoad` is `repr(C)`, two `DVec3` (three `repr(C)` `f64` each).
        unsafe { six_as_rows(self) }
    }
}

impl OwnLoad {
    /// The six numbers as rows: (force, torque_a.x), (torque_a.y, torque_a.z).
    #[inline(always)]
    pub(crate) fn as_rows_mut(&mut self) -> (&mut [f64; 4], &mut [f64; 2]) {
        // SAFETY: `OwnLoad` is `repr(C)`, two `DVec3` (three `repr(C)` `f64` each).
        unsafe { six_as_rows(self) }
    }
}

impl LawReport {
    /// The report's two numbers in the order of the fields.
    #[inline(always)]
    pub(crate) fn as_array_mut(&mut self) -> &mut [f64; 2] {
        // SAFETY: `LawReport` is `repr(C)`, two `f64` with no padding (asserted above).
        unsafe { &mut *(self as *mut LawReport).cast::<[f64; 2]>() }
    }
}
