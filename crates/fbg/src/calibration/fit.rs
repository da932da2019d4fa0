//! Least-squares fits: polynomial (quadratic, linear) with R² and RMSE.

use nalgebra::{DMatrix, DVector};

/// Why a fit could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// Fewer points than coefficients, or mismatched lengths.
    #[error("need at least {need} points with matching x and y, got {got}")]
    TooFewPoints {
        /// Points needed.
        need: usize,
        /// Points given.
        got: usize,
    },
    /// The normal equations are singular (all x equal, for example).
    #[error("the data do not determine the fit (singular design: are all x values equal?)")]
    Singular,
    /// A value is NaN, infinite or so large that its square overflows.
    #[error("{what} holds a non-finite value or one beyond ±{MAX_FIT_MAGNITUDE:e}")]
    NonFinite {
        /// Which input: `x`, `y` or `design`.
        what: &'static str,
    },
    /// The SVD did not converge within `MAX_SVD_ITERATIONS` (10 000) iterations.
    #[error("the least-squares solution did not converge within {MAX_SVD_ITERATIONS} iterations")]
    NoConvergence,
}

/// Largest magnitude of any input to a fit. Why: the squares and products the SVD forms must stay
/// far from overflow (1e150² is 1e300, near `f64::MAX` 1.8e308); the calibration's inputs are
/// forces of a few newtons and shifts of a few thousand pm, so 1e100 refuses only garbage.
pub const MAX_FIT_MAGNITUDE: f64 = 1e100;

/// Iteration bound of the SVD: nalgebra's unbounded default spun forever on values near 1e160;
/// well-conditioned 3-column designs converge in tens of iterations.
pub const MAX_SVD_ITERATIONS: usize = 10_000;

fn all_sane(values: impl IntoIterator<Item = f64>) -> bool {
    values.into_iter().all(|v| v.is_finite() && v.abs() <= MAX_FIT_MAGNITUDE)
}

/// A polynomial fit `y = Σ coefᵢ·xⁱ` with its quality.
#[derive(Debug, Clone, PartialEq)]
pub struct PolyFit {
    /// Coefficients, constant term first.
    pub coefficients: Vec<f64>,
    /// Coefficient of determination [-].
    pub r2: f64,
    /// Root-mean-square residual [unit of y].
    pub rmse: f64,
}

impl PolyFit {
    /// The fitted value at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        self.coefficients.iter().rev().fold(0.0, |acc, c| acc * x + c)
    }
}

/// Least-squares linear regression of `y` on the columns of `design` (one row per point).
pub fn least_squares(design: &DMatrix<f64>, y: &[f64]) -> Result<Vec<f64>, FitError> {
    let (n, k) = design.shape();
    if n < k || n != y.len() {
        return Err(FitError::TooFewPoints { need: k, got: n.min(y.len()) });
    }
    if !all_sane(design.iter().copied()) {
        return Err(FitError::NonFinite { what: "design" });
    }
    if !all_sane(y.iter().copied()) {
        return Err(FitError::NonFinite { what: "y" });
    }
    // Column scaling keeps the normal equations well conditioned for x up to a few thousand.
    let scales: Vec<f64> = (0..k).map(|j| design.column(j).amax().max(1e-300)).collect();
    let scaled = DMatrix::from_fn(n, k, |i, j| design[(i, j)] / scales[j]);
    let yv = DVector::from_column_slice(y);
    let svd =
        nalgebra::SVD::try_new(scaled, true, true, f64::EPSILON, MAX_SVD_ITERATIONS).ok_or(FitError::NoConvergence)?;
    let max_sv = svd.singular_values.max();
    if max_sv.is_nan() || max_sv <= 0.0 || svd.singular_values.min() < 1e-10 * max_sv {
        return Err(FitError::Singular);
    }
    let sol = svd.solve(&yv, 1e-12 * max_sv).map_err(|_| FitError::Singular)?;
    Ok(sol.iter().zip(&scales).map(|(c, s)| c / s).collect())
}

/// Least-squares polynomial of `degree` through `(x, y)`.
pub fn poly_fit(x: &[f64], y: &[f64], degree: usize) -> Result<PolyFit, FitError> {
    if x.len() != y.len() || x.len() <= degree {
        return Err(FitError::TooFewPoints { need: degree + 1, got: x.len().min(y.len()) });
    }
    // Checked before the powers are formed: x = 1e160 squared is infinite.
    if !all_sane(x.iter().copied()) {
        return Err(FitError::NonFinite { what: "x" });
    }
    let design = DMatrix::from_fn(x.len(), degree + 1, |i, j| x[i].powi(j as i32));
    let coefficients = least_squares(&design, y)?;
    let fit = PolyFit { coefficients, r2: 0.0, rmse: 0.0 };
    let n = y.len() as f64;
    let mean = y.iter().sum::<f64>() / n;
    let ss_res: f64 = x.iter().zip(y).map(|(x, y)| (y - fit.eval(*x)).powi(2)).sum();
    let ss_tot: f64 = y.iter().map(|y| (y - mean).powi(2)).sum();
    let r2 = if ss_tot > 0.0 { 1.0 - ss_res / ss_tot } else { 1.0 };
    Ok(PolyFit { r2, rmse: (ss_res / n).sqrt(), ..fit })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_known_quadratic_and_reports_quality() {
        let x: Vec<f64> = (0..200).map(|i| i as f64 * 0.025).collect();
        let y: Vec<f64> = x.iter().map(|x| 144.99 * x * x + 527.62 * x - 91.42).collect();
        let f = poly_fit(&x, &y, 2).unwrap();
        assert!((f.coefficients[2] - 144.99).abs() < 1e-6 && (f.coefficients[0] + 91.42).abs() < 1e-6);
        assert!(f.rmse < 1e-6 && (f.r2 - 1.0).abs() < 1e-12);
        // Alternating ±10 residuals: RMSE 10, R² below one.
        let noisy: Vec<f64> = y.iter().enumerate().map(|(i, y)| y + if i % 2 == 0 { 10.0 } else { -10.0 }).collect();
        let f = poly_fit(&x, &noisy, 2).unwrap();
        assert!((f.rmse - 10.0).abs() < 0.1, "{}", f.rmse);
        assert!(f.r2 < 1.0 && f.r2 > 0.99);
    }

    #[test]
    fn refuses_degenerate_data() {
        assert!(matches!(poly_fit(&[1.0, 1.0, 1.0, 1.0], &[1.0, 2.0, 3.0, 4.0], 1), Err(FitError::Singular)));
        assert!(matches!(poly_fit(&[1.0], &[1.0], 2), Err(FitError::TooFewPoints { .. })));
    }

    #[test]
    fn huge_values_fail_fast_instead_of_spinning() {
        let x = [0.0, 1.0, 2.0, 1e160];
        let started = std::time::Instant::now();
        assert_eq!(poly_fit(&x, &[0.0, 1.0, 2.0, 3.0], 2), Err(FitError::NonFinite { what: "x" }));
        assert_eq!(
            poly_fit(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, f64::NAN, 3.0], 1),
            Err(FitError::NonFinite { what: "y" })
        );
        // Within bounds but badly scaled: an answer or an error, never a hang.
        for big in [1e50, 1e99] {
            let _ = poly_fit(&[0.0, 1.0, 2.0, big], &[0.0, 1.0, 2.0, 3.0], 2);
        }
        assert!(started.elapsed().as_secs_f64() < 5.0);
    }
}
