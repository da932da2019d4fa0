"""``GripVectorEnv``: N grasp-and-carry twins stepped in parallel in Rust (the GIL released), the
vector form of :class:`tendril.env.GripEnv`, made by ``gymnasium.make_vec("tendril/Grip-v0",
num_envs=N)``.

Each sub-environment is a :class:`~tendril.env.GripEnv` (same spaces, reward, ends and info); a
step hands every twin's action to Rust at once (``tendril._native.step_all``), which steps them on
one worker thread per core. The scene models are compiled once and shared.

Autoreset is Gymnasium's default, ``NEXT_STEP``: the step after a sub-environment's episode ended
resets it (its action is ignored; reward 0, not terminated) and returns the new episode's first
observation. ``reset(seed=s)`` seeds sub-environment i with ``s + i``; later episodes draw their
seeds from each sub-environment's generator, so a seeded vector repeats exactly.
"""

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import ModelCache, _native
from .env import GripEnv


class GripVectorEnv(VectorEnv):
    """``num_envs`` :class:`~tendril.env.GripEnv` twins stepped together (see the module's
    documentation); the other arguments are ``GripEnv``'s."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs=2, **kwargs):
        if int(num_envs) < 1:
            raise ValueError(f"num_envs must be at least 1, got {num_envs}")
        if kwargs.get("render_mode") is not None:
            raise ValueError("GripVectorEnv does not render: make a GripEnv with render_mode='rgb_array'")
        kwargs.pop("render_mode", None)
        models = kwargs.pop("models", None) or ModelCache()
        self.num_envs = int(num_envs)
        self.envs = [GripEnv(models=models, **kwargs) for _ in range(self.num_envs)]
        self.single_action_space = self.envs[0].action_space
        self.single_observation_space = self.envs[0].observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.render_mode = None
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)

    def reset(self, *, seed=None, options=None):
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, int):
            seeds = [seed + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"reset: {len(seeds)} seeds for {self.num_envs} environments")
        observations, infos = [], {}
        for i, (env, s) in enumerate(zip(self.envs, seeds)):
            obs, info = env.reset(seed=s, options=options)
            observations.append(obs)
            infos = self._add_info(infos, info, i)
        self._needs_reset[:] = False
        return np.stack(observations), infos

    def step(self, actions):
        actions = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, -1)
        stepping = [i for i in range(self.num_envs) if not self._needs_reset[i]]
        speeds = [self.envs[i]._twine_speed(actions[i]) for i in stepping]
        rows = _native.step_all([self.envs[i]._session for i in stepping], speeds)
        observations = np.zeros((self.num_envs,) + self.single_observation_space.shape, dtype=np.float32)
        rewards = np.zeros(self.num_envs, dtype=np.float64)
        terminated = np.zeros(self.num_envs, dtype=bool)
        truncated = np.zeros(self.num_envs, dtype=bool)
        infos = {}
        answers = dict(zip(stepping, rows))
        for i, env in enumerate(self.envs):
            if self._needs_reset[i]:
                obs, info = env.reset()
                reward, term, trunc = 0.0, False, False
            else:
                obs, reward, term, trunc, info = env._after_step(answers[i])
            observations[i], rewards[i], terminated[i], truncated[i] = obs, reward, term, trunc
            infos = self._add_info(infos, info, i)
        self._needs_reset = terminated | truncated
        return observations, rewards, terminated, truncated, infos

    def close_extras(self, **kwargs):
        for env in self.envs:
            env.close()
