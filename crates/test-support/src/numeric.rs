//! Vector helpers and finite differences, written independently of the crates under test.

/// Largest absolute entry (0 for an empty slice).
pub fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |acc, v| acc.max(v.abs()))
}

/// `x + s y`.
pub fn axpy(x: &[f64], s: f64, y: &[f64]) -> Vec<f64> {
    x.iter().zip(y).map(|(a, b)| a + s * b).collect()
}

/// `max |x - y| / max(|x|, |y|, floor)`: the relative difference of two vectors, with `floor`
/// as the scale below which differences count as absolute.
pub fn relative_difference(x: &[f64], y: &[f64], floor: f64) -> f64 {
    assert_eq!(x.len(), y.len());
    let diff = x
        .iter()
        .zip(y)
        .fold(0.0f64, |acc, (a, b)| acc.max((a - b).abs()));
    diff / max_abs(x).max(max_abs(y)).max(floor)
}

/// The derivative of `f: R -> R^k` at `x` by central differences with step-size control
/// (Ridders' extrapolation: central differences at steps `h, h/1.4, h/1.4^2, ...`, extrapolated
/// to zero step by Neville's scheme, keeping the estimate whose error estimate is smallest).
/// Returns the derivative and its error estimate (largest absolute entry).
pub fn ridders(mut f: impl FnMut(f64) -> Vec<f64>, x: f64, h: f64) -> (Vec<f64>, f64) {
    const SHRINK: f64 = 1.4;
    const STEPS: usize = 10;
    let mut central = |step: f64| -> Vec<f64> {
        let (plus, minus) = (f(x + step), f(x - step));
        plus.iter()
            .zip(&minus)
            .map(|(p, m)| (p - m) / (2.0 * step))
            .collect()
    };
    let distance = |a: &[f64], b: &[f64]| max_abs(&axpy(a, -1.0, b));
    let mut previous: Vec<Vec<f64>> = vec![central(h)];
    let (mut best, mut error) = (previous[0].clone(), f64::INFINITY);
    let mut step = h;
    for i in 1..STEPS {
        step /= SHRINK;
        let mut row = vec![central(step)];
        let mut factor = SHRINK * SHRINK;
        for j in 1..=i {
            let next: Vec<f64> = row[j - 1]
                .iter()
                .zip(&previous[j - 1])
                .map(|(a, b)| (a * factor - b) / (factor - 1.0))
                .collect();
            factor *= SHRINK * SHRINK;
            let estimate = distance(&next, &row[j - 1]).max(distance(&next, &previous[j - 1]));
            if estimate <= error {
                error = estimate;
                best = next.clone();
            }
            row.push(next);
        }
        let diverging = distance(&row[i], &previous[i - 1]);
        previous = row;
        if diverging >= 2.0 * error {
            break;
        }
    }
    (best, error)
}

/// The rotation matrix of the unit quaternion `[w, x, y, z]` (Hamilton's convention, the
/// matrix acting on column vectors).
pub fn quaternion_matrix([w, x, y, z]: [f64; 4]) -> [[f64; 3]; 3] {
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ridders_differentiates_to_near_rounding() {
        let (d, error) = ridders(|x| vec![x.sin(), x.exp()], 0.7, 0.1);
        assert!((d[0] - 0.7f64.cos()).abs() < 1e-12, "{d:?}");
        assert!((d[1] - 0.7f64.exp()).abs() < 1e-12, "{d:?}");
        assert!(error < 1e-10);
    }

    #[test]
    fn relative_difference_uses_the_floor_for_small_vectors() {
        assert_eq!(relative_difference(&[1.0, 2.0], &[1.0, 2.5], 1e-9), 0.2);
        assert_eq!(relative_difference(&[0.0], &[1e-6], 1.0), 1e-6);
    }
}
