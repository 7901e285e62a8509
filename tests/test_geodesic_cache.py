"""The geometry cache on disk (pointnav_core.geodesic.cache): hits, misses, faults, races."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from pointnav_core.floor.collision import FloorCollision
from pointnav_core.floor.maps import OBSTACLE
from pointnav_core.geodesic import cache
from pointnav_core.geodesic.planner import Planner
from pointnav_core.scenes import Scene


def _geo(shift: int = 0) -> FloorCollision:
    grid = np.zeros((40, 50), np.uint8)
    grid[[0, -1], :] = grid[:, [0, -1]] = OBSTACLE
    grid[10:30, 20 + shift] = OBSTACLE
    grid[5:9, 5:12] = OBSTACLE
    return FloorCollision.from_map(Scene.from_array(grid, 0.1).floors[0])


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    monkeypatch.setattr(cache, "MIN_SECONDS", 0.0)  # keep every build, however quick
    return tmp_path


def _built(geo: FloorCollision, radius: float = 0.18) -> Planner:
    p = Planner(geo, radius)
    p.build_all_edges()
    return p


def _distances(p: Planner) -> list[float]:
    return [p.shortest_path(a, b)[1] for a, b in (((0.5, 0.5), (4.5, 3.5)), ((0.4, 3.5), (4.6, 0.5)))]


def test_a_rebuilt_floor_reads_the_same_graph_back(folder) -> None:
    first = _built(_geo())
    files = list(folder.glob("*.npz"))
    assert len(files) == 1 and not list(folder.glob("*.tmp"))
    second = Planner(_geo(), 0.18)
    assert second.edge_store == first.edge_store  # every edge, before any search asks
    np.testing.assert_array_equal(second.sights, first.sights)
    assert _distances(second) == _distances(first)


def test_a_cached_floor_reads_each_node_s_edges_when_first_asked(folder) -> None:
    """A floor from the cache makes a node's edge lists when a search reads them, and they
    are the lists the build made; the counts hold before anything is read, and a pickled
    planner carries every edge."""
    import pickle

    first = _built(_geo())
    second = Planner(_geo(), 0.18)
    store = second.edge_store
    n_first = sum(len(v[0]) for v in first.edge_store.values())
    assert dict.__len__(store) == 0  # nothing made yet
    assert len(store) == len(first.edge_store) and store.n_edges() == n_first
    some = sorted(first.edge_store)[:: max(1, len(first.edge_store) // 7)]
    for key in some:
        assert key in store and store[key] == first.edge_store[key]
        assert store.get(key) == first.edge_store[key]
    assert dict.__len__(store) == len(some) and store.n_edges() == n_first
    assert (10**6, 1) not in store and store.get((10**6, 1)) is None
    copy = pickle.loads(pickle.dumps(second))
    assert dict(copy.edge_store.items()) == dict(first.edge_store.items())
    assert _distances(copy) == _distances(first)


def test_a_changed_map_radius_or_version_misses(folder, monkeypatch) -> None:
    _built(_geo())
    keys = {cache.floor_key(_geo(), 0.18), cache.floor_key(_geo(shift=1), 0.18), cache.floor_key(_geo(), 0.2)}
    monkeypatch.setattr("pointnav_core.__version__", "9.9.9")
    keys.add(cache.floor_key(_geo(), 0.18))
    assert len(keys) == 4
    assert cache.load(cache.floor_key(_geo(shift=1), 0.18), 10) is None
    _built(_geo(shift=1))
    assert len(list(folder.glob("*.npz"))) == 2


@pytest.mark.parametrize("damage", ["truncate", "garbage", "other floor"])
def test_a_damaged_file_warns_and_is_rebuilt(folder, damage: str) -> None:
    want = _distances(_built(_geo()))
    (path,) = folder.glob("*.npz")
    data = path.read_bytes()
    if damage == "truncate":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(b"\x00" * 100)
    else:  # a whole, readable file whose floor has another node count
        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
        arrays["sights"] = arrays["sights"][:-1]
        np.savez(path.with_suffix(""), **arrays)  # numpy adds the .npz: the same file
    with pytest.warns(RuntimeWarning, match="geometry cache file .* is unreadable"):
        rebuilt = _built(_geo())
    assert _distances(rebuilt) == want
    assert cache.load(cache.floor_key(_geo(), 0.18), rebuilt.n_nodes) is not None  # written anew, valid


def test_two_processes_building_one_entry_leave_one_valid_file(folder) -> None:
    script = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(__import__("pathlib").Path(__file__).parent)!r})
        from pointnav_core.geodesic import cache
        cache.MIN_SECONDS = 0.0
        from test_geodesic_cache import _built, _geo
        _built(_geo())
        """
    )
    env = {**__import__("os").environ, cache.ENV_VAR: str(folder)}
    procs = [subprocess.Popen([sys.executable, "-c", script], env=env) for _ in range(2)]
    assert [p.wait(timeout=300) for p in procs] == [0, 0]
    assert len(list(folder.glob("*.npz"))) == 1 and not list(folder.glob("*.tmp"))
    p = Planner(_geo(), 0.18)
    assert cache.load(cache.floor_key(_geo(), 0.18), p.n_nodes) is not None


def test_the_cache_can_be_turned_off_and_follows_the_platform(monkeypatch, tmp_path) -> None:
    for off in ("", "0", "off"):
        monkeypatch.setenv(cache.ENV_VAR, off)
        assert cache.cache_dir() is None
    monkeypatch.delenv(cache.ENV_VAR)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    if sys.platform.startswith("linux"):
        assert cache.cache_dir() == tmp_path / "pointnav-core"


# ---------------------------------------------------------------- cell links
def test_cell_links_are_kept_and_read_back_whole(folder) -> None:
    first = _built(_geo())
    links = first.cell_links()
    assert links is not None and len(links.node)
    second = Planner(_geo(), 0.18)
    again = second.cell_links(build=False)  # read from the file: nothing to build
    assert again is not None
    for name, array in links.arrays().items():
        np.testing.assert_array_equal(again.arrays()[name], array)


@pytest.mark.parametrize("damage", ["node", "first", "side", "missing"])
def test_damaged_cell_links_are_never_read_and_are_built_again(folder, damage: str) -> None:
    want = _built(_geo()).cell_links().arrays()
    (path,) = folder.glob("*.npz")
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    if damage == "node":
        arrays["link_node"][0] = 10**6  # a node the floor does not have
    elif damage == "first":
        arrays["link_first"][-1] = len(arrays["link_node"]) + 5
        arrays["link_count"][-1] = 1
    elif damage == "side":
        arrays["link_side"][0] = 7
    else:
        del arrays["link_pos"]
    np.savez(path.with_suffix(""), **arrays)
    p = Planner(_geo(), 0.18)
    assert p.cell_links(build=False) is None
    for name, array in p.cell_links().arrays().items():
        np.testing.assert_array_equal(array, want[name])


def test_cell_links_are_built_once_the_roots_without_them_cost_as_much(folder, monkeypatch) -> None:
    from pointnav_core.geodesic import cell_links

    monkeypatch.setattr(cell_links, "BUILD_SECONDS_PER_PAIR", 1.0)  # never worth it
    p = Planner(_geo(), 0.18)
    p.goal_field((4.55, 2.05)).settle()
    assert p.cell_links(build=False) is None
    monkeypatch.setattr(cell_links, "BUILD_SECONDS_PER_PAIR", 0.0)  # at once
    p = Planner(_geo(), 0.18)
    p.goal_field((0.55, 3.55)).settle()
    assert p.cell_links(build=False) is not None


# ---------------------------------------------------------------- pointnav scene build
def test_scene_build_keeps_every_floor_for_later_processes(folder, capsys):
    from pointnav_core import scenes
    from pointnav_core.cli import main
    from pointnav_core.geodesic import planner_for

    assert main(["scene", "build", "maze:3", "--robot-radius", "0.1", "0.15", "--quiet"]) == 0
    assert "2 kept" in capsys.readouterr().out
    assert len(list(folder.glob("*.npz"))) == 2
    # A fresh build of the same scene (as in another process) reads it back, and a radius
    # that was not built misses.
    tmap = scenes.maze(seed=3).floors[0]
    assert planner_for(tmap, 0.1).cached and planner_for(tmap, 0.15).cached
    assert planner_for(tmap, 0.1).cell_links(build=False) is not None  # kept with the rest
    assert not planner_for(tmap, 0.12).cached


@pytest.mark.parametrize(
    ("argv", "env", "message"),
    [
        (["scene", "build"], None, "give at least one SCENE"),
        (["scene", "build", "rooms:0"], "off", "the geometry cache is off"),
        (["scene", "build", "nope:1"], None, "unknown scene_id 'nope:1'"),
        (["scene", "build", "rooms:0", "--robot-radius", "0"], None, "--robot-radius must be > 0"),
    ],
)
def test_scene_build_refuses_bad_input_in_one_line(folder, monkeypatch, capsys, argv, env, message):
    from pointnav_core.cli import main

    if env is not None:
        monkeypatch.setenv(cache.ENV_VAR, env)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_scene_build_in_worker_processes_names_a_bad_scene(folder, capsys):
    from pointnav_core.cli import main

    assert main(["scene", "build", "maze:3", "nope.map", "--workers", "2", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "scene 'nope.map'" in err and "no such file" in err and len(err.strip().splitlines()) == 1
