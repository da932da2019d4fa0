"""Finds MuJoCo's C library in the ``mujoco`` wheel and loads it for the extension module.

The extension needs ``libmujoco.so.3.17.0`` by name, without a search path (``readelf -d`` shows
it as NEEDED); loading that file first, with its symbols global, satisfies the dependency wherever
pip installed the wheel. The ``mujoco`` package is only located, not imported.
"""

import ctypes
import glob
import importlib.util
import os

#: The MuJoCo release the extension is built against (mujoco-rs 7.0.0).
MUJOCO_VERSION = "3.17.0"
_INSTALL = f"pip install mujoco=={MUJOCO_VERSION}"


def library_path():
    """The path of ``libmujoco.so.3.17.0`` in the installed ``mujoco`` package."""
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise ImportError(f"tendril needs MuJoCo {MUJOCO_VERSION}'s library from the `mujoco` package: {_INSTALL}")
    folder = list(spec.submodule_search_locations)[0]
    wanted = os.path.join(folder, f"libmujoco.so.{MUJOCO_VERSION}")
    if os.path.isfile(wanted):
        return wanted
    found = sorted(os.path.basename(f) for f in glob.glob(os.path.join(folder, "libmujoco.so*")))
    raise ImportError(
        f"tendril needs MuJoCo {MUJOCO_VERSION}, but the `mujoco` package in {folder} holds "
        f"{', '.join(found) or 'no libmujoco.so'}: {_INSTALL}"
    )


def preload():
    """Loads the library with its symbols global (a second call finds it loaded)."""
    return ctypes.CDLL(library_path(), mode=ctypes.RTLD_GLOBAL)
