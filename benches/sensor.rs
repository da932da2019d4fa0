//! Sensor twin throughput: forward model + estimate per sample (analytic mode), and per spectrum
//! (spectral mode). Goals (issue 2 §6): ≥ 10 M samples/s analytic, ≥ 10 k spectra/s spectral.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use tendril_fbg::estimate::{ForceCalibration, ForceEstimator};
use tendril_fbg::{FbgSensor, InterrogatorConfig, InterrogatorMode, SensorConfig};

const BATCH: u64 = 1000;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("sensor");
    for (name, mode) in [
        ("analytic forward+estimate", InterrogatorMode::Analytic),
        ("spectral forward+estimate", InterrogatorMode::Spectral),
    ] {
        let interrogator = InterrogatorConfig { mode, ..InterrogatorConfig::default() };
        let mut sensor = FbgSensor::new(&SensorConfig::default(), &interrogator, 1);
        let mut est = ForceEstimator::new(ForceCalibration::default());
        est.tare(sensor.sample(0.0, 25.0, 0.001));
        // Precomputed inputs: the bench measures the model, not the input generator.
        let inputs: Vec<(f64, f64)> = (0..4000)
            .map(|k| {
                // A load/unload triangle and a slow temperature ramp, so hysteresis and lags do real work.
                let phase = k as f64 / 2000.0;
                (4.0 * if phase < 1.0 { phase } else { 2.0 - phase }, 25.0 + k as f64 * 1e-3)
            })
            .collect();
        let mut k = 0usize;
        group.throughput(Throughput::Elements(BATCH));
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for _ in 0..BATCH {
                    k = if k + 1 == inputs.len() { 0 } else { k + 1 };
                    let (force, temp) = inputs[k];
                    let w = sensor.sample(black_box(force), black_box(temp), 0.001);
                    acc += est.estimate(w).map(|e| e.force_n).unwrap_or(0.0);
                }
                acc
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
