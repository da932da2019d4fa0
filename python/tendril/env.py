"""``GripEnv`` (Gymnasium id ``tendril/Grip-v0``): the grasp-and-carry task as a learning
environment, one episode a run of a scenario on the twin.

Each step is one control tick (10 ms at the default 100 Hz). The task runs as ``tendril run``
runs it (home, grow, wrap, grasp, lift, transfer, lower, release); the agent's action replaces the
force controller's output in the phases where the controller acts (the grasp, and the arm's moves
when ``feedback`` is on), and is ignored in the others.

Action
    ``Box(-1, 1, (1,), float32)``: the twine motor speed as a fraction of the controller's speed
    limit (``controller.max_speed_deg_s``, 90 °/s with the paper's PID); positive tightens.

Observation
    ``Box(float32, (6,))``: ``[Δλ1, Δλ2, F, F*, phase, τ]``: the shifts of FBG1 and FBG2 from their
    tare [pm] (the sensor's raw signal; FBG2 moves only with temperature), the force estimate F
    (eq. 8) [N], the setpoint F* [N], the phase's index in ``tendril.PHASES`` (0 home ... 8 done),
    and the time to the arm's next move τ [s] (capped at ``max_time_to_motion_s``; 0 while it
    moves). Non-finite values (an invalid sample) read as 0.

Reward
    Per tick of ``dt`` seconds (the control tick), with F the force estimate (eq. 8, what the
    paper's metrics read), F* the setpoint and e = |F - F*| / F* the relative error:

    - ``+ hold_reward * dt`` while the object is in the hand (grasp, lift, transfer, lower) and
      not lost: 1 per second held;
    - ``- band_weight * max(0, e - band) * dt`` on the ticks the controller acts: force beyond the
      setpoint band (``band`` = 0.1, the ±10 % band of the paper's oscillation check), 5 per
      unit of relative error beyond it per second;
    - ``- fluctuation_weight * e * dt`` while the arm moves (lift, transfer, lower): the paper's
      "fluctuation while moving" (``max_fluctuation_pct`` in the summary) as a running cost, 2 per
      unit of relative error per second;
    - ``- drop_penalty`` (100, a hundred seconds of holding) on the tick the object is lost.

    The constants are the constructor's arguments of the same names. They are stated choices, not
    fitted: holding dominates (a drop costs more than any grip earns in a paper task of 43.5 s),
    and the force terms rank grips that hold by the paper's two force metrics.

End
    ``terminated`` when the task is done or the object is lost (ground truth: out of contact for
    0.3 s, or slid 20 mm in the hand); ``truncated`` when the cell stops on an error (a physics
    failure), with the error in ``info["error"]``.

Info
    ``time_s``, ``phase``, the ground truth (``true_force_n``, ``grip_force_n``,
    ``object_height_m``, ``slip_speed_m_s``, ``in_contact``), ``dropped``; with a produce item
    (``scenarios/cherry-tomato.toml``, ...) also ``produce``: the contact pressure now and its peak
    so far [kPa], the bruise threshold [kPa], ``bruised``, the stem's tension [N] and ``on_plant``;
    at the end also ``summary`` (``summary.json``'s content, a produce item's under ``produce``).

Domain randomisation
    ``randomize={"produce.modulus_pa": (3e5, 8e5), "object.friction": (0.4, 0.7), ...}``: at
    every reset each key is drawn uniformly from its range with the environment's generator (so a
    seeded sequence repeats) and set for the episode, before ``options["set"]``. Any scenario key
    with a number takes a range: a produce item's properties within their literature range, its
    friction, mass, the setpoint. ``info["randomized"]`` holds the episode's draws.

Render
    ``render_mode="rgb_array"``: ``render()`` returns the scene as MuJoCo's offscreen renderer
    draws it (as ``tendril render`` does: the pad in orange, the contact forces as arrows), a
    ``(render_height, render_width, 3)`` uint8 array. ``render_camera`` chooses the camera as
    ``tendril render --camera`` does: ``"tracking"`` (the default) follows the object through every
    phase, ``"fixed"`` stays aimed at its start, ``"hand"`` looks along the tool from the hand, or
    the name of a camera in the scene's model (``"follow"``: the model's camera on the arm's base
    link, aimed at the object, the one MuJoCo's viewers show). It needs an EGL driver (Mesa's
    ``libegl1 libgl1-mesa-dri`` on Debian/Ubuntu).

Vector
    ``gymnasium.make_vec("tendril/Grip-v0", num_envs=N)`` makes a
    :class:`tendril.vector.GripVectorEnv`: N twins stepped in parallel in Rust, the GIL released.

``reset(seed=..., options={"set": {...}})``: the seed is the scenario's (the sensor noise);
without one, a seed is drawn from the environment's generator. ``options["set"]`` overrides
scenario keys for that episode, after the ``set`` given at construction.
"""

import json
import math
import os

import gymnasium
import numpy as np
from gymnasium import spaces

from . import PHASES, ModelCache, Renderer, Session, load

#: Reward for each second the object is in the hand (see the module's documentation).
HOLD_REWARD = 1.0
#: Half-width of the setpoint band, as a fraction of the setpoint (the ±10 % of the paper's
#: oscillation check, ``crates/run/src/metrics.rs``).
BAND = 0.1
#: Cost of force beyond the band, per unit of relative error per second.
BAND_WEIGHT = 5.0
#: Cost of the relative error while the arm moves, per unit per second.
FLUCTUATION_WEIGHT = 2.0
#: Cost of losing the object: a hundred seconds of holding.
DROP_PENALTY = 100.0
#: Phases in which the object is in the hand.
HOLDING_PHASES = ("grasp", "lift", "transfer", "lower")
#: Phases in which the arm moves with the object.
MOVING_PHASES = ("lift", "transfer", "lower")

#: The scenario an environment runs unless given another: the crimper's short grasp-and-lift
#: (a copy of the repository's ``scenarios/short-lift.toml``, about 15 s of cell time).
DEFAULT_SCENARIO = os.path.join(os.path.dirname(__file__), "scenarios", "short-lift.toml")


class GripEnv(gymnasium.Env):
    """The grasp-and-carry task on the twin (see the module's documentation)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 100}

    def __init__(
        self,
        scenario=None,
        set=None,
        overlay=None,
        drop_penalty=DROP_PENALTY,
        hold_reward=HOLD_REWARD,
        band=BAND,
        band_weight=BAND_WEIGHT,
        fluctuation_weight=FLUCTUATION_WEIGHT,
        max_time_to_motion_s=10.0,
        render_mode=None,
        render_width=640,
        render_height=480,
        render_camera="tracking",
        models=None,
        randomize=None,
    ):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode: expected None or 'rgb_array', got {render_mode!r}")
        self.render_mode = render_mode
        self._render_size = (int(render_width), int(render_height))
        self._render_camera = str(render_camera)
        self._renderer = None
        self._last_frame = None
        self._path = os.fspath(scenario) if scenario is not None else DEFAULT_SCENARIO
        self._set = _as_dict(set)
        self._overlay = overlay
        self._randomize = _ranges(randomize)
        self._drawn = {}
        self.drop_penalty = float(drop_penalty)
        self.hold_reward = float(hold_reward)
        self.band = float(band)
        self.band_weight = float(band_weight)
        self.fluctuation_weight = float(fluctuation_weight)
        self.max_time_to_motion_s = float(max_time_to_motion_s)
        # Compiled scene models, shared with other environments when given (a vector of them).
        self._models = models if models is not None else ModelCache()
        self._session = None
        # Checked now: a bad scenario fails at construction, not at the first reset.
        self._scenario = load(self._path, self._set, self._overlay)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        low = np.array([-1e4, -1e4, -20.0, 0.0, 0.0, 0.0], dtype=np.float32)
        high = np.array([1e4, 1e4, 20.0, 20.0, len(PHASES) - 1, self.max_time_to_motion_s], dtype=np.float32)
        self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self._last_obs = np.zeros(6, dtype=np.float32)
        # The control tick [s]: the render rate and the reward's time unit.
        self.metadata = dict(self.metadata, render_fps=round(1.0 / self._scenario_tick_s()))

    def _scenario_tick_s(self):
        return 1.0 / float(self._scenario.to_dict().get("control_rate_hz", 100.0))

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._end()
        overrides = dict(self._set)
        # Domain randomisation: each range drawn with the environment's generator.
        self._drawn = {key: float(self.np_random.uniform(low, high)) for key, (low, high) in self._randomize.items()}
        overrides.update(self._drawn)
        overrides.update(_as_dict((options or {}).get("set")))
        # The twin's seed: the one given, else drawn from the environment's generator (seeded by
        # an earlier reset(seed=...)), so every episode differs and a seeded sequence repeats.
        overrides["seed"] = int(seed) if seed is not None else int(self.np_random.integers(0, 2**63 - 1))
        self._scenario = load(self._path, overrides, self._overlay)
        self._session = Session(self._scenario, self._models)
        self._dropped = False
        seen = self._session.observation()
        if seen is None:
            summary = json.loads(self._session.finish())
            raise RuntimeError(f"the run could not start: {summary.get('error')}")
        self._last_obs = self._observe(seen)
        return self._last_obs, self._info(seen, None)

    def step(self, action):
        speed = self._twine_speed(action)
        return self._after_step(self._session.step(twine_speed_deg_s=speed))

    def render(self):
        """The scene now, as a ``(height, width, 3)`` uint8 array (``render_mode="rgb_array"``);
        ``None`` without a render mode. After the episode's end, its last picture."""
        if self.render_mode is None:
            return None
        if self._session is None:
            return self._last_frame
        if self._renderer is None or not self._renderer.draws(self._session):
            width, height = self._render_size
            self._renderer = Renderer(self._session, width=width, height=height, camera=self._render_camera)
        rgb = self._renderer.render(self._session)
        if rgb is not None:
            width, height = self._render_size
            self._last_frame = np.frombuffer(rgb, dtype=np.uint8).reshape(height, width, 3)
        return self._last_frame

    def _twine_speed(self, action):
        """The twine speed [°/s] an action in [-1, 1] stands for."""
        if self._session is None:
            raise RuntimeError("step() before reset(), or after the episode ended: call reset()")
        a = float(np.asarray(action, dtype=np.float64).reshape(-1)[0])
        if not math.isfinite(a):
            raise ValueError(f"the action must be finite, got {a}")
        return float(np.clip(a, -1.0, 1.0)) * self._session.max_speed_deg_s

    def _after_step(self, row):
        """``step``'s answer for the tick that gave trace row ``row``."""
        if row is None:
            # The run was already over (an error on the last read): nothing ran.
            return self._last_obs, 0.0, False, True, self._finish({})
        was_dropped = self._dropped
        self._dropped = self._dropped or self._session.dropped() is not None
        reward = self._reward(row, lost_now=self._dropped and not was_dropped)
        seen = self._session.observation()
        if seen is not None:
            self._last_obs = self._observe(seen)
        info = self._info(seen, row)
        terminated = self._dropped or row["phase"] == "done"
        truncated = not terminated and self._session.is_over
        if terminated or truncated:
            info = self._finish(info)
        return self._last_obs, float(reward), terminated, truncated, info

    def close(self):
        self._end()

    def _reward(self, row, lost_now):
        """The tick's reward (see the module's documentation)."""
        if lost_now:
            return -self.drop_penalty
        if self._dropped:
            return 0.0
        dt = self._session.dt_s
        setpoint = row["setpoint_n"]
        error = abs(row["force_n"] - setpoint) / setpoint if setpoint > 0.0 and math.isfinite(row["force_n"]) else 0.0
        reward = 0.0
        if row["phase"] in HOLDING_PHASES:
            reward += self.hold_reward * dt
        if row["controller_on"]:
            reward -= self.band_weight * max(0.0, error - self.band) * dt
        if row["phase"] in MOVING_PHASES:
            reward -= self.fluctuation_weight * error * dt
        return reward

    def _observe(self, seen):
        ttm = seen["time_to_motion_s"]
        values = [
            seen["delta1_pm"],
            seen["delta2_pm"],
            seen["force_n"],
            seen["setpoint_n"],
            seen["phase_index"],
            min(ttm, self.max_time_to_motion_s) if not math.isnan(ttm) else 0.0,
        ]
        obs = np.nan_to_num(np.array(values, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
        return np.clip(obs, self.observation_space.low, self.observation_space.high).astype(np.float32)

    def _info(self, seen, row):
        info = {"dropped": self._dropped}
        if self._drawn:
            info["randomized"] = dict(self._drawn)
        if seen is not None:
            info["time_s"] = seen["time_s"]
            info["phase"] = seen["phase"]
            truth = seen["truth"] or {}
            info["true_force_n"] = truth.get("sensor_force_n", math.nan)
            for key in ("grip_force_n", "object_height_m", "slip_speed_m_s", "in_contact"):
                info[key] = truth.get(key)
            if truth.get("produce") is not None:
                info["produce"] = dict(truth["produce"])
        elif row is not None:
            info["time_s"] = row["time_s"]
            info["phase"] = row["phase"]
            info["true_force_n"] = row["true_force_n"]
            for key in ("grip_force_n", "object_height_m", "slip_speed_m_s"):
                info[key] = row[key]
        return info

    def _finish(self, info):
        if self.render_mode is not None:
            self.render()
        summary = json.loads(self._session.finish())
        self._session = None
        info["summary"] = summary
        if summary.get("error"):
            info["error"] = summary["error"]
        return info

    def _end(self):
        if self._session is not None:
            self._session.finish()
            self._session = None


def _as_dict(set):
    """``set`` as a dict of overrides (a list of ``"key=value"`` strings is split)."""
    if set is None:
        return {}
    if isinstance(set, dict):
        return dict(set)
    out = {}
    for item in set:
        key, sep, value = str(item).partition("=")
        if not sep:
            raise ValueError(f"set: expected \"key=value\", got {item!r}")
        out[key.strip()] = value.strip()
    return out


def _ranges(randomize):
    """``{key: (low, high)}`` checked: each key a string, each range two finite numbers, low <= high."""
    out = {}
    for key, bounds in dict(randomize or {}).items():
        if not isinstance(key, str):
            raise TypeError(f"randomize: a key must be a scenario key (str), got {key!r}")
        try:
            low, high = (float(b) for b in bounds)
        except (TypeError, ValueError):
            raise ValueError(f"randomize: {key}: expected a (low, high) pair of numbers, got {bounds!r}") from None
        if not (math.isfinite(low) and math.isfinite(high) and low <= high):
            raise ValueError(f"randomize: {key}: expected finite low <= high, got ({low}, {high})")
        out[key] = (low, high)
    return out
