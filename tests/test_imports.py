"""The core imports no env library; the ids register with each library in any import order."""

import subprocess
import sys

import pytest

ENV_LIBRARIES = ("gymnasium", "pettingzoo", "PIL")


def run(code: str) -> str:
    """Run ``code`` in a fresh interpreter and return its stdout."""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.parametrize(
    "modules",
    [
        "pointnav_core.scenes, pointnav_core.task",
        "pointnav_core.floor.maps, pointnav_core.transforms, pointnav_core.task.metrics, pointnav_core.backends.protocol",
        "pointnav_core.geodesic.planner, pointnav_core.geodesic.field, pointnav_core.floor.collision",
        "pointnav_kinematic, pointnav_pymunk",
    ],
)
def test_core_modules_load_no_env_library(modules):
    loaded = run(f"import sys, {modules}\nprint(sorted(m for m in {ENV_LIBRARIES!r} if m in sys.modules))")
    assert loaded == "[]"


@pytest.mark.parametrize(
    "imports",
    [
        "import pointnav_core\nimport gymnasium, pettingzoo",  # the package first
        "import gymnasium, pettingzoo\nimport pointnav_core",  # the libraries first
        "import gymnasium\nimport pointnav_core\nimport pettingzoo",
    ],
)
def test_ids_register_whatever_the_import_order(imports):
    code = (
        f"{imports}\n"
        "env = gymnasium.make('pointnav_core/PointNav-v0')\n"
        "par = pettingzoo.parallel_registry['pointnav_core/MultiPointNav-v0']\n"
        "aec = pettingzoo.aec_registry['pointnav_core/MultiPointNav-v0']\n"
        "print(type(env.unwrapped).__name__, par is not None, aec is not None)\n"
    )
    assert run(code) == "PointNavEnv True True"


def test_the_module_prefix_imports_the_package_by_itself():
    code = "import gymnasium\nenv = gymnasium.make('pointnav_core:pointnav_core/PointNav-v0')\nprint(type(env.unwrapped).__name__)"
    assert run(code) == "PointNavEnv"


def test_the_envs_are_exported_lazily():
    code = (
        "import sys, pointnav_core\n"
        "before = 'gymnasium' in sys.modules\n"
        "from pointnav_core import PointNavEnv, MultiPointNavEnv\n"
        "print(before, PointNavEnv.__module__, MultiPointNavEnv.__module__, 'PointNavEnv' in dir(pointnav_core))\n"
    )
    assert run(code) == "False pointnav_core.envs.pointnav pointnav_core.envs.multi_pointnav True"


def test_an_unknown_attribute_is_an_attribute_error():
    import pointnav_core

    with pytest.raises(AttributeError, match="no_such_thing"):
        pointnav_core.no_such_thing  # noqa: B018
