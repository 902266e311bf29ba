//! How far each body's box is enlarged when the candidate list is made ([`Margins`]), and so how
//! far it may move before the list must be made again.
//!
//! A uniform margin of half the skin makes the list last until the fastest body has moved it
//! (with the two largest moves, until they add up to a skin). In a settling bed that is a handful
//! of bodies: on the 10,000-sphere bench bed, steps 5,000–7,000, the list was made every 34 steps,
//! when the fastest body had moved half a skin while half of all bodies had moved less than 0.4 %
//! of it and only one in a hundred more than a tenth (a probe at each list; docs/benchmarks.md).
//! So each body gets a margin in proportion to its speed when the list is made, from half the skin
//! for the bulk up to [`GROWTH_LIMIT`] times that for the fastest: the few fast bodies carry
//! larger boxes (few more candidates), and the list lasts until some body has outrun its own
//! margin. The reference speed is that of the body faster than [`REFERENCE_QUANTILE`] of the
//! others, so the rule needs no time step and no scale, and a flow where every body moves alike
//! keeps the uniform margin (and the list's life) it had.
//!
//! Correctness does not rest on the guess: two bodies that are not candidates were more than
//! their two margins apart (gap between their bounding spheres) when the list was made, and can
//! touch only once their moves since add up to that, which [`Margins::ByBody`]'s rule (no body
//! beyond its own margin) excludes; a body within its margin cannot reach a plane farther than
//! its margin, nor a triangle of a wall (which moves half a skin at most) farther than its margin
//! and half a skin. A pair that touches is a candidate under either rule, so the forces,
//! and every body's motion, are the same bits whatever the margins (only the contact store's
//! chunks, and so the order in which the energy ledger adds up its dissipation, change).

use crate::math::DVec3;

/// How the margins are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Margins {
    /// Half the skin for every body; the list is made again once the two largest moves add up
    /// to a skin (or, with mesh walls, one body moved half a skin). Kept by the shares of a
    /// decomposed world, whose ghost layers and look-ahead at the bodies' next move assume it.
    Uniform,
    /// Half the skin, grown with the body's speed ([`by_speed`]); the list is made again once a
    /// body has moved beyond its own margin. A single world's.
    ByBody,
}

/// The most a margin grows: four times half the skin, two skins. A fast body's box then reaches
/// a few more neighbours in a dense bed; more would make the fastest hundredth of a flowing bed
/// carry boxes with several times the partners.
pub const GROWTH_LIMIT: f64 = 4.0;

/// The share of bodies at least as slow as the reference speed (see the module's text).
pub const REFERENCE_QUANTILE: f64 = 0.99;

/// Each body's margin for the velocities `velocity` (`out`, cleared first): half the skin
/// `half_skin`, times the body's speed over the reference speed where it is faster, at most
/// [`GROWTH_LIMIT`] times (a body that is not still among still ones: the limit). A function of
/// the velocities alone, so the same for any thread count.
pub fn by_speed(velocity: &[DVec3], half_skin: f64, out: &mut Vec<f64>) {
    out.clear();
    // Squared speeds: the quantile of the squares is the square of the speeds' quantile, and only
    // the fast bodies need a square root.
    let mut squared: Vec<f64> = velocity.iter().map(|v| v.length_squared()).collect();
    let Some(last) = squared.len().checked_sub(1) else {
        return;
    };
    let k = ((squared.len() as f64 * REFERENCE_QUANTILE) as usize).min(last);
    let reference_squared = *squared.select_nth_unstable_by(k, f64::total_cmp).1;
    out.extend(
        velocity
            .iter()
            .map(|v| half_skin * growth(v.length_squared(), reference_squared)),
    );
}

/// The factor on half the skin of a body whose squared speed is `squared`, the reference's
/// `reference_squared`: 1 up to the reference speed (and for a speed that is not a number, which
/// the run's checks stop it for), then the ratio of the speeds, at most [`GROWTH_LIMIT`].
fn growth(squared: f64, reference_squared: f64) -> f64 {
    if squared > reference_squared {
        // Above a still reference (0): the quotient is infinite, and the limit is taken.
        (squared / reference_squared).sqrt().min(GROWTH_LIMIT)
    } else {
        // Also NaN, which compares false.
        1.0
    }
}

/// Whether a body beyond its margin: `moved_squared` its squared distance from where the list was
/// made. The rule of [`Margins::ByBody`].
#[inline(always)]
pub fn beyond(moved_squared: f64, margin: f64) -> bool {
    moved_squared > margin * margin
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bulk_keeps_half_the_skin_and_the_fastest_grow_up_to_the_limit() {
        // 1,000 bodies: 985 creep at 1 mm/s or less, 10 at 2 mm/s, five fly at 3, 6, 10, 50 and
        // 500 mm/s. The reference is the 990th slowest's speed, 2 mm/s.
        let mut velocity: Vec<DVec3> = (0..985)
            .map(|k| DVec3::new(0.0, 1e-3 * k as f64 / 985.0, 0.0))
            .collect();
        velocity.extend((0..10).map(|_| DVec3::new(0.0, 0.0, -2e-3)));
        velocity.extend([3e-3, 6e-3, 10e-3, 50e-3, 500e-3].map(|s| DVec3::new(s, 0.0, 0.0)));
        let mut margin = Vec::new();
        by_speed(&velocity, 0.1, &mut margin);
        assert_eq!(margin.len(), 1000);
        assert!(margin[..995].iter().all(|&m| m == 0.1), "the bulk's margin");
        let fast = &margin[995..];
        let expected = [0.15, 0.3, 0.4, 0.4, 0.4];
        for (m, e) in fast.iter().zip(expected) {
            assert!((m - e).abs() < 1e-12, "{fast:?}");
        }
    }

    #[test]
    fn still_bodies_keep_half_the_skin_and_a_lone_mover_among_them_the_limit() {
        let mut margin = Vec::new();
        let mut velocity = vec![DVec3::ZERO; 200];
        by_speed(&velocity, 0.1, &mut margin);
        assert!(margin.iter().all(|&m| m == 0.1));
        velocity[7] = DVec3::new(0.0, 1e-9, 0.0);
        by_speed(&velocity, 0.1, &mut margin);
        assert_eq!(margin[7], 0.1 * GROWTH_LIMIT);
        assert_eq!(margin.iter().filter(|&&m| m == 0.1).count(), 199);
        // A speed that is not a number grows nothing.
        velocity[3] = DVec3::new(f64::NAN, 0.0, 0.0);
        by_speed(&velocity, 0.1, &mut margin);
        assert_eq!(margin[3], 0.1);
        by_speed(&[], 0.1, &mut margin);
        assert!(margin.is_empty());
    }

    #[test]
    fn a_body_is_beyond_its_margin_only_past_it() {
        assert!(!beyond(0.04, 0.2));
        assert!(beyond(0.0401, 0.2));
        assert!(!beyond(0.0, 0.0));
    }
}
