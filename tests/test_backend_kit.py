"""The backend kit: its old names still answer, the backends use only public names, and a
backend built from it in a few lines conforms wherever it does not skip the work."""

from __future__ import annotations

import ast
import pathlib

import numpy as np
import pytest

import pointnav_core.backends.protocol as backend_module
from pointnav_core.backends import kit as backend_kit
from pointnav_core.backends.kit import (
    FloorGrid,
    RobotState,
    RobotStateBackend,
    check_load,
    drive_arc,
)
from pointnav_core.backends.protocol import check_backend, float_twin
from pointnav_core.backends.robot_spec import RobotSpec
from pointnav_core.scenes import Scene
from pointnav_core.testing.conformance import run_checks

BACKENDS_DIR = pathlib.Path(__file__).resolve().parents[1] / "src" / "backends"


@pytest.mark.parametrize(
    "name",
    ["RobotStateBackend", "check_index", "check_load", "parse_orientation", "parse_position",
     "planar_quat"],
)
def test_the_names_that_moved_are_still_importable_from_backend(name):
    assert getattr(backend_module, name) is getattr(backend_kit, name)
    namespace: dict = {}
    exec(f"from pointnav_core.backends.protocol import {name}", namespace)
    assert namespace[name] is getattr(backend_kit, name)


def test_an_unknown_name_of_backend_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_thing"):
        backend_module.no_such_thing  # noqa: B018


def test_the_shipped_backends_import_no_private_core_name():
    private = []
    for path in sorted(BACKENDS_DIR.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("pointnav_core"):
                private += [f"{path.name}: {a.name}" for a in node.names if a.name.startswith("_")]
    assert private == []


class Walker(RobotState):
    __slots__ = ("x", "y", "yaw")

    def __init__(self, spec: RobotSpec) -> None:
        super().__init__(spec)
        self.x = self.y = self.yaw = 0.0


class Ghosts(RobotStateBackend):
    """Robots drive exactly as commanded through walls and each other, and fall into holes."""

    def load(self, scene, robots, action_frequency=10.0):
        specs, n_floors, self._dt = check_load(scene, robots, action_frequency)
        self._floors = [
            FloorGrid(scene.floors[f], scene.get_floor_height(f)) for f in range(n_floors)
        ]
        self._robots = [Walker(spec) for spec in specs]
        for rb in self._robots:
            rb.z = self._floors[0].height

    def _pose(self, rb):
        return rb.x, rb.y, rb.yaw

    def _place(self, rb, x, y, yaw):
        rb.x, rb.y, rb.yaw = x, y, yaw

    def step(self, actions):
        dt = self._dt
        for rb in self._start_step(actions):
            vx, vy, w = rb.cmd
            dx, dy = drive_arc(rb.yaw, vx, vy, w, dt)
            rb.x, rb.y, rb.yaw = rb.x + dx, rb.y + dy, rb.yaw + w * dt
            rb.vel = (dx / dt, dy / dt, 0.0, w)
            if self._floors[rb.floor].is_void(rb.x, rb.y):
                self._fall(rb, first=True, planar=(dx / dt, dy / dt, w))


def test_a_backend_from_the_kit_conforms_but_for_the_contacts_it_skips():
    check_backend(Ghosts)
    results = {r.name: r for r in run_checks(Ghosts)}
    failed = {name for name, r in results.items() if not r.passed}
    assert failed == {"wall_contact", "robot_contact", "no_tunnelling", "reset"}
    assert "is not flagged" in results["reset"].message  # it never flags a contact
    assert float_twin(Ghosts(), "get_pose_floats") is not None


def test_the_hooks_a_subclass_must_write_are_named_when_missing():
    class NoPose(RobotStateBackend):
        def load(self, scene, robots, action_frequency=10.0):
            _, _, self._dt = check_load(scene, robots, action_frequency)
            self._floors = [FloorGrid(scene.floors[0], 0.0)]
            self._robots = [RobotState(spec) for spec in robots]

        def step(self, actions): ...

    backend = NoPose()
    backend.load(Scene.from_array(np.zeros((4, 4), np.uint8), 0.5), [RobotSpec()])
    with pytest.raises(NotImplementedError, match=r"NoPose must implement _place\(rb, x, y, yaw\)"):
        backend.land(0, 0, (1.0, 1.0), (0.0, 0.0, 0.0, 1.0))
    with pytest.raises(NotImplementedError, match=r"NoPose must implement _pose\(rb\)"):
        backend.get_pose(0)


def test_start_step_checks_every_action_before_any_robot_moves():
    backend = Ghosts()
    backend.load(Scene.from_array(np.zeros((8, 8), np.uint8), 0.5), [RobotSpec()] * 2)
    backend.land(0, 0, (1.0, 1.0), (0.0, 0.0, 0.0, 1.0))
    backend.land(1, 0, (2.0, 2.0), (0.0, 0.0, 0.0, 1.0))
    for bad in ({0: [1.0, 0.0], 1: [np.nan, 0.0]}, {0: [1.0, 0.0], 2: [0.0, 0.0]}):
        with pytest.raises(ValueError):
            backend.step(bad)
        assert backend.get_pose_floats(0)[:2] == (1.0, 1.0)
    backend.step({1: [1.0, 0.0]})  # robot 0 has no action: a zero command
    assert backend.get_pose_floats(0)[:2] == (1.0, 1.0)
    assert backend.get_pose_floats(1)[:2] == (2.05, 2.0)
