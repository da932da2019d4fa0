//! The sensor's wavelengths and the eq. 8 estimate over a load cycle at a warmer temperature:
//! `cargo run -p tendril-fbg --example sensor`.

use tendril_fbg::estimate::{ForceCalibration, ForceEstimator};
use tendril_fbg::{FbgSensor, InterrogatorConfig, SensorConfig};

fn main() {
    let dt = 1e-3;
    let mut sensor = FbgSensor::new(&SensorConfig::default(), &InterrogatorConfig::default(), 1);
    let mut estimator = ForceEstimator::new(ForceCalibration::default());
    estimator.tare(sensor.sample(0.0, 25.0, dt));
    println!("  t [s]  force [N]  FBG1 [nm]   FBG2 [nm]   estimate [N]");
    for k in 0..=8000 {
        let t = k as f64 * dt;
        // Up to 2 N and back down over 8 s, the sensor 2 °C warmer than at the tare.
        let force = 2.0 * (std::f64::consts::PI * t / 8.0).sin().max(0.0);
        let w = sensor.sample(force, 27.0, dt);
        let estimate = estimator.track(w).map_or(f64::NAN, |e| e.force_n);
        if k % 1000 == 0 {
            println!("{t:7.1}  {force:9.3}  {:10.4}  {:10.4}  {estimate:12.3}", w.fbg1_nm, w.fbg2_nm);
        }
    }
}
