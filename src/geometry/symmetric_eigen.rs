//! Eigen-decomposition of a symmetric 3×3 matrix by the cyclic Jacobi method.
//!
//! Golub & Van Loan (2013), "Matrix Computations", 4th ed., §8.5.2–8.5.3: sweep over the
//! off-diagonal entries in row order, annihilating each with a plane rotation chosen by
//! `sym.schur2` (Algorithm 8.5.1). Convergence is quadratic; a 3×3 matrix needs about 5 sweeps
//! to reach rounding level. Jacobi is used rather than a closed-form cubic because it is accurate
//! for nearly equal eigenvalues (cubes, regular polyhedra), and because an already diagonal matrix
//! is left untouched: its eigenvectors come out as exact signed unit vectors, so the principal
//! frame of an axis-aligned box is an exact axis permutation.

use crate::math::{DMat3, DQuat, DVec3};

/// Eigenvalues in ascending order and the matching unit eigenvectors as the columns of a proper
/// rotation matrix (det = +1), so that `a = v · diag(λ) · vᵀ`.
///
/// `a` must be symmetric (only its upper triangle is read).
pub fn symmetric_eigen(a: DMat3) -> (DVec3, DMat3) {
    // Row-major working copy: m[i][j] = a_ij.
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            let (r, c) = if i <= j { (i, j) } else { (j, i) };
            *entry = a.col(c)[r];
        }
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    let frobenius = m.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    for _sweep in 0..50 {
        let off = (2.0 * (m[0][1].powi(2) + m[0][2].powi(2) + m[1][2].powi(2))).sqrt();
        if off <= f64::EPSILON * frobenius || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            let (c, s) = sym_schur2(&m, p, q);
            if s == 0.0 {
                continue;
            }
            // m ← Jᵀ m J, with J the identity except J_pp = J_qq = c, J_pq = s, J_qp = −s.
            for row in m.iter_mut() {
                let (mp, mq) = (row[p], row[q]);
                row[p] = c * mp - s * mq;
                row[q] = s * mp + c * mq;
            }
            let (row_p, row_q) = (m[p], m[q]);
            for k in 0..3 {
                m[p][k] = c * row_p[k] - s * row_q[k];
                m[q][k] = s * row_p[k] + c * row_q[k];
            }
            m[p][q] = 0.0; // exactly, by construction of (c, s)
            m[q][p] = 0.0;
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }

    // Sort ascending; the sort is stable so that equal eigenvalues keep their axes' order.
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| m[i][i].total_cmp(&m[j][j]));
    let values = DVec3::new(
        m[order[0]][order[0]],
        m[order[1]][order[1]],
        m[order[2]][order[2]],
    );
    let column = |k: usize| DVec3::new(v[0][k], v[1][k], v[2][k]);
    let (c0, c1, mut c2) = (column(order[0]), column(order[1]), column(order[2]));
    // Eigenvectors are defined up to sign: flip the last one to make the frame right-handed.
    if c0.cross(c1).dot(c2) < 0.0 {
        c2 = -c2;
    }
    (values, DMat3::from_cols(c0, c1, c2))
}

/// The rotation from the eigenframe to the input frame, as a unit quaternion.
pub fn eigen_rotation(axes: DMat3) -> DQuat {
    DQuat::from_mat3(&axes).normalize()
}

/// Golub & Van Loan Algorithm 8.5.1: cosine–sine pair that zeroes entry (p, q) of `m`.
fn sym_schur2(m: &[[f64; 3]; 3], p: usize, q: usize) -> (f64, f64) {
    if m[p][q] == 0.0 {
        return (1.0, 0.0);
    }
    let tau = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
    // The smaller root of t² + 2τt − 1 = 0 (|θ| ≤ π/4), written without cancellation;
    // hypot keeps it finite for huge |τ|.
    let t = if tau >= 0.0 {
        1.0 / (tau + tau.hypot(1.0))
    } else {
        -1.0 / (-tau + tau.hypot(1.0))
    };
    let c = 1.0 / t.hypot(1.0);
    (c, t * c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn reconstruct(values: DVec3, v: DMat3) -> DMat3 {
        v * DMat3::from_diagonal(values) * v.transpose()
    }

    fn max_abs_diff(a: DMat3, b: DMat3) -> f64 {
        (0..3)
            .flat_map(|j| (0..3).map(move |i| (j, i)))
            .map(|(j, i)| (a.col(j)[i] - b.col(j)[i]).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn diagonal_matrix_gives_exact_permutation() {
        let a = DMat3::from_diagonal(DVec3::new(3.0, 1.0, 2.0));
        let (values, v) = symmetric_eigen(a);
        assert_eq!(values, DVec3::new(1.0, 2.0, 3.0));
        for j in 0..3 {
            for i in 0..3 {
                let x = v.col(j)[i];
                assert!(x == 0.0 || x.abs() == 1.0);
            }
        }
        assert_eq!(v.determinant(), 1.0);
        assert_eq!(reconstruct(values, v), a);
    }

    #[test]
    fn known_matrix() {
        // Eigenvalues of [[2,1,0],[1,2,0],[0,0,5]] are 1, 3, 5.
        let a = DMat3::from_cols(
            DVec3::new(2.0, 1.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 0.0, 5.0),
        );
        let (values, v) = symmetric_eigen(a);
        assert!((values - DVec3::new(1.0, 3.0, 5.0)).abs().max_element() < 1e-14);
        assert!(max_abs_diff(reconstruct(values, v), a) < 1e-14);
    }

    proptest! {
        #[test]
        fn random_symmetric_matrices(e in proptest::array::uniform6(-1e3f64..1e3)) {
            let a = DMat3::from_cols(
                DVec3::new(e[0], e[3], e[4]),
                DVec3::new(e[3], e[1], e[5]),
                DVec3::new(e[4], e[5], e[2]),
            );
            let (values, v) = symmetric_eigen(a);
            prop_assert!(values.x <= values.y && values.y <= values.z);
            prop_assert!((v.determinant() - 1.0).abs() < 1e-13);
            prop_assert!(max_abs_diff(v.transpose() * v, DMat3::IDENTITY) < 1e-14);
            let scale = e.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            prop_assert!(max_abs_diff(reconstruct(values, v), a) < 1e-13 * scale);
            let q = eigen_rotation(v);
            prop_assert!(max_abs_diff(DMat3::from_quat(q), v) < 1e-14);
        }
    }
}
