//! The viewer's own keys (`tendril view`) and what they do to the run, apart from the window.

use mujoco_rs::viewer::egui::Key;

/// What a key asks of the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Stop or restart the twin's clock (the window stays live: camera, perturbation).
    TogglePause,
    /// Switch force control during the arm's moves on or off.
    ToggleFeedback,
    /// Knock the object now (the scenario's `[disturbance.push]` size, or the default knock).
    Knock,
}

/// The keys, for the on-screen help: (key, what it does).
pub const HELP: [(&str, &str); 3] =
    [("Space", "pause / resume"), ("F", "force feedback on / off"), ("K", "knock the object")];

/// The keys MuJoCo's viewer (mujoco-rs) already takes; none of ours is among them.
pub const VIEWER_KEYS: [Key; 20] = [
    Key::F1,
    Key::F2,
    Key::F3,
    Key::F4,
    Key::F5,
    Key::Escape,
    Key::Backspace,
    Key::OpenBracket,
    Key::CloseBracket,
    Key::C,
    Key::U,
    Key::J,
    Key::M,
    Key::H,
    Key::Z,
    Key::T,
    Key::I,
    Key::E,
    Key::X,
    Key::Q,
];

/// The action of `key`, if it has one.
pub fn action(key: Key) -> Option<Action> {
    match key {
        Key::Space => Some(Action::TogglePause),
        Key::F => Some(Action::ToggleFeedback),
        Key::K => Some(Action::Knock),
        _ => None,
    }
}

/// What the keys have set so far, and the knocks still to apply.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Controls {
    /// The twin's clock is stopped.
    pub paused: bool,
    /// Feedback switches asked for and not yet applied by the run loop.
    pub feedback_toggles: u32,
    /// Knocks asked for and not yet applied.
    pub knocks: u32,
}

impl Controls {
    /// Records `action`.
    pub fn apply(&mut self, action: Action) {
        match action {
            Action::TogglePause => self.paused = !self.paused,
            Action::ToggleFeedback => self.feedback_toggles += 1,
            Action::Knock => self.knocks += 1,
        }
    }

    /// Whether the feedback switches asked for change the setting (an odd number of them), and
    /// forgets them.
    pub fn take_feedback_switch(&mut self) -> bool {
        std::mem::take(&mut self.feedback_toggles) % 2 == 1
    }

    /// The knocks asked for, forgotten.
    pub fn take_knocks(&mut self) -> u32 {
        std::mem::take(&mut self.knocks)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_key_has_its_action() {
        assert_eq!(action(Key::Space), Some(Action::TogglePause));
        assert_eq!(action(Key::F), Some(Action::ToggleFeedback));
        assert_eq!(action(Key::K), Some(Action::Knock));
        assert_eq!(action(Key::A), None);
        assert_eq!(action(Key::Enter), None);
    }

    #[test]
    fn no_key_of_ours_is_one_of_the_viewers() {
        for key in VIEWER_KEYS {
            assert_eq!(action(key), None, "{key:?} is the viewer's");
        }
    }

    #[test]
    fn the_help_names_every_key() {
        let keys: Vec<&str> = HELP.iter().map(|(k, _)| *k).collect();
        for (name, key) in [("Space", Key::Space), ("F", Key::F), ("K", Key::K)] {
            assert!(keys.contains(&name) && action(key).is_some(), "{name}");
        }
    }

    #[test]
    fn pause_toggles_feedback_switches_pair_up_and_knocks_count() {
        let mut c = Controls::default();
        c.apply(Action::TogglePause);
        assert!(c.paused);
        c.apply(Action::TogglePause);
        assert!(!c.paused);
        c.apply(Action::ToggleFeedback);
        assert!(c.take_feedback_switch());
        assert!(!c.take_feedback_switch(), "taken");
        c.apply(Action::ToggleFeedback);
        c.apply(Action::ToggleFeedback);
        assert!(!c.take_feedback_switch(), "two switches cancel");
        c.apply(Action::Knock);
        c.apply(Action::Knock);
        assert_eq!(c.take_knocks(), 2);
        assert_eq!(c.take_knocks(), 0);
    }
}
