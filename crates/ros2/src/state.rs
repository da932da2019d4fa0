//! The state topics' messages, built in one place from one sample of the cell: what
//! `tendril serve --ros2` publishes, what a run's bag records, and what [`crate::Ros2Cell`] reads
//! back ([`wavelengths_of`]).
//!
//! - `joint_states`: the arm's six joints, then the growth and the twine motor (positions;
//!   velocities and efforts when the cell gives them);
//! - `/clock`;
//! - `fbg/peaks`: `pad0/fbg1`, `pad0/fbg2`, then each further pad's `padK/fbg1` and, when it has
//!   its own reference grating, `padK/fbg2`;
//! - `fbg/padK/wrench`: pad K's eq. (8) estimate as `force.z` in frame `fbg_padK` (the pad's
//!   normal);
//! - the tool wrench: the external force on the tool in the base frame, `force.z` = −the load the
//!   tool carries (RTDE's `actual_TCP_force`), when the cell measures it.

use super::config::Ros2Config;
use tendril_cell::ARM_JOINTS;
use tendril_fbg::array::{ArrayConfig, ArrayPeaks};
use tendril_fbg::signals::Wavelengths;
use tendril_ros2msg::{Clock, FbgPeaks, Header, JointState, Time, WrenchStamped};

/// One sample of the cell, as the state topics carry it.
#[derive(Debug, Clone, PartialEq)]
pub struct CellSample {
    /// Cell time \[s\] (the stamp of every message).
    pub time_s: f64,
    /// Arm joints \[rad\].
    pub arm_q: [f64; ARM_JOINTS],
    /// Arm joint velocities \[rad/s\], when known.
    pub arm_qd: Option<[f64; ARM_JOINTS]>,
    /// Growth and twine motor angles \[rad\].
    pub motors_rad: [f64; 2],
    /// Their velocities \[rad/s\], when known.
    pub motors_rad_s: Option<[f64; 2]>,
    /// Their output shafts' loads \[N·m\], when known.
    pub motors_nm: Option<[f64; 2]>,
    /// Pad 0's peaks.
    pub wavelengths: Wavelengths,
    /// The further pads' peaks.
    pub array: ArrayPeaks,
    /// Each pad's eq. (8) estimate \[N\], pad 0 first (empty: not estimated).
    pub pad_force_n: Vec<f64>,
    /// The load the tool carries \[N\], when measured.
    pub tool_load_n: Option<f64>,
}

/// Which further pads have a reference grating of their own (the rest read pad 0's).
pub fn own_references(array: &ArrayConfig) -> Vec<bool> {
    array.pads.iter().map(|p| p.lambda2_nm.is_some()).collect()
}

/// The gratings' names in `fbg/peaks`, in order.
pub fn grating_names(own_reference: &[bool]) -> Vec<String> {
    let mut names = vec!["pad0/fbg1".to_string(), "pad0/fbg2".to_string()];
    for (k, own) in own_reference.iter().enumerate() {
        names.push(format!("pad{}/fbg1", k + 1));
        if *own {
            names.push(format!("pad{}/fbg2", k + 1));
        }
    }
    names
}

/// Every state topic's message for one sample.
#[derive(Debug, Clone, PartialEq)]
pub struct StateMessages {
    /// `joint_states`.
    pub joints: JointState,
    /// `/clock`.
    pub clock: Clock,
    /// `fbg/peaks`.
    pub peaks: FbgPeaks,
    /// `fbg/padK/wrench`, pad 0 first (empty when not estimated).
    pub pad_wrenches: Vec<WrenchStamped>,
    /// The tool wrench, when measured.
    pub tool: Option<WrenchStamped>,
}

/// The messages of `s` under `config`'s joint names, for a layout whose further pads have their
/// own reference grating where `own_reference` says.
pub fn state_messages(config: &Ros2Config, own_reference: &[bool], s: &CellSample) -> StateMessages {
    let header = |frame: &str| Header::at(s.time_s, frame);
    let both = |arm: Option<[f64; ARM_JOINTS]>, motors: Option<[f64; 2]>| match (arm, motors) {
        (Some(a), Some(m)) => a.iter().chain(&m).copied().collect(),
        _ => Vec::new(),
    };
    let joints = JointState {
        header: header(""),
        name: config.joints.all().into_iter().map(String::from).collect(),
        position: s.arm_q.iter().chain(&s.motors_rad).copied().collect(),
        velocity: both(s.arm_qd, s.motors_rad_s),
        // The arm's joint torques are not modelled apart from the motors': efforts only when
        // every joint has one.
        effort: Vec::new(),
    };
    let mut wavelength_nm = vec![s.wavelengths.fbg1_nm, s.wavelengths.fbg2_nm];
    for (w, own) in s.array.as_slice().iter().zip(own_reference) {
        wavelength_nm.push(w.fbg1_nm);
        if *own {
            wavelength_nm.push(w.fbg2_nm);
        }
    }
    StateMessages {
        joints,
        clock: Clock { clock: Time::from_secs_f64(s.time_s) },
        peaks: FbgPeaks { header: header("fbg_pad0"), grating: grating_names(own_reference), wavelength_nm },
        pad_wrenches: s
            .pad_force_n
            .iter()
            .enumerate()
            .map(|(k, &f)| WrenchStamped::force_z(s.time_s, &format!("fbg_pad{k}"), f))
            .collect(),
        tool: s.tool_load_n.map(|load| WrenchStamped::force_z(s.time_s, "base", -load)),
    }
}

/// Pad 0's peaks and `further_pads` further pads' from an `fbg/peaks` message, by grating name (a
/// further pad without its own `fbg2` reads pad 0's).
pub fn wavelengths_of(m: &FbgPeaks, further_pads: usize) -> Result<(Wavelengths, ArrayPeaks), String> {
    if m.grating.len() != m.wavelength_nm.len() {
        return Err(format!(
            "{} grating names but {} wavelengths: each wavelength needs its grating's name",
            m.grating.len(),
            m.wavelength_nm.len()
        ));
    }
    let get = |name: &str| m.grating.iter().position(|g| g == name).map(|i| m.wavelength_nm[i]);
    let need = |name: &str| get(name).ok_or_else(|| format!("no grating `{name}` in the message ({:?})", m.grating));
    let pad0 = Wavelengths { fbg1_nm: need("pad0/fbg1")?, fbg2_nm: need("pad0/fbg2")? };
    let mut array = ArrayPeaks::filled(further_pads, Wavelengths::default());
    for (k, w) in array.as_mut_slice().iter_mut().enumerate() {
        let pad = k + 1;
        *w = Wavelengths {
            fbg1_nm: need(&format!("pad{pad}/fbg1"))?,
            fbg2_nm: get(&format!("pad{pad}/fbg2")).unwrap_or(pad0.fbg2_nm),
        };
    }
    Ok((pad0, array))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peaks_round_trip_through_their_names() {
        let own = [false, true];
        let w = |a, b| Wavelengths { fbg1_nm: a, fbg2_nm: b };
        let mut array = ArrayPeaks::filled(2, Wavelengths::default());
        array.as_mut_slice().copy_from_slice(&[w(1530.0, 1550.0), w(1520.0, 1560.0)]);
        let s = CellSample {
            time_s: 1.5,
            arm_q: [0.1; 6],
            arm_qd: None,
            motors_rad: [1.0, 2.0],
            motors_rad_s: None,
            motors_nm: None,
            wavelengths: w(1540.0, 1550.0),
            array,
            pad_force_n: vec![0.5, 0.0, 0.25],
            tool_load_n: Some(2.0),
        };
        let m = state_messages(&Ros2Config::default(), &own, &s);
        assert_eq!(m.peaks.grating, ["pad0/fbg1", "pad0/fbg2", "pad1/fbg1", "pad2/fbg1", "pad2/fbg2"]);
        assert_eq!(m.peaks.wavelength_nm, [1540.0, 1550.0, 1530.0, 1520.0, 1560.0]);
        let (pad0, back) = wavelengths_of(&m.peaks, 2).unwrap();
        assert_eq!(pad0, s.wavelengths);
        assert_eq!(back, s.array, "pad 1 reads pad 0's reference");
        assert_eq!(m.joints.name.len(), 8);
        assert_eq!(m.joints.position[6..], [1.0, 2.0]);
        assert!(m.joints.velocity.is_empty());
        assert_eq!(m.pad_wrenches[2].wrench.force.z, 0.25);
        assert_eq!(m.pad_wrenches[2].header.frame_id, "fbg_pad2");
        assert_eq!(m.tool.unwrap().wrench.force.z, -2.0);
        assert_eq!(m.clock.clock.as_secs_f64(), 1.5);
        let short = FbgPeaks { grating: vec!["pad0/fbg1".into()], wavelength_nm: vec![1.0], ..FbgPeaks::default() };
        assert!(wavelengths_of(&short, 0).unwrap_err().contains("no grating `pad0/fbg2`"));
    }
}
