//! What a share of a decomposed world must know of its bodies' next move before the shares step
//! again: how far each owned body will be, after the next step's drift, from where the shares
//! were drawn (beyond its slack), and the two largest distances from where the neighbour search
//! made its list. [`accumulate`](super::accumulate) finds it in its pass over the bodies, where
//! each body's velocity and force are at hand after the closing kick: a pass of its own read
//! seven arrays of every body each step (3 % of a rank's time on the 65,000-sphere bed).
//!
//! Ghosts are left out: each body is some share's own, and the shares' figures are merged
//! ([`Moves::merge`]), so the whole sees every body once, as a single world would.

use crate::integrate::Kick;
use crate::math::DVec3;

/// Where the bodies of a share were when the shares were drawn, and where its neighbour search
/// made its list.
#[derive(Clone, Copy)]
pub struct Lookahead<'a> {
    /// Each body's place when the shares were drawn.
    pub drawn_at: &'a [DVec3],
    /// How much farther than the shares' common bound each body may go from there.
    pub slack: &'a [f64],
    /// Each body's place when the list was made; `None` when it is to be made anew anyway.
    pub listed: Option<&'a [DVec3]>,
    /// The step [s].
    pub dt: f64,
}

/// What the lookahead finds over some bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moves {
    /// The largest distance a body will be from where the shares were drawn, beyond its slack
    /// (−∞ over no body).
    pub excess: f64,
    /// The two largest squared distances a body will be from where the list was made, largest
    /// first.
    pub listed_squared: [f64; 2],
}

impl Moves {
    /// Over no body.
    pub const NONE: Moves = Moves {
        excess: f64::NEG_INFINITY,
        listed_squared: [0.0, 0.0],
    };

    /// Over the bodies of both.
    pub fn merge(self, other: Moves) -> Moves {
        Moves {
            excess: self.excess.max(other.excess),
            listed_squared: largest_two_of(self.listed_squared, other.listed_squared),
        }
    }

    /// With body `i`, whose velocity after the closing `kick` is `v` and whose force is `f`:
    /// the next step's opening kick and drift, as `integrate::kick_drift` makes them.
    ///
    /// Always inlined: called out of line, the body's numbers went through the stack and were
    /// read back in halves, a stalled load per body (`perf annotate`: 7.6 % of a rank's samples
    /// in this function, nearly half of them on one such load).
    #[inline(always)]
    pub fn with_body(
        self,
        ahead: &Lookahead,
        kick: &Kick,
        i: usize,
        (x, v, f, inv_mass): (DVec3, DVec3, DVec3, f64),
    ) -> Moves {
        let next = x + (v + (f * inv_mass + kick.gravity) * kick.h) * ahead.dt;
        let squared = match ahead.listed {
            Some(from) => with_largest_two(self.listed_squared, (next - from[i]).length_squared()),
            None => self.listed_squared,
        };
        Moves {
            excess: self
                .excess
                .max((next - ahead.drawn_at[i]).length() - ahead.slack[i]),
            listed_squared: squared,
        }
    }
}

/// The two largest of four numbers, each pair given largest first.
pub(crate) fn largest_two_of(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    with_largest_two(with_largest_two(a, b[0]), b[1])
}

/// `top` (the two largest of some numbers, largest first) with `d` among them (a NaN is passed
/// over, as by a comparison).
#[inline]
pub(crate) fn with_largest_two(top: [f64; 2], d: f64) -> [f64; 2] {
    if d > top[0] {
        [d, top[0]]
    } else if d > top[1] {
        [top[0], d]
    } else {
        top
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_largest_of_two_pairs_are_found() {
        assert_eq!(largest_two_of([5.0, 1.0], [3.0, 2.0]), [5.0, 3.0]);
        assert_eq!(largest_two_of([3.0, 2.0], [5.0, 4.0]), [5.0, 4.0]);
        assert_eq!(largest_two_of([0.0, 0.0], [f64::NAN, 1.0]), [1.0, 0.0]);
    }
}
