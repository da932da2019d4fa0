"""tendril.env.GripEnv (tendril/Grip-v0): a Gymnasium environment on the twin."""

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import tendril
from tendril.env import GripEnv
from conftest import ROOT, SHORT_LIFT


def test_the_environment_passes_gymnasiums_checks():
    env = GripEnv()
    check_env(env)
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


def test_rgb_array_renders_the_scene():
    env = GripEnv(SHORT_LIFT, render_mode="rgb_array", render_width=160, render_height=120)
    check_env(env)
    env.reset(seed=1)
    for _ in range(200):
        env.step(np.array([0.3], dtype=np.float32))
    frame = env.render()
    assert frame.shape == (120, 160, 3) and frame.dtype == np.uint8
    # A picture of something: the scene, not a blank buffer.
    assert frame.std() > 10.0
    env.close()
    with pytest.raises(ValueError, match="render_mode"):
        GripEnv(render_mode="human")


def test_the_render_camera_follows_the_object_or_stays_and_a_wrong_one_is_named():
    def frames(camera):
        env = GripEnv(SHORT_LIFT, render_mode="rgb_array", render_width=160, render_height=120, render_camera=camera)
        env.reset(seed=1)
        first = env.render().copy()
        for _ in range(900):  # past the grasp into the lift
            if any(env.step(np.array([0.3], dtype=np.float32))[2:4]):
                break
        last = env.render().copy()
        env.close()
        return first, last

    def red(frame):  # the crimper's red handle
        r, g, b = (frame[..., k].astype(int) for k in range(3))
        return (r > 90) & (r > 2 * g + 30) & (r > 2 * b + 30)

    def mean_row(frame):
        return np.nonzero(red(frame))[0].mean()

    tracking, fixed = frames("tracking"), frames("fixed")
    np.testing.assert_array_equal(tracking[0], fixed[0])  # both start aimed at the object
    # The lift raises the object in the fixed camera's picture (by 2.9 rows of 120 in this short
    # lift); the tracking camera keeps it in place (within its follow's lag).
    assert mean_row(fixed[1]) < mean_row(fixed[0]) - 1.5
    assert abs(mean_row(tracking[1]) - mean_row(tracking[0])) < abs(mean_row(fixed[1]) - mean_row(fixed[0]))
    hand = frames("hand")[1]
    assert red(hand).sum() > 100  # the hand's camera looks at the handle
    follow = frames("follow")[1]
    assert red(follow).sum() > 100  # the model's follow camera, aimed at the object, sees it in the lift
    env = GripEnv(SHORT_LIFT, render_mode="rgb_array", render_width=160, render_height=120, render_camera="ceiling")
    env.reset(seed=1)
    with pytest.raises(RuntimeError, match="camera ceiling.*tracking, fixed, follow, hand"):
        env.render()
    env.close()


def test_the_reward_ranks_a_grip_at_the_setpoint_above_a_hard_squeeze():
    def episode(gain):
        env = GripEnv(SHORT_LIFT)
        obs, _ = env.reset(seed=2)
        total, done = 0.0, False
        while not done:
            # Proportional on the setpoint (gain 1) or on three times it (a squeeze).
            action = np.clip([0.5 * (gain * obs[3] - obs[2])], -1.0, 1.0).astype(np.float32)
            obs, reward, terminated, truncated, info = env.step(action)
            total += reward
            done = terminated or truncated
        env.close()
        return total, info["summary"]["outcome"]

    near, near_outcome = episode(1.0)
    squeeze, squeeze_outcome = episode(3.0)
    assert near_outcome == squeeze_outcome == "held"
    assert near > squeeze + 0.5


CHERRY = ROOT / "scenarios" / "cherry-tomato.toml"
#: The cherry tomato's task shortened: the grasp and the moves a few seconds each.
SHORT = {"task.grasp_s": 3.0, "task.lift_s": 2.0, "task.transfer_s": 1.0, "task.lower_s": 1.0}


def test_a_produce_item_reports_its_damage_in_the_info():
    env = GripEnv(CHERRY, set=SHORT)
    _, info = env.reset(seed=1)
    assert info["produce"]["bruise_threshold_kpa"] == pytest.approx(150.0)
    peak = 0.0
    terminated = truncated = False
    while not (terminated or truncated):
        _, _, terminated, truncated, info = env.step(np.array([0.0], dtype=np.float32))
        if "produce" in info:
            assert info["produce"]["peak_pressure_kpa"] >= peak - 1e-9, "the peak so far never falls"
            peak = info["produce"]["peak_pressure_kpa"]
    assert peak > 0.0
    assert info["summary"]["produce"]["peak_pressure_kpa"] == pytest.approx(peak)
    env.close()


def test_randomize_draws_each_key_per_episode_and_a_seeded_sequence_repeats():
    ranges = {"produce.modulus_pa": (3e5, 8e5), "produce.bruise_pa": (1e5, 2e5)}
    env = GripEnv(CHERRY, set=SHORT, randomize=ranges)
    _, first = env.reset(seed=4)
    _, second = env.reset()
    for key, (low, high) in ranges.items():
        assert low <= first["randomized"][key] <= high
    assert first["randomized"] != second["randomized"], "each episode draws anew"
    assert first["produce"]["bruise_threshold_kpa"] == pytest.approx(first["randomized"]["produce.bruise_pa"] / 1e3)
    _, again = env.reset(seed=4)
    assert again["randomized"] == first["randomized"], "a seeded reset draws the same"
    env.close()
    with pytest.raises(ValueError, match="low <= high"):
        GripEnv(CHERRY, randomize={"produce.modulus_pa": (8e5, 3e5)})
