//! Prescribed motion of a mesh wall: translation (constant velocity or a velocity time table),
//! rotation about an axis (constant rate or a rate time table), both at once, and a conveyor-belt
//! surface velocity of a wall that does not move. Time tables make runs in stages: a screw at
//! rest while the trough fills, then turning.
//!
//! A moving wall keeps its triangles in the placement it had at time 0 (its reference frame);
//! its [`WallPose`] at time t maps reference points to the world. Contacts are found with the
//! body taken into the reference frame, so the wall's adjacency, normals and search grid are
//! built once, never per step.

use crate::math::{is_finite_vec, DQuat, DVec3};
use crate::time_table::{TableError, TimeTable};
use thiserror::Error;

/// Why a motion is not allowed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MotionError {
    #[error(transparent)]
    Table(#[from] TableError),
    #[error("the rotation axis must be a finite, non-zero vector")]
    Axis,
    #[error("the rotation point, rate and surface velocity must be finite")]
    NonFinite,
    #[error("the wall has no rotation axis yet: give one (a point and a direction)")]
    NoAxis,
    #[error("the wall has turned about its axis already: its axis cannot change")]
    AxisOfTurnedWall,
}

/// Where a moving wall is at one moment: world point = `rotation` × reference point +
/// `translation`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallPose {
    pub rotation: DQuat,
    pub translation: DVec3,
}

impl Default for WallPose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl WallPose {
    pub const IDENTITY: Self = Self {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }

    /// World point of a reference point.
    #[inline]
    pub fn to_world(&self, reference: DVec3) -> DVec3 {
        self.rotation * reference + self.translation
    }

    /// Reference point of a world point.
    #[inline]
    pub fn to_reference(&self, world: DVec3) -> DVec3 {
        self.rotation.inverse() * (world - self.translation)
    }
}

/// How a wall moves. The default does not move.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WallMotion {
    /// Translation velocity [m/s] over time (see [`TimeTable`]). Empty: no translation.
    velocity_table: TimeTable<DVec3>,
    /// The rotation axis (unit, right hand), zero for none.
    axis: DVec3,
    /// Rotation rate [rad/s] about `axis` over time. Empty: no rotation.
    spin: TimeTable<f64>,
    /// A point of the rotation axis at time 0 [m]; it moves with the translation.
    axis_point: DVec3,
    /// Velocity of the wall's surface material along the wall (a conveyor belt) [m/s]; only its
    /// part tangential to the surface at a contact acts.
    surface_velocity: DVec3,
}

impl WallMotion {
    /// A wall that does not move.
    pub fn fixed() -> Self {
        Self::default()
    }

    /// Translation at a constant velocity.
    pub fn with_velocity(self, velocity: DVec3) -> Result<Self, MotionError> {
        self.with_velocity_table(vec![(0.0, velocity)])
    }

    /// Translation following a velocity time table: knots (time [s], velocity [m/s]), see
    /// [`TimeTable`].
    pub fn with_velocity_table(mut self, table: Vec<(f64, DVec3)>) -> Result<Self, MotionError> {
        self.velocity_table = TimeTable::new(table)?;
        Ok(self)
    }

    /// Rotation at `rpm` revolutions per minute about the axis through `point` along `axis`
    /// (right hand: positive rpm turns counter-clockwise seen from the tip of `axis`).
    pub fn with_rotation(self, point: DVec3, axis: DVec3, rpm: f64) -> Result<Self, MotionError> {
        if !rpm.is_finite() {
            return Err(MotionError::NonFinite);
        }
        self.with_rotation_table(point, axis, vec![(0.0, rpm)])
    }

    /// Rotation about the axis through `point` along `axis` at a rate that follows the knots
    /// (time [s], revolutions per minute), see [`TimeTable`]: the angle turned is the rate's
    /// exact integral.
    pub fn with_rotation_table(
        mut self,
        point: DVec3,
        axis: DVec3,
        rpm: Vec<(f64, f64)>,
    ) -> Result<Self, MotionError> {
        let axis = axis.try_normalize().ok_or(MotionError::Axis)?;
        if !is_finite_vec(point) {
            return Err(MotionError::NonFinite);
        }
        let per_second = std::f64::consts::TAU / 60.0;
        let spin = rpm.into_iter().map(|(t, n)| (t, n * per_second)).collect();
        self.spin = TimeTable::new(spin)?;
        self.axis = axis;
        self.axis_point = point;
        Ok(self)
    }

    /// A conveyor-belt surface velocity (the wall itself stays where it is unless also moved).
    pub fn with_surface_velocity(mut self, velocity: DVec3) -> Result<Self, MotionError> {
        if !is_finite_vec(velocity) {
            return Err(MotionError::NonFinite);
        }
        self.surface_velocity = velocity;
        Ok(self)
    }

    /// The same motion up to time `t`, then with its translation velocity changing linearly to
    /// `velocity` [m/s] by time `until` and staying there (a change during a run: where the
    /// wall is at `t` stays as it was).
    pub fn with_velocity_changed_at(
        mut self,
        t: f64,
        until: f64,
        velocity: DVec3,
    ) -> Result<Self, MotionError> {
        self.velocity_table = self.velocity_table.changed_at(t, until, velocity)?;
        Ok(self)
    }

    /// The same motion up to time `t`, then with its rotation rate changing linearly to `rpm`
    /// by time `until` and staying there. A wall without a rotation axis needs one, `axis` (a
    /// point and a direction); a wall that has turned keeps the axis it has.
    pub fn with_rpm_changed_at(
        mut self,
        t: f64,
        until: f64,
        rpm: f64,
        axis: Option<(DVec3, DVec3)>,
    ) -> Result<Self, MotionError> {
        if !rpm.is_finite() {
            return Err(MotionError::NonFinite);
        }
        if let Some((point, direction)) = axis {
            let direction = direction.try_normalize().ok_or(MotionError::Axis)?;
            if !is_finite_vec(point) {
                return Err(MotionError::NonFinite);
            }
            let same = direction == self.axis && point == self.axis_point;
            if !same {
                if self.spin.integral(t) != 0.0 {
                    return Err(MotionError::AxisOfTurnedWall);
                }
                self.axis = direction;
                self.axis_point = point;
            }
        } else if self.axis == DVec3::ZERO {
            return Err(MotionError::NoAxis);
        }
        let per_second = std::f64::consts::TAU / 60.0;
        self.spin = self.spin.changed_at(t, until, rpm * per_second)?;
        Ok(self)
    }

    /// True when the wall's triangles never leave their reference placement.
    pub fn keeps_place(&self) -> bool {
        self.spin.knots().iter().all(|&(_, w)| w == 0.0)
            && self
                .velocity_table
                .knots()
                .iter()
                .all(|&(_, v)| v == DVec3::ZERO)
    }

    /// True when the wall neither moves nor has a surface velocity.
    pub fn is_fixed(&self) -> bool {
        self.keeps_place() && self.surface_velocity == DVec3::ZERO
    }

    /// Angular velocity of the wall at time `t` [rad/s].
    pub fn angular_velocity(&self, t: f64) -> DVec3 {
        self.axis * self.spin.value(t)
    }

    /// Translation velocity at time `t`.
    pub fn velocity(&self, t: f64) -> DVec3 {
        self.velocity_table.value(t)
    }

    /// Displacement from time 0 to `t` ≥ 0: the integral of the piecewise-linear velocity, exact
    /// (trapezoids between the knots).
    pub fn displacement(&self, t: f64) -> DVec3 {
        self.velocity_table.integral(t)
    }

    /// Where the wall is at time `t`.
    pub fn pose(&self, t: f64) -> WallPose {
        if self.keeps_place() {
            return WallPose::IDENTITY;
        }
        let rotation = DQuat::from_scaled_axis(self.axis * self.spin.integral(t));
        let axis_now = self.axis_point + self.displacement(t);
        WallPose {
            rotation,
            translation: axis_now - rotation * self.axis_point,
        }
    }

    /// The point the wall's torque is reported about at time `t`: the rotation axis point, moved
    /// with the translation (the origin for a wall without rotation, moved likewise).
    pub fn reference_point(&self, t: f64) -> DVec3 {
        self.axis_point + self.displacement(t)
    }

    /// An upper bound of the wall's surface speed at any time, for a wall with these reference
    /// vertices: fastest translation + rotation rate × farthest vertex from the axis + belt.
    pub fn max_surface_speed(&self, vertices: &[DVec3]) -> f64 {
        let translation = self
            .velocity_table
            .knots()
            .iter()
            .map(|&(_, v)| v.length())
            .fold(0.0, f64::max);
        // Linear between knots: the fastest is at a knot.
        let w = self
            .spin
            .knots()
            .iter()
            .map(|&(_, w)| w.abs())
            .fold(0.0, f64::max);
        let reach = if w > 0.0 {
            vertices
                .iter()
                .map(|&v| {
                    (v - self.axis_point)
                        .reject_from_normalized(self.axis)
                        .length()
                })
                .fold(0.0, f64::max)
        } else {
            0.0
        };
        translation + w * reach + self.surface_velocity.length()
    }

    /// The wall's motion at time `t`, worked out once for all its contacts.
    pub fn state(&self, t: f64) -> WallState {
        WallState {
            velocity: self.velocity(t),
            angular_velocity: self.angular_velocity(t),
            centre: self.reference_point(t),
            belt: self.surface_velocity,
        }
    }

    /// Velocity at time `t` of the wall's surface at world point `x` where the surface normal is
    /// `normal` (see [`WallState::surface_velocity`]).
    pub fn surface_velocity_at(&self, t: f64, x: DVec3, normal: DVec3) -> DVec3 {
        self.state(t).surface_velocity(x, normal)
    }
}

/// A moving wall at one moment: translation velocity, angular velocity about `centre` (the
/// reference point, see [`WallMotion::reference_point`]) and belt velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallState {
    pub velocity: DVec3,
    pub angular_velocity: DVec3,
    pub centre: DVec3,
    belt: DVec3,
}

impl WallState {
    /// Velocity of the wall's surface at world point `x` where the surface normal is `normal`:
    /// rigid motion plus the tangential part of the belt velocity.
    #[inline]
    pub fn surface_velocity(&self, x: DVec3, normal: DVec3) -> DVec3 {
        let belt = self.belt - normal * normal.dot(self.belt);
        self.velocity + self.angular_velocity.cross(x - self.centre) + belt
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn velocity_table_is_piecewise_linear_and_its_integral_exact() {
        // v = 0 at 0, ramps to 2 at 1 s, holds to 3 s, drops to 0 at 4 s.
        let m = WallMotion::fixed()
            .with_velocity_table(vec![
                (0.0, DVec3::ZERO),
                (1.0, DVec3::X * 2.0),
                (3.0, DVec3::X * 2.0),
                (4.0, DVec3::ZERO),
            ])
            .unwrap();
        assert_eq!(m.velocity(0.5), DVec3::X);
        assert_eq!(m.velocity(2.0), DVec3::X * 2.0);
        assert_eq!(m.velocity(10.0), DVec3::ZERO);
        // Areas: 1 (ramp) + 4 (hold) + 1 (drop).
        for (t, x) in [(0.5, 0.25), (1.0, 1.0), (2.5, 4.0), (4.0, 6.0), (9.0, 6.0)] {
            assert!((m.displacement(t).x - x).abs() < 1e-14, "{t}");
        }
        // Constant before the first knot.
        let late = WallMotion::fixed()
            .with_velocity_table(vec![(1.0, DVec3::Y), (2.0, DVec3::ZERO)])
            .unwrap();
        assert!((late.displacement(1.0).y - 1.0).abs() < 1e-15);
        assert!((late.displacement(3.0).y - 1.5).abs() < 1e-15);
    }

    #[test]
    fn rotation_turns_points_about_the_axis_at_the_rpm() {
        let centre = DVec3::new(1.0, 2.0, 0.0);
        let m = WallMotion::fixed()
            .with_rotation(centre, DVec3::Z, 60.0)
            .unwrap();
        // 60 rpm: a quarter turn in a quarter second.
        let pose = m.pose(0.25);
        let p = pose.to_world(centre + DVec3::X);
        assert!((p - (centre + DVec3::Y)).length() < 1e-14);
        assert!((pose.to_reference(p) - (centre + DVec3::X)).length() < 1e-14);
        let v = m.surface_velocity_at(0.25, p, DVec3::Y);
        assert!((v - DVec3::new(-2.0 * PI, 0.0, 0.0)).length() < 1e-12);
        // Combined with a translation, the axis travels.
        let both = m.with_velocity(DVec3::Z).unwrap();
        let pose = both.pose(0.5);
        assert!((pose.to_world(centre) - (centre + DVec3::Z * 0.5)).length() < 1e-14);
    }

    #[test]
    fn a_wall_at_rest_then_turning_has_turned_by_the_rate_integral() {
        // At rest for 1 s, spun up to 60 rpm over the next second, then steady.
        let m = WallMotion::fixed()
            .with_rotation_table(DVec3::ZERO, DVec3::Z, vec![(1.0, 0.0), (2.0, 60.0)])
            .unwrap();
        assert!(!m.keeps_place());
        assert_eq!(m.pose(0.9), WallPose::IDENTITY);
        assert_eq!(m.angular_velocity(0.5), DVec3::ZERO);
        assert!((m.angular_velocity(1.5) - DVec3::Z * PI).length() < 1e-15);
        // By 2 s: half a turn's worth of a second at 1 rev/s on average ½ → π; by 2.25 s another
        // quarter turn: 3π/2 in all.
        let p = m.pose(2.25).to_world(DVec3::X);
        assert!((p - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-14, "{p}");
        assert!((m.state(3.0).angular_velocity - DVec3::Z * TAU).length() < 1e-14);
        assert!((m.max_surface_speed(&[DVec3::X * 2.0]) - 2.0 * TAU).abs() < 1e-14);
    }

    #[test]
    fn belt_velocity_acts_along_the_surface_only() {
        let m = WallMotion::fixed()
            .with_surface_velocity(DVec3::new(1.0, 0.0, 1.0))
            .unwrap();
        assert!(m.keeps_place() && !m.is_fixed());
        assert_eq!(m.pose(3.0), WallPose::IDENTITY);
        assert_eq!(m.surface_velocity_at(1.0, DVec3::ONE, DVec3::Z), DVec3::X);
    }

    #[test]
    fn bad_motions_are_refused() {
        let f = WallMotion::fixed;
        assert_eq!(
            f().with_velocity_table(vec![]),
            Err(MotionError::Table(TableError::Empty))
        );
        assert!(matches!(
            f().with_velocity_table(vec![(1.0, DVec3::X), (1.0, DVec3::Y)]),
            Err(MotionError::Table(TableError::TimesNotIncreasing {
                row: 1,
                ..
            }))
        ));
        assert!(matches!(
            f().with_velocity_table(vec![(0.0, DVec3::NAN)]),
            Err(MotionError::Table(TableError::NonFiniteRow { row: 0 }))
        ));
        assert_eq!(
            f().with_rotation(DVec3::ZERO, DVec3::ZERO, 10.0),
            Err(MotionError::Axis)
        );
        assert_eq!(
            f().with_rotation(DVec3::ZERO, DVec3::Z, f64::NAN),
            Err(MotionError::NonFinite)
        );
    }
}
