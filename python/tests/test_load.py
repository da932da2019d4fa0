"""tendril.load: scenarios, overlays and overrides checked as `tendril run` checks them."""

import subprocess

import numpy as np
import pytest

import tendril
from conftest import ROOT, SHORT_LIFT


def test_a_scenario_loads_with_its_values():
    s = tendril.load(SHORT_LIFT)
    assert s.name == "short-lift"
    assert s.setpoint_n == 0.6
    assert s.seed == 1
    assert s.to_dict()["controller"]["kp"] == 20.0
    assert "short-lift" in repr(s)


def test_set_takes_a_dict_or_key_value_strings():
    by_dict = tendril.load(SHORT_LIFT, set={"controller.kp": 40, "seed": 7, "feedback": False})
    by_list = tendril.load(SHORT_LIFT, set=["controller.kp=40", "seed=7", "feedback=false"])
    assert by_dict.to_json() == by_list.to_json()
    assert by_dict.seed == 7
    assert '"kp":40.0' in by_dict.to_json().replace(" ", "")
    # numpy values are their plain Python selves.
    by_numpy = tendril.load(SHORT_LIFT, set={"controller.kp": np.float64(40), "seed": np.int64(7), "feedback": False})
    assert by_numpy.to_json() == by_dict.to_json()
    assert by_dict.set == ["controller.kp=40", "seed=7", "feedback=false"]


def test_a_seed_beyond_i64_is_taken_as_the_command_line_takes_it():
    assert tendril.load(SHORT_LIFT, set={"seed": 2**64 - 1}).seed == 2**64 - 1


def test_a_bad_key_raises_scenario_error_with_the_command_lines_message(tendril_bin, tmp_path):
    with pytest.raises(tendril.ScenarioError) as caught:
        tendril.load(SHORT_LIFT, set={"controller.kp": -1})
    message = str(caught.value)
    assert str(SHORT_LIFT) in message and "controller.kp" in message, message
    assert isinstance(caught.value, ValueError)
    cli = subprocess.run(
        [tendril_bin, "run", str(SHORT_LIFT), "--set", "controller.kp=-1", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
    )
    assert cli.returncode != 0
    assert cli.stderr == f"tendril: {message}\n"


def test_unknown_keys_missing_files_and_bad_overlays_are_scenario_errors(tmp_path):
    with pytest.raises(tendril.ScenarioError, match="no_such_key"):
        tendril.load(SHORT_LIFT, set={"controller.no_such_key": 1})
    with pytest.raises(tendril.ScenarioError, match="cannot read"):
        tendril.load(tmp_path / "missing.toml")
    overlay = tmp_path / "overlay.toml"
    overlay.write_text("[controller]\nkp = -5\n")
    with pytest.raises(tendril.ScenarioError) as caught:
        tendril.load(SHORT_LIFT, overlay=overlay)
    assert str(caught.value).startswith(f"{overlay}: key `controller.kp`"), caught.value
    with pytest.raises(tendril.ScenarioError, match="dotted path"):
        tendril.load(SHORT_LIFT, set=["=3"])


def test_values_python_cannot_express_in_toml_are_type_errors():
    with pytest.raises(TypeError, match="controller.kp"):
        tendril.load(SHORT_LIFT, set={"controller.kp": object()})
    with pytest.raises(TypeError):
        tendril.load(SHORT_LIFT, set="controller.kp=3")


def test_an_overlay_applies_before_set(tmp_path):
    overlay = tmp_path / "overlay.toml"
    overlay.write_text('"controller.kp" = 30.0\n[controller]\nki = 0.1\n')
    s = tendril.load(SHORT_LIFT, overlay=overlay, set={"controller.kp": 35.0})
    assert s.overlay is not None
    text = s.to_json().replace(" ", "")
    assert '"kp":35.0' in text and '"ki":0.1' in text


def test_the_packaged_scenario_is_the_repositorys():
    from tendril.env import DEFAULT_SCENARIO

    assert open(DEFAULT_SCENARIO).read() == (ROOT / "scenarios" / "short-lift.toml").read_text()
