//! When a simulated object counts as dropped, from ground truth.
//!
//! While the arm carries the object, it is lost when the finger has not touched it for
//! [`LOST_CONTACT_S`], or when it has slid more than [`SLIP_OUT_M`] from where it sat in the hand
//! when the arm started moving: then it is no longer carried but falling or dragged along, and
//! the pick-and-place has failed even if a strip segment still brushes it.

use super::report::Drop;
use tendril_cell::GroundTruth;
use tendril_control::task::Phase;

/// Contact must be absent this long before the object counts as lost \[s\]: a contact
/// flickering during a slip is not yet a drop.
pub const LOST_CONTACT_S: f64 = 0.3;

/// Slide in the hand that counts as lost \[m\]: 20 mm, more than the 12 mm sensor pad, so the
/// grasp no longer has the configuration it was closed in.
pub const SLIP_OUT_M: f64 = 0.02;

/// Watches ground truth tick by tick.
#[derive(Debug, Default)]
pub struct DropWatch {
    carried_at: Option<[f64; 3]>,
    no_contact_since: Option<f64>,
    drop: Option<Drop>,
}

impl DropWatch {
    /// Feeds one tick. Returns the drop once it has happened.
    pub fn update(&mut self, time_s: f64, phase: Phase, truth: &GroundTruth) -> Option<Drop> {
        if self.drop.is_some() || !phase.arm_moving() {
            self.no_contact_since = None;
            return self.drop;
        }
        let start = *self.carried_at.get_or_insert(truth.object_in_hand_m);
        let slid = start.iter().zip(truth.object_in_hand_m).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        if slid > SLIP_OUT_M {
            self.drop = Some(Drop { cell_time_s: time_s, phase });
        } else if !truth.in_contact {
            let since = *self.no_contact_since.get_or_insert(time_s);
            if time_s - since >= LOST_CONTACT_S {
                self.drop = Some(Drop { cell_time_s: since, phase });
            }
        } else {
            self.no_contact_since = None;
        }
        self.drop
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth(z: f64, in_contact: bool) -> GroundTruth {
        GroundTruth { object_in_hand_m: [0.0, 0.0, z], in_contact, ..Default::default() }
    }

    #[test]
    fn sliding_out_of_the_hand_is_a_drop_and_standing_still_is_not() {
        let mut w = DropWatch::default();
        assert_eq!(w.update(0.0, Phase::Grasp, &truth(0.5, true)), None, "not watched before the arm moves");
        for i in 0..100 {
            let t = 1.0 + i as f64 * 0.01;
            assert_eq!(w.update(t, Phase::Lift, &truth(-0.1 - 0.0001 * i as f64, true)), None);
        }
        let d = w.update(2.5, Phase::Transfer, &truth(-0.125, true)).unwrap();
        assert_eq!((d.cell_time_s, d.phase), (2.5, Phase::Transfer));
    }

    #[test]
    fn losing_contact_for_long_enough_is_a_drop() {
        let mut w = DropWatch::default();
        w.update(0.0, Phase::Lift, &truth(0.0, true));
        assert_eq!(w.update(0.1, Phase::Lift, &truth(0.0, false)), None);
        assert_eq!(w.update(0.2, Phase::Lift, &truth(0.0, true)), None, "flicker resets");
        w.update(0.3, Phase::Lift, &truth(0.0, false));
        assert_eq!(w.update(0.6, Phase::Lift, &truth(0.0, false)).map(|d| d.cell_time_s), Some(0.3));
    }
}
