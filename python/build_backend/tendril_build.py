"""The package's PEP 517 build backend: maturin, after making sure MuJoCo's library is there to
link against.

mujoco-rs's build script links ``libmujoco.so`` from the folder ``MUJOCO_DYNAMIC_LINK_DIR`` names.
In a checkout set up by ``cargo xtask fetch`` that is ``vendor/mujoco/lib`` (``.cargo/config.toml``);
on a fresh machine, ``pip install .`` gets the library from the ``mujoco`` wheel (a build
requirement) and copies it into ``target/mujoco-lib``. A ``MUJOCO_DYNAMIC_LINK_DIR`` already set
wins, as everywhere in the project.
"""

import importlib.util
import os
import shutil
import sys

import maturin

MUJOCO_VERSION = "3.17.0"
_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _mujoco_lib_dir():
    """A folder holding ``libmujoco.so`` (MuJoCo 3.17.0), made from the wheel if need be."""
    given = os.environ.get("MUJOCO_DYNAMIC_LINK_DIR")
    if given:
        return given
    vendored = os.path.join(_ROOT, "vendor", "mujoco", "lib")
    if os.path.isfile(os.path.join(vendored, f"libmujoco.so.{MUJOCO_VERSION}")):
        return vendored
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError(
            f"building tendril needs MuJoCo {MUJOCO_VERSION}'s library: pip install mujoco=={MUJOCO_VERSION} "
            "(a build requirement), run `cargo xtask fetch`, or set MUJOCO_DYNAMIC_LINK_DIR to a folder with libmujoco.so"
        )
    source = os.path.join(list(spec.submodule_search_locations)[0], f"libmujoco.so.{MUJOCO_VERSION}")
    if not os.path.isfile(source):
        raise RuntimeError(f"{source}: not found; building tendril needs mujoco=={MUJOCO_VERSION}")
    folder = os.path.join(_ROOT, "target", "mujoco-lib")
    os.makedirs(folder, exist_ok=True)
    copy = os.path.join(folder, f"libmujoco.so.{MUJOCO_VERSION}")
    if not os.path.isfile(copy) or os.path.getsize(copy) != os.path.getsize(source):
        shutil.copyfile(source, copy)
    link = os.path.join(folder, "libmujoco.so")
    if not os.path.lexists(link):
        os.symlink(f"libmujoco.so.{MUJOCO_VERSION}", link)
    return folder


def _prepared():
    os.environ["MUJOCO_DYNAMIC_LINK_DIR"] = _mujoco_lib_dir()
    # maturin's backend runs the `maturin` program from PATH: the one installed beside this
    # Python (a venv's bin/, not necessarily on PATH) is found too.
    scripts = os.path.dirname(sys.executable)
    if shutil.which("maturin") is None and os.path.isfile(os.path.join(scripts, "maturin")):
        os.environ["PATH"] = scripts + os.pathsep + os.environ.get("PATH", "")


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    _prepared()
    return maturin.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    _prepared()
    return maturin.build_editable(wheel_directory, config_settings, metadata_directory)


def build_sdist(sdist_directory, config_settings=None):
    _prepared()
    return maturin.build_sdist(sdist_directory, config_settings)


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    _prepared()
    return maturin.prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    _prepared()
    return maturin.prepare_metadata_for_build_editable(metadata_directory, config_settings)


get_requires_for_build_wheel = maturin.get_requires_for_build_wheel
get_requires_for_build_editable = maturin.get_requires_for_build_editable
get_requires_for_build_sdist = maturin.get_requires_for_build_sdist
