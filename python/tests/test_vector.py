"""tendril.vector.GripVectorEnv: N twins stepped in parallel, behind gymnasium.make_vec."""

import gymnasium
import numpy as np
import pytest

import tendril
from tendril.env import GripEnv
from tendril.vector import GripVectorEnv
from conftest import SHORT_LIFT


def _rollout(env, seed, steps):
    obs, _ = env.reset(seed=seed)
    seen, rewards = [obs], []
    rng = np.random.default_rng(0)
    for _ in range(steps):
        obs, reward, terminated, truncated, _ = env.step(rng.uniform(-0.3, 0.6, size=env.action_space.shape))
        seen.append(obs)
        rewards.append(reward)
    return np.array(seen), np.array(rewards)


def test_make_vec_gives_the_native_vector_env():
    envs = gymnasium.make_vec("tendril/Grip-v0", num_envs=3)
    assert isinstance(envs.unwrapped, GripVectorEnv)
    obs, info = envs.reset(seed=5)
    assert obs.shape == (3, 6) and obs.dtype == np.float32
    assert envs.observation_space.contains(obs)
    envs.close()


def test_a_seeded_vector_repeats_and_each_twin_is_the_single_env_with_its_seed():
    envs = GripVectorEnv(num_envs=2, scenario=SHORT_LIFT)
    first = _rollout(envs, 11, 400)
    again = _rollout(envs, 11, 400)
    np.testing.assert_array_equal(first[0], again[0])
    np.testing.assert_array_equal(first[1], again[1])
    # Twin 1 is the single environment reset with seed 12 and given twin 1's actions.
    single = GripEnv(SHORT_LIFT)
    obs, _ = single.reset(seed=12)
    rng = np.random.default_rng(0)
    track = [obs]
    for _ in range(400):
        actions = rng.uniform(-0.3, 0.6, size=(2, 1))
        obs, *_ = single.step(actions[1])
        track.append(obs)
    np.testing.assert_array_equal(first[0][:, 1], np.array(track))
    # Different seeds, different sensor noise.
    assert not np.array_equal(first[0][:, 0], first[0][:, 1])
    envs.close()
    single.close()


def test_an_ended_episode_resets_on_the_next_step():
    envs = GripVectorEnv(num_envs=2, scenario=SHORT_LIFT)
    envs.reset(seed=3)
    # Loosen fully: both objects fall during the lift and the episodes end.
    ended_at = None
    for k in range(3000):
        obs, reward, terminated, truncated, info = envs.step(np.full((2, 1), -1.0, dtype=np.float32))
        if terminated.any() or truncated.any():
            ended_at = k
            done = terminated | truncated
            break
    assert ended_at is not None, "no episode ended"
    obs, reward, terminated, truncated, info = envs.step(np.zeros((2, 1), dtype=np.float32))
    # The ended twin started over: home phase, no reward, not ended.
    assert np.all(obs[done, 4] == 0.0) and np.all(reward[done] == 0.0) and not terminated[done].any()
    envs.close()


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="num_envs"):
        GripVectorEnv(num_envs=0)
    envs = GripVectorEnv(num_envs=2, scenario=SHORT_LIFT)
    with pytest.raises(ValueError, match="seeds"):
        envs.reset(seed=[1, 2, 3])
    envs.close()
    a = tendril.Session(tendril.load(SHORT_LIFT))
    with pytest.raises(ValueError, match="twice"):
        tendril._native.step_all([a, a], [None, None])
    with pytest.raises(ValueError, match="2 sessions but 1 actions"):
        tendril._native.step_all([a, tendril.Session(tendril.load(SHORT_LIFT))], [None])
