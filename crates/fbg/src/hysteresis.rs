//! Prandtl-Ishlinskii (PI) hysteresis: the forward operator (used by the FBG forward model) and its
//! exact inverse (used by the estimator's optional software hysteresis compensation).
//!
//! The operator is built from *one-sided* play operators: play `i` keeps an internal state `hᵢ`
//! inside the band `[x − dᵢ, x]` (`dᵢ` the play width), moving only when the input pushes the band
//! edge against it. The output is
//!
//! ```text
//! y = p0·x + Σ wᵢ·hᵢ + offset
//! ```
//!
//! A one-sided play of width `d` is the textbook play of radius `d/2` started at the upper edge of
//! its band and shifted by `−d/2`. That choice matters for a contact force, which never goes below
//! zero: starting from rest (`hᵢ = 0` at `x = 0`), every excursion that returns to `x = 0` leaves
//! `hᵢ = 0` again, so the loop closes at zero force (no remanence), as the paper's sensor reads 0 at
//! 0 N after each unloading. On a `0 → X → 0` cycle the gap between the unloading and the loading
//! branch of play `i` is `min(x, dᵢ, X − dᵢ)`-shaped: it rises, holds `dᵢ`, and closes at the top.
//!
//! With `p0 > 0` and `wᵢ ≥ 0` the map from `x` to `y` (for the current states) is continuous,
//! piecewise linear and strictly increasing, so [`PiModel::invert`] solves it exactly.

use serde::{Deserialize, Serialize};
use tendril_config::{Checker, Validate};

/// The most plays a [`PiModel`] may have (the states live in a fixed array, no allocation per sample).
pub const MAX_PLAYS: usize = 8;

/// One-sided play operator: the new state for input `x`, previous state `prev` and width `width`
/// (same unit as `x`): `prev` clamped into `[x − width, x]`.
#[inline]
pub fn one_sided_play(prev: f64, x: f64, width: f64) -> f64 {
    prev.max(x - width).min(x)
}

/// A Prandtl-Ishlinskii operator `y = p0·x + Σ wᵢ·playᵢ[x] + offset` over one-sided plays.
///
/// Units: `x` and `y` share one unit (newtons in this crate: the forward model maps the true force
/// to an "effective" force, the estimator maps an estimate back). Widths are in that unit, the gain
/// and the weights are dimensionless.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PiModel {
    /// Linear (play-free) gain `p0` (dimensionless, > 0 so the operator is invertible).
    pub linear_gain: f64,
    /// Play widths `dᵢ` (same unit as the input, ≥ 0), at most [`MAX_PLAYS`].
    pub widths: Vec<f64>,
    /// Play weights `wᵢ` (dimensionless, ≥ 0), one per width.
    pub weights: Vec<f64>,
    /// Constant output offset (same unit as the input).
    #[serde(default)]
    pub offset: f64,
}

impl Validate for PiModel {
    fn validate(&self, at: &mut Checker) {
        at.positive("linear_gain", self.linear_gain);
        at.require("widths", self.widths.len() <= MAX_PLAYS, || {
            format!("at most {MAX_PLAYS} plays, got {}", self.widths.len())
        });
        at.require("weights", self.weights.len() == self.widths.len(), || {
            format!("needs one weight per width ({} widths, {} weights)", self.widths.len(), self.weights.len())
        });
        for (i, d) in self.widths.iter().enumerate() {
            at.non_negative(&format!("widths[{i}]"), *d);
        }
        for (i, w) in self.weights.iter().enumerate() {
            at.non_negative(&format!("weights[{i}]"), *w);
        }
        at.finite("offset", self.offset);
    }
}

/// The play states of one [`PiModel`] instance; `Default` is rest (zero input, all states 0).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PiState {
    h: [f64; MAX_PLAYS],
}

impl PiModel {
    /// The play-free operator `y = x`.
    pub fn identity() -> PiModel {
        PiModel { linear_gain: 1.0, widths: Vec::new(), weights: Vec::new(), offset: 0.0 }
    }

    /// A hysteresis that leaves the unloading branch on `y = x` and drags the loading branch down:
    /// `y = x − Σ wᵢ·(x − playᵢ[x])`, i.e. `p0 = 1 − Σ wᵢ`. This is the forward model's form (the
    /// sensor's strain lags on loading and recovers on unloading).
    pub fn lagging(widths: &[f64], weights: &[f64]) -> PiModel {
        PiModel {
            linear_gain: 1.0 - weights.iter().sum::<f64>(),
            widths: widths.to_vec(),
            weights: weights.to_vec(),
            offset: 0.0,
        }
    }

    fn plays(&self) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        self.widths.iter().zip(&self.weights).take(MAX_PLAYS).enumerate().map(|(i, (d, w))| (i, *d, *w))
    }

    /// Output for input `x`; advances the play states.
    #[inline]
    pub fn output(&self, state: &mut PiState, x: f64) -> f64 {
        let mut y = self.linear_gain * x + self.offset;
        for (i, d, w) in self.plays() {
            state.h[i] = one_sided_play(state.h[i], x, d);
            y += w * state.h[i];
        }
        y
    }

    /// Output for input `x` given the current states, without advancing them.
    fn peek(&self, state: &PiState, x: f64) -> f64 {
        let mut y = self.linear_gain * x + self.offset;
        for (i, d, w) in self.plays() {
            y += w * one_sided_play(state.h[i], x, d);
        }
        y
    }

    /// The input that produces output `y` from the current states (the exact inverse); advances
    /// the states as [`PiModel::output`] would for that input. Requires a valid model (`p0 > 0`).
    pub fn invert(&self, state: &mut PiState, y: f64) -> f64 {
        // Breakpoints of the piecewise-linear map: where a play's band edge meets its state.
        let mut bps = [0.0_f64; 2 * MAX_PLAYS];
        let mut n = 0;
        for (i, d, _) in self.plays() {
            bps[n] = state.h[i];
            bps[n + 1] = state.h[i] + d;
            n += 2;
        }
        let bps = &mut bps[..n];
        bps.sort_unstable_by(f64::total_cmp);
        // Outside all breakpoints every play follows an edge, so the slope is p0 + Σw.
        let outer_slope = self.linear_gain + self.weights.iter().take(MAX_PLAYS).sum::<f64>();
        let x = if bps.is_empty() {
            (y - self.offset) / self.linear_gain
        } else {
            let first = bps[0];
            let y_first = self.peek(state, first);
            if y <= y_first {
                first - (y_first - y) / outer_slope
            } else {
                let mut lo = (first, y_first);
                let mut found = None;
                for &bp in &bps[1..] {
                    let hi = (bp, self.peek(state, bp));
                    if y <= hi.1 {
                        let span = hi.1 - lo.1;
                        found = Some(if span > 0.0 { lo.0 + (y - lo.1) * (hi.0 - lo.0) / span } else { lo.0 });
                        break;
                    }
                    lo = hi;
                }
                found.unwrap_or_else(|| lo.0 + (y - lo.1) / outer_slope)
            }
        };
        self.output(state, x);
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cycle(peak: f64, steps: usize) -> Vec<f64> {
        let up = (0..=steps).map(|i| peak * i as f64 / steps as f64);
        let down = (0..=steps).rev().map(|i| peak * i as f64 / steps as f64);
        up.chain(down).collect()
    }

    #[test]
    fn loop_closes_at_zero_and_unloading_follows_identity() {
        let m = PiModel::lagging(&[0.5, 1.0], &[0.1, 0.05]);
        let mut s = PiState::default();
        let ys: Vec<f64> = cycle(3.0, 300).iter().map(|&x| m.output(&mut s, x)).collect();
        assert!(ys.last().unwrap().abs() < 1e-12, "remanence {}", ys.last().unwrap());
        // Loading branch at x = 2: both plays dragged fully: y = 2 − 0.1·0.5 − 0.05·1.0.
        assert!((ys[200] - (2.0 - 0.05 - 0.05)).abs() < 1e-12);
        // Unloading at x = 1 (index 301 + 200): back on y = x.
        assert!((ys[501] - 1.0).abs() < 1e-12, "{}", ys[501]);
    }

    #[test]
    fn inverse_recovers_the_input_along_a_random_walk() {
        let m = PiModel { linear_gain: 0.7, widths: vec![0.3, 0.9, 2.0], weights: vec![0.1, 0.15, 0.05], offset: 0.2 };
        let (mut fwd, mut inv) = (PiState::default(), PiState::default());
        let mut x = 0.0_f64;
        for k in 0..2000 {
            x = (x + ((k * 7919 % 13) as f64 - 6.0) * 0.05).max(0.0);
            let y = m.output(&mut fwd, x);
            let back = m.invert(&mut inv, y);
            assert!((back - x).abs() < 1e-9, "step {k}: x {x}, back {back}");
        }
        for (a, b) in fwd.h.iter().zip(&inv.h) {
            assert!((a - b).abs() < 1e-9);
        }
    }

    #[test]
    fn validation_names_bad_weights() {
        let m = PiModel { linear_gain: 1.0, widths: vec![0.5], weights: vec![-0.1], offset: 0.0 };
        let mut at = Checker::default();
        m.validate(&mut at);
        assert_eq!(at.errors()[0].0, "weights[0]");
    }
}
