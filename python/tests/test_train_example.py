"""python/examples/train_grip.py's wiring with a random policy: no Stable-Baselines3, no torch."""

import sys

import numpy as np
import pytest

import tendril
from conftest import ROOT

sys.path.insert(0, str(ROOT / "python" / "examples"))

import grip_eval  # noqa: E402
import train_grip  # noqa: E402
from grip_task import ACTING_PHASES, DISTURBANCE_SETS, OBJECTS, GripTask  # noqa: E402

SETPOINTS = {"crimper": 0.6, "shampoo": 0.8, "hammer": 1.6}


def test_the_disturbance_sets_are_the_controller_studys_and_load():
    assert list(DISTURBANCE_SETS) == ["none", "paper limits", "limits + 0.3 N·s knock", "noise 10 pm", "dropout 0.2 s"]
    knocked = tendril.load(OBJECTS["crimper"], set=DISTURBANCE_SETS["limits + 0.3 N·s knock"]).to_dict()
    assert knocked["task"]["minimum_durations"] is False
    assert knocked["disturbance"]["push"]["impulse_n_s"] == 0.3
    assert knocked["disturbance"]["push"]["phase"] == "transfer"
    for overrides in DISTURBANCE_SETS.values():
        tendril.load(OBJECTS["hammer"], set=overrides)


def test_randomisation_draws_every_object_and_the_policy_sees_its_setpoint():
    env = GripTask()
    drawn = []
    for seed in range(12):
        obs, info = env.reset(seed=seed)
        drawn.append((env.object, env.disturbance))
        # The ticks before the wrap are run for the policy: it first sees the wrap.
        assert info["phase"] == "wrap" and obs[7 + ACTING_PHASES.index("wrap")] == 1.0
        assert obs[2] * 2.0 == pytest.approx(SETPOINTS[env.object])
        assert env.twin_seed >= 1000, "training never uses the evaluation's seeds"
    assert {o for o, _ in drawn} == set(OBJECTS)
    assert len({d for _, d in drawn}) >= 3
    env.close()


def test_a_random_policy_steps_the_randomised_task_within_the_space():
    env = GripTask()
    rng = np.random.default_rng(1)
    obs, _ = env.reset(seed=3)
    ends = 0
    for _ in range(400):
        obs, reward, terminated, truncated, info = env.step(rng.uniform(-1, 1, size=1).astype(np.float32))
        assert env.observation_space.contains(obs) and np.isfinite(obs).all()
        assert np.isfinite(reward)
        if terminated or truncated:
            ends += 1
            assert {"object", "disturbance", "episode_return", "summary"} <= set(info)
            obs, _ = env.reset()
    env.close()


def test_fixed_options_repeat_an_episode():
    env = GripTask()
    options = {"object": "hammer", "disturbance": "paper limits", "seed": 3}
    runs = []
    for _ in range(2):
        obs, _ = env.reset(options=options)
        seq = [obs] + [env.step(np.array([0.3], dtype=np.float32))[0] for _ in range(100)]
        runs.append(np.array(seq))
    np.testing.assert_array_equal(runs[0], runs[1])
    assert runs[0][0][2] * 2.0 == pytest.approx(1.6)
    env.close()


def test_the_quick_run_evaluates_a_policy_and_the_pid_on_the_same_metrics(tmp_path):
    assert train_grip.main(["--quick", "--out", str(tmp_path)]) == 0
    rows = list(__import__("csv").DictReader(open(tmp_path / "evaluation.csv")))
    assert [r["controller"] for r in rows] == ["random", "pid"]
    for r in rows:
        assert set(grip_eval.COLUMNS) == set(r)
        assert r["object"] == "crimper" and r["disturbance"] == "paper limits" and r["seed"] == "1"
        assert r["outcome"] in ("held", "dropped")
        assert float(r["peak_force_n"]) > 0.0
    pid = rows[1]
    # The paper's PID holds the crimper at the paper's limits with a rise of about 1.5 s.
    assert pid["outcome"] == "held" and 1.0 < float(pid["rise_time_90_s"]) < 2.0
    assert float(pid["max_fluctuation_pct"]) > 0.0
    table = (tmp_path / "evaluation.md").read_text()
    assert "| crimper | paper limits | pid | 1/1 |" in table
