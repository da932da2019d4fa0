//! Contacts per geom pair over one run on the twin (issue 39, lever 3; docs/studies/levers.md):
//! which of the pairs MuJoCo's collision search may test ever touch, and when.
//!
//! ```text
//! cargo run --release --example contact_census -- scenarios/crimper.toml [key=value ...]
//! ```
//!
//! The overrides are `--set`'s (`feedback=false`, `seed=1`, `finger.segments=16`, ...). Prints
//! every candidate pair (MuJoCo's contype/conaffinity filter passes it) with the steps it was in
//! contact, its contacts summed over the steps, and the first and last cell time it touched.

use std::path::Path;
use tendril_run::clock::RunClock;
use tendril_run::execute::{ModelCache, run_on_cell};
use tendril_run::scenario::PickPlaceScenario;
use tendril_twin::physics::ContactCensus;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let file = args.next().ok_or_else(|| anyhow::anyhow!("usage: contact_census SCENARIO [key=value ...]"))?;
    let overrides = args
        .map(|a| a.parse().map_err(|e| anyhow::anyhow!("{a}: {e}")))
        .collect::<anyhow::Result<Vec<tendril_config::Override>>>()?;
    let scenario: PickPlaceScenario = tendril_config::load(Path::new(&file), &overrides)?;
    let model = ModelCache::default().get(&scenario.scene_spec())?;
    let mut cell = scenario.sim_cell(model.clone());
    cell.count_contacts();
    let (summary, _) = run_on_cell(&mut cell, &scenario, None, RunClock::start())?;
    let census = cell.contact_census().ok_or_else(|| anyhow::anyhow!("the backend counts no contacts"))?;
    let touched = census.named(model.model());
    let m = model.model().ffi();
    println!(
        "{}: {} ({} steps, {:.2} s simulated); nv {}, nbody {}, ngeom {}",
        scenario.name, summary.outcome, census.steps, summary.sim_time_s, m.nv, m.nbody, m.ngeom
    );
    println!("{:<16} {:<16} {:>8} {:>9} {:>8} {:>8}", "geom", "geom", "steps", "contacts", "first s", "last s");
    for (a, b) in ContactCensus::candidate_pairs(model.model()) {
        match touched.iter().find(|(x, y, _)| (x, y) == (&a, &b) || (x, y) == (&b, &a)) {
            Some((_, _, t)) => {
                println!("{a:<16} {b:<16} {:>8} {:>9} {:>8.3} {:>8.3}", t.steps, t.contacts, t.first_s, t.last_s)
            }
            None => println!("{a:<16} {b:<16} {:>8} {:>9} {:>8} {:>8}", 0, 0, "-", "-"),
        }
    }
    Ok(())
}
