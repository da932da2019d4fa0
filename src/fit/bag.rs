//! A rosbag2 recording as a fit's recording (`[[bags]]` in a fit file): a lab's bag of its cell's
//! ROS 2 topics (sqlite3 or MCAP storage), or a run's own `bag/`, read as `trace.csv` is.
//!
//! ```toml
//! [[bags]]
//! path = "../../bags/crimper-on"     # the bag's folder (or one of its .db3 / .mcap files)
//! scenario = "../crimper.toml"       # the scenario the cell ran: the twin runs it to compare
//! name = "crimper-on"                # optional: the folder's name (a run's `bag/`: the run's)
//! outcome = "held"                   # or "dropped", with drop_cell_time_s and drop_phase
//! [bags.topics]                      # optional; these are the defaults (tendril's own topics)
//! force = "/fbg/pad0/wrench"         # WrenchStamped (force.z) or ControlTick (force_n)
//! joint_states = "/joint_states"     # JointState; the twine motor by [ros2.joints] twine
//! phase = "/tendril/control_tick"    # ControlTick (phase) or std_msgs/msg/String (data)
//! ```
//!
//! The task's clock starts at the first message on the phase topic; a tick every control period
//! from there takes each quantity's latest message at or before it.

use super::recording::{Events, Recording, RecordingError, Tick, check_ticks};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use tendril_ros2::bag::{BagMessage, read_bag};
use tendril_ros2msg::{ControlTick, JointState, Message, StringMsg, WrenchStamped, from_payload};
use tendril_run::scenario::PickPlaceScenario;

/// Where a bag's quantities are.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BagTopics {
    /// The force estimate: `geometry_msgs/msg/WrenchStamped` (`force.z`) or
    /// `tendril_msgs/msg/ControlTick` (`force_n`).
    pub force: String,
    /// The motors' positions: `sensor_msgs/msg/JointState`, the twine motor by the scenario's
    /// `[ros2.joints] twine` name.
    pub joint_states: String,
    /// The task's phase: `tendril_msgs/msg/ControlTick` (`phase`) or `std_msgs/msg/String`
    /// (`data`, a phase name as `trace.csv` writes it).
    pub phase: String,
}

impl Default for BagTopics {
    fn default() -> Self {
        BagTopics {
            force: "/fbg/pad0/wrench".into(),
            joint_states: "/joint_states".into(),
            phase: "/tendril/control_tick".into(),
        }
    }
}

fn held() -> String {
    "held".into()
}

/// One `[[bags]]` entry.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BagSpec {
    /// The bag, relative to the fit file.
    pub path: PathBuf,
    /// The scenario the cell ran, relative to the fit file.
    pub scenario: PathBuf,
    /// Its name (scoped parameters, the report).
    #[serde(default)]
    pub name: Option<String>,
    /// Where its quantities are.
    #[serde(default)]
    pub topics: BagTopics,
    /// What happened: `held` or `dropped`.
    #[serde(default = "held")]
    pub outcome: String,
    /// When the object dropped, from the task's start \[s\] (with `dropped`).
    #[serde(default)]
    pub drop_cell_time_s: Option<f64>,
    /// The phase it dropped in (with `dropped`).
    #[serde(default)]
    pub drop_phase: Option<String>,
}

/// The value of each quantity a message carries, by topic.
enum Quantity {
    Force(f64),
    Twine(f64),
    Phase(String),
}

fn decode(m: &BagMessage, topics: &BagTopics, twine: &str) -> Result<Vec<Quantity>, String> {
    let bad = |e: tendril_ros2msg::CdrError| format!("topic {}: malformed {}: {e}", m.topic, m.type_name);
    let mut out = Vec::new();
    let is = |t: &str| m.type_name == t;
    if m.topic == topics.force {
        if is(WrenchStamped::TYPE.name) {
            out.push(Quantity::Force(from_payload::<WrenchStamped>(&m.payload).map_err(bad)?.wrench.force.z));
        } else if is(ControlTick::TYPE.name) {
            out.push(Quantity::Force(from_payload::<ControlTick>(&m.payload).map_err(bad)?.force_n));
        } else {
            return Err(format!(
                "topic {} is {}: the force comes from {} or {}",
                m.topic,
                m.type_name,
                WrenchStamped::TYPE.name,
                ControlTick::TYPE.name
            ));
        }
    }
    if m.topic == topics.joint_states {
        if !is(JointState::TYPE.name) {
            return Err(format!("topic {} is {}, not {}", m.topic, m.type_name, JointState::TYPE.name));
        }
        let js = from_payload::<JointState>(&m.payload).map_err(bad)?;
        if let Some(q) = js.name.iter().position(|n| n == twine).and_then(|i| js.position.get(i)) {
            out.push(Quantity::Twine(*q));
        }
    }
    if m.topic == topics.phase {
        if is(ControlTick::TYPE.name) {
            out.push(Quantity::Phase(from_payload::<ControlTick>(&m.payload).map_err(bad)?.phase));
        } else if is(StringMsg::TYPE.name) {
            out.push(Quantity::Phase(from_payload::<StringMsg>(&m.payload).map_err(bad)?.data));
        } else {
            return Err(format!(
                "topic {} is {}: the phase comes from {} or {}",
                m.topic,
                m.type_name,
                ControlTick::TYPE.name,
                StringMsg::TYPE.name
            ));
        }
    }
    Ok(out)
}

/// The ticks of `messages` at `rate_hz`: from the first phase message, each quantity's latest.
fn ticks_of(messages: &[BagMessage], spec: &BagSpec, twine: &str, rate_hz: f64) -> Result<Vec<Tick>, String> {
    let mut timeline: Vec<(u64, Quantity)> = Vec::new();
    for m in messages {
        timeline.extend(decode(m, &spec.topics, twine)?.into_iter().map(|q| (m.time_ns, q)));
    }
    let t = &spec.topics;
    let first = |want: fn(&Quantity) -> bool, topic: &str, what: &str| {
        timeline.iter().find(|(_, q)| want(q)).map(|(t, _)| *t).ok_or_else(|| format!("no {what} on topic {topic}"))
    };
    let start = first(|q| matches!(q, Quantity::Phase(_)), &t.phase, "phase")?;
    first(|q| matches!(q, Quantity::Force(_)), &t.force, "force")?;
    first(|q| matches!(q, Quantity::Twine(_)), &t.joint_states, &format!("position of joint `{twine}`"))?;
    let end = timeline.iter().filter(|(_, q)| matches!(q, Quantity::Force(_))).map(|(t, _)| *t).max().unwrap_or(start);
    // A message stamped within a microsecond of a tick belongs to it (stamps are whole nanoseconds).
    let slack_ns = 1_000;
    let (mut force, mut twine_rad, mut phase) = (None, None, None);
    let mut next = 0usize;
    let mut ticks = Vec::new();
    for k in 0u64.. {
        let at = start + (k as f64 * 1e9 / rate_hz).round() as u64;
        if at > end + slack_ns {
            break;
        }
        while let Some((t, q)) = timeline.get(next).filter(|(t, _)| *t <= at + slack_ns) {
            let _ = t;
            match q {
                Quantity::Force(f) => force = Some(*f),
                Quantity::Twine(q) => twine_rad = Some(*q),
                Quantity::Phase(p) => phase = Some(p.clone()),
            }
            next += 1;
        }
        if let (Some(force_n), Some(twine_motor_rad), Some(phase)) = (force, twine_rad, phase.clone()) {
            ticks.push(Tick { time_s: (at - start) as f64 * 1e-9, phase, force_n, twine_motor_rad });
        }
    }
    Ok(ticks)
}

/// Reads the bag `spec` names (paths relative to `base`) as a recording.
pub fn read_bag_recording(base: &Path, spec: &BagSpec) -> Result<Recording, RecordingError> {
    let path = base.join(&spec.path);
    let scenario_path = base.join(&spec.scenario);
    let scenario: PickPlaceScenario = tendril_config::load(&scenario_path, &[])
        .map_err(|e| RecordingError { file: scenario_path.clone(), reason: e.to_string() })?;
    let table = match toml::Value::try_from(&scenario) {
        Ok(toml::Value::Table(t)) => t,
        _ => return Err(RecordingError { file: scenario_path, reason: "cannot be written as TOML".into() }),
    };
    let err = |reason: String| RecordingError { file: path.clone(), reason };
    let topics = [spec.topics.force.as_str(), spec.topics.joint_states.as_str(), spec.topics.phase.as_str()];
    let messages = read_bag(&path, Some(&topics)).map_err(|e| RecordingError { file: e.path, reason: e.reason })?;
    let ticks = ticks_of(&messages, spec, &scenario.ros2.joints.twine, scenario.control_rate_hz).map_err(err)?;
    let ticks = check_ticks(&path, ticks, scenario.control_rate_hz)?;
    let outcome = spec.outcome.clone();
    if !matches!(outcome.as_str(), "held" | "dropped") || (outcome == "dropped") != spec.drop_cell_time_s.is_some() {
        return Err(err(format!("outcome `{outcome}`: `held`, or `dropped` with drop_cell_time_s (and drop_phase)")));
    }
    let name = spec.name.clone().unwrap_or_else(|| {
        let folder = if path.file_name().is_some_and(|n| n == tendril_run::bag::BAG_DIR) {
            path.parent()
        } else {
            Some(path.as_path())
        };
        folder
            .and_then(Path::file_name)
            .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
    });
    let sim_time_s = ticks.last().map_or(0.0, |t| t.time_s);
    let events = Events {
        outcome,
        drop_cell_time_s: spec.drop_cell_time_s,
        drop_time_s: None,
        drop_phase: spec.drop_phase.clone(),
        sim_time_s,
    };
    Ok(Recording { dir: path, source: scenario_path, name, table, scenario, ticks, events })
}
