"""How fast the Python package drives the twin: ``python python/bench/speed.py [--quick]``.

Prints a Markdown table (the book's figures in docs/guide/python.md#speed) of:

1. environment steps per second: ``GripEnv`` alone, and ``gymnasium.make_vec`` vectors of N twins
   (steps of all twins together per wall second);
2. a Python controller's cost per control tick: the same run with the built-in PID and with the
   paper's PID written in Python (which gives the built-in's trace, so the two runs do the same
   work but for the calls), and each call's time as ``Run.controller_times`` measures it;
3. a whole run from Python (``tendril.run``) against the command line (``tendril run``).

Each figure is the best of ``--repeat`` runs (3), so that other work on the machine inflates it
as little as possible; CPU times are given beside wall times where they tell more. Run from the
repository root with the package installed (``pip install .``) and ``target/release/tendril``
built (``cargo build --release``) for the command line's row.
"""

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

import gymnasium
import numpy as np

import tendril

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHORT_LIFT = os.path.join(ROOT, "scenarios", "short-lift.toml")
CRIMPER = os.path.join(ROOT, "scenarios", "crimper.toml")


def best(repeat, measure):
    """The smallest of ``repeat`` measurements (each a tuple; compared on the first element)."""
    return min(measure() for _ in range(repeat))


def env_steps_per_s(num_envs, steps):
    """Steps of all twins per wall second over ``steps`` vector steps (random actions)."""
    if num_envs == 1:
        env = gymnasium.make("tendril/Grip-v0", scenario=SHORT_LIFT)
    else:
        env = gymnasium.make_vec("tendril/Grip-v0", num_envs=num_envs, scenario=SHORT_LIFT)
    env.reset(seed=1)
    env.action_space.seed(1)
    started, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if num_envs == 1 and (terminated or truncated):
            env.reset()
    wall = time.perf_counter() - started
    cpu = time.process_time() - cpu
    env.close()
    return (wall / (steps * num_envs), cpu / (steps * num_envs))


class PythonPid:
    """The paper's PID (Kp 20, Ki 0.05, ±90 °/s, conditional integration) in Python."""

    max_speed_deg_s = 90.0

    def __init__(self):
        self.integral = 0.0

    def reset(self):
        self.integral = 0.0

    def update(self, ctx):
        error = ctx.setpoint_n - ctx.force_n
        out = 20.0 * error + 0.05 * (self.integral + error * ctx.dt_s)
        clamped = max(-90.0, min(90.0, out))
        if clamped == out and not ctx.blocked:
            self.integral += error * ctx.dt_s
        return clamped


def run_cpu_s(controller):
    """CPU and wall seconds of one crimper run on the twin, and the controller's call times."""
    started, cpu = time.perf_counter(), time.process_time()
    run = tendril.run(CRIMPER, controller=controller)
    return (time.process_time() - cpu, time.perf_counter() - started, run.controller_times)


def cli_run_s(out):
    """Wall and CPU seconds of ``tendril run scenarios/crimper.toml`` (a process of its own)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    binary = os.path.join(ROOT, "target", "release", "tendril")
    subprocess.run([binary, "run", CRIMPER, "--out", out], check=True, capture_output=True)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))


def python_run_s(out):
    """Wall and CPU seconds of ``tendril.run(scenarios/crimper.toml, out=...)``."""
    started, cpu = time.perf_counter(), time.process_time()
    tendril.run(CRIMPER, out=out)
    return (time.perf_counter() - started, time.process_time() - cpu)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="few steps, one repeat: the wiring only")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    repeat = 1 if args.quick else args.repeat
    steps = 200 if args.quick else 3000

    print(f"tendril speed, {os.cpu_count()} cores, best of {repeat}\n")
    print("| environment | steps/s (all twins) | µs per twin step (wall) | µs per twin step (CPU) |")
    print("| --- | --- | --- | --- |")
    for n in (1, 2, 4):
        wall, cpu = best(repeat, lambda n=n: env_steps_per_s(n, steps // n))
        name = "GripEnv" if n == 1 else f"make_vec, {n} twins"
        print(f"| {name} | {1.0 / wall:,.0f} | {wall * 1e6:.0f} | {cpu * 1e6:.0f} |")

    print("\n| crimper run (43.5 s of cell time) | CPU s | wall s | calls | CPU µs per call (run difference) | µs per call, mean / max (timed) |")
    print("| --- | --- | --- | --- | --- | --- |")
    builtin = best(repeat, lambda: run_cpu_s(None))
    print(f"| built-in PID | {builtin[0]:.2f} | {builtin[1]:.2f} | - | - | - |")
    cpu, wall, times = best(repeat, lambda: run_cpu_s(PythonPid()))
    extra = (cpu - builtin[0]) / times["calls"] * 1e6
    print(
        f"| paper's PID in Python | {cpu:.2f} | {wall:.2f} | {times['calls']} | {extra:.1f} | "
        f"{times['mean_ms'] * 1e3:.1f} / {times['max_ms'] * 1e3:.0f} |"
    )

    with tempfile.TemporaryDirectory() as tmp:
        cli = best(repeat, lambda: cli_run_s(os.path.join(tmp, "cli")))
        py = best(repeat, lambda: python_run_s(os.path.join(tmp, "py")))
    print("\n| whole crimper run, files written | wall s | CPU s |")
    print("| --- | --- | --- |")
    print(f"| `tendril run` (a process) | {cli[0]:.2f} | {cli[1]:.2f} |")
    print(f"| `tendril.run(..., out=...)` | {py[0]:.2f} | {py[1]:.2f} |")
    print(f"| Python / command line | {py[0] / cli[0]:.2f} | {py[1] / cli[1]:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
