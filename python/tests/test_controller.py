"""Python force controllers: a PID written in Python, errors that stop the run."""

import json

import numpy as np
import pytest

import tendril
from conftest import SHORT_LIFT


class PythonPid:
    """The paper's PID (crates/control/src/pid.rs) in Python: Kp = 20, Ki = 0.05, Kd = 0, ±90 °/s,
    conditional-integration anti-windup, the derivative on the measurement."""

    def __init__(self, kp=20.0, ki=0.05, kd=0.0, max_speed_deg_s=90.0, derivative_filter_s=0.05):
        self.kp, self.ki, self.kd = kp, ki, kd
        self.max_speed_deg_s = max_speed_deg_s
        self.filter_s = derivative_filter_s
        self.resets = 0
        self.calls = 0
        self.reset()

    def reset(self):
        self.integral = 0.0
        self.derivative = 0.0
        self.previous = None
        self.resets += 1

    def update(self, ctx):
        self.calls += 1
        error = ctx.setpoint_n - ctx.force_n
        if self.previous is not None and ctx.dt_s > 0.0:
            raw = -(ctx.force_n - self.previous) / ctx.dt_s
            alpha = ctx.dt_s / (self.filter_s + ctx.dt_s)
            self.derivative += alpha * (raw - self.derivative)
        self.previous = ctx.force_n
        unclamped = self.kp * error + self.ki * (self.integral + error * ctx.dt_s) + self.kd * self.derivative
        output = min(max(unclamped, -self.max_speed_deg_s), self.max_speed_deg_s)
        saturated = output != unclamped
        pushing_further = (saturated or ctx.blocked) and np.sign(error) == np.sign(unclamped)
        if not pushing_further:
            self.integral += error * ctx.dt_s
        return output


def test_a_python_pid_with_the_papers_gains_gives_the_built_in_pids_trace():
    builtin = tendril.run(SHORT_LIFT, seed=2)
    pid = PythonPid()
    python = tendril.run(SHORT_LIFT, seed=2, controller=pid)
    assert pid.calls > 100 and pid.resets >= 2
    assert len(python) == len(builtin)
    for name in ("force_n", "controller_output_deg_s", "twine_motor_rad", "grip_force_n"):
        np.testing.assert_allclose(python.trace[name], builtin.trace[name], rtol=1e-9, atol=1e-9, err_msg=name)
    assert python.outcome == builtin.outcome == "held"


def test_the_context_holds_what_the_built_in_controllers_are_told():
    seen = []

    def hold(ctx):
        seen.append(ctx)
        return 0.0

    tendril.run(SHORT_LIFT, controller=hold)
    phases = {c.phase for c in seen}
    assert "grasp" in phases and "lift" in phases
    first = seen[0]
    assert first.setpoint_n == 0.6 and first.dt_s == pytest.approx(0.01)
    assert len(first.arm_qd_rad_s) == 6 and len(first.arm_qdd_rad_s2) == 6
    assert first.time_to_motion_s > 0.0
    assert any(c.time_to_motion_s == 0.0 for c in seen)
    assert isinstance(first.blocked, bool)


def test_an_exception_stops_the_run_and_is_raised_with_its_traceback(tmp_path):
    class Faulty:
        def __init__(self):
            self.calls = 0

        def update(self, ctx):
            self.calls += 1
            if self.calls == 50:
                raise ZeroDivisionError("the controller divided by zero")
            return 1.0

    faulty = Faulty()
    with pytest.raises(tendril.ControllerError) as caught:
        tendril.run(SHORT_LIFT, controller=faulty, out=tmp_path)
    message = str(caught.value)
    assert "Traceback" in message and "ZeroDivisionError: the controller divided by zero" in message
    assert "test_controller.py" in message
    assert isinstance(caught.value.__cause__, ZeroDivisionError)
    assert faulty.calls == 50, "no call after the failure"
    # The run was stopped there: the files say so, the trace ends at the failing tick.
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["outcome"] == "error"
    assert "ZeroDivisionError" in summary["error"]
    trace = np.genfromtxt(tmp_path / "trace.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert int(trace["controller_on"].sum()) == 50
    assert trace["controller_on"][-1] == 1


def test_a_bad_return_value_is_an_error():
    with pytest.raises(tendril.ControllerError, match="finite"):
        tendril.run(SHORT_LIFT, controller=lambda ctx: float("nan"))
    with pytest.raises(tendril.ControllerError, match="not a number"):
        tendril.run(SHORT_LIFT, controller=lambda ctx: "fast")
    with pytest.raises(TypeError, match="update"):
        tendril.run(SHORT_LIFT, controller=42)


def test_the_output_is_clamped_to_the_speed_limit():
    run = tendril.run(SHORT_LIFT, controller=lambda ctx: 1e6)
    on = run.trace["controller_on"]
    assert np.all(np.abs(run.trace["controller_output_deg_s"][on]) <= 90.0)
