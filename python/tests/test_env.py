"""tendril.env.GripEnv (tendril/Grip-v0): a Gymnasium environment on the twin."""

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import tendril
from tendril.env import GripEnv
from conftest import SHORT_LIFT


def test_the_environment_passes_gymnasiums_checks():
    env = GripEnv()
    check_env(env, skip_render_check=True)
    env.close()


def test_it_is_registered():
    env = gymnasium.make("tendril/Grip-v0")
    obs, info = env.reset(seed=1)
    assert obs.shape == (6,) and obs.dtype == np.float32
    env.close()


def test_an_episode_runs_to_the_end_of_the_task():
    env = GripEnv(SHORT_LIFT)
    obs, info = env.reset(seed=4)
    assert info["phase"] == "home" and obs[4] == 0.0
    total, steps, phases = 0.0, 0, set()
    terminated = truncated = False
    while not (terminated or truncated):
        # Tighten while below the setpoint, ease off above it.
        action = np.array([0.2 if obs[2] < obs[3] else -0.2], dtype=np.float32)
        obs, reward, terminated, truncated, info = env.step(action)
        assert env.observation_space.contains(obs)
        total += reward
        steps += 1
        phases.add(info["phase"])
    assert terminated and not truncated
    assert {"grasp", "lift"} <= phases
    assert info["summary"]["outcome"] == "held"
    assert not info["dropped"]
    # Held through the grasp and the lift (about 6 s): the holding reward outweighs the force terms.
    assert 3.0 < total < 7.0 and steps > 500
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(1, dtype=np.float32))
    env.close()


def test_letting_go_is_a_drop_that_ends_the_episode():
    env = GripEnv(SHORT_LIFT)
    obs, info = env.reset(seed=1)
    terminated = truncated = False
    rewards = []
    while not (terminated or truncated):
        # Loosen as fast as allowed once the grasp is done: the object falls during the lift.
        action = [-1.0] if info.get("phase") in ("lift", "transfer") else [0.3 if obs[2] < obs[3] else -0.3]
        obs, reward, terminated, truncated, info = env.step(np.array(action, dtype=np.float32))
        rewards.append(reward)
    assert terminated and info["dropped"]
    assert rewards[-1] <= -env.drop_penalty
    assert info["summary"]["outcome"] == "dropped"


def test_reset_options_override_scenario_keys():
    env = GripEnv(SHORT_LIFT)
    obs, _ = env.reset(seed=2, options={"set": {"setpoint_n": 1.0}})
    assert obs[3] == pytest.approx(1.0)
    obs, _ = env.reset(seed=2)
    assert obs[3] == pytest.approx(0.6)
    with pytest.raises(tendril.ScenarioError):
        env.reset(options={"set": {"setpoint_n": -1.0}})
    env.close()


def test_a_seeded_reset_repeats_the_episode():
    env = GripEnv(SHORT_LIFT)
    first = [env.reset(seed=9)[0]] + [env.step(np.array([0.5], dtype=np.float32))[0] for _ in range(300)]
    again = [env.reset(seed=9)[0]] + [env.step(np.array([0.5], dtype=np.float32))[0] for _ in range(300)]
    np.testing.assert_array_equal(np.array(first), np.array(again))
    env.close()
