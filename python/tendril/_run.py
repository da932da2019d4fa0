"""The result of a run: its summary and its trace."""

import json

import numpy as np


class Run:
    """A finished run on the twin.

    ``summary``: ``summary.json``'s content (a dict: outcome, drop time, metrics, timing, and the
    effective scenario under ``"effective_scenario"``). ``trace``: one numpy array per
    ``trace.csv`` column, in its order, at full precision (the file rounds to 3-5 decimals);
    ``phase`` holds the phases' names, ``over_range`` and ``controller_on`` are booleans.
    ``controller_times``: with a Python controller, how long its ``update`` calls took (``calls``,
    ``mean_ms``, ``max_ms``, ``over_tick``: calls longer than the tick, ``tick_ms``); else ``None``.
    """

    def __init__(self, summary_json, columns, controller_times=None):
        self.summary = json.loads(summary_json)
        self.controller_times = controller_times
        self.trace = {}
        for name, kind, data in columns:
            if kind == "f8":
                array = np.frombuffer(data, dtype="<f8").copy()
            elif kind == "bool":
                array = np.frombuffer(data, dtype=np.uint8).astype(bool)
            else:
                array = np.array(data, dtype=str)
            self.trace[name] = array

    @property
    def outcome(self):
        """``"held"``, ``"dropped"`` or ``"error"``."""
        return self.summary["outcome"]

    def to_pandas(self):
        """The trace as a pandas DataFrame (pandas must be installed)."""
        import pandas as pd

        return pd.DataFrame(self.trace)

    def __len__(self):
        return len(self.trace.get("time_s", ()))

    def __repr__(self):
        return f"<tendril.Run {self.summary.get('scenario')!r}: {self.outcome}, {len(self)} ticks>"
