"""tendril.Session: a run stepped tick by tick from Python."""

import json

import numpy as np
import pytest

import tendril
from conftest import SHORT_LIFT, without_timing


def test_stepping_with_the_scenarios_controller_is_the_whole_run():
    scenario = tendril.load(SHORT_LIFT, set={"seed": 6})
    whole = tendril.run(scenario)
    session = tendril.Session(scenario)
    rows = []
    while (seen := session.observation()) is not None:
        assert seen["phase"] == tendril.PHASES[seen["phase_index"]]
        row = session.step()
        rows.append(row)
    assert session.is_over
    assert session.dropped() is None
    assert [r["force_n"] for r in rows] == list(whole.trace["force_n"])
    summary = json.loads(session.finish())
    assert without_timing(summary) == without_timing(whole.summary)
    assert session.finish() == session.finish(), "finish() again returns the same summary"
    assert session.step() is None and session.observation() is None


def test_an_observation_holds_the_reading_and_the_ground_truth():
    session = tendril.Session(tendril.load(SHORT_LIFT), tendril.ModelCache())
    seen = session.observation()
    assert seen["phase"] == "home" and seen["time_s"] == 0.0
    assert 1539.0 < seen["fbg1_nm"] < 1541.0 and 1549.0 < seen["fbg2_nm"] < 1551.0
    assert len(seen["arm_q_rad"]) == 6
    assert set(seen["truth"]) == {"sensor_force_n", "grip_force_n", "object_height_m", "slip_speed_m_s", "in_contact"}
    assert session.max_speed_deg_s == 90.0
    session.finish()


def test_actions_are_checked():
    session = tendril.Session(tendril.load(SHORT_LIFT))
    with pytest.raises(ValueError, match="not both"):
        session.step(twine_speed_deg_s=1.0, setpoint_n=0.5)
    with pytest.raises(ValueError, match="finite"):
        session.step(twine_speed_deg_s=float("nan"))
    row = session.step(setpoint_n=0.7)
    assert row["time_s"] == 0.0
    assert session.observation()["time_s"] == pytest.approx(0.01)
    session.finish()
