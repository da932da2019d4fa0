"""Shared fixtures: the repository's scenarios and the command line to compare with."""

import os
import pathlib
import shutil
import socket

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHORT_LIFT = ROOT / "scenarios" / "short-lift.toml"

#: summary.json's fields that measure the machine, not the run.
TIMING = {"wall_time_s", "real_time_factor", "cpu_time_s", "sim_s_per_cpu_s"}


@pytest.fixture(scope="session")
def tendril_bin():
    """The `tendril` command line: $TENDRIL_BIN (set by `cargo xtask test`), else a built one."""
    given = os.environ.get("TENDRIL_BIN")
    if given:
        assert os.access(given, os.X_OK), f"TENDRIL_BIN={given} is not an executable"
        return given
    for profile in ("debug", "release"):
        candidate = ROOT / "target" / profile / "tendril"
        if candidate.is_file():
            return str(candidate)
    found = shutil.which("tendril")
    if found is None:
        pytest.skip("no tendril binary: build it (cargo build) or set TENDRIL_BIN")
    return found


def without_timing(summary):
    """A summary without the fields that measure the machine."""
    return {k: v for k, v in summary.items() if k not in TIMING}


def free_port_base():
    """Seven consecutive free ports on loopback (serve's --port-base N takes N..N+6)."""
    for base in range(43_000 + (os.getpid() % 500) * 12, 60_000, 12):
        sockets = []
        try:
            for port in range(base, base + 7):
                s = socket.socket()
                sockets.append(s)
                s.bind(("127.0.0.1", port))
            return base
        except OSError:
            continue
        finally:
            for s in sockets:
                s.close()
    raise RuntimeError("no seven consecutive free ports")
