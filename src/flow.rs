//! Mass flow meters: the mass that crosses a plane, or leaves a region, counted every step.
//!
//! A body is counted when its centre crosses: through a plane in the direction of its normal
//! (+ its mass), or against it (− its mass), so the running total is the net mass passed; out of a
//! region (+) or into it (−). Counting each step by the centre's move is exact for any speed the
//! time step allows (a body moves a small fraction of its size per step), and a body that rattles
//! on the plane adds nothing on balance.

use crate::body::Bodies;
use crate::math::{Aabb, DVec3};

/// What a meter counts the flow through.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum FlowSurface {
    /// Bodies crossing the plane through `point` with unit `normal`, counted positive along it.
    Plane { point: DVec3, normal: DVec3 },
    /// Bodies leaving the box (entering it counts negative).
    RegionOutflow(Aabb),
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FlowMeter {
    pub name: String,
    pub surface: FlowSurface,
    /// Net mass passed since the start [kg].
    pub mass: f64,
    /// Net number of bodies passed since the start.
    pub bodies: i64,
}

impl FlowMeter {
    pub fn new(name: impl Into<String>, surface: FlowSurface) -> Self {
        Self {
            name: name.into(),
            surface,
            mass: 0.0,
            bodies: 0,
        }
    }

    /// Counts the bodies whose centres crossed during the drift just done (from x − v·dt to x).
    pub fn record(&mut self, b: &Bodies, dt: f64) {
        // A ghost is counted by its owner.
        for i in (0..b.len()).filter(|&i| b.counts(i)) {
            let after = b.position[i];
            let before = after - b.velocity[i] * dt;
            let sign = match &self.surface {
                FlowSurface::Plane { point, normal } => {
                    let (s0, s1) = (
                        (before - *point).dot(*normal),
                        (after - *point).dot(*normal),
                    );
                    match (s0 < 0.0, s1 < 0.0) {
                        (true, false) => 1,
                        (false, true) => -1,
                        _ => 0,
                    }
                }
                FlowSurface::RegionOutflow(region) => {
                    match (region.contains(before), region.contains(after)) {
                        (true, false) => 1,
                        (false, true) => -1,
                        _ => 0,
                    }
                }
            };
            if sign != 0 {
                self.mass += sign as f64 * b.mass[i];
                self.bodies += sign;
            }
        }
    }
}
