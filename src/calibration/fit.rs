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
    // Column scaling keeps the normal equations well conditioned for x up to a few thousand.
    let scales: Vec<f64> = (0..k).map(|j| design.column(j).amax().max(1e-300)).collect();
    let scaled = DMatrix::from_fn(n, k, |i, j| design[(i, j)] / scales[j]);
    let yv = DVector::from_column_slice(y);
    let svd = scaled.svd(true, true);
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
}
