//! How far each body's box is enlarged when the candidate list is made ([`Margins`]), and so how
//! far it may move before the list must be made again.
//!
//! A uniform margin of half the skin makes the list last until the fastest body has moved it
//! (with the two largest moves, until they add up to a skin). In a settling bed that is a handful
//! of bodies: on the 10,000-sphere bench bed, steps 5,000–7,000, the list was made every 34 steps,
//! when the fastest body had moved half a skin while half of all bodies had moved less than 0.4 %
//! of it and only one in a hundred more than a tenth (a probe at each list; docs/benchmarks.md).
//! So each body gets a margin in proportion to its speed when the list is made: half the skin at
//! the reference speed, up to [`GROWTH_LIMIT`] times that for the fastest, and down to
//! [`SHRINK_LIMIT`] times it for the slow bulk. The few fast bodies carry larger boxes (few more
//! candidates), the creeping bulk smaller ones (a tenth fewer candidates in a settled bed, whose
//! sort and store every step pays for), and the list lasts until some body has outrun its own
//! margin. The reference speed is that of the body faster than [`REFERENCE_QUANTILE`] of the
//! others, so the rule needs no time step and no scale, and a flow where every body moves alike
//! keeps the uniform margin (and the list's life) it had.
//!
//! Why not smaller still: a creeping body is jostled, and once a step's kick carries it past a
//! small margin the list is made again (a list costs two to four steps of a settled bed). On the
//! 10,000-sphere bench bed, steps 5,000–7,000, the list was made 22 times with the bulk at half
//! the skin, 26 at a half of that and 39 at a quarter, for 36,099, 31,830 and 28,939 candidates;
//! a half and a quarter were as fast, a tenth (68 lists) slower (docs/benchmarks.md, "Margins
//! that shrink for the slow bulk").
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
    /// Half the skin, shrunk or grown with the body's speed ([`by_speed`]); the list is made
    /// again once a body has moved beyond its own margin. A single world's.
    ByBody,
}

/// The most a margin grows: four times half the skin, two skins. A fast body's box then reaches
/// a few more neighbours in a dense bed; more would make the fastest hundredth of a flowing bed
/// carry boxes with several times the partners.
pub const GROWTH_LIMIT: f64 = 4.0;

/// The least a margin shrinks: half of half the skin, for a body far slower than the reference
/// (or still).
pub const SHRINK_LIMIT: f64 = 0.5;

/// The share of bodies at least as slow as the reference speed (see the module's text).
pub const REFERENCE_QUANTILE: f64 = 0.99;

/// Each body's margin for the velocities `velocity` (`out`, cleared first): half the skin
/// `half_skin`, times the body's speed over the reference speed, at least [`SHRINK_LIMIT`] and
/// at most [`GROWTH_LIMIT`] times (a body that is not still among still ones: the growth limit;
/// a still one: the shrink limit). A function of the velocities alone, so the same for any
/// thread count.
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
/// `reference_squared`: the ratio of the speeds, at least [`SHRINK_LIMIT`] and at most
/// [`GROWTH_LIMIT`]; 1 for a speed that is not a number (which the run's checks stop it for).
fn growth(squared: f64, reference_squared: f64) -> f64 {
    if squared > reference_squared {
        // Above a still reference (0): the quotient is infinite, and the growth limit is taken.
        (squared / reference_squared).sqrt().min(GROWTH_LIMIT)
    } else if squared <= reference_squared {
        // A still body under a still reference: 0/0, not a number, which `max` passes over.
        (squared / reference_squared).sqrt().max(SHRINK_LIMIT)
    } else {
        // A speed that is not a number compares false both ways.
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
    fn margins_follow_the_speed_from_the_shrink_limit_to_the_growth_limit() {
        // 1,000 bodies: 985 creep at 1 mm/s or less, 10 at 2 mm/s, five fly at 3, 6, 10, 50 and
        // 500 mm/s. The reference is the 990th slowest's speed, 2 mm/s.
        let creep = |k: usize| 1e-3 * k as f64 / 985.0;
        let mut velocity: Vec<DVec3> = (0..985).map(|k| DVec3::new(0.0, creep(k), 0.0)).collect();
        velocity.extend((0..10).map(|_| DVec3::new(0.0, 0.0, -2e-3)));
        velocity.extend([3e-3, 6e-3, 10e-3, 50e-3, 500e-3].map(|s| DVec3::new(s, 0.0, 0.0)));
        let mut margin = Vec::new();
        by_speed(&velocity, 0.1, &mut margin);
        assert_eq!(margin.len(), 1000);
        // At half the reference speed or less: the shrink limit.
        assert!(
            margin[..985].iter().all(|&m| m == 0.1 * SHRINK_LIMIT),
            "the creeping bulk's margin"
        );
        assert!(
            margin[985..995].iter().all(|&m| m == 0.1),
            "at the reference"
        );
        let fast = &margin[995..];
        let expected = [0.15, 0.3, 0.4, 0.4, 0.4];
        for (m, e) in fast.iter().zip(expected) {
            assert!((m - e).abs() < 1e-12, "{fast:?}");
        }
        // Between the shrink limit and the reference speed, in proportion to the speed.
        velocity[0] = DVec3::new(1.5e-3, 0.0, 0.0);
        by_speed(&velocity, 0.1, &mut margin);
        assert!((margin[0] - 0.075).abs() < 1e-12, "{}", margin[0]);
    }

    #[test]
    fn still_bodies_take_the_shrink_limit_and_a_lone_mover_among_them_the_growth_limit() {
        let mut margin = Vec::new();
        let mut velocity = vec![DVec3::ZERO; 200];
        let least = 0.1 * SHRINK_LIMIT;
        by_speed(&velocity, 0.1, &mut margin);
        assert!(margin.iter().all(|&m| m == least));
        velocity[7] = DVec3::new(0.0, 1e-9, 0.0);
        by_speed(&velocity, 0.1, &mut margin);
        assert_eq!(margin[7], 0.1 * GROWTH_LIMIT);
        assert_eq!(margin.iter().filter(|&&m| m == least).count(), 199);
        // A speed that is not a number keeps half the skin.
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
