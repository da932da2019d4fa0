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

import sys
import warnings

from . import _mujoco

_mujoco.preload()

from . import _native  # noqa: E402  (after the library it needs)
from ._native import (  # noqa: E402
    PHASES,
    TRACE_COLUMNS,
    ControlContext,
    ControllerError,
    ModelCache,
    Renderer,
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
    "Renderer",
    "Run",
    "Scenario",
    "ScenarioError",
    "Session",
    "SlowControllerWarning",
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


def run(
    scenario,
    seed=None,
    feedback=None,
    backend=None,
    out=None,
    controller=None,
    hardware="sim",
    ur="127.0.0.1",
    dxl=None,
    interrogator="127.0.0.1",
    port_base=None,
    rt_priority=0,
):
    """Runs ``scenario`` (a :class:`Scenario` or a scenario file's path) on the twin, or on the
    devices with ``hardware="real"``.

    As ``tendril run``: ``seed``, ``feedback`` (``True``/``False`` or ``"on"``/``"off"``) and
    ``backend`` (``"mujoco"`` or ``"rapier"``) override the scenario's; with ``out``, writes
    ``trace.csv``, ``summary.json``, ``scenario.toml`` (and on the twin ``frames.bin``) there.
    ``hardware="real"`` drives the UR5e at ``ur``, the Dynamixel bus on ``dxl`` and the
    interrogator at ``interrogator`` (``port_base`` as ``tendril serve --port-base``; ``rt_priority``
    a SCHED_FIFO priority for the loop, as ``--rt-priority``): the same loop, against ``tendril
    serve``'s virtual devices or the real ones.

    ``controller`` replaces the scenario's force controller: an object with ``update(ctx) ->
    float`` (the twine motor speed in °/s, given a :class:`ControlContext`) and optionally
    ``reset()`` (called when force control starts) and ``max_speed_deg_s``, or a callable
    ``f(ctx) -> float``. If it raises, the run stops (the cell deactivated) and
    :class:`ControllerError` is raised. Its call times are in :attr:`Run.controller_times`; on
    the twin a controller slower than the control tick gets a :class:`SlowControllerWarning`, on
    the real cell its first late call stops the run (the summary's ``error`` says how late).

    Ctrl-C stops the run through the cell's safe stop; ``KeyboardInterrupt`` is raised once the
    trace and summary are written. Returns a :class:`Run`.
    """
    result = Run(
        *_native.run(
            scenario, seed, feedback, backend, out, controller, hardware, ur, dxl, interrogator, port_base, rt_priority
        )
    )
    times = result.controller_times
    if hardware == "sim" and times and times["over_tick"] > 0:
        warnings.warn(
            f"the controller took up to {times['max_ms']:.2f} ms per call, longer than the "
            f"{times['tick_ms']:.2f} ms control tick in {times['over_tick']} of {times['calls']} calls: "
            "on the real cell those ticks would be late (the run stops there)",
            SlowControllerWarning,
            stacklevel=2,
        )
    return result


class SlowControllerWarning(UserWarning):
    """A Python controller's ``update`` took longer than the control tick on the twin."""


def run_many(scenarios, threads=None, progress=None):
    """Runs ``scenarios`` (each a :class:`Scenario` or a path) in parallel on ``threads`` threads
    (default: one per core), without holding the GIL. ``progress``: called as ``progress(done,
    total)`` after each run ends; ``progress=True`` prints a line for each. Returns the
    :class:`Run` of each, in order. Ctrl-C stops the runs under way and raises
    ``KeyboardInterrupt``."""
    if progress is True:
        progress = _print_progress
    return [Run(*r) for r in _native.run_many(list(scenarios), threads, progress)]


def _print_progress(done, total):
    print(f"tendril: {done}/{total} runs done", file=sys.stderr, flush=True)


def _register_env():
    try:
        import gymnasium
    except ImportError:
        return
    if "tendril/Grip-v0" not in gymnasium.registry:
        gymnasium.register(
            id="tendril/Grip-v0",
            entry_point="tendril.env:GripEnv",
            vector_entry_point="tendril.vector:GripVectorEnv",
        )


_register_env()
