"""A Python controller on the real path: `tendril.run(hardware="real")` against `tendril serve`."""

import os
import queue
import subprocess
import threading

import numpy as np
import pytest

import tendril
from conftest import SHORT_LIFT, free_port_base
from test_controller import PythonPid


def _may_use_sched_fifo():
    """Whether this process may raise a thread to SCHED_FIFO (as the Rust real-path tests ask)."""
    result = []

    def probe():
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
            result.append(True)
        except (PermissionError, OSError, AttributeError):
            result.append(False)

    t = threading.Thread(target=probe)
    t.start()
    t.join()
    return result[0]


@pytest.fixture
def served(tendril_bin):
    """`tendril serve scenarios/short-lift.toml` on free ports: (port base, Dynamixel pty, rt priority)."""
    fifo = _may_use_sched_fifo()
    base = free_port_base()
    args = [tendril_bin, "serve", str(SHORT_LIFT), "--port-base", str(base), "--seconds", "120"]
    if fifo:
        args += ["--rt-priority", "19"]
    server = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in server.stdout], daemon=True).start()
    pty = None
    try:
        while pty is None:
            line = lines.get(timeout=60)
            if line.strip().startswith("Dynamixel "):
                pty = line.split()[1]
        yield base, pty, (20 if fifo else 0)
    finally:
        server.kill()
        server.wait()


def test_a_python_controller_drives_the_real_path_against_tendril_serve(served, tmp_path):
    base, pty, priority = served
    pid = PythonPid()
    run = tendril.run(
        SHORT_LIFT, hardware="real", dxl=pty, port_base=base, rt_priority=priority, controller=pid, out=tmp_path
    )
    summary = run.summary
    assert summary["backend"] == "real", summary
    assert run.outcome == "held", summary.get("error")
    assert pid.calls > 200 and run.controller_times["calls"] == pid.calls
    # The grip the Python PID holds in the grasp's last second, on the virtual cell's sensor.
    t, phase, force = run.trace["time_s"], run.trace["phase"], run.trace["force_n"]
    grasp = phase == "grasp"
    late = grasp & (t > t[grasp].max() - 1.0)
    assert abs(np.median(force[late]) - 0.6) < 0.06
    assert (tmp_path / "summary.json").is_file() and (tmp_path / "trace.csv").is_file()


def test_the_real_path_is_refused_without_a_port_or_with_a_twin_only_option():
    with pytest.raises(ValueError, match="dxl"):
        tendril.run(SHORT_LIFT, hardware="real")
    with pytest.raises(ValueError, match="hardware"):
        tendril.run(SHORT_LIFT, hardware="robot")
    with pytest.raises(ValueError, match="rt_priority"):
        tendril.run(SHORT_LIFT, rt_priority=10)
