//! Load/unload cycle segmentation of a bench record, from the load-cell force alone.
//!
//! The load cell is noisy (≈ 0.1 N on the paper's bench), so the force is first smoothed with a
//! centred 0.3 s moving average. A cycle is a run of samples whose smoothed force exceeds 5 % of the
//! record's maximum; samples before the run's maximum are loading, after it unloading.

/// Bins averaged (centred) when locating the widest gap of a loop: ±0.2 N at 0.1 N bins, which
/// keeps the location within ±0.1 N on the shipped calibration run (the raw bins are noisy).
pub const GAP_AVERAGE_BINS: usize = 5;

/// Width of the centred moving average applied to the load-cell force [s].
pub const SMOOTHING_WINDOW_S: f64 = 0.3;
/// A sample belongs to a cycle when its smoothed force exceeds this fraction of the maximum [-].
pub const ACTIVE_FRACTION: f64 = 0.05;
/// A run above [`ACTIVE_FRACTION`] counts as a cycle only if its peak reaches this fraction of the
/// maximum [-]: noise near the threshold otherwise splits off short spurious runs.
pub const CYCLE_PEAK_FRACTION: f64 = 0.5;

/// Which branch of a load/unload cycle a sample lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Branch {
    /// Force rising towards the cycle's peak.
    Loading,
    /// Force falling from the cycle's peak.
    Unloading,
    /// Between cycles (near zero force).
    Rest,
}

/// One detected cycle: sample indices `[start, end)` and its peak.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycle {
    /// First sample index.
    pub start: usize,
    /// One past the last sample index.
    pub end: usize,
    /// Index of the smoothed force's maximum.
    pub peak: usize,
}

/// Centred moving average of `values` over `half` samples on each side (shorter at the ends).
pub fn smooth(values: &[f64], half: usize) -> Vec<f64> {
    let mut prefix = Vec::with_capacity(values.len() + 1);
    prefix.push(0.0);
    for v in values {
        prefix.push(prefix.last().unwrap() + v);
    }
    (0..values.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(values.len()));
            (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// Half-window in samples for [`SMOOTHING_WINDOW_S`] given sample times.
pub fn half_window(times: &[f64]) -> usize {
    if times.len() < 2 {
        return 0;
    }
    let dt = (times[times.len() - 1] - times[0]) / (times.len() - 1) as f64;
    if dt > 0.0 { (SMOOTHING_WINDOW_S / dt / 2.0).round() as usize } else { 0 }
}

/// Cycles and per-sample branches for a smoothed force trace.
pub fn segment(smoothed: &[f64]) -> (Vec<Cycle>, Vec<Branch>) {
    let max = smoothed.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let level = ACTIVE_FRACTION * max;
    let mut branches = vec![Branch::Rest; smoothed.len()];
    let mut cycles = Vec::new();
    let mut i = 0;
    while i < smoothed.len() {
        if smoothed[i] <= level {
            i += 1;
            continue;
        }
        let start = i;
        while i < smoothed.len() && smoothed[i] > level {
            i += 1;
        }
        let end = i;
        let peak = (start..end).max_by(|&a, &b| smoothed[a].total_cmp(&smoothed[b])).unwrap_or(start);
        if smoothed[peak] < CYCLE_PEAK_FRACTION * max {
            continue;
        }
        for (k, b) in branches.iter_mut().enumerate().take(end).skip(start) {
            *b = if k <= peak { Branch::Loading } else { Branch::Unloading };
        }
        cycles.push(Cycle { start, end, peak });
    }
    (cycles, branches)
}

/// Largest gap `mean(unloading) − mean(loading)` of `signal` between the two branches, in bins of
/// `bin_width` of the (smoothed) force `x`, averaged over `GAP_AVERAGE_BINS` neighbouring bins to
/// damp noise.
/// Returns `(gap, force at the gap)`, or `None` when no bin has samples on both branches.
pub fn max_branch_gap(x: &[f64], signal: &[f64], branches: &[Branch], bin_width: f64) -> Option<(f64, f64)> {
    let max_x = x.iter().copied().fold(0.0, f64::max);
    let bins = ((max_x / bin_width).ceil() as usize).max(1);
    let mut sums = vec![[0.0_f64; 2]; bins];
    let mut counts = vec![[0_usize; 2]; bins];
    for ((&x, &s), b) in x.iter().zip(signal).zip(branches) {
        let side = match b {
            Branch::Loading => 0,
            Branch::Unloading => 1,
            Branch::Rest => continue,
        };
        if x < 0.0 {
            continue;
        }
        let k = ((x / bin_width) as usize).min(bins - 1);
        sums[k][side] += s;
        counts[k][side] += 1;
    }
    // Bins need a few samples on each branch to be compared.
    let gaps: Vec<Option<f64>> = (0..bins)
        .map(|k| {
            (counts[k][0] >= 3 && counts[k][1] >= 3)
                .then(|| sums[k][1] / counts[k][1] as f64 - sums[k][0] / counts[k][0] as f64)
        })
        .collect();
    let mut best: Option<(f64, f64)> = None;
    for k in 0..bins {
        let half = GAP_AVERAGE_BINS / 2;
        let window: Vec<f64> =
            gaps[k.saturating_sub(half)..(k + half + 1).min(bins)].iter().flatten().copied().collect();
        if gaps[k].is_none() || window.is_empty() {
            continue;
        }
        let g = window.iter().sum::<f64>() / window.len() as f64;
        if best.is_none_or(|(bg, _)| g > bg) {
            best = Some((g, (k as f64 + 0.5) * bin_width));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_cycles_and_branches() {
        let tri = |t: f64| {
            if t < 1.0 {
                t
            } else if t < 2.0 {
                2.0 - t
            } else {
                0.0
            }
        };
        let f: Vec<f64> = (0..600).map(|i| 3.0 * tri((i % 300) as f64 / 100.0)).collect();
        let (cycles, branches) = segment(&f);
        assert_eq!(cycles.len(), 2);
        assert_eq!(cycles[0].peak, 100);
        assert_eq!(branches[50], Branch::Loading);
        assert_eq!(branches[150], Branch::Unloading);
        assert_eq!(branches[250], Branch::Rest);
        // A small bump is not a cycle.
        let mut g = f.clone();
        g.extend((0..50).map(|i| if (10..20).contains(&i) { 0.5 } else { 0.0 }));
        assert_eq!(segment(&g).0.len(), 2);
    }

    #[test]
    fn gap_of_a_known_loop() {
        // Loading y = x, unloading y = x + 0.2·sin(πx/3): widest at x = 1.5.
        let mut x = Vec::new();
        let mut y = Vec::new();
        let mut b = Vec::new();
        for i in 0..=3000 {
            let v = i as f64 * 0.001;
            x.push(v);
            y.push(v);
            b.push(Branch::Loading);
        }
        for i in (0..3000).rev() {
            let v = i as f64 * 0.001;
            x.push(v);
            y.push(v + 0.2 * (std::f64::consts::PI * v / 3.0).sin());
            b.push(Branch::Unloading);
        }
        let (gap, at) = max_branch_gap(&x, &y, &b, 0.1).unwrap();
        assert!((gap - 0.2).abs() < 0.005, "{gap}"); // the 5-bin average flattens the crest slightly
        assert!((at - 1.5).abs() < 0.11, "{at}");
    }
}
