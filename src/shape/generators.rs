//! Built-in convex shapes: boxes, the regular polyhedra (not the cube, a box), regular prisms and
//! seeded random "rocks". Each is built by `ConvexPolyhedron::from_points` from its vertices, so
//! it comes in its principal frame with its mass properties (of the points as generated below,
//! centred on the origin unless said otherwise).

use super::{ConvexPolyhedron, MassProperties, ShapeError};
use crate::math::DVec3;
use crate::rng::SplitMix64;
use std::f64::consts::TAU;

type Built = Result<(ConvexPolyhedron, MassProperties), ShapeError>;

/// The golden ratio φ = (1 + √5)/2.
const PHI: f64 = 1.618_033_988_749_895;

fn positive(name: &str, value: f64) -> Result<f64, ShapeError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ShapeError::InvalidParameter(format!(
            "{name} must be a positive finite number, got {value}"
        )))
    }
}

/// A rectangular box with side lengths `a`, `b`, `c` along x, y, z.
pub fn cuboid(a: f64, b: f64, c: f64) -> Built {
    let half = DVec3::new(positive("a", a)?, positive("b", b)?, positive("c", c)?) * 0.5;
    let points: Vec<DVec3> = (0..8)
        .map(|k| {
            let sign = |bit: u32| if k >> bit & 1 == 0 { -1.0 } else { 1.0 };
            half * DVec3::new(sign(0), sign(1), sign(2))
        })
        .collect();
    ConvexPolyhedron::from_points(&points)
}

/// Regular tetrahedron: alternate corners of a cube, (±1, ±1, ±1) with an even number of minus
/// signs, whose edge is 2√2.
pub fn regular_tetrahedron(edge: f64) -> Built {
    let s = positive("edge", edge)? / (2.0 * 2f64.sqrt());
    let points = [
        (1.0, 1.0, 1.0),
        (1.0, -1.0, -1.0),
        (-1.0, 1.0, -1.0),
        (-1.0, -1.0, 1.0),
    ];
    ConvexPolyhedron::from_points(&points.map(|(x, y, z)| s * DVec3::new(x, y, z)))
}

/// Regular octahedron: (±1, 0, 0) and permutations, edge √2.
pub fn regular_octahedron(edge: f64) -> Built {
    let s = positive("edge", edge)? / 2f64.sqrt();
    let points = [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    ConvexPolyhedron::from_points(&points.map(|p| s * p))
}

/// Regular dodecahedron: (±1, ±1, ±1) and the cyclic permutations of (0, ±1/φ, ±φ), edge 2/φ.
pub fn regular_dodecahedron(edge: f64) -> Built {
    let s = positive("edge", edge)? * PHI / 2.0;
    let mut points = Vec::with_capacity(20);
    for k in 0..8 {
        let sign = |bit: u32| if k >> bit & 1 == 0 { -1.0 } else { 1.0 };
        points.push(DVec3::new(sign(0), sign(1), sign(2)));
    }
    for k in 0..4 {
        let sign = |bit: u32| if k >> bit & 1 == 0 { -1.0 } else { 1.0 };
        let (u, v) = (sign(0) / PHI, sign(1) * PHI);
        points.extend(cyclic(DVec3::new(0.0, u, v)));
    }
    ConvexPolyhedron::from_points(&points.iter().map(|&p| s * p).collect::<Vec<_>>())
}

/// Regular icosahedron: the cyclic permutations of (0, ±1, ±φ), edge 2.
pub fn regular_icosahedron(edge: f64) -> Built {
    let s = positive("edge", edge)? / 2.0;
    let mut points = Vec::with_capacity(12);
    for k in 0..4 {
        let sign = |bit: u32| if k >> bit & 1 == 0 { -1.0 } else { 1.0 };
        points.extend(cyclic(DVec3::new(0.0, sign(0), sign(1) * PHI)));
    }
    ConvexPolyhedron::from_points(&points.iter().map(|&p| s * p).collect::<Vec<_>>())
}

fn cyclic(p: DVec3) -> [DVec3; 3] {
    [p, DVec3::new(p.z, p.x, p.y), DVec3::new(p.y, p.z, p.x)]
}

/// A right prism over a regular `n`-gon with the given circumradius; its axis along z.
pub fn regular_prism(n: usize, circumradius: f64, height: f64) -> Built {
    if n < 3 {
        return Err(ShapeError::InvalidParameter(format!(
            "a prism needs a polygon of at least 3 sides, got {n}"
        )));
    }
    let r = positive("circumradius", circumradius)?;
    let h = positive("height", height)? / 2.0;
    let mut points = Vec::with_capacity(2 * n);
    for k in 0..n {
        let angle = TAU * k as f64 / n as f64;
        let (sin, cos) = angle.sin_cos();
        points.push(DVec3::new(r * cos, r * sin, -h));
        points.push(DVec3::new(r * cos, r * sin, h));
    }
    ConvexPolyhedron::from_points(&points)
}

/// A seeded random convex "rock": the hull of `vertex_count` points spread over an ellipsoid with
/// semi-axes proportional to `elongation`, scaled so that its volume is that of a sphere of
/// diameter `size` (the volume-equivalent diameter).
///
/// The points are drawn uniformly on the unit sphere (normalised Gaussian triples, Muller 1959)
/// with a minimum angular spacing of half the mean spacing √(4π/n) (dart throwing), so that no
/// sliver faces or tiny edges appear; then stretched by `elongation`. All points on an ellipsoid
/// are corners of their hull, so the rock has `vertex_count` vertices. The same seed gives the same
/// rock on every platform that rounds IEEE arithmetic alike.
pub fn random_rock(seed: u64, vertex_count: usize, elongation: DVec3, size: f64) -> Built {
    if vertex_count < 4 {
        return Err(ShapeError::InvalidParameter(format!(
            "a rock needs at least 4 vertices, got {vertex_count}"
        )));
    }
    for (axis, e) in ["x", "y", "z"].iter().zip(elongation.to_array()) {
        positive(&format!("elongation {axis}"), e)?;
    }
    let size = positive("size", size)?;
    let mut rng = SplitMix64::new(seed);
    let min_spacing = 0.5 * (4.0 * std::f64::consts::PI / vertex_count as f64).sqrt();
    let mut directions: Vec<DVec3> = Vec::with_capacity(vertex_count);
    let mut attempts = 0usize;
    while directions.len() < vertex_count {
        let d = DVec3::new(rng.normal(), rng.normal(), rng.normal());
        let Some(d) = d.try_normalize() else {
            continue;
        };
        attempts += 1;
        // Spacing is a wish, not a must: after many rejections accept anything.
        let crowded = directions.iter().any(|&e| (e - d).length() < min_spacing);
        if !crowded || attempts > 1000 * vertex_count {
            directions.push(d);
        }
    }
    let points: Vec<DVec3> = directions.iter().map(|&d| d * elongation).collect();
    let (rock, mass) = ConvexPolyhedron::from_points(&points)?;
    let equivalent_volume = std::f64::consts::PI / 6.0 * size.powi(3);
    let factor = (equivalent_volume / mass.volume).cbrt();
    Ok((rock.scaled(factor), mass.scaled(factor)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(p: &ConvexPolyhedron) -> (usize, usize, usize) {
        (p.vertices().len(), p.edges().len(), p.faces().len())
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn box_counts_and_mass() {
        let (p, m) = cuboid(1.0, 2.0, 3.0).unwrap();
        assert_eq!(counts(&p), (8, 12, 6));
        assert!(close(m.volume, 6.0, 1e-14));
        assert!(m.center_of_mass.length() < 1e-15);
        // The long side (c = 3) is the axis of the smallest moment: body x.
        assert!(close(p.bounds().max.x, 1.5, 1e-15));
        assert!(close(
            p.unit_mass_properties().principal_inertia_per_density.x,
            6.0 * 5.0 / 12.0,
            1e-14
        ));
    }

    #[test]
    fn regular_polyhedra_counts_and_volumes() {
        let a: f64 = 0.7;
        let sqrt5 = 5f64.sqrt();
        type Case = (Built, (usize, usize, usize), f64, f64);
        let cases: [Case; 4] = [
            // (shape, (V, E, F), volume / a³, I / (m a²))
            (
                regular_tetrahedron(a),
                (4, 6, 4),
                1.0 / (6.0 * 2f64.sqrt()),
                1.0 / 20.0,
            ),
            (
                regular_octahedron(a),
                (6, 12, 8),
                2f64.sqrt() / 3.0,
                1.0 / 10.0,
            ),
            (
                regular_dodecahedron(a),
                (20, 30, 12),
                (15.0 + 7.0 * sqrt5) / 4.0,
                (95.0 + 39.0 * sqrt5) / 300.0,
            ),
            (
                regular_icosahedron(a),
                (12, 30, 20),
                5.0 * (3.0 + sqrt5) / 12.0,
                (3.0 + sqrt5) / 20.0,
            ),
        ];
        for (built, expected_counts, volume, inertia) in cases {
            let (p, m) = built.unwrap();
            assert_eq!(counts(&p), expected_counts);
            assert!(
                close(m.volume, volume * a.powi(3), 1e-13),
                "{} vs {}",
                m.volume,
                volume * a.powi(3)
            );
            let expected_i = inertia * m.volume * a * a;
            let moments = m.principal_moments;
            assert!(
                (moments - DVec3::splat(expected_i)).abs().max_element() < 1e-12 * expected_i,
                "{moments}"
            );
            // Every edge has length a.
            for e in p.edges() {
                let [u, v] = e.vertices.map(|i| p.vertices()[i]);
                assert!(close((u - v).length(), a, 1e-12));
            }
        }
        // Dodecahedron: pentagons merged from nearly (not exactly) coplanar hull triangles.
        let (p, _) = regular_dodecahedron(1.0).unwrap();
        assert!(p.faces().iter().all(|f| f.vertices.len() == 5));
    }

    #[test]
    fn prisms() {
        for n in [3, 4, 5, 6, 17, 64] {
            let (r, h) = (0.4, 1.3);
            let (p, m) = regular_prism(n, r, h).unwrap();
            assert_eq!(counts(&p), (2 * n, 3 * n, n + 2));
            let base_area = 0.5 * n as f64 * r * r * (TAU / n as f64).sin();
            assert!(close(m.volume, base_area * h, 1e-13));
        }
        assert!(matches!(
            regular_prism(2, 1.0, 1.0),
            Err(ShapeError::InvalidParameter(_))
        ));
        assert!(matches!(
            regular_prism(5, -1.0, 1.0),
            Err(ShapeError::InvalidParameter(_))
        ));
    }

    #[test]
    fn rocks_are_seeded_sized_and_elongated() {
        let elongation = DVec3::new(2.0, 1.0, 0.6);
        let (a, ma) = random_rock(7, 50, elongation, 0.01).unwrap();
        let (b, _) = random_rock(7, 50, elongation, 0.01).unwrap();
        let (c, _) = random_rock(8, 50, elongation, 0.01).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(a.vertices().len(), 50);
        let d = 0.01f64;
        assert!(close(
            ma.volume,
            std::f64::consts::PI / 6.0 * d.powi(3),
            1e-12
        ));
        // Principal frame: longest extent along body x, shortest along z.
        let ext = a.bounds().extent();
        assert!(ext.x > ext.y && ext.y > ext.z, "{ext}");
        let ratio = ext.x / ext.z;
        assert!(ratio > 2.5 && ratio < 3.5, "{ratio}");
        let (round, _) = random_rock(1, 200, DVec3::ONE, 1.0).unwrap();
        assert_eq!(round.vertices().len(), 200);
        assert!(round.bounding_radius() < 0.56 && round.bounding_radius() > 0.5);
        assert!(matches!(
            random_rock(1, 3, DVec3::ONE, 1.0),
            Err(ShapeError::InvalidParameter(_))
        ));
        assert!(matches!(
            random_rock(1, 9, DVec3::new(1.0, 0.0, 1.0), 1.0),
            Err(ShapeError::InvalidParameter(_))
        ));
    }
}
