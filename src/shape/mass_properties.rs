//! Exact mass properties (volume, centre of mass, inertia tensor, principal axes) of a solid
//! bounded by a closed triangle mesh, at unit density.
//!
//! By the divergence theorem the volume integrals of 1, x and x xᵀ over the solid equal sums over
//! the signed tetrahedra spanned by a reference point and each surface triangle (Mirtich 1996,
//! "Fast and accurate computation of polyhedral mass properties"; the tetrahedron moments are those
//! of Tonon 2004, "Explicit exact formulas for the 3-D tetrahedron inertia tensor in terms of its
//! vertex coordinates"). Parts of tetrahedra outside the solid cancel between triangles, so the
//! sums are exact for any closed, consistently outward-oriented mesh, convex or not.

use super::{ShapeError, UnitMassProperties};
use crate::geometry::symmetric_eigen::{eigen_rotation, symmetric_eigen};
use crate::math::{DMat3, DQuat, DVec3};

/// Mass properties of a solid of unit density, in the frame of its input coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Volume \[m³\] (the mass at density 1).
    pub volume: f64,
    /// Centre of mass in the input frame \[m\].
    pub center_of_mass: DVec3,
    /// Inertia tensor about the centre of mass, axes of the input frame, per unit density \[m⁵\].
    pub inertia: DMat3,
    /// Principal moments of inertia per unit density, ascending \[m⁵\].
    pub principal_moments: DVec3,
    /// Columns: the principal axes in the input frame, right-handed (det = +1). As a matrix it maps
    /// principal-frame coordinates to input-frame directions: `inertia = A · diag(moments) · Aᵀ`.
    pub principal_axes: DMat3,
}

impl MassProperties {
    /// Mass properties of the solid bounded by `triangles` (indices into `vertices`), each
    /// counter-clockwise seen from outside.
    ///
    /// A mesh that is not closed gives meaningless numbers (not detected here). An inward-oriented
    /// or flat mesh gives a volume ≤ 10⁻¹² L³ (L the diagonal of its bounding box), which is
    /// refused.
    pub fn from_mesh(vertices: &[DVec3], triangles: &[[usize; 3]]) -> Result<Self, ShapeError> {
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v >= vertices.len()) {
                return Err(ShapeError::VertexIndexOutOfRange {
                    triangle: t,
                    vertex: v,
                    count: vertices.len(),
                });
            }
        }
        let crate::math::Aabb { min: lo, max: hi } =
            crate::geometry::point_in_polyhedron::bounds_of(vertices, triangles);
        if triangles.is_empty() {
            return Err(ShapeError::NonPositiveVolume {
                volume: 0.0,
                size: 0.0,
            });
        }
        // Integrate about the middle of the bounding box: keeps the terms small and the
        // cancellation between them mild wherever the mesh sits in space.
        let reference = 0.5 * (lo + hi);
        let size = (hi - lo).length();

        let mut six_volume = 0.0; // Σ det
        let mut first = DVec3::ZERO; // Σ det (a + b + c), = 24 ∫x dV
        let mut second = DMat3::ZERO; // Σ det (aaᵀ + bbᵀ + ccᵀ + ssᵀ), = 120 ∫x xᵀ dV
        for tri in triangles {
            let [a, b, c] = tri.map(|i| vertices[i] - reference);
            // Signed tetrahedron (0, a, b, c): volume det/6, ∫x dV = det/24 (a + b + c) and
            // ∫x xᵀ dV = det/120 (Σ vvᵀ + s sᵀ), s = a + b + c (Tonon 2004, eqs. 2–7).
            let det = a.dot(b.cross(c));
            let s = a + b + c;
            six_volume += det;
            first += det * s;
            second += det * (outer(a, a) + outer(b, b) + outer(c, c) + outer(s, s));
        }
        let volume = six_volume / 6.0;
        // Written so that a NaN volume is refused too.
        if volume.is_nan() || volume <= 1e-12 * size.powi(3) {
            return Err(ShapeError::NonPositiveVolume { volume, size });
        }
        let centroid = first / (24.0 * volume);
        // Second moment about the centre of mass (parallel-axis theorem), then
        // I = tr(C) 1 − C for C = ∫ r rᵀ dV.
        let c_com = second / 120.0 - volume * outer(centroid, centroid);
        let c_com = symmetrised(c_com);
        let trace = c_com.col(0).x + c_com.col(1).y + c_com.col(2).z;
        let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - c_com;
        let (principal_moments, principal_axes) = symmetric_eigen(inertia);
        Ok(Self {
            volume,
            center_of_mass: reference + centroid,
            inertia,
            principal_moments,
            principal_axes,
        })
    }

    /// The rotation from the principal frame to the input frame.
    pub fn principal_rotation(&self) -> DQuat {
        eigen_rotation(self.principal_axes)
    }

    /// Volume and principal moments, as the rest of the engine uses them.
    pub fn unit(&self) -> UnitMassProperties {
        UnitMassProperties {
            volume: self.volume,
            principal_inertia_per_density: self.principal_moments,
        }
    }

    /// The mass properties of the solid scaled by `factor` about the input origin
    /// (volume ∝ factor³, inertia ∝ factor⁵).
    pub fn scaled(&self, factor: f64) -> Self {
        let f5 = factor.powi(5);
        Self {
            volume: self.volume * factor.powi(3),
            center_of_mass: self.center_of_mass * factor,
            inertia: self.inertia * f5,
            principal_moments: self.principal_moments * f5,
            principal_axes: self.principal_axes,
        }
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn symmetrised(m: DMat3) -> DMat3 {
    (m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::convex_hull::convex_hull;
    use crate::geometry::test_meshes::{box_mesh, l_shape_mesh};
    use crate::rng::SplitMix64;
    use proptest::prelude::*;

    fn max_abs(m: DMat3) -> f64 {
        (0..3)
            .map(|j| m.col(j).abs().max_element())
            .fold(0.0, f64::max)
    }

    fn hull_mesh(points: &[DVec3]) -> (Vec<DVec3>, Vec<[usize; 3]>) {
        (points.to_vec(), convex_hull(points).unwrap())
    }

    fn assert_isotropic(p: &MassProperties, expected: f64) {
        let err = (p.principal_moments - DVec3::splat(expected))
            .abs()
            .max_element();
        assert!(
            err < 1e-13 * expected,
            "{:?} vs {expected}",
            p.principal_moments
        );
        assert!(
            max_abs(p.inertia - DMat3::from_diagonal(DVec3::splat(expected))) < 1e-13 * expected
        );
    }

    #[test]
    fn unit_cube() {
        let (v, t) = box_mesh(DVec3::ZERO, DVec3::ONE);
        let p = MassProperties::from_mesh(&v, &t).unwrap();
        assert!((p.volume - 1.0).abs() < 1e-15);
        assert!((p.center_of_mass - DVec3::splat(0.5)).length() < 1e-15);
        // I = m a²/6 about any axis through the centre.
        assert_isotropic(&p, 1.0 / 6.0);
    }

    #[test]
    fn box_1_by_2_by_3() {
        let (a, b, c) = (1.0, 2.0, 3.0);
        let (v, t) = box_mesh(
            DVec3::new(-4.0, 1.0, 7.0),
            DVec3::new(-4.0 + a, 1.0 + b, 7.0 + c),
        );
        let p = MassProperties::from_mesh(&v, &t).unwrap();
        let m = a * b * c;
        assert!((p.volume - m).abs() < 1e-13);
        assert!((p.center_of_mass - DVec3::new(-3.5, 2.0, 8.5)).length() < 1e-13);
        // I_x = m (b² + c²)/12 etc., ascending: about z (1+4), y (1+9), x (4+9).
        let expected = DVec3::new(a * a + b * b, a * a + c * c, b * b + c * c) * m / 12.0;
        assert!((p.principal_moments - expected).abs().max_element() < 1e-12);
        // The smallest moment is about the longest side (z).
        assert!((p.principal_axes.col(0).z.abs() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn regular_tetrahedron() {
        // Alternate corners of a cube of side 2: edge a = 2√2, volume a³/(6√2) = 8/3.
        let pts = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        let (v, t) = hull_mesh(&pts);
        let p = MassProperties::from_mesh(&v, &t).unwrap();
        let a2 = 8.0;
        assert!((p.volume - 8.0 / 3.0).abs() < 1e-14);
        assert!(p.center_of_mass.length() < 1e-15);
        // I = m a²/20 about every axis through the centroid.
        assert_isotropic(&p, p.volume * a2 / 20.0);
    }

    #[test]
    fn regular_octahedron() {
        // Vertices ±e_i: edge a = √2, volume √2 a³/3 = 4/3.
        let pts = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ];
        let (v, t) = hull_mesh(&pts);
        let p = MassProperties::from_mesh(&v, &t).unwrap();
        assert!((p.volume - 4.0 / 3.0).abs() < 1e-14);
        // I = m a²/10.
        assert_isotropic(&p, p.volume * 2.0 / 10.0);
    }

    #[test]
    fn l_shape_equals_its_two_boxes() {
        // Non-convex: [0,2]×[0,1]×[0,1] ∪ [0,1]×[1,2]×[0,1] (see test_meshes).
        let (v, t) = l_shape_mesh();
        let p = MassProperties::from_mesh(&v, &t).unwrap();
        let parts = [
            (DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0)),
            (DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 2.0, 1.0)),
        ];
        let parts: Vec<MassProperties> = parts
            .iter()
            .map(|&(lo, hi)| {
                let (v, t) = box_mesh(lo, hi);
                MassProperties::from_mesh(&v, &t).unwrap()
            })
            .collect();
        let volume: f64 = parts.iter().map(|q| q.volume).sum();
        let com = parts
            .iter()
            .map(|q| q.volume * q.center_of_mass)
            .sum::<DVec3>()
            / volume;
        // Parallel-axis theorem: I = Σ I_k + m_k (|d|² 1 − d dᵀ), d = c_k − c.
        let inertia = parts.iter().fold(DMat3::ZERO, |acc, q| {
            let d = q.center_of_mass - com;
            acc + q.inertia
                + q.volume * (DMat3::from_diagonal(DVec3::splat(d.length_squared())) - outer(d, d))
        });
        assert!((p.volume - 3.0).abs() < 1e-14 && (volume - 3.0).abs() < 1e-14);
        assert!((p.center_of_mass - com).length() < 1e-14);
        assert!((com - DVec3::new(5.0 / 6.0, 5.0 / 6.0, 0.5)).length() < 1e-14);
        assert!(
            max_abs(p.inertia - inertia) < 1e-13,
            "{:?}\n{:?}",
            p.inertia,
            inertia
        );
    }

    #[test]
    fn inverted_and_flat_meshes_are_refused() {
        let (v, t) = box_mesh(DVec3::ZERO, DVec3::ONE);
        let inverted: Vec<[usize; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        assert!(matches!(
            MassProperties::from_mesh(&v, &inverted),
            Err(ShapeError::NonPositiveVolume { .. })
        ));
        let (v, t) = box_mesh(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0));
        assert!(matches!(
            MassProperties::from_mesh(&v, &t),
            Err(ShapeError::NonPositiveVolume { .. })
        ));
        assert!(matches!(
            MassProperties::from_mesh(&v, &[[0, 1, 99]]),
            Err(ShapeError::VertexIndexOutOfRange { vertex: 99, .. })
        ));
    }

    /// Random convex hulls against a Monte Carlo estimate of ∫1, ∫x, ∫x xᵀ over the solid.
    ///
    /// N = 10⁶ uniform samples in the bounding box B per hull; each integral ∫f is estimated by
    /// |B| · mean(f · χ) with standard error |B| · std(f · χ) / √N. Every component must agree
    /// within 5 standard errors (two-sided false-alarm chance 6·10⁻⁷ per component; the seeds
    /// are fixed, so the test is deterministic anyway).
    #[test]
    fn random_hulls_against_monte_carlo() {
        const N: usize = 1_000_000;
        let mut rng = SplitMix64::new(2024);
        for hull_index in 0..3 {
            let pts: Vec<DVec3> = (0..12 + 10 * hull_index)
                .map(|_| {
                    DVec3::new(
                        rng.uniform(-1.0, 2.0),
                        rng.uniform(0.0, 1.0),
                        rng.uniform(-0.5, 0.5),
                    )
                })
                .collect();
            let (v, t) = hull_mesh(&pts);
            let p = MassProperties::from_mesh(&v, &t).unwrap();
            let planes: Vec<(DVec3, f64)> = t
                .iter()
                .map(|&[a, b, c]| {
                    let n = (v[b] - v[a]).cross(v[c] - v[a]);
                    (n, n.dot(v[a]))
                })
                .collect();
            let (lo, hi) = v
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), &x| {
                    (l.min(x), h.max(x))
                });
            let box_volume = (hi - lo).x * (hi - lo).y * (hi - lo).z;
            // Ten integrands: 1, x, y, z, xx, yy, zz, xy, yz, zx.
            let integrand = |x: DVec3| {
                [
                    1.0,
                    x.x,
                    x.y,
                    x.z,
                    x.x * x.x,
                    x.y * x.y,
                    x.z * x.z,
                    x.x * x.y,
                    x.y * x.z,
                    x.z * x.x,
                ]
            };
            let mut sum = [0.0; 10];
            let mut sum_sq = [0.0; 10];
            for _ in 0..N {
                let x = lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
                if planes.iter().all(|&(n, d)| n.dot(x) <= d) {
                    for (k, f) in integrand(x).into_iter().enumerate() {
                        sum[k] += f;
                        sum_sq[k] += f * f;
                    }
                }
            }
            // Exact values: raw second moments about the origin from I and the centre of mass.
            let c = p.center_of_mass;
            let trace_i = p.inertia.col(0).x + p.inertia.col(1).y + p.inertia.col(2).z;
            let second = DMat3::from_diagonal(DVec3::splat(trace_i / 2.0)) - p.inertia
                + p.volume * outer(c, c);
            let m = p.volume;
            let exact = [
                m,
                m * c.x,
                m * c.y,
                m * c.z,
                second.col(0).x,
                second.col(1).y,
                second.col(2).z,
                second.col(1).x,
                second.col(2).y,
                second.col(0).z,
            ];
            for k in 0..10 {
                let mean = sum[k] / N as f64;
                let var = sum_sq[k] / N as f64 - mean * mean;
                let estimate = box_volume * mean;
                let standard_error = box_volume * (var / N as f64).sqrt();
                assert!(
                    (estimate - exact[k]).abs() < 5.0 * standard_error,
                    "hull {hull_index}, integrand {k}: MC {estimate} ± {standard_error}, exact {}",
                    exact[k]
                );
            }
        }
    }

    fn random_rotation(axis: [f64; 3], angle: f64) -> DQuat {
        let axis = DVec3::from(axis);
        if axis.length() < 1e-3 {
            DQuat::IDENTITY
        } else {
            DQuat::from_axis_angle(axis.normalize(), angle)
        }
    }

    proptest! {
        /// Rigidly moving a mesh moves its mass properties: V' = V, c' = R c + t,
        /// I' = R I Rᵀ, same principal moments. Checked on the non-convex L-shape and a hull.
        #[test]
        fn rigid_motion_transforms_mass_properties(
            axis in proptest::array::uniform3(-1.0f64..1.0),
            angle in -3.2f64..3.2,
            shift in proptest::array::uniform3(-100.0f64..100.0),
            seed in any::<u64>(),
        ) {
            let q = random_rotation(axis, angle);
            let r = DMat3::from_quat(q);
            let t = DVec3::from(shift);
            let mut rng = SplitMix64::new(seed);
            let cloud: Vec<DVec3> = (0..20)
                .map(|_| DVec3::new(rng.normal(), 0.5 * rng.normal(), 2.0 * rng.normal()))
                .collect();
            for (v, tris) in [l_shape_mesh(), hull_mesh(&cloud)] {
                let p = MassProperties::from_mesh(&v, &tris).unwrap();
                let moved: Vec<DVec3> = v.iter().map(|&x| q * x + t).collect();
                let pm = MassProperties::from_mesh(&moved, &tris).unwrap();
                let scale = p.principal_moments.z;
                prop_assert!((pm.volume - p.volume).abs() < 1e-11 * p.volume);
                prop_assert!((pm.center_of_mass - (q * p.center_of_mass + t)).length() < 1e-11);
                prop_assert!(max_abs(pm.inertia - r * p.inertia * r.transpose()) < 1e-10 * scale);
                prop_assert!(
                    (pm.principal_moments - p.principal_moments).abs().max_element() < 1e-10 * scale
                );
            }
        }
    }
}
