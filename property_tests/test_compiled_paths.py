"""Every compiled kernel gives its plain path's results: one check per (plain, compiled) pair.

:data:`PAIRS` maps each entry point of the kernel modules (``src/pointnav_core/**/_*kernel*.py``)
to the hypothesis checks that run the public function over it once on the compiled path and
once on the plain one (inside ``numpy_paths()`` or with ``method="array"``) and compare them
(exactly, or within the rounding the check states). The checks live beside their strategies
in ``tests/pairs_*.py``; here they run as one parametrised test, with every kernel function
replaced by a stub that fails while the plain side runs, so that a path which reaches a
kernel around :func:`pointnav_core.utils.compiled.kernel` is caught.

An entry point is a kernel a caller obtains through ``kernel(module, name)`` (read from the
package's sources) or a public jitted function of a kernel module that no other kernel calls
(kernels called only by kernels are covered by their caller's check). A new entry point
without a check fails :func:`test_every_kernel_has_a_check`. Without numba the comparisons
are skipped (CI installs it with the ``dev`` extra); the coverage tests run anyway.
"""

from __future__ import annotations

import ast
import importlib
import re
from collections.abc import Callable, Iterator, Mapping
from contextlib import ExitStack, contextmanager
from functools import partial
from pathlib import Path
from unittest import mock

import pairs_crowds
import pairs_floor
import pairs_geodesic
import pairs_scan
import pairs_vector
import pytest

from pointnav_core.utils.compiled import numpy_paths

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "pointnav_core"

Entry = tuple[str, str]  # (kernel module, function)

#: Every entry point's checks (each takes ``plain_paths``, the context of its plain side).
PAIRS: dict[Entry, tuple[Callable[..., None], ...]] = {
    ("pointnav_core.crowds._orca_kernel", "orca_worlds"): (pairs_crowds.check_orca,),
    ("pointnav_core.crowds._social_force_kernel", "social_force_worlds"): (pairs_crowds.check_social_force,),
    ("pointnav_core.crowds._crowd_kernel", "orca_crowd_step"): (pairs_crowds.check_crowd_step,),
    ("pointnav_core.crowds._crowd_kernel", "orca_crowd_worlds"): (pairs_crowds.check_crowd_worlds,),
    ("pointnav_core.floor._collision_kernel", "cells_hit"): (pairs_floor.check_cell_test,),
    ("pointnav_core.floor._collision_kernel", "segments_clear"): (pairs_floor.check_cell_test,),
    ("pointnav_core.floor._collision_kernel", "segment_hits"): (pairs_floor.check_cell_test,),
    ("pointnav_core.floor._collision_kernel", "polygons_hit"): (pairs_floor.check_polygon_test,),
    ("pointnav_core.floor._draw_kernel", "row_spans"): (pairs_floor.check_draw,),
    ("pointnav_core.floor._component_kernel", "point_component"): (pairs_floor.check_point_component,),
    ("pointnav_core.geodesic._sight_kernel", "sight_rays"): (pairs_floor.check_sights,),
    ("pointnav_core.geodesic._sight_kernel", "misses_full"): (pairs_floor.check_fully_blocked_samples,),
    ("pointnav_core.geodesic._edges_kernel", "edge_pairs"): (pairs_floor.check_edges,),
    ("pointnav_core.geodesic._search_kernel", "seeded_dijkstra"): (pairs_geodesic.check_goal_search,),
    ("pointnav_core.geodesic._search_kernel", "seeded_astar"): (pairs_geodesic.check_point_search,),
    ("pointnav_core.geodesic._path_kernel", "point_path"): (
        pairs_geodesic.check_point_search, pairs_geodesic.check_point_search_pinched,
    ),
    ("pointnav_core.geodesic._roots_kernel", "arc_tables"): (pairs_geodesic.check_arc_tables,),
    ("pointnav_core.geodesic._roots_kernel", "point_links"): (pairs_geodesic.check_point_links,),
    ("pointnav_core.geodesic._roots_kernel", "best_links"): (
        pairs_geodesic.check_exact_query, pairs_geodesic.check_way, pairs_geodesic.check_settle,
    ),
    ("pointnav_core.geodesic._roots_kernel", "cell_links"): (pairs_geodesic.check_settle,),
    ("pointnav_core.geodesic._roots_kernel", "table_roots"): (pairs_geodesic.check_settle,),
    ("pointnav_core.sensors._noise_kernel", "ray_uniforms"): (pairs_scan.check_noise,),
    ("pointnav_core.sensors._raycast_kernel", "cast"): (
        pairs_scan.check_small_scenes, pairs_scan.check_one_pose, pairs_scan.check_open_scenes,
        pairs_scan.check_big_floor, pairs_scan.check_grazing_scans,
    ),
    ("pointnav_core.vector._scan_kernel", "cast_worlds"): (
        pairs_vector.check_batched_scan, pairs_vector.check_batched_scan_large_floor, pairs_scan.check_grazing_scans,
        pairs_vector.check_batched_scan_wall_near_range,
    ),
    ("pointnav_core.vector._contact_kernel", "advance_worlds"): tuple(
        partial(check, device=device)
        for check in (pairs_vector.check_contacts_multi_robot, pairs_vector.check_contacts_one_robot,
                      pairs_vector.check_engines_step_alike)
        for device in pairs_vector.DEVICES
    ),
}

_LOADED = re.compile(r'kernel\(\s*"(pointnav_core\.[\w.]+)",\s*"(\w+)"\s*\)|KERNEL = \("(pointnav_core\.[\w.]+)", "(\w+)"\)')
#: ``geodesic.roots.compiled(planner, name)``: a function of ``geodesic._roots_kernel``.
_ROOTS_LOADED = re.compile(r'\bcompiled\(\s*\w+,\s*"(\w+)"\s*\)')


def module_name(path: Path, src: Path = SRC) -> str:
    """``src/pointnav_core/floor/_collision_kernel.py`` -> ``pointnav_core.floor._collision_kernel``."""
    return ".".join(path.relative_to(src).with_suffix("").parts)


def jitted(tree: ast.Module) -> dict[str, ast.AST]:
    """The module's compiled functions by name: decorated top-level functions, and names bound
    to a call of a call (``numba.njit(...)(plain_function)``)."""
    found: dict[str, ast.AST] = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.decorator_list:
            found[node.name] = node
        elif isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) and isinstance(node.value.func, ast.Call):
            found.update({t.id: node for t in node.targets if isinstance(t, ast.Name)})
    return found


def called_by_kernels(trees: Mapping[str, ast.Module]) -> set[Entry]:
    """The kernels another kernel calls: by name within its module, or imported from another."""
    out: set[Entry] = set()
    for module, tree in trees.items():
        for node in tree.body:
            if isinstance(node, ast.ImportFrom) and node.module in trees:
                out |= {(node.module, a.name) for a in node.names}
        own = jitted(tree)
        for name, fn in own.items():
            calls = {n.func.id for n in ast.walk(fn) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
            out |= {(module, c) for c in calls - {name} if c in own}
    return out


def entry_points(kernels: Mapping[str, str], callers: Mapping[str, str]) -> set[Entry]:
    """The kernels a caller can reach, from the kernel modules' sources (by module name) and the
    other modules' sources: every ``kernel(module, name)`` (or ``KERNEL = (module, name)``, or
    ``geodesic.roots.compiled(planner, name)``) of the callers, and every public jitted
    function that no other kernel calls."""
    trees = {module: ast.parse(text) for module, text in kernels.items()}
    loaded = {
        (m[0] or m[2], m[1] or m[3]) for text in callers.values() for m in _LOADED.findall(text)
    } | {("pointnav_core.geodesic._roots_kernel", m) for text in callers.values() for m in _ROOTS_LOADED.findall(text)}
    inner = called_by_kernels(trees)
    public = {(m, name) for m, tree in trees.items() for name in jitted(tree) if not name.startswith("_")}
    return loaded | (public - inner)


def uncovered(entries: set[Entry], pairs: Mapping[Entry, object]) -> list[Entry]:
    """The entry points without a check, sorted."""
    return sorted(entries - set(pairs))


def _sources() -> tuple[dict[str, str], dict[str, str]]:
    """The kernel modules' sources (``_*kernel*`` modules that import numba: not
    ``transforms._kernels``, plain Python) and every other module's, by module name."""
    files = sorted(PACKAGE.rglob("*.py"))
    kernels = {
        module_name(p): p.read_text() for p in files
        if re.fullmatch(r"_\w*kernel\w*", p.stem) and re.search(r"^(import|from) numba", p.read_text(), re.M)
    }
    callers = {module_name(p): p.read_text() for p in files if module_name(p) not in kernels}
    return kernels, callers


def test_every_kernel_has_a_check() -> None:
    entries = entry_points(*_sources())
    assert uncovered(entries, PAIRS) == []
    assert sorted(set(PAIRS) - entries) == [], "a check for a kernel that is not an entry point"


def test_a_kernel_without_a_check_is_found() -> None:
    # A fake kernel module: two entry points (one loaded by a caller, one public and called by
    # no other kernel), a helper of theirs (called by a kernel), a private one and plain code.
    kernel = (
        "import numba\n_jit = numba.njit()\n"
        "@_jit\ndef helper(x):\n    return x\n"
        "@_jit\ndef _private(x):\n    return x\n"
        "@_jit\ndef entry(x):\n    return helper(x) + _private(x)\n"
        "loaded = numba.njit()(helper)\n"
        "def not_compiled(x):\n    return x\n"
    )
    caller = 'k = kernel("pkg._fake_kernel", "loaded")\n'
    entries = entry_points({"pkg._fake_kernel": kernel}, {"pkg.user": caller})
    assert entries == {("pkg._fake_kernel", "entry"), ("pkg._fake_kernel", "loaded")}
    assert uncovered(entries, {("pkg._fake_kernel", "entry"): ()}) == [("pkg._fake_kernel", "loaded")]


def test_only_the_loader_imports_kernel_modules() -> None:
    """No module but the kernels themselves names a kernel module in an import: every
    compiled function comes from ``utils.compiled.kernel``, which ``numpy_paths()`` turns off."""
    kernels, callers = _sources()
    bad = []
    for module, text in callers.items():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ImportFrom):  # "from pkg import _x_kernel" names it too
                names = [node.module or ""] + [f"{node.module}.{a.name}" for a in node.names]
            else:
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            bad += [f"{module}: {n}" for n in names if n in kernels]
    assert bad == []


@contextmanager
def guarded_plain_paths() -> Iterator[None]:
    """``numpy_paths()``, with every kernel module's compiled functions replaced by stubs that
    fail: a plain side that reaches a kernel by any road fails its check."""
    kernels, _ = _sources()
    # Every kernel module is imported before any is patched: one imported after would bind
    # another's stub for good (``from ..._collision_kernel import segment_hits as _hits``).
    modules = {module: importlib.import_module(module) for module in kernels}
    with ExitStack() as stack:
        stack.enter_context(numpy_paths())
        for module, text in kernels.items():
            names = list(jitted(ast.parse(text)))
            loaded = modules[module]
            for name in names:
                def stub(*args: object, _where: str = f"{module}.{name}") -> None:
                    raise AssertionError(f"{_where} ran inside numpy_paths()")

                stack.enter_context(mock.patch.object(loaded, name, stub))
        yield


def check_id(check: Callable[..., None]) -> str:
    """A check's name, with the arguments a partial binds (``check_contacts_one_robot[cpu]``)."""
    if isinstance(check, partial):
        return f"{check.func.__name__}[{','.join(map(str, check.keywords.values()))}]"
    return check.__name__


#: Every check once (one may cover several entry points), with the entries it covers.
CHECKS = {check: [entry for entry, checks in PAIRS.items() if check in checks]
          for checks in PAIRS.values() for check in checks}


#: The checks that take tens of seconds on CI's cores (``--durations``), run first.
LONG = {pairs_geodesic.check_way, pairs_geodesic.check_settle, pairs_geodesic.check_exact_query,
        pairs_scan.check_big_floor, pairs_scan.check_open_scenes}


@pytest.mark.parametrize("check", [
    pytest.param(check, id=check_id(check), marks=[pytest.mark.long] if check in LONG else [])
    for check in CHECKS
])
def test_the_compiled_path_equals_the_plain_one(check: Callable[..., None]) -> None:
    pytest.importorskip("numba", reason="the compiled paths are the `fast` extra")
    check(plain_paths=guarded_plain_paths)


def test_the_guard_catches_a_kernel_reached_around_the_loader() -> None:
    """A plain side that imports a kernel itself (as ``vector.scan`` once did) fails."""
    pytest.importorskip("numba", reason="the compiled paths are the `fast` extra")
    with guarded_plain_paths(), pytest.raises(AssertionError, match="cast_worlds ran inside numpy_paths"):
        from pointnav_core.vector._scan_kernel import cast_worlds

        cast_worlds()
    from pointnav_core.vector import _scan_kernel

    assert not isinstance(_scan_kernel.cast_worlds, type(check_id))  # the kernel is back


def test_inside_numpy_paths_the_default_methods_reach_no_kernel() -> None:
    """The public functions with compiled paths, called as users call them (``method="auto"``,
    engines built and stepped), run no kernel inside ``numpy_paths()``."""
    pytest.importorskip("numba", reason="the compiled paths are the `fast` extra")
    import numpy as np

    from pointnav_core.scenes import Scene
    from pointnav_core.sensors import ScanGeometry, cast_rays
    from pointnav_core.sensors.noise import episode_key, scan_noise
    from pointnav_core.sensors.raycast import cast_pose_compiled
    from pointnav_core.vector import VectorPointNavEnv

    grid = np.zeros((24, 24), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = 1
    grid[8:16, 12] = 1
    scene = Scene.from_array(grid, 0.1)
    geo = ScanGeometry(scene.floors[0])
    with guarded_plain_paths():
        assert cast_rays(geo, [[0.55, 0.55]], [0.0], [0.0, 1.0], 2.0).shape == (1, 2)
        trig = (np.ones(1), np.zeros(1))
        assert cast_pose_compiled(geo, np.array([[0.55, 0.55]]), np.array([1.0, 0.0]), trig, 2.0) is None
        assert scan_noise(episode_key(1, 0), 0, 0, 4, 0.1, 0.1)[0].shape == (4,)
        env = VectorPointNavEnv(2, n_robots=2, scene=scene, sensors={"scan": {"n_rays": 8, "noise_std": 0.1}})
        env.reset(seed=0)
        for _ in range(10):
            env.step(np.tile([1.0, 0.3], (2, 2, 1)))
        env.close()
