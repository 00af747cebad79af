//! Small dense `f64` linear algebra for compile-time checks.

/// Whether the symmetric matrix `m` is positive definite (Cholesky succeeds
/// with pivots above a relative tolerance).
pub fn is_positive_definite(m: &[Vec<f64>]) -> bool {
    let n = m.len();
    let scale = (0..n).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    let mut l = vec![vec![0.0; n]; n];
    for j in 0..n {
        let d = m[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        // Written so that a NaN pivot also fails.
        if d.partial_cmp(&(1e-12 * scale)) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        l[j][j] = d.sqrt();
        for i in j + 1..n {
            l[i][j] = (m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>()) / l[j][j];
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::is_positive_definite;

    #[test]
    fn positive_definiteness() {
        assert!(is_positive_definite(&[vec![2.0, 1.0], vec![1.0, 2.0]]));
        assert!(!is_positive_definite(&[vec![1.0, 2.0], vec![2.0, 1.0]]));
        assert!(!is_positive_definite(&[vec![0.0]]));
        assert!(!is_positive_definite(&[vec![-1.0]]));
    }
}
