"""tendril: the digital twin of the FBG-sensed grow-and-twine gripping cell, from Python.

    import tendril
    run = tendril.run("scenarios/short-lift.toml", seed=3)
    run.summary["outcome"]        # summary.json's content: 'held'
    run.trace["force_n"].max()    # numpy arrays by trace.csv column

- :func:`load` reads and checks a scenario file as ``tendril run`` does (``set`` is ``--set``,
  ``overlay`` is ``--overlay``); a bad file or key raises :class:`ScenarioError`.
- :func:`run` runs one on the twin (the numbers are the command line's for the same scenario and
  seed), optionally with a Python force controller; :func:`run_many` runs many in parallel.
- :class:`Session` steps one run tick by tick; ``tendril.env.GripEnv`` (Gymnasium id
  ``tendril/Grip-v0``) makes a learning environment of it.
"""

from . import _mujoco

_mujoco.preload()

from . import _native  # noqa: E402  (after the library it needs)
from ._native import (  # noqa: E402
    PHASES,
    TRACE_COLUMNS,
    ControlContext,
    ControllerError,
    ModelCache,
    Scenario,
    ScenarioError,
    Session,
)
from ._run import Run  # noqa: E402

__all__ = [
    "PHASES",
    "TRACE_COLUMNS",
    "ControlContext",
    "ControllerError",
    "ModelCache",
    "Run",
    "Scenario",
    "ScenarioError",
    "Session",
    "load",
    "run",
    "run_many",
]


def load(path, set=None, overlay=None):
    """Loads scenario file ``path``, checked as ``tendril run`` checks it.

    ``overlay``: a file of scenario keys applied after the file (``--overlay``). ``set``: a dict
    of dotted keys to values (``{"controller.kp": 40}``) or a list of ``"key=value"`` strings,
    applied last (``--set``); a string value is read as the command line reads it. Raises
    :class:`ScenarioError` (a ``ValueError``) with the command line's message: the file, the key
    and what is wrong.
    """
    return _native.load(path, set, overlay)


def run(scenario, seed=None, feedback=None, backend=None, out=None, controller=None):
    """Runs ``scenario`` (a :class:`Scenario` or a scenario file's path) on the twin.

    As ``tendril run``: ``seed``, ``feedback`` (``True``/``False`` or ``"on"``/``"off"``) and
    ``backend`` (``"mujoco"`` or ``"rapier"``) override the scenario's; with ``out``, writes
    ``trace.csv``, ``summary.json``, ``scenario.toml`` and ``frames.bin`` there. ``controller``
    replaces the scenario's force controller: an object with ``update(ctx) -> float`` (the twine
    motor speed in °/s, given a :class:`ControlContext`) and optionally ``reset()`` (called when
    force control starts) and ``max_speed_deg_s``, or a callable ``f(ctx) -> float``. If it raises,
    the run stops (the cell deactivated) and :class:`ControllerError` is raised. Returns a
    :class:`Run`.
    """
    return Run(*_native.run(scenario, seed, feedback, backend, out, controller))


def run_many(scenarios, threads=None):
    """Runs ``scenarios`` (each a :class:`Scenario` or a path) in parallel on ``threads`` threads
    (default: one per core), without holding the GIL. Returns the :class:`Run` of each, in order."""
    return [Run(*r) for r in _native.run_many(list(scenarios), threads)]


def _register_env():
    try:
        import gymnasium
    except ImportError:
        return
    if "tendril/Grip-v0" not in gymnasium.registry:
        gymnasium.register(id="tendril/Grip-v0", entry_point="tendril.env:GripEnv")


_register_env()
