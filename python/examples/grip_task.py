"""The learning task of ``train_grip.py``: ``GripEnv`` over the three paper objects and the
disturbance sets of ``tendril chart controllers``, with the observation the policy sees.

Nothing here needs Stable-Baselines3 or torch: the wiring runs (and is tested) without them.

- :data:`OBJECTS`: the paper's three tasks (``scenarios/{crimper,shampoo,hammer}.toml``, 43.5 s
  each: their object, setpoint and gains).
- :data:`DISTURBANCE_SETS`: the five sets of ``src/study/controllers.rs`` (``disturbance_sets``),
  each a dict of scenario overrides with the same keys and the same TOML values.
- :class:`GripTask`: one episode is one run of one object under one set on the twin. ``reset``
  draws both (domain randomisation) unless ``options`` names them; the ticks in which the
  controller's output is ignored are run without asking the policy; the observation is
  :func:`features` of ``GripEnv``'s.
"""

import math
import pathlib

import gymnasium
import numpy as np
from gymnasium import spaces

import tendril
from tendril.env import GripEnv

ROOT = pathlib.Path(__file__).resolve().parents[2]

#: The paper's three tasks, by object name.
OBJECTS = {name: ROOT / "scenarios" / f"{name}.toml" for name in ("crimper", "shampoo", "hammer")}

#: The arm at the paper's joint limits: its moves not stretched to the task's durations.
_LIMITS = {"task.minimum_durations": "false"}

#: The disturbance sets of ``tendril chart controllers`` (``src/study/controllers.rs``), in its
#: order. Values are TOML literals, read as ``--set key=VALUE`` reads them.
DISTURBANCE_SETS = {
    "none": {},
    "paper limits": dict(_LIMITS),
    "limits + 0.3 N·s knock": {
        **_LIMITS,
        "disturbance.push.impulse_n_s": "0.3",
        "disturbance.push.direction_deg": "0.0",
        "disturbance.push.duration_s": "0.02",
        "disturbance.push.phase": '"transfer"',
        "disturbance.push.offset_s": "1.0",
    },
    "noise 10 pm": {"interrogator.noise_pm": "10.0"},
    "dropout 0.2 s": {
        "disturbance.dropout.duration_s": "0.2",
        "disturbance.dropout.phase": '"lift"',
        "disturbance.dropout.offset_s": "1.0",
    },
}

#: Phases in which no action has any effect and nothing the policy does could change what
#: follows: before the wrap (home, grow) and after the lowering (release, done). The wrap is
#: left to the policy although its action is ignored there too: the tick on which the wrap sees
#: the touch already runs the grasp, and that tick's action must be the policy's.
SKIPPED_PHASES = ("home", "grow", "release", "done")

#: The phases the observation encodes one-hot (the others are skipped).
ACTING_PHASES = ("wrap", "grasp", "lift", "transfer", "lower")

#: The first twin seed of training episodes: evaluation uses seeds 1-10, training never does.
TRAIN_SEED_BASE = 1000


def features(obs, previous_action):
    """The policy's observation, from ``GripEnv``'s ``[Δλ1, Δλ2, F, F*, phase, τ]`` and the
    action of the previous step.

    Scaled to order one by fixed constants (not running statistics, so training and evaluation
    read the same numbers): the relative error (F - F*) / F* (what the reward grades, clipped to
    ±3), F and F* [N] / 2, Δλ1 / 1000 pm and Δλ2 / 100 pm, τ / 10 s, the previous action, and the
    phase one-hot over :data:`ACTING_PHASES`.
    """
    d1, d2, force, setpoint, phase, tau = (float(x) for x in obs)
    error = (force - setpoint) / setpoint if setpoint > 0.0 else 0.0
    phase_name = tendril.PHASES[int(round(phase))]
    one_hot = [1.0 if phase_name == p else 0.0 for p in ACTING_PHASES]
    values = [
        max(-3.0, min(3.0, error)),
        force / 2.0,
        setpoint / 2.0,
        d1 / 1000.0,
        d2 / 100.0,
        tau / 10.0,
        float(previous_action),
        *one_hot,
    ]
    return np.array(values, dtype=np.float32)


#: Length of :func:`features`' vector.
FEATURES = 7 + len(ACTING_PHASES)


class GripTask(gymnasium.Env):
    """``GripEnv`` on the three objects under the disturbance sets (see the module's docstring).

    ``objects`` and ``sets`` name the choices ``reset`` draws from, uniformly, with the
    environment's generator; ``reset(options={"object": ..., "disturbance": ..., "seed": ...})``
    fixes any of them (``seed`` is the twin's: sensor noise). Rewards are ``GripEnv``'s, summed
    over the skipped ticks too. At the episode's end ``info`` holds ``object``, ``disturbance``,
    ``twin_seed``, ``episode_return``, ``ticks`` and ``GripEnv``'s ``summary``.
    """

    metadata = {"render_modes": []}

    def __init__(self, objects=None, sets=None):
        self.objects = list(objects or OBJECTS)
        self.sets = list(sets or DISTURBANCE_SETS)
        for name in self.objects:
            if name not in OBJECTS:
                raise ValueError(f"unknown object {name!r}; one of {sorted(OBJECTS)}")
        for name in self.sets:
            if name not in DISTURBANCE_SETS:
                raise ValueError(f"unknown disturbance set {name!r}; one of {list(DISTURBANCE_SETS)}")
        # One GripEnv per object: each keeps its compiled scene (ModelCache) between episodes.
        self._envs = {name: GripEnv(OBJECTS[name]) for name in self.objects}
        self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(FEATURES,), dtype=np.float32)
        self._env = None

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        options = options or {}
        rng = self.np_random
        self.object = options.get("object") or self.objects[int(rng.integers(len(self.objects)))]
        self.disturbance = options.get("disturbance") or self.sets[int(rng.integers(len(self.sets)))]
        self.twin_seed = int(options["seed"]) if "seed" in options else int(rng.integers(TRAIN_SEED_BASE, 2**31))
        self._env = self._envs[self.object]
        obs, info = self._env.reset(seed=self.twin_seed, options={"set": DISTURBANCE_SETS[self.disturbance]})
        self._return, self._ticks, self._previous = 0.0, 0, 0.0
        obs, _, done, info = self._skip(obs, info)
        if done:
            raise RuntimeError(f"{self.object} / {self.disturbance}: the episode ended before the wrap: {info}")
        return features(obs, 0.0), info

    def step(self, action):
        a = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0], -1.0, 1.0))
        obs, reward, terminated, truncated, info = self._env.step(np.array([a], dtype=np.float32))
        self._ticks += 1
        self._return += reward
        self._previous = a
        if not (terminated or truncated):
            obs, skipped, done, info = self._skip(obs, info)
            reward += skipped
            terminated = done and not info.get("error")
            truncated = done and bool(info.get("error"))
        if terminated or truncated:
            info.update(
                object=self.object,
                disturbance=self.disturbance,
                twin_seed=self.twin_seed,
                episode_return=self._return,
                ticks=self._ticks,
            )
        return features(obs, a), float(reward), terminated, truncated, info

    def _skip(self, obs, info):
        """Runs the ticks of :data:`SKIPPED_PHASES` (action 0, which the task ignores there).
        Returns the observation, the summed reward, whether the episode ended, and the info."""
        total = 0.0
        while tendril.PHASES[int(round(float(obs[4])))] in SKIPPED_PHASES:
            obs, reward, terminated, truncated, info = self._env.step(np.zeros(1, dtype=np.float32))
            self._ticks += 1
            self._return += reward
            total += reward
            if terminated or truncated:
                return obs, total, True, info
        return obs, total, False, info

    def close(self):
        for env in self._envs.values():
            env.close()


def summary_metrics(summary):
    """The evaluation's metrics of one run's ``summary.json``: the outcome and the paper's
    numbers (``None`` where the run gave none, e.g. a fluctuation after a drop)."""

    def number(key):
        v = summary.get(key)
        return float(v) if v is not None and math.isfinite(float(v)) else None

    return {
        "outcome": summary.get("outcome"),
        "drop_phase": summary.get("drop_phase"),
        "rise_time_90_s": number("rise_time_90_s"),
        "overshoot_pct": number("overshoot_pct"),
        "max_fluctuation_pct": number("max_fluctuation_pct"),
        "max_fluctuation_outside_push_pct": number("max_fluctuation_outside_push_pct"),
        "peak_force_n": number("peak_force_n"),
        "error": summary.get("error"),
    }
