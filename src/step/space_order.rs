//! Bodies kept in space order: every so often the bodies are renumbered along a Morton (Z-order)
//! curve, so that bodies near each other in space are near each other in memory. The contact loops
//! read both bodies of every contact; with bodies in insertion order (a random fill is random in
//! space) nearly every partner is a cache miss once the bodies' data outgrow the cache. LAMMPS
//! and LIGGGHTS do the same (`atom_modify sort`, every 1000 steps by default).

use crate::math::DVec3;

/// Steps between two re-orderings by default: bodies drift slowly out of order.
pub const SORT_INTERVAL: u64 = 1000;

/// Below this many bodies everything the step reads fits in a core's cache and the order does not
/// matter; the world then keeps the insertion order (and so stable body indices).
pub const SORT_MIN_BODIES: usize = 2048;

/// The order of the bodies along the Morton curve through the box around `positions`: the
/// `k`-th body of the new order is body `order[k]` of the old one. Ties (bodies in one cell of
/// the 2²¹-per-axis grid) keep their old order, so the result depends on the positions only.
pub fn morton_order(positions: &[DVec3], order: &mut Vec<u32>) {
    order.clear();
    if positions.is_empty() {
        return;
    }
    let (lo, hi) = positions
        .iter()
        .fold((positions[0], positions[0]), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    let cells = ((1u64 << 21) - 1) as f64;
    let scale = cells / (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let mut keyed: Vec<(u64, u32)> = positions
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let c = ((x - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(cells));
            let code = spread(c.x as u64) | spread(c.y as u64) << 1 | spread(c.z as u64) << 2;
            (code, i as u32)
        })
        .collect();
    keyed.sort_unstable();
    order.extend(keyed.iter().map(|&(_, i)| i));
}

/// The 21 low bits of `v` spread to every third bit (Morton interleaving).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spreading_puts_each_bit_three_places_apart() {
        for bit in 0..21 {
            assert_eq!(spread(1 << bit), 1 << (3 * bit));
        }
        assert_eq!(spread(0x1f_ffff), 0x1249_2492_4924_9249);
    }

    /// Neighbours on a scrambled grid end up near each other in the new order.
    #[test]
    fn grid_neighbours_end_up_near_each_other() {
        let n = 16;
        let mut positions = Vec::new();
        for i in 0..n * n * n {
            // A fixed scramble of the grid cells (multiplication by an odd number modulo 2^12).
            let cell = (i * 2_654_435_761usize) % (n * n * n);
            let (x, y, z) = (cell % n, cell / n % n, cell / (n * n));
            positions.push(DVec3::new(x as f64, y as f64, z as f64));
        }
        // Fraction of x-neighbours at most 64 places apart in memory.
        let near_in_memory = |positions: &[DVec3]| {
            let mut index = std::collections::HashMap::new();
            for (i, x) in positions.iter().enumerate() {
                index.insert((x.x as i64, x.y as i64, x.z as i64), i as i64);
            }
            let (mut near, mut pairs) = (0, 0);
            for (&(x, y, z), &i) in &index {
                if let Some(&j) = index.get(&(x + 1, y, z)) {
                    near += ((i - j).abs() <= 64) as usize;
                    pairs += 1;
                }
            }
            near as f64 / pairs as f64
        };
        let mut order = Vec::new();
        morton_order(&positions, &mut order);
        let sorted: Vec<DVec3> = order.iter().map(|&k| positions[k as usize]).collect();
        let (before, after) = (near_in_memory(&positions), near_in_memory(&sorted));
        assert!(
            before < 0.1,
            "the scramble left neighbours together: {before}"
        );
        assert!(
            after > 0.7,
            "x-neighbours within 64 places after sorting: {after}"
        );
        let mut seen = order.clone();
        seen.sort_unstable();
        assert!(seen.iter().enumerate().all(|(k, &i)| k == i as usize));
    }
}
