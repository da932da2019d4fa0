"""tendril.run and run_many: the command line's runs, from Python."""

import _thread
import json
import signal
import subprocess
import threading
import time

import numpy as np
import pytest

import tendril
from conftest import ROOT, SHORT_LIFT, without_timing


@pytest.fixture(scope="module")
def cli_and_python(tendril_bin, tmp_path_factory):
    """The same scenario and seed run by `tendril run` and by tendril.run, each into a folder."""
    cli_dir = tmp_path_factory.mktemp("cli")
    py_dir = tmp_path_factory.mktemp("py")
    subprocess.run(
        [tendril_bin, "run", str(SHORT_LIFT), "--seed", "3", "--feedback", "off", "--out", str(cli_dir)],
        check=True,
        capture_output=True,
    )
    run = tendril.run(SHORT_LIFT, seed=3, feedback="off", out=py_dir)
    return cli_dir, py_dir, run


def test_the_files_equal_the_command_lines(cli_and_python):
    cli_dir, py_dir, _ = cli_and_python
    assert (py_dir / "trace.csv").read_bytes() == (cli_dir / "trace.csv").read_bytes()
    cli = json.loads((cli_dir / "summary.json").read_text())
    py = json.loads((py_dir / "summary.json").read_text())
    assert without_timing(py) == without_timing(cli)
    assert (py_dir / "scenario.toml").read_bytes() == (cli_dir / "scenario.toml").read_bytes()
    assert (py_dir / "frames.bin").read_bytes() == (cli_dir / "frames.bin").read_bytes()


def test_the_summary_and_the_trace_are_the_runs(cli_and_python):
    cli_dir, _, run = cli_and_python
    cli = json.loads((cli_dir / "summary.json").read_text())
    assert without_timing(run.summary) == without_timing(cli)
    assert run.outcome == run.summary["outcome"] == "held"
    assert list(run.trace) == list(tendril.TRACE_COLUMNS)
    header = (cli_dir / "trace.csv").read_text().splitlines()[0].split(",")
    assert list(run.trace) == header
    csv = np.genfromtxt(cli_dir / "trace.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert len(run) == len(csv)
    for name in ("time_s", "force_n", "fbg1_nm", "twine_motor_rad", "grip_force_n"):
        assert run.trace[name].dtype == np.float64
        np.testing.assert_allclose(run.trace[name], csv[name], atol=1e-3, err_msg=name)
    assert list(run.trace["phase"]) == list(csv["phase"])
    assert run.trace["controller_on"].dtype == bool
    np.testing.assert_array_equal(run.trace["controller_on"], csv["controller_on"].astype(bool))


def test_to_pandas_is_the_trace(cli_and_python):
    _, _, run = cli_and_python
    frame = run.to_pandas()
    assert list(frame.columns) == list(run.trace)
    assert len(frame) == len(run)
    assert frame["phase"].iloc[-1] == "done"


def test_a_loaded_scenario_runs_as_its_path_does():
    scenario = tendril.load(SHORT_LIFT, set={"seed": 5})
    by_scenario = tendril.run(scenario)
    by_path = tendril.run(SHORT_LIFT, seed=5)
    assert without_timing(by_scenario.summary) == without_timing(by_path.summary)
    np.testing.assert_array_equal(by_scenario.trace["force_n"], by_path.trace["force_n"])


def test_run_many_gives_the_runs_one_by_one_would_in_order():
    scenarios = [tendril.load(SHORT_LIFT, set={"seed": s}) for s in (1, 2)]
    many = tendril.run_many(scenarios, threads=2)
    assert [r.summary["seed"] for r in many] == [1, 2]
    alone = tendril.run(scenarios[1])
    assert without_timing(many[1].summary) == without_timing(alone.summary)
    np.testing.assert_array_equal(many[1].trace["force_n"], alone.trace["force_n"])
    with pytest.raises(ValueError, match="threads"):
        tendril.run_many(scenarios, threads=0)


def test_run_many_reports_progress_and_stops_when_the_callback_raises():
    scenarios = [tendril.load(SHORT_LIFT, set={"seed": s}) for s in (1, 2, 3)]
    seen = []
    tendril.run_many(scenarios, threads=2, progress=lambda done, total: seen.append((done, total)))
    assert seen == [(1, 3), (2, 3), (3, 3)]

    def give_up(done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        tendril.run_many(scenarios, threads=1, progress=give_up)


@pytest.fixture
def ctrl_c_raises():
    """Python's own Ctrl-C handler (KeyboardInterrupt) for the test. A process started in the
    background by a shell without job control inherits SIGINT ignored, and then Python neither
    installs the handler nor turns `_thread.interrupt_main()` into a KeyboardInterrupt."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_ctrl_c_stops_the_run_safely_and_keeps_what_it_wrote(tmp_path, ctrl_c_raises):
    # Ctrl-C half a second in (what Python's SIGINT handler does: a KeyboardInterrupt on the main
    # thread), in a run slowed by a controller that sleeps, so that it is still going.
    def slow(ctx):
        time.sleep(0.002)
        return 0.0

    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        tendril.run(SHORT_LIFT, out=tmp_path, controller=slow)
    assert time.monotonic() - started < 5.0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["outcome"] == "error" and "interrupted" in summary["error"]
    lines = (tmp_path / "trace.csv").read_text().splitlines()
    assert len(lines) > 10 and lines[-1].count(",") == lines[0].count(",")


def test_run_many_stops_on_ctrl_c(ctrl_c_raises):
    scenarios = [tendril.load(SHORT_LIFT, set={"seed": s}) for s in range(1, 9)]
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        tendril.run_many(scenarios, threads=1)
    # Eight runs one after another take several seconds; the interrupt ends them at once.
    assert time.monotonic() - started < 2.0


def test_a_controller_slower_than_the_tick_is_reported_with_its_time():
    calls = []

    def sometimes_slow(ctx):
        calls.append(1)
        if len(calls) == 5:
            time.sleep(0.015)
        return 20.0 * (ctx.setpoint_n - ctx.force_n)

    with pytest.warns(tendril.SlowControllerWarning, match=r"longer than the 10.00 ms control tick in 1 of"):
        run = tendril.run(SHORT_LIFT, controller=sometimes_slow)
    times = run.controller_times
    assert times["calls"] == len(calls) and times["over_tick"] == 1 and times["max_ms"] >= 15.0
    assert times["mean_ms"] < times["max_ms"]
    assert tendril.run(SHORT_LIFT).controller_times is None


def test_a_run_lets_other_python_threads_go_on():
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    try:
        tendril.run(SHORT_LIFT)
    finally:
        stop.set()
        counter.join()
    # With the GIL held for the whole run the counter would have run only before and after.
    assert len(ticks) > 50


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="unknown physics backend `bullet`"):
        tendril.run(SHORT_LIFT, backend="bullet")
    with pytest.raises(ValueError, match="feedback"):
        tendril.run(SHORT_LIFT, feedback="sometimes")
    with pytest.raises(ValueError, match="seed"):
        tendril.run(SHORT_LIFT, seed=-1)
    with pytest.raises(TypeError, match="scenario"):
        tendril.run(42)
    with pytest.raises(tendril.ScenarioError):
        tendril.run(SHORT_LIFT.with_name("none.toml"))


def test_a_sensor_arrays_pads_are_in_the_trace_and_the_observation(tmp_path):
    """hammer-array's three pads: the trace's array columns as `trace.csv` has them, and each
    further pad's estimate in a session's observation."""
    scenario = tendril.load(ROOT / "scenarios" / "hammer-array.toml", set={"task.grasp_s": 3})
    run = tendril.run(scenario, out=tmp_path)
    header = (tmp_path / "trace.csv").read_text().splitlines()[0].split(",")
    assert list(run.trace) == header
    assert header[-1] == "control_force_n" and "pad2_force_n" in header
    np.testing.assert_array_equal(run.trace["control_force_n"], run.trace["force_n"])
    assert run.summary["array"]["pad_figures"][1]["pad"] == 1
    session = tendril.Session(scenario)
    observation = session.observation()
    assert len(observation["array_force_n"]) == 2
    assert observation["control_force_n"] == observation["force_n"]


def test_a_produce_run_has_its_damage_in_the_summary_and_the_trace():
    cherry = ROOT / "scenarios" / "cherry-tomato.toml"
    short = {"task.grasp_s": 3.0, "task.lift_s": 2.0, "task.transfer_s": 1.0, "task.lower_s": 1.0}
    run = tendril.run(tendril.load(cherry, set=short))
    produce = run.summary["produce"]
    assert produce["peak_pressure_kpa"] > 0.0 and produce["bruise_threshold_kpa"] == 150.0
    assert produce["bruised"] == (produce["peak_pressure_kpa"] > 150.0)
    for column in ("pressure_kpa", "bruise_area_mm2", "stem_tension_n", "on_plant", "bump_force_n"):
        assert column in run.trace, column
    assert run.trace["pressure_kpa"].max() <= produce["peak_pressure_kpa"] + 1e-9
