//! `symmetric_eigen` and the inertia check of `SpatialModel::new` on inertias of known principal
//! moments turned by random rotations, the degenerate ones included (slender rods `(0, I, I)`,
//! spheres `(I, I, I)`, thin plates `(a, b, a + b)`): the moments come back to 1e-14 of the
//! largest with orthonormal axes, every such inertia is accepted, and the ones breaking the
//! triangle inequalities by a clear margin are refused.

use manip_dyn::DynError;
use manip_dyn::spatial::{
    Mat3, SpatialJoint, SpatialLink, SpatialModel, Transform, Vec3, symmetric_eigen,
};
use proptest::prelude::*;
use test_support::numeric::quaternion_matrix;

/// A random rotation: the matrix of a random unit quaternion.
fn rotation() -> impl Strategy<Value = Mat3> {
    [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64]
        .prop_filter("not too short", |q| {
            q.iter().map(|x| x * x).sum::<f64>() > 0.01
        })
        .prop_map(|q| {
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            quaternion_matrix(q.map(|v| v / norm))
        })
}

/// Principal moments satisfying the triangle inequalities, of order one: general ones (from
/// non-negative second moments), rods, spheres and plates, in a random order.
fn moments() -> impl Strategy<Value = Vec3> {
    let general = [0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64]
        .prop_filter("not all small", |s| s.iter().sum::<f64>() > 0.01)
        .prop_map(|[a, b, c]| [b + c, a + c, a + b]);
    let rod = (0.01..1.0f64).prop_map(|i| [0.0, i, i]);
    let sphere = (0.01..1.0f64).prop_map(|i| [i, i, i]);
    let plate = (0.01..1.0f64, 0.01..1.0f64).prop_map(|(a, b)| [a, b, a + b]);
    (prop_oneof![general, rod, sphere, plate], 0..6usize).prop_map(|(m, order)| {
        let [i, j, k] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ][order];
        [m[i], m[j], m[k]]
    })
}

/// `R diag(d) R^T`, exactly symmetric.
fn rotated(r: &Mat3, d: Vec3) -> Mat3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| d[k] * (r[i][k] * r[j][k])).sum()))
}

fn sorted(mut d: Vec3) -> Vec3 {
    d.sort_by(f64::total_cmp);
    d
}

/// A one-link chain whose link has the rotational inertia `inertia`.
fn one_link(inertia: Mat3) -> Result<SpatialModel, DynError> {
    SpatialModel::new(
        vec![SpatialJoint::revolute([0.0, 0.0, 1.0], Transform::IDENTITY)],
        vec![SpatialLink {
            mass: 1.0,
            com: [0.1, 0.0, 0.0],
            inertia,
        }],
        [0.0, 0.0, -9.81],
    )
}

/// The largest entry of `V^T V - E`, `det V - 1` and `V diag(values) V^T - m` (the last over
/// `scale`) of the decomposition of `m`.
fn decomposition_errors(m: &Mat3, scale: f64) -> (f64, f64, f64) {
    let eigen = symmetric_eigen(m);
    let v = &eigen.vectors;
    let mut orthonormal = 0.0f64;
    for a in 0..3 {
        for b in 0..3 {
            let dot: f64 = (0..3).map(|k| v[k][a] * v[k][b]).sum();
            orthonormal = orthonormal.max((dot - f64::from(u8::from(a == b))).abs());
        }
    }
    let back = rotated(v, eigen.values);
    let reconstruction = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| (back[i][j] - m[i][j]).abs() / scale)
        .fold(0.0, f64::max);
    (orthonormal, (det(v) - 1.0).abs(), reconstruction)
}

fn det(v: &Mat3) -> f64 {
    v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1])
        - v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0])
        + v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// The moments to 1e-14 of the largest, ascending, with a rotation of eigenvectors that
    /// gives the matrix back; at any scale from 1e-300 to 1e300.
    #[test]
    fn rotated_principal_moments_are_recovered(
        r in rotation(),
        d in moments(),
        exponent in -300..=300i32,
    ) {
        let d = d.map(|x| x * 10f64.powi(exponent));
        let largest = sorted(d)[2];
        let m = rotated(&r, d);
        let eigen = symmetric_eigen(&m);
        prop_assert!(eigen.values[0] <= eigen.values[1] && eigen.values[1] <= eigen.values[2]);
        for (got, want) in eigen.values.iter().zip(sorted(d)) {
            prop_assert!((got - want).abs() <= 1e-14 * largest, "{:?} vs {:?}", eigen.values, d);
        }
        let (orthonormal, det, reconstruction) = decomposition_errors(&m, largest);
        prop_assert!(orthonormal <= 1e-14 && det <= 1e-14, "{orthonormal:e} {det:e}");
        prop_assert!(reconstruction <= 1e-14, "{reconstruction:e}");
    }

    /// Every rotated physical inertia is a valid link (about 70% of rotated rods were refused
    /// when the eigenvalues came from the closed form of the cubic).
    #[test]
    fn rotated_physical_inertias_are_accepted(
        r in rotation(),
        d in moments(),
        exponent in -9..=9i32,
    ) {
        let d = d.map(|x| x * 10f64.powi(exponent));
        prop_assert!(one_link(rotated(&r, d)).is_ok(), "{d:?}");
    }

    /// A moment beyond the sum of the other two by 1e-6 of it, or negative by 1e-6 of the
    /// others, is refused however the tensor is turned.
    #[test]
    fn rotated_unphysical_inertias_are_refused(
        r in rotation(),
        (a, b) in (0.01..1.0f64, 0.01..1.0f64),
        negative in any::<bool>(),
    ) {
        let d = if negative {
            [-1e-6 * a, a, a]
        } else {
            [a, b, (a + b) * (1.0 + 1e-6)]
        };
        let error = one_link(rotated(&r, d)).unwrap_err();
        prop_assert!(error.to_string().contains("triangle inequalities"), "{error}");
    }
}

/// The tensors the closed form of the cubic refused: a rod (0, I, I) turned by a quarter turn of
/// pitch, and rods along (3, 4, 5) and (1, 1, 3) written as exact decimals. Each is accepted,
/// its moments come back as (0, I, I) and its zero moment's axis is the rod's.
#[test]
fn rotated_rods_are_accepted_with_their_axes() {
    let quarter = Transform::from_rpy([0.0, std::f64::consts::FRAC_PI_2, 0.0], [0.0; 3]).rotation;
    let root = |x: f64| x.sqrt();
    let cases: [(Mat3, f64, Vec3); 3] = [
        (
            rotated(&quarter, [0.0, 0.01, 0.01]),
            0.01,
            [quarter[0][0], quarter[1][0], quarter[2][0]],
        ),
        (
            [[0.82, -0.24, -0.3], [-0.24, 0.68, -0.4], [-0.3, -0.4, 0.5]],
            1.0,
            [3.0, 4.0, 5.0].map(|x| x / root(50.0)),
        ),
        (
            [
                [
                    0.9090909090909091,
                    -0.09090909090909091,
                    -0.27272727272727276,
                ],
                [
                    -0.09090909090909091,
                    0.9090909090909091,
                    -0.27272727272727276,
                ],
                [
                    -0.27272727272727276,
                    -0.27272727272727276,
                    0.18181818181818177,
                ],
            ],
            1.0,
            [1.0, 1.0, 3.0].map(|x| x / root(11.0)),
        ),
    ];
    for (inertia, moment, axis) in cases {
        assert!(one_link(inertia).is_ok(), "{inertia:?}");
        let eigen = symmetric_eigen(&inertia);
        for (got, want) in eigen.values.iter().zip([0.0, moment, moment]) {
            assert!((got - want).abs() <= 1e-15 * moment, "{:?}", eigen.values);
        }
        let along: f64 = (0..3).map(|k| eigen.vectors[k][0] * axis[k]).sum();
        assert!((along.abs() - 1.0).abs() <= 1e-15, "{along}");
    }
}

/// A diagonal matrix gives its diagonal exactly, ascending, and a rotation (determinant +1) that
/// permutes the axes accordingly.
#[test]
fn a_diagonal_matrix_gives_its_diagonal_exactly() {
    let diagonal = [0.03, 0.01, 0.02];
    let eigen = symmetric_eigen(&rotated(&Transform::IDENTITY.rotation, diagonal));
    assert_eq!(eigen.values, [0.01, 0.02, 0.03]);
    assert_eq!(det(&eigen.vectors), 1.0);
    for (k, value) in eigen.values.iter().enumerate() {
        let column = [0, 1, 2].map(|row| eigen.vectors[row][k]);
        let axis = column.iter().position(|x| x.abs() == 1.0).unwrap();
        assert_eq!(diagonal[axis], *value);
    }
}
