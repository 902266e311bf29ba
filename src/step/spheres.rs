//! The sphere–sphere fast path: narrow phase and contact law of a pair of spheres in one go, from
//! the two bodies' packed motion, with no intermediate geometry read back. Most contacts of a
//! granular run are of this kind, and this is where its step spends its time.
//!
//! The arithmetic is the general path's (`narrow_phase::sphere_sphere`, then
//! `forces::LawInputs::respond` and `contact_law::evaluate`), in the same order, so both give the
//! same bits; a test below holds them together.

use super::forces::{ended, kinematics, LawInputs};
use crate::contact::{ContactKey, LawReport, Load, OwnLoad, PartnerLoad};
use crate::contact_law::{self, effective_radius_and_mass, History, PairLaw, SpinHistory};
use crate::narrow_phase;

/// What the step writes of one entry.
pub(crate) struct EntryOut<'a> {
    pub touching: &'a mut bool,
    pub history: &'a mut History,
    /// In worlds with rolling friction (see `contact_law::SpinHistory`).
    pub spin: Option<&'a mut SpinHistory>,
    /// The partner's side of the load (the store's) and body `a`'s (the contact loop's scratch).
    pub load: &'a mut PartnerLoad,
    pub own: &'a mut OwnLoad,
    /// In worlds that keep reports (see `contact::StoreLayout::reports`).
    pub report: Option<&'a mut LawReport>,
    /// The energy dissipated over the step (the contact loop's scratch).
    pub dissipated: &'a mut f64,
}

/// Contact and response of the sphere pair `key` (its partner a body) over the step `dt`: the
/// scalar path whole, which the tests hold against the general path and the four-wide kernel.
#[cfg(test)]
#[inline(always)]
pub(crate) fn sphere_pair(inputs: &LawInputs, key: ContactKey, out: EntryOut, dt: f64) {
    if overlaps(inputs, key) {
        touching_pair(inputs, key, out, dt);
    } else {
        apart(out);
    }
}

/// The two bodies of `key`.
#[inline(always)]
pub(crate) fn bodies(key: ContactKey) -> (usize, usize) {
    (key.a as usize, key.partner.body().unwrap_or(0) as usize)
}

/// The contact law of the sphere pair `key`.
#[inline(always)]
pub(crate) fn law<'a>(inputs: &LawInputs<'a>, key: ContactKey) -> &'a PairLaw {
    let (a, j) = bodies(key);
    let material = &inputs.scene.bodies.material;
    inputs.laws.get(material[a], material[j])
}

/// Whether the sphere pair `key` overlaps (the narrow phase's test).
#[inline(always)]
pub(crate) fn overlaps(inputs: &LawInputs, key: ContactKey) -> bool {
    let (a, j) = bodies(key);
    let (ma, mb) = (&inputs.motion[a], &inputs.motion[j]);
    let reach = ma.radius + mb.radius;
    // As narrow_phase::sphere_sphere: a NaN position gives a (NaN) contact, so a blow-up shows.
    let apart = (ma.position - mb.position).length_squared() >= reach * reach;
    !apart
}

/// A sphere pair that does not touch: no load, and a history it had is dropped.
#[inline(always)]
pub(crate) fn apart(out: EntryOut) {
    *out.touching = false;
    let r = ended(out.history, out.spin);
    *out.load = PartnerLoad::default();
    *out.own = OwnLoad::default();
    if let Some(report) = out.report {
        *report = LawReport::of(&r);
    }
    *out.dissipated = r.dissipated;
}

/// Contact and response of the sphere pair `key`, which [`overlaps`], over the step `dt`.
#[inline(always)]
pub(crate) fn touching_pair(inputs: &LawInputs, key: ContactKey, out: EntryOut, dt: f64) {
    let (a, j) = bodies(key);
    let (ma, mb) = (&inputs.motion[a], &inputs.motion[j]);
    let g = narrow_phase::overlapping_spheres(ma.position, ma.radius, mb.position, mb.radius);
    // As LawInputs::respond for two bodies.
    let arm_a = g.point - ma.position;
    let arm_b = g.point - mb.position;
    let va = ma.velocity + ma.angular_velocity.cross(arm_a);
    let va_end = ma.velocity_end + ma.angular_velocity_end.cross(arm_a);
    let vb = mb.velocity + mb.angular_velocity.cross(arm_b);
    let vb_end = mb.velocity_end + mb.angular_velocity_end.cross(arm_b);
    let bodies = inputs.scene.bodies;
    let (effective_radius, effective_mass) =
        effective_radius_and_mass((ma.radius, mb.radius), (bodies.mass[a], bodies.mass[j]));
    let k = kinematics(
        &g,
        None,
        va - vb,
        va_end - vb_end,
        ma.angular_velocity - mb.angular_velocity,
        effective_radius,
        effective_mass,
        inputs.inverse_step,
    );
    let law = law(inputs, key);
    let r = if law.rolling_friction > 0.0 {
        debug_assert!(
            out.spin.is_some(),
            "rolling friction without spin histories"
        );
        let mut none = SpinHistory::default();
        let spin = out.spin.unwrap_or(&mut none);
        contact_law::evaluate(law, &k, out.history, spin, dt)
    } else {
        contact_law::evaluate_point(law, &k, out.history, dt)
    };
    let load = Load::new(&r, g.point, ma.position, Some(mb.position));
    *out.load = load.partner_side();
    *out.own = load.own_side();
    if let Some(report) = out.report {
        *report = LawReport::of(&r);
    }
    *out.dissipated = r.dissipated;
    *out.touching = true;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::{Bodies, BodyInit};
    use crate::contact::{PairKind, Partner};
    use crate::contact_law::NormalLaw;
    use crate::integrate::BodyMotion;
    use crate::material::{Material, PairTable};
    use crate::math::{DQuat, DVec3};
    use crate::narrow_phase;
    use crate::shape::{Shape, Sphere};
    use proptest::prelude::*;

    fn vec3(r: f64) -> impl Strategy<Value = DVec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    fn material(friction: f64, rolling_friction: f64, restitution: f64) -> Material {
        Material {
            name: "m".into(),
            density: 2500.0,
            youngs_modulus: 5e6,
            poisson_ratio: 0.25,
            restitution,
            friction,
            rolling_friction,
        }
    }

    /// Both normal laws, without and with friction, without and with rolling friction.
    const LAWS: usize = 8;

    /// The pair tables, made once: the damping for a restitution is found by integrating a
    /// collision, which would take most of the test's time if done per case.
    fn tables() -> &'static [PairTable] {
        static TABLES: std::sync::OnceLock<Vec<PairTable>> = std::sync::OnceLock::new();
        TABLES.get_or_init(|| {
            (0..LAWS)
                .map(|k| {
                    let friction = if k & 2 != 0 { 0.4 } else { 0.0 };
                    let rolling_friction = if k & 4 != 0 { 0.05 } else { 0.0 };
                    let materials = [
                        material(friction, rolling_friction, 0.3),
                        material(friction, rolling_friction, 0.9),
                    ];
                    let normal = if k & 1 != 0 {
                        NormalLaw::Hertz
                    } else {
                        NormalLaw::Linear { stiffness: 1e3 }
                    };
                    PairTable::new(&materials, normal, 2.0 / 7.0, &[])
                })
                .collect()
        })
    }

    proptest! {
        /// The fused path gives the general path's response and history to the bit,
        /// for both normal laws, with and without friction and rolling friction, from random
        /// histories (including ones that hit the Coulomb limit) and for pairs that do not touch.
        #[test]
        fn the_sphere_fast_path_is_the_general_path_to_the_bit(
            ra in 0.5e-3..2e-3f64,
            rb in 0.5e-3..2e-3f64,
            direction in vec3(1.0).prop_filter("a direction", |d| d.length() > 1e-3),
            // Most pairs overlap, some by a lot, some not at all.
            gap in 0.6..1.1f64,
            motion in prop::array::uniform4(vec3(0.1)),
            end in prop::array::uniform4(vec3(0.01)),
            spring in vec3(2e-5),
            law in 0..LAWS,
            dt in 1e-6..1e-4f64,
        ) {
            let laws = &tables()[law];
            let mut bodies = Bodies::default();
            let shapes = [Shape::Sphere(Sphere { radius: ra }), Shape::Sphere(Sphere { radius: rb })];
            let offset = direction.normalize() * gap * (ra + rb);
            let positions = [DVec3::new(0.01, 0.02, 0.03), DVec3::new(0.01, 0.02, 0.03) + offset];
            for (i, (&r, &x)) in [ra, rb].iter().zip(&positions).enumerate() {
                let init = BodyInit {
                    shape: shapes[i].clone(),
                    material: i as u32,
                    position: x,
                    orientation: DQuat::IDENTITY,
                    velocity: DVec3::ZERO,
                    angular_velocity: DVec3::ZERO,
                };
                let mass = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
                bodies.push(i as u64, i as u32, i as u32, r, r, mass, DVec3::splat(0.4 * mass * r * r), &init);
            }
            let packed: Vec<BodyMotion> = (0..2)
                .map(|i| BodyMotion {
                    position: positions[i],
                    velocity: motion[2 * i],
                    angular_velocity: motion[2 * i + 1] * 100.0,
                    velocity_end: motion[2 * i] + end[2 * i],
                    angular_velocity_end: (motion[2 * i + 1] + end[2 * i + 1]) * 100.0,
                    radius: [ra, rb][i],
                })
                .collect();
            let inputs = LawInputs::of_bodies(&bodies, &shapes, laws, &packed, 1.0 / dt);
            let key = ContactKey { a: 0, partner: Partner::Body(1), region: 0 };
            let start = History {
                tangential_spring: spring,
                tangential_stiffness: 1e3,
                damper_force: (spring * 1e2).as_vec3(),
                damper_work_estimate: 1e-6,
            };
            let start_spin = SpinHistory {
                rolling_torque: spring * 1e-2,
                rolling_stiffness: 1e-3,
                ..SpinHistory::default()
            };

            let mut touching = false;
            let (mut history, mut spin) = (start, start_spin);
            let (mut load, mut report) = (PartnerLoad::default(), LawReport::default());
            let (mut own, mut dissipated) = (OwnLoad::default(), 0.0);
            let out = EntryOut {
                touching: &mut touching,
                history: &mut history,
                spin: Some(&mut spin),
                load: &mut load,
                own: &mut own,
                report: Some(&mut report),
                dissipated: &mut dissipated,
            };
            sphere_pair(&inputs, key, out, dt);

            let found = narrow_phase::sphere_sphere(positions[0], ra, positions[1], rb);
            let (mut general_history, mut general_spin) = (start, start_spin);
            let general = match found {
                Some(g) => inputs.respond(
                    key,
                    PairKind::Spheres,
                    &g.contact_point(),
                    None,
                    (&mut general_history, &mut general_spin),
                    dt,
                ),
                None => ended(&mut general_history, Some(&mut general_spin)),
            };
            prop_assert_eq!(touching, found.is_some());
            // Debug prints the shortest string that reads back to the same bits (and tells -0 from 0).
            let general_load = match found {
                Some(g) => Load::new(&general, g.point, positions[0], Some(positions[1])),
                None => Load::default(),
            };
            prop_assert_eq!(format!("{load:?}"), format!("{:?}", general_load.partner_side()));
            prop_assert_eq!(format!("{own:?}"), format!("{:?}", general_load.own_side()));
            prop_assert_eq!(format!("{report:?}"), format!("{:?}", LawReport::of(&general)));
            prop_assert_eq!(format!("{dissipated:?}"), format!("{:?}", general.dissipated));
            prop_assert_eq!(format!("{history:?}"), format!("{general_history:?}"));
            prop_assert_eq!(format!("{spin:?}"), format!("{general_spin:?}"));
        }
    }
}
