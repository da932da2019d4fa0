"""Evaluation for ``train_grip.py``: a policy and the built-in controllers on the same runs (object
× disturbance set × seed), the same metrics, one table.

- :func:`evaluate_policy` runs a policy through :class:`grip_task.GripTask` episodes, so it sees
  the observation it was trained on; every tick of the real 43.5 s task runs on the twin.
- :func:`evaluate_controllers` runs ``[controller] type`` = ``pid`` (the paper's), ``feedforward``
  and ``slip_margin`` (``src/study/controllers.rs``' CONTROLLERS) with ``tendril.run_many``.
- :func:`aggregate` groups the rows as ``controllers_summary.csv`` does (fluctuation over held
  runs only), :func:`markdown` writes the book's table.

Both paths end in the same ``summary.json`` (a stepped session's summary is ``tendril run``'s,
``python/tests/test_session.py``), read by :func:`grip_task.summary_metrics`.
"""

import csv
import math

import tendril

from grip_task import DISTURBANCE_SETS, OBJECTS, GripTask, summary_metrics

#: The built-in controllers compared (``[controller] type``).
CONTROLLERS = ("pid", "feedforward", "slip_margin")

#: One row per run.
COLUMNS = (
    "controller",
    "object",
    "disturbance",
    "seed",
    "outcome",
    "drop_phase",
    "rise_time_90_s",
    "overshoot_pct",
    "max_fluctuation_pct",
    "max_fluctuation_outside_push_pct",
    "peak_force_n",
    "error",
)


def evaluate_policy(act, name, objects, sets, seeds):
    """Rows of ``act`` (``obs -> action``) on every object × set × twin seed, one episode each."""
    env = GripTask(objects, sets)
    rows = []
    try:
        for obj in objects:
            for s in sets:
                for seed in seeds:
                    obs, info = env.reset(options={"object": obj, "disturbance": s, "seed": seed})
                    done = False
                    while not done:
                        obs, _, terminated, truncated, info = env.step(act(obs))
                        done = terminated or truncated
                    rows.append({"controller": name, "object": obj, "disturbance": s, "seed": seed,
                                 **summary_metrics(info["summary"])})
    finally:
        env.close()
    return rows


def evaluate_controllers(objects, sets, seeds, controllers=CONTROLLERS, threads=None):
    """Rows of the built-in controllers on every object × set × seed (``tendril.run_many``)."""
    cases, scenarios = [], []
    for obj in objects:
        for s in sets:
            for c in controllers:
                for seed in seeds:
                    overrides = {**DISTURBANCE_SETS[s], "controller.type": f'"{c}"', "seed": seed}
                    cases.append((c, obj, s, seed))
                    scenarios.append(tendril.load(OBJECTS[obj], set=overrides))
    rows = []
    for (c, obj, s, seed), run in zip(cases, tendril.run_many(scenarios, threads=threads)):
        rows.append({"controller": c, "object": obj, "disturbance": s, "seed": seed, **summary_metrics(run.summary)})
    return rows


def _mean_max(values):
    return (sum(values) / len(values), max(values)) if values else (None, None)


def aggregate(rows):
    """One row per (object, disturbance, controller), in order of appearance: runs, held, and
    mean / worst of fluctuation (held runs), fluctuation outside a knock (held runs), rise,
    overshoot and peak force (all runs that have them)."""
    keys = []
    for r in rows:
        key = (r["object"], r["disturbance"], r["controller"])
        if key not in keys:
            keys.append(key)
    out = []
    for obj, s, c in keys:
        group = [r for r in rows if (r["object"], r["disturbance"], r["controller"]) == (obj, s, c)]
        held = [r for r in group if r["outcome"] == "held"]

        def values(column, among):
            return [r[column] for r in among if r[column] is not None]

        row = {"object": obj, "disturbance": s, "controller": c, "runs": len(group), "held": len(held),
               "errors": sum(r["outcome"] == "error" for r in group)}
        for label, column, among in (
            ("fluctuation", "max_fluctuation_pct", held),
            ("outside_push", "max_fluctuation_outside_push_pct", held),
            ("rise", "rise_time_90_s", group),
            ("overshoot", "overshoot_pct", group),
            ("peak_force", "peak_force_n", group),
        ):
            row[f"{label}_mean"], row[f"{label}_worst"] = _mean_max(values(column, among))
        out.append(row)
    return out


def write_csv(path, rows, columns):
    """``rows`` (dicts) as CSV, ``columns`` in order; ``None`` as an empty cell."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow(["" if r.get(c) is None else r.get(c) for c in columns])


def _cell(mean, worst, digits):
    def f(v):
        return "-" if v is None or not math.isfinite(v) else f"{v:.{digits}f}"

    return f"{f(mean)} / {f(worst)}"


def markdown(summary):
    """The aggregated rows as a Markdown table (the book's)."""
    lines = [
        "| object | disturbance | controller | held | fluctuation while moving, mean / worst [%] "
        "| outside a knock's impact, mean / worst [%] | rise, mean / worst [s] | overshoot, mean / worst [%] "
        "| peak force, mean / worst [N] |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in summary:
        lines.append(
            f"| {r['object']} | {r['disturbance']} | {r['controller']} | {r['held']}/{r['runs']} "
            f"| {_cell(r['fluctuation_mean'], r['fluctuation_worst'], 0)} "
            f"| {_cell(r['outside_push_mean'], r['outside_push_worst'], 0)} "
            f"| {_cell(r['rise_mean'], r['rise_worst'], 2)} "
            f"| {_cell(r['overshoot_mean'], r['overshoot_worst'], 0)} "
            f"| {_cell(r['peak_force_mean'], r['peak_force_worst'], 2)} |"
        )
    return "\n".join(lines) + "\n"


#: The aggregated table's columns.
SUMMARY_COLUMNS = (
    "object", "disturbance", "controller", "runs", "held", "errors",
    "fluctuation_mean", "fluctuation_worst", "outside_push_mean", "outside_push_worst",
    "rise_mean", "rise_worst", "overshoot_mean", "overshoot_worst", "peak_force_mean", "peak_force_worst",
)
