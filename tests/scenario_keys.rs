//! The book's scenario key reference is what the code says: `docs/guide/scenario-keys.md` equals
//! `tendril keys`, and the reference names the keys a user meets.

use std::process::Command;

#[test]
fn the_shipped_key_reference_is_the_generated_one() {
    let out = Command::new(env!("CARGO_BIN_EXE_tendril")).arg("keys").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let generated = String::from_utf8(out.stdout).unwrap();
    let page = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/guide/scenario-keys.md");
    let shipped = std::fs::read_to_string(&page).unwrap();
    assert!(
        shipped == generated,
        "docs/guide/scenario-keys.md differs from the code's reference: rewrite it with\n  \
         cargo run --release -- keys > docs/guide/scenario-keys.md"
    );
    // Keys from every part of the loop, with their units and checks.
    for row in [
        "| `setpoint_n` | N | required |",
        "| `physics.timestep_s` | s |",
        "| `controller.kp` |",
        "| `disturbance.push.impulse_n_s` | N·s | required |",
        "| `hardware.dxl_baud` |",
        "| `interrogator.noise_pm` |",
        "| `finger.segments` |",
    ] {
        assert!(generated.contains(row), "the reference has no row starting {row}");
    }
}
