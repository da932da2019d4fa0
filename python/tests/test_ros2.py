"""tendril on a lab's ROS 2 graph, with third-party peers from PyPI and no ROS installation:
Cyclone DDS as the lab's node against `tendril serve --ros2`, and `rosbags` and Foxglove's `mcap`
reading a run's bag."""

import csv
import math
import os
import pathlib
import subprocess
import time

import pytest

from conftest import SHORT_LIFT, free_port_base

ros2_lab = pytest.importorskip("ros2_lab", reason="cyclonedds is installed by `cargo xtask test`")


def _domain():
    """A ROS domain of this test process's own (so concurrent test runs on one machine never meet)."""
    return 100 + os.getpid() % 100


def _take_until(reader, done, timeout_s, what):
    """Samples from `reader` until `done(samples)` holds; fails with `what` after `timeout_s`."""
    got = []
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        got.extend(reader.take(32))
        if done(got):
            return got
        time.sleep(0.01)
    pytest.fail(f"{what}: not within {timeout_s} s ({len(got)} samples)")


@pytest.fixture
def served_ros2(tendril_bin):
    """`tendril serve scenarios/short-lift.toml --ros2` in a domain of its own: (domain, process)."""
    domain = _domain()
    args = [tendril_bin, "serve", str(SHORT_LIFT), "--ros2", "--set", f"ros2.domain_id={domain}"]
    args += ["--port-base", str(free_port_base()), "--seconds", "120"]
    server = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = ""
    while "ROS 2" not in line:
        line = server.stdout.readline()
        if not line:
            pytest.fail(f"tendril serve ended: {server.stderr.read()}")
    yield domain, server
    server.terminate()
    server.wait(timeout=30)


def test_a_lab_node_reads_the_twin_and_drives_its_motors(served_ros2):
    domain, server = served_ros2
    lab = ros2_lab.LabNode(domain)
    joints = lab.reader("/joint_states", ros2_lab.JointState)
    peaks = lab.reader("/fbg/peaks", ros2_lab.FbgPeaks)
    wrench = lab.reader("/fbg/pad0/wrench", ros2_lab.WrenchStamped)
    clock = lab.reader("/clock", ros2_lab.Clock)
    commands = lab.writer("/robot_joint_command", ros2_lab.JointState)

    state = _take_until(joints, lambda s: len(s) > 0, 20, "/joint_states")[-1]
    assert list(state.name) == [
        "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
        "wrist_3_joint", "growth_motor_joint", "twine_motor_joint",
    ]
    assert abs(state.position[0] + math.pi / 2) < 1e-2, "the arm at home: base joint at -90°"
    assert len(state.velocity) == 8 and all(abs(v) < 1e-6 for v in state.velocity[:6]), "the arm stands still"

    sample = _take_until(peaks, lambda s: len(s) > 0, 10, "/fbg/peaks")[-1]
    assert list(sample.grating) == ["pad0/fbg1", "pad0/fbg2"]
    assert 1530 < sample.wavelength_nm[0] < 1545 and 1545 < sample.wavelength_nm[1] < 1560, sample

    # The sensor node's estimate once tared (after 0.5 s): the untouched pad reads what the twin's
    # own run reads at home, eq. 8's intercept (0.16 N, trace.csv's force_n in the home phase).
    force = _take_until(wrench, lambda s: sum(not math.isnan(w.wrench.force.z) for w in s) > 3, 10, "/fbg/pad0/wrench")
    tared = [w.wrench.force.z for w in force if not math.isnan(w.wrench.force.z)]
    assert force[-1].header.frame_id == "fbg_pad0"
    assert all(0.12 < f < 0.21 for f in tared), tared

    # /clock follows the twin, in real time.
    first = ros2_lab.as_seconds(_take_until(clock, lambda s: len(s) > 0, 10, "/clock")[-1].clock)
    wall = time.monotonic()
    time.sleep(1.0)
    later = ros2_lab.as_seconds(_take_until(clock, lambda s: len(s) > 0, 10, "/clock")[-1].clock)
    assert abs((later - first) - (time.monotonic() - wall)) < 0.25, (first, later)

    # The twine motor by position: it turns to the goal and settles short of it where its
    # position gain balances the tendon's pull (the retracted finger's tendon is stiff).
    def positions():
        latest = _take_until(joints, lambda s: len(s) > 0, 5, "/joint_states")[-1]
        return dict(zip(latest.name, latest.position))

    def command(name, position=(), velocity=()):
        commands.write(ros2_lab.JointState(ros2_lab.Header(ros2_lab.stamp(0.0), ""), [name], list(position), list(velocity), []))

    start = positions()["twine_motor_joint"]
    end = time.monotonic() + 3.0
    while time.monotonic() < end:
        command("twine_motor_joint", position=[start + 0.3])
        time.sleep(0.05)
    turned = positions()["twine_motor_joint"] - start
    assert 0.2 < turned < 0.32, turned
    # The growth motor by velocity: 0.2 rad/s for 2 s of commands moves it about 0.4 rad.
    before = positions()["growth_motor_joint"]
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        command("growth_motor_joint", velocity=[0.2])
        time.sleep(0.02)
    time.sleep(0.5)
    moved = positions()["growth_motor_joint"] - before
    assert 0.3 < moved < 0.5, moved

    # A command the twin cannot follow is refused with its reason; the twin goes on.
    commands.write(ros2_lab.JointState(ros2_lab.Header(ros2_lab.stamp(0.0), ""), ["gripper_joint"], [0.1], [], []))
    _take_until(joints, lambda s: len(s) > 5, 5, "/joint_states after a bad command")
    assert server.poll() is None, "serve still runs"
    server.terminate()
    _, err = server.communicate(timeout=30)
    assert "joint `gripper_joint` is not one of the twin's" in err, err


def _trace(run_dir):
    with open(run_dir / "trace.csv") as f:
        return list(csv.DictReader(f))


def test_rosbags_and_mcap_read_a_runs_bag_with_the_traces_values(tendril_bin, tmp_path):
    from mcap.reader import make_reader
    from rosbags.highlevel import AnyReader

    out = tmp_path / "run"
    subprocess.run([tendril_bin, "run", str(SHORT_LIFT), "--out", str(out), "--bag"], check=True, capture_output=True)
    rows = _trace(out)
    bag = out / "bag"
    assert (bag / "metadata.yaml").is_file()

    with AnyReader([bag]) as reader:
        topics = {c.topic: c.msgtype for c in reader.connections}
        assert topics["/joint_states"] == "sensor_msgs/msg/JointState"
        assert topics["/fbg/pad0/wrench"] == "geometry_msgs/msg/WrenchStamped"
        assert topics["/tendril/control_tick"] == "tendril_msgs/msg/ControlTick"
        by_topic = {}
        for connection, timestamp, raw in reader.messages():
            by_topic.setdefault(connection.topic, []).append((timestamp, reader.deserialize(raw, connection.msgtype)))

    ticks, states, peaks = by_topic["/tendril/control_tick"], by_topic["/joint_states"], by_topic["/fbg/peaks"]
    assert len(ticks) == len(rows) == len(states) == len(peaks) == len(by_topic["/clock"])
    # trace.csv rounds each column to a stated number of decimals: equal to that precision.
    def same(value, column, decimals):
        assert value == pytest.approx(float(row[column]), abs=0.51 * 10**-decimals, nan_ok=True), column

    for row, (t_ns, tick), (_, js), (_, pk), (_, w) in zip(rows, ticks, states, peaks, by_topic["/fbg/pad0/wrench"]):
        same(t_ns * 1e-9, "time_s", 4)
        assert tick.phase == row["phase"]
        for field in ("force_n", "true_force_n", "object_height_m"):
            same(getattr(tick, field), field, 5)
        same(tick.setpoint_n, "setpoint_n", 3)
        same(tick.grip_force_n, "grip_force_n", 4)
        same(js.position[6], "growth_motor_rad", 5)
        same(js.position[7], "twine_motor_rad", 5)
        same(pk.wavelength_nm[0], "fbg1_nm", 4)
        same(pk.wavelength_nm[1], "fbg2_nm", 4)
        same(w.wrench.force.z, "force_n", 5)

    # Foxglove's own MCAP library: a ros2 profile, ros2msg schemas, CDR channels, an index.
    mcap_file = next(bag.glob("*.mcap"))
    with open(mcap_file, "rb") as f:
        mcap = make_reader(f)
        assert mcap.get_header().profile == "ros2"
        summary = mcap.get_summary()
        assert summary is not None and summary.statistics.message_count > 5 * len(rows)
        assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
        assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
        assert summary.chunk_indexes, "indexed chunks, for seeking"


def test_a_bag_that_exists_is_never_written_over(tendril_bin, tmp_path):
    out = tmp_path / "run"
    (out / "bag").mkdir(parents=True)
    (out / "trace.csv").write_text("kept\n")
    done = subprocess.run([tendril_bin, "run", str(SHORT_LIFT), "--out", str(out), "--bag"], capture_output=True, text=True)
    assert done.returncode != 0
    assert "bag: exists" in done.stderr, done.stderr
    assert (out / "trace.csv").read_text() == "kept\n"


def _fit(tendril_bin, spec, out):
    done = subprocess.run([tendril_bin, "fit", str(spec), "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    import json

    return json.loads((out / "fit.json").read_text())


def test_fit_reads_a_labs_sqlite3_bag_as_it_reads_the_runs_trace(tendril_bin, tmp_path):
    """A lab's recording of its cell (Humble's default sqlite3 storage, written by `rosbags`):
    the force on the pad's wrench topic, the joint states, the phase as `std_msgs/msg/String` from
    the lab's scheduler whenever it changes, stamped on the wall clock."""
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    run = tmp_path / "on"
    subprocess.run([tendril_bin, "run", str(SHORT_LIFT), "--out", str(run), "--bag"], check=True, capture_output=True)
    store = get_typestore(Stores.ROS2_HUMBLE)
    epoch_ns = 1_764_000_000 * 10**9
    lab = tmp_path / "lab"
    with AnyReader([run / "bag"]) as reader, Writer(lab, version=8, storage_plugin=StoragePlugin.SQLITE3) as writer:
        wrench = writer.add_connection("/fbg/pad0/wrench", "geometry_msgs/msg/WrenchStamped", typestore=store)
        joints = writer.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=store)
        phase = writer.add_connection("/scheduler/phase", "std_msgs/msg/String", typestore=store)
        last_phase = None
        for connection, t, raw in reader.messages():
            if connection.topic == "/fbg/pad0/wrench":
                writer.write(wrench, epoch_ns + t, raw)
            elif connection.topic == "/joint_states":
                writer.write(joints, epoch_ns + t, raw)
            elif connection.topic == "/tendril/control_tick":
                now = reader.deserialize(raw, connection.msgtype).phase
                if now != last_phase:
                    message = store.types["std_msgs/msg/String"](data=now)
                    writer.write(phase, epoch_ns + t, store.serialize_cdr(message, "std_msgs/msg/String"))
                    last_phase = now
    assert next(lab.glob("*.db3")).is_file()

    parameter = '[parameters."finger.relaxation_time_s"]\nmin = 5.0\nmax = 60.0\nstart = 18.0\n[budget]\nevaluations = 1\n'
    on_csv = tmp_path / "csv.toml"
    on_csv.write_text('recordings = ["on"]\n' + parameter)
    on_bag = tmp_path / "bag.toml"
    on_bag.write_text(
        '[[bags]]\npath = "lab"\nscenario = "on/scenario.toml"\n[bags.topics]\nphase = "/scheduler/phase"\n' + parameter
    )
    csv_fit, bag_fit = _fit(tendril_bin, on_csv, tmp_path / "f1"), _fit(tendril_bin, on_bag, tmp_path / "f2")
    a, b = csv_fit["residuals"][0], bag_fit["residuals"][0]
    assert b["recording"] == "lab" and a["same_outcome"] and b["same_outcome"]
    # trace.csv's rounding (10 µN) is all that tells the two recordings apart.
    assert abs(a["force_rmse_n"] - b["force_rmse_n"]) < 1e-4, (a, b)
    assert abs(a["twine_motor_rmse_rad"] - b["twine_motor_rmse_rad"]) < 1e-4, (a, b)

    # A truncated bag is named in the error.
    db3 = next(lab.glob("*.db3"))
    db3.write_bytes(db3.read_bytes()[:2000])
    done = subprocess.run([tendril_bin, "fit", str(on_bag), "--out", str(tmp_path / "f3")], capture_output=True, text=True)
    assert done.returncode != 0 and str(db3) in done.stderr, done.stderr
