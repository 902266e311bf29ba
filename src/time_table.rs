//! Values that change over a run by a table of knots: a wall's velocity or rotation rate, gravity.
//! Linear between knots, constant before the first and after the last, so a table of one row is a
//! constant and two rows at nearly the same time a step. Runs in stages (fill at rest, then turn
//! the screw) are written this way.

use std::ops::{Add, Mul, Sub};
use thiserror::Error;

/// Why a table is not allowed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TableError {
    #[error("the table needs at least one row")]
    Empty,
    #[error("row {row}: every value must be finite and the time ≥ 0")]
    NonFiniteRow { row: usize },
    #[error(
        "row {row}: time {time} is not after the previous row's {previous}; list the rows in \
         increasing time"
    )]
    TimesNotIncreasing {
        row: usize,
        time: f64,
        previous: f64,
    },
}

/// What a table can hold: numbers and vectors.
pub trait Value:
    Copy + Default + Add<Output = Self> + Sub<Output = Self> + Mul<f64, Output = Self>
{
    fn is_finite_value(&self) -> bool;
}

impl Value for f64 {
    fn is_finite_value(&self) -> bool {
        self.is_finite()
    }
}

impl Value for glam::DVec3 {
    fn is_finite_value(&self) -> bool {
        self.is_finite()
    }
}

/// Knots (time [s], value) in increasing time.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimeTable<V> {
    knots: Vec<(f64, V)>,
}

impl<V: Value> TimeTable<V> {
    /// The same value at all times.
    pub fn constant(value: V) -> Self {
        Self {
            knots: vec![(0.0, value)],
        }
    }

    pub fn new(knots: Vec<(f64, V)>) -> Result<Self, TableError> {
        if knots.is_empty() {
            return Err(TableError::Empty);
        }
        for (row, &(time, v)) in knots.iter().enumerate() {
            if !(time.is_finite() && time >= 0.0 && v.is_finite_value()) {
                return Err(TableError::NonFiniteRow { row });
            }
            if row > 0 && time <= knots[row - 1].0 {
                return Err(TableError::TimesNotIncreasing {
                    row,
                    time,
                    previous: knots[row - 1].0,
                });
            }
        }
        Ok(Self { knots })
    }

    pub fn knots(&self) -> &[(f64, V)] {
        &self.knots
    }

    /// The value at time `t` (zero for an empty table).
    pub fn value(&self, t: f64) -> V {
        let Some(&(t_first, v_first)) = self.knots.first() else {
            return V::default();
        };
        if t <= t_first {
            return v_first;
        }
        for pair in self.knots.windows(2) {
            let ((t0, v0), (t1, v1)) = (pair[0], pair[1]);
            if t <= t1 {
                return v0 + (v1 - v0) * ((t - t0) / (t1 - t0));
            }
        }
        self.knots[self.knots.len() - 1].1
    }

    /// The integral of the value from time 0 to `t` ≥ 0, exact (trapezoids between the knots).
    pub fn integral(&self, t: f64) -> V {
        if self.knots.is_empty() || t <= 0.0 {
            return V::default();
        }
        let mut sum = V::default();
        let mut from = 0.0;
        for &(knot, _) in &self.knots {
            if knot >= t {
                break;
            }
            if knot > from {
                sum = sum + (self.value(from) + self.value(knot)) * (0.5 * (knot - from));
                from = knot;
            }
        }
        sum + (self.value(from) + self.value(t)) * (0.5 * (t - from))
    }

    /// The same table up to time `t`, then going linearly from its value at `t` to `value` at
    /// `until` (> `t`) and staying there: a change made during a run, which leaves the past
    /// (and so the integral up to `t`: where a wall has got to) as it was.
    pub fn changed_at(&self, t: f64, until: f64, value: V) -> Result<Self, TableError> {
        let mut knots: Vec<(f64, V)> = self.knots.iter().copied().filter(|k| k.0 < t).collect();
        knots.push((t, self.value(t)));
        knots.push((until, value));
        Self::new(knots)
    }

    /// Whether the value is the same at all times.
    pub fn is_constant(&self) -> bool
    where
        V: PartialEq,
    {
        self.knots.windows(2).all(|w| w[0].1 == w[1].1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_change_at_a_time_keeps_the_past_and_its_integral() {
        let t = TimeTable::new(vec![(0.0, 1.0), (2.0, 3.0), (5.0, 0.0)]).unwrap();
        let changed = t.changed_at(1.0, 1.5, 10.0).unwrap();
        assert_eq!(changed.knots(), &[(0.0, 1.0), (1.0, 2.0), (1.5, 10.0)]);
        assert_eq!(changed.integral(1.0), t.integral(1.0));
        assert_eq!(changed.value(7.0), 10.0);
        // An empty table (no motion) is zero up to the change.
        let empty = TimeTable::<f64>::default()
            .changed_at(0.5, 0.6, 2.0)
            .unwrap();
        assert_eq!(empty.integral(0.5), 0.0);
        assert!(t.changed_at(1.0, 1.0, 0.0).is_err());
    }

    #[test]
    fn values_between_before_and_after_the_knots() {
        let t = TimeTable::new(vec![(1.0, 2.0), (3.0, 6.0)]).unwrap();
        assert_eq!(t.value(0.0), 2.0);
        assert_eq!(t.value(2.0), 4.0);
        assert_eq!(t.value(5.0), 6.0);
        // 2 × 1 s, then the ramp's mean 4 × 2 s, then 6 × 1 s.
        assert_eq!(t.integral(4.0), 2.0 + 8.0 + 6.0);
        assert_eq!(TimeTable::constant(3.0).integral(2.0), 6.0);
    }

    #[test]
    fn bad_tables_are_refused_with_the_row() {
        assert_eq!(TimeTable::<f64>::new(vec![]), Err(TableError::Empty));
        assert_eq!(
            TimeTable::new(vec![(0.0, 1.0), (0.0, 2.0)]),
            Err(TableError::TimesNotIncreasing {
                row: 1,
                time: 0.0,
                previous: 0.0
            })
        );
        assert_eq!(
            TimeTable::new(vec![(0.0, f64::NAN)]),
            Err(TableError::NonFiniteRow { row: 0 })
        );
        assert_eq!(
            TimeTable::new(vec![(-1.0, 0.0)]),
            Err(TableError::NonFiniteRow { row: 0 })
        );
    }

    proptest! {
        /// The exact integral agrees with a fine midpoint sum of the values.
        #[test]
        fn integral_matches_a_fine_sum(
            rows in proptest::collection::vec((0.01f64..1.0, -10.0f64..10.0), 1..6),
            t in 0.0f64..5.0,
        ) {
            let mut time = 0.0;
            let knots: Vec<(f64, f64)> = rows.iter().map(|&(dt, v)| { time += dt; (time, v) }).collect();
            let table = TimeTable::new(knots).unwrap();
            let n = 20_000;
            let h = t / n as f64;
            let sum: f64 = (0..n).map(|k| table.value((k as f64 + 0.5) * h) * h).sum();
            // The midpoint rule is exact on linear pieces; only the cells holding a knot err, by
            // at most slope × h² each.
            prop_assert!((table.integral(t) - sum).abs() < 1e-6 * (1.0 + sum.abs()) + 6.0 * 2000.0 * h * h);
        }
    }
}
