//! Contact laws: the force and moment of one contact from its kinematics and history.
//!
//! A law is composed of sub-laws, in the manner of LAMMPS' granular package (`granular_model.cpp`):
//! an elastic normal law ([`normal`]), normal damping set from the coefficient of restitution
//! ([`restitution`]), a tangential spring with Coulomb limit and history ([`tangential`]) and a
//! rolling-resistance spring with its own limit ([`rolling`]). Each sub-law is a pure function of an
//! explicit [`Kinematics`] value and the contact's [`History`]; the composition is in [`evaluate`].

pub mod normal;
pub mod restitution;
pub mod rocking;
pub mod rolling;
pub mod tangential;
pub mod twisting;

use crate::math::DVec3;
use glam::Vec3;

/// The largest a dashpot may be for the explicit step: γ dt / m* ≤ this. A dashpot γ on a mass m*
/// under this step (half kicks with the end-of-step velocity predicted from the last force) is
/// stable while γ dt/m* < 1; at ½ the velocity it damps falls by at least a third per step. A
/// restitution so small that its dashpot would be stronger (e ≲ 0.01 at the automatic step, and
/// e = 0) gets this one: the strongest the step can take, which is the perfectly plastic limit
/// the step can resolve (issue #11, point 3; `docs/physics.md`).
pub const DASHPOT_BOUND: f64 = 0.5;

/// The share of m* that resists a tangential impulse at the contact point of two solid spheres
/// (1/m_t = 1/m* + R²/I: 2/7): the tangential dashpot's bound is taken on this mass.
pub const TANGENTIAL_MASS_SHARE: f64 = 2.0 / 7.0;

/// Elastic law of the normal force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NormalLaw {
    /// Linear spring F = k δ, with `stiffness` k [N/m].
    Linear { stiffness: f64 },
    /// Hertz: F = 4/3 E* √R* δ^{3/2} (Hertz 1882; Johnson 1985, eq. 4.22). Tangential stiffness
    /// after Mindlin (1949): k_t = 8 G* √(R* δ).
    Hertz,
}

/// Contact parameters of one pair of materials, resolved before the run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairLaw {
    pub normal: NormalLaw,
    /// E* [Pa].
    pub effective_youngs_modulus: f64,
    /// G* [Pa].
    pub effective_shear_modulus: f64,
    pub restitution: f64,
    pub friction: f64,
    pub rolling_friction: f64,
    /// k_t / k_n for the linear law.
    pub tangential_stiffness_ratio: f64,
    /// Dimensionless damping coefficient c (F_d = c √(m* S_n) δ̇), chosen so that a binary
    /// collision rebounds with `restitution` exactly; see [`restitution`].
    pub damping: f64,
    /// The same for the volume law of polyhedra, which is linear in the depth of a flat contact.
    pub damping_volume: f64,
    /// √(k_t/S_n) of a point contact: √(4 G*/E*) under Hertz–Mindlin (k_t = 8 G* a over
    /// S_n = 2 E* a), √(tangential_stiffness_ratio) under the linear law. The tangential dashpot
    /// c √(m* k_t) is the normal one times this, with no square root per contact.
    pub tangential_damping_ratio: f64,
    /// The same under the volume law of polyhedra: √(tangential_stiffness_ratio).
    pub tangential_damping_ratio_volume: f64,
}

/// Relative motion of the two bodies at one contact, in the world frame.
#[derive(Clone, Copy, Debug)]
pub struct Kinematics {
    /// Unit normal pointing from body j towards body i (the direction of the force on i).
    pub normal: DVec3,
    /// Overlap δ > 0 [m].
    pub overlap: f64,
    /// dδ/dt [m/s], positive while the bodies approach, predicted at the end of the step: the
    /// damping force acts over the next half-kicks, so it must see the velocity of that moment,
    /// not the half-step velocity (which lags by dt/2 and would bias the dissipation to first
    /// order in dt).
    pub overlap_rate: f64,
    /// Tangential velocity of i relative to j at the contact point over the step just taken
    /// (half-step velocity) [m/s]: the tangential spring stretches by exactly this times dt.
    pub tangential_velocity: DVec3,
    /// The same, predicted at the end of the step, for tangential damping [m/s].
    pub tangential_velocity_end: DVec3,
    /// The relative velocity at the end of the previous step, 2 v_half − v_end (exact for the
    /// centres' velocities: the half kick that separates them is the same force both ways). The
    /// dashpots' work of the previous step is booked against it ([`History::damper_force`]).
    pub velocity_start: DVec3,
    /// ω_i − ω_j over the step just taken [rad/s].
    pub relative_angular_velocity: DVec3,
    /// R* = r_i r_j / (r_i + r_j) [m] (r_i for a sphere on a wall).
    pub effective_radius: f64,
    /// m* = m_i m_j / (m_i + m_j) [kg] (m_i for a body on a wall).
    pub effective_mass: f64,
    /// For contacts of polyhedra under the volume law: the overlap volume and contact area.
    pub overlap_volume: Option<OverlapVolume>,
    /// The strongest normal and tangential dashpots the step allows at this contact [N s/m]
    /// ([`DashpotLimit`]).
    pub dashpot_limit: DashpotLimit,
}

/// R* = r_a r_b/(r_a + r_b) and m* = m_a m_b/(m_a + m_b) of a sphere pair, with one division
/// for both (the divider is the contact loop's narrowest unit).
#[inline(always)]
pub fn effective_radius_and_mass(radius: (f64, f64), mass: (f64, f64)) -> (f64, f64) {
    let (radius_sum, mass_sum) = (radius.0 + radius.1, mass.0 + mass.1);
    let inverse = 1.0 / (radius_sum * mass_sum);
    (
        radius.0 * radius.1 * mass_sum * inverse,
        mass.0 * mass.1 * radius_sum * inverse,
    )
}

/// The strongest dashpots the explicit step allows at a contact, along the normal and (at most)
/// along the tangent [N s/m]: [`DASHPOT_BOUND`] m/Δt, with m the mass a push at the contact point
/// moves, 1/m = Σ 1/m_i + (r_i × d)·I_i⁻¹(r_i × d) over the bodies (r_i the arm, d the
/// direction): m* and 2/7 m* for two spheres; at a polyhedron's corner the body turns as well,
/// and m is smaller.
///
/// Δt is the world's time step, the interval over which the force will act, and not the
/// interval the contact's history advances by: when the forces are found again between two
/// steps (after bodies were added or removed, and before the first step) the histories advance
/// by nothing, but the force still acts over the next half kick. A limit taken on that zero
/// interval was infinite, and with restitution 0 (whose dashpot is the limit) the force too:
/// a pour with e = 0 blew up at its first insertion among touching bodies (issue #11).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DashpotLimit {
    pub normal: f64,
    pub tangential: f64,
}

impl DashpotLimit {
    /// At a contact where a push along the normal moves `normal_mass` and one along the worst
    /// tangent `tangential_mass`, under a step of 1/`inverse_step`.
    #[inline(always)]
    pub fn of_masses(normal_mass: f64, tangential_mass: f64, inverse_step: f64) -> Self {
        Self {
            normal: DASHPOT_BOUND * normal_mass * inverse_step,
            tangential: DASHPOT_BOUND * tangential_mass * inverse_step,
        }
    }

    /// Two solid spheres (or a sphere on a wall) of effective mass `m`: the normal push moves
    /// m, a tangential one m/(1 + m R²/I) = 2/7 m.
    #[inline(always)]
    pub fn of_spheres(m: f64, inverse_step: f64) -> Self {
        Self::of_masses(m, TANGENTIAL_MASS_SHARE * m, inverse_step)
    }
}

/// Which law polyhedral contacts use (scene: `[contact] polyhedra`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PolyhedralLaw {
    /// The elastic foundation over the overlap volume (`normal::volume_law`).
    #[default]
    Volume,
    /// The seed paper's law: a spring at every vertex inside the other body, along the normal
    /// of the face it penetrates (`normal::volume_law` with `points`).
    Vertex,
}

/// The overlap of two polyhedra (or a polyhedron and a wall).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OverlapVolume {
    /// The law this overlap is measured for.
    pub law: PolyhedralLaw,
    /// Vertex law: the number of penetrating points (each a spring).
    pub points: usize,
    /// V [m³].
    pub volume: f64,
    /// Area of the overlap's cross-section normal to the contact normal, |S| [m²].
    pub area: f64,
    /// |Resultant| of the elastic-foundation pressure per unit stiffness [m³] (V for a face
    /// contact), its moment about the contact point on body i [m⁴] and its potential [m⁴]
    /// (see `narrow_phase::clip::Winkler`).
    pub load: f64,
    pub couple: DVec3,
    pub potential: f64,
}

/// What every contact remembers between steps while it lasts: its tangential spring.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct History {
    /// Tangential spring elongation ξ [m].
    pub tangential_spring: DVec3,
    /// Stiffness of the previous step: with Hertz–Mindlin it changes with the overlap, and the
    /// energy ledger must compare this step's spring energy with the one reported last step.
    pub tangential_stiffness: f64,
    /// The dashpots' force on body i in the last step (normal and tangential). Its work is booked
    /// one step late, against the velocity it met ([`Kinematics::velocity_start`]): the
    /// end-of-step velocity a step predicts misses that step's own forces, and for a strong
    /// dashpot booking against the prediction over-counted the loss by up to a half (issue #11,
    /// point 4). Single precision: the ledger needs no more, and the store stays small.
    #[serde(default)]
    pub damper_force: Vec3,
    /// The same work estimated against the predicted velocity, booked instead if the contact
    /// ends before the next step can book it [J].
    #[serde(default)]
    pub damper_work_estimate: f32,
}

// The layout `History::as_rows_mut` writes: four `f64` (spring, stiffness), then four `f32`.
const _: () = {
    use std::mem::{offset_of, size_of};
    assert!(size_of::<History>() == 48 && offset_of!(History, tangential_stiffness) == 24);
    assert!(offset_of!(History, damper_force) == 32);
    assert!(offset_of!(History, damper_work_estimate) == 44);
};

impl History {
    /// The history as two rows, (spring, stiffness) and (dashpot force, work estimate): what
    /// the four-wide sphere kernel writes whole (`step::sphere_lanes`).
    #[inline(always)]
    pub(crate) fn as_rows_mut(&mut self) -> (&mut [f64; 4], &mut [f32; 4]) {
        let start = (self as *mut History).cast::<u8>();
        // SAFETY: `History` is `repr(C)`, four `f64` and then four `f32` with no padding
        // (asserted above; glam's `DVec3` and `Vec3` are three `repr(C)` numbers); the two rows
        // do not overlap, and their alignments are no stronger than the history's.
        unsafe {
            (
                &mut *start.cast::<[f64; 4]>(),
                &mut *start.add(32).cast::<[f32; 4]>(),
            )
        }
    }

    /// Energy held in the tangential spring. When a contact ends this energy is lost with it: the
    /// ledger counts it as dissipated. (The normal spring needs no such care: its energy goes
    /// back into motion as the overlap closes.)
    pub fn stored_energy(&self) -> f64 {
        0.5 * self.tangential_stiffness * self.tangential_spring.length_squared()
    }
}

/// What a contact remembers of the relative rotation of its bodies: the rolling-resistance and
/// twisting springs. Only worlds with rolling friction or polyhedra keep it (a side array of the
/// contact store), so that a sphere contact carries nothing it does not use.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct SpinHistory {
    /// Rolling-resistance torque on body i [N m], and its stiffness of the previous step.
    pub rolling_torque: DVec3,
    pub rolling_stiffness: f64,
    /// Twisting torque on body i about the normal, and its stiffness (area contacts only).
    pub twisting_torque: f64,
    pub twisting_stiffness: f64,
}

// The layout `SpinHistory::rolling_row` reads and writes: the rolling torque and its stiffness,
// four `f64` from the start.
const _: () = {
    use std::mem::offset_of;
    assert!(offset_of!(SpinHistory, rolling_torque) == 0);
    assert!(offset_of!(SpinHistory, rolling_stiffness) == 24);
};

impl SpinHistory {
    /// The rolling spring as one row, (torque, stiffness): what the four-wide sphere kernels read
    /// and write whole (`step::rolling_lanes`).
    #[inline(always)]
    pub(crate) fn rolling_row(&self) -> &[f64; 4] {
        // SAFETY: `SpinHistory` is `repr(C)` and starts with a `DVec3` (three `repr(C)` `f64`)
        // and an `f64` (asserted above): four `f64` with no padding, aligned as the history.
        unsafe { &*(self as *const SpinHistory).cast::<[f64; 4]>() }
    }

    /// [`SpinHistory::rolling_row`] to write.
    #[inline(always)]
    pub(crate) fn rolling_row_mut(&mut self) -> &mut [f64; 4] {
        // SAFETY: as `rolling_row`; the row borrows the history mutably.
        unsafe { &mut *(self as *mut SpinHistory).cast::<[f64; 4]>() }
    }

    /// Energy held in the rolling and twisting springs (see [`History::stored_energy`]).
    pub fn stored_energy(&self) -> f64 {
        let rolling = if self.rolling_stiffness > 0.0 {
            0.5 * self.rolling_torque.length_squared() / self.rolling_stiffness
        } else {
            0.0
        };
        let twisting = if self.twisting_stiffness > 0.0 {
            0.5 * self.twisting_torque * self.twisting_torque / self.twisting_stiffness
        } else {
            0.0
        };
        rolling + twisting
    }
}

/// Force and torque the contact applies to body i (body j gets the reaction), and energy figures.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Response {
    /// Total contact force on i at the contact point [N].
    pub force: DVec3,
    /// Pure torque on i that is not the moment of `force` (rolling resistance) [N m].
    pub torque: DVec3,
    /// Normal force magnitude (≥ 0) [N].
    pub normal_force: f64,
    /// Elastic energy stored in the contact after this step [J].
    pub elastic_energy: f64,
    /// Energy dissipated by damping, sliding and rolling in this step [J].
    pub dissipated: f64,
}

/// [`evaluate`] for a point contact (no overlap volume) under a law without rolling friction, the
/// contact of two spheres or a sphere and a wall: the same arithmetic in the same order, without
/// the terms that are zero there, so the result is the same to the bit (a property test holds
/// them together); the sphere fast path (`step::spheres`) calls it.
#[inline(always)]
pub fn evaluate_point(law: &PairLaw, k: &Kinematics, history: &mut History, dt: f64) -> Response {
    debug_assert!(k.overlap_volume.is_none() && law.rolling_friction <= 0.0);
    let (elastic, stiffness, elastic_energy, contact_radius) =
        normal::elastic(law, k.overlap, k.effective_radius);
    let damping_coefficient = normal::bounded_dashpot(
        law.damping * (k.effective_mass * stiffness).sqrt(),
        k.dashpot_limit.normal,
    );
    let n = normal::NormalForce {
        elastic,
        total: (elastic + damping_coefficient * k.overlap_rate).max(0.0),
        stiffness,
        elastic_energy,
        couple: DVec3::ZERO,
        contact_radius,
        damping_coefficient,
    };
    let t = tangential::tangential_force(law, k, &n, history, dt);
    let damper_work = book_dampers(history, k, &n, t.damper, dt);
    Response {
        force: k.normal * n.total + t.force,
        torque: DVec3::ZERO,
        normal_force: n.total,
        elastic_energy: n.elastic_energy + t.elastic_energy,
        // `+ 0.0` as in the full sum: it makes a negative zero positive.
        dissipated: damper_work + t.dissipated + 0.0,
    }
}

/// Evaluates the composed law for one contact over a step `dt`, updating its history.
pub fn evaluate(
    law: &PairLaw,
    k: &Kinematics,
    history: &mut History,
    spin: &mut SpinHistory,
    dt: f64,
) -> Response {
    let n = normal::normal_force(law, k);
    let t = tangential::tangential_force(law, k, &n, history, dt);
    let damper_work = book_dampers(history, k, &n, t.damper, dt);
    let r = rolling::rolling_torque(law, k, &n, spin, dt);
    let kt = history.tangential_stiffness;
    let w = twisting::twisting_torque(law, k, &n, kt, spin, dt);
    let rock = rocking::rocking_torque(law, k, &n, dt);
    Response {
        force: k.normal * n.total + t.force,
        torque: r.torque + k.normal * w.torque + rock.torque + n.couple,
        normal_force: n.total,
        elastic_energy: n.elastic_energy + t.elastic_energy + r.elastic_energy + w.elastic_energy,
        dissipated: damper_work + t.dissipated + r.dissipated + w.dissipated + rock.dissipated,
    }
}

/// The work the dashpots did in the previous step, against the velocity they met; and this
/// step's dashpot force, kept for the next step to book (see [`History::damper_force`]). The
/// normal part counts the no-tension cut-off too: it is the force less its elastic part.
///
/// Forces found again between steps (`dt` = 0: after bodies were added or removed, and before
/// the first step) replace the last step's for the next opening half kick only: the last step's
/// force acted over its closing half kick, the new one acts over the next opening one, both
/// against the same velocity. So the force kept is the mean of the two, and the next step books
/// each over its half step; booking the new one over a whole step put up to a quarter of a
/// plastic impact's energy out of the ledger.
#[inline(always)]
fn book_dampers(
    history: &mut History,
    k: &Kinematics,
    n: &normal::NormalForce,
    tangential: DVec3,
    dt: f64,
) -> f64 {
    let previous = history.damper_force.as_dvec3();
    let normal = n.total - n.elastic;
    let force = k.normal * normal + tangential;
    if dt == 0.0 {
        // The estimate (booked if the contact ends first) stays the last step's.
        history.damper_force = (0.5 * (previous + force)).as_vec3();
        return 0.0;
    }
    let work = -previous.dot(k.velocity_start) * dt;
    history.damper_force = force.as_vec3();
    history.damper_work_estimate =
        ((normal * k.overlap_rate - tangential.dot(k.tangential_velocity_end)) * dt) as f32;
    work
}
