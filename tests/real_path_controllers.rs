//! The controllers beyond the paper's PID (`feedforward`, `slip_margin`) run on the real path as
//! they do on the twin: the short grasp-hold-lift against the virtual devices (`tendril serve`'s
//! devices, in-process, in real time), compared phase by phase with the same scenario on the
//! simulated path within `tendril_run::compare`'s tolerances, with the default watchdogs.

use tendril_run::execute::run_on_twin;
use tendril_run::real::run_on_real;
use tendril_run::runner::Outcome;
use tendril_serve::{ServeConfig, start};

use crate::common::{one_at_a_time, phases, short_lift};

#[test]
fn feedforward_and_slip_margin_run_on_the_real_path_as_on_the_twin() {
    for (controller, port_base) in [("feedforward", 21950), ("slip_margin", 21960)] {
        let _turn = one_at_a_time();
        let set = format!("controller.type=\"{controller}\"");
        let scenario = short_lift(&[set.as_str()]);
        let (_, sim) = run_on_twin(&scenario, &Default::default(), None).unwrap();
        assert_eq!(sim.outcome, Outcome::Held, "{controller} on the twin: {:?}", sim.error);

        let serve = start(&scenario, &ServeConfig::loopback().with_port_base(port_base)).unwrap();
        let config = serve.real_cell_config();
        let (summary, real) = run_on_real(&scenario, config, None).unwrap();
        serve.stop().unwrap();

        assert_eq!(real.error, None, "{controller}");
        assert_eq!(summary.run.controller_type, controller);
        assert_eq!(real.outcome, Outcome::Held, "{controller}: the sensor lost the object on the real path");
        phases::assert_phases_agree(&phases::from_report(&sim), &phases::from_report(&real));
    }
}
