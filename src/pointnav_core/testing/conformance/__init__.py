"""Behavioural checks that any backend must pass: the Backend protocol, as the task uses it.

Each check is a plain function that takes a *backend factory* (a callable returning a fresh,
unloaded backend), builds tiny scenes with :meth:`Scene.from_array`, drives robots and
raises :class:`AssertionError` with a readable message at the first thing that is wrong.
They are gathered in :data:`CHECKS`, in the order below, and run:

- from pytest, one test per check and backend (a failing check fails its test)::

      import pytest
      from pointnav_core.testing.conformance import CHECKS, backend_factory

      @pytest.mark.parametrize("check", CHECKS, ids=str)
      def test_my_backend_conforms(check):
          check(backend_factory("my_backend"))  # a name, a class or a factory

- from the command line, one line per check, exit status 0 when every check passes::

      python -m pointnav_core.testing my_backend

- from code: :func:`run_checks` returns one :class:`CheckResult` per check and
  :func:`assert_conforms` raises :class:`ConformanceError` listing the failures.

==========================  ===================================================================
Check                       What it asks of a backend
==========================  ===================================================================
``protocol``                every protocol member; right return types and shapes; fresh arrays;
                            bad actions are a ValueError and move nothing
``pose_round_trip``         ``set_pose`` then ``get_pose`` gives the pose back; ``land`` puts z
                            at the floor height
``open_space_motion``       in open space a robot moves as commanded (clipped to [-1, 1])
``velocity_matches_motion`` ``get_velocity`` is the displacement and yaw change over the step
``wall_contact``            driving into a wall sets the flag, never ends inside the wall, stops
                            at it; backing away is no contact
``robot_contact``           two robots driven into each other both get the flag and never
                            overlap; a robot hit while standing is flagged too
``no_tunnelling``           at full speed, nothing passes through a one-cell wall or a robot
``valid_pose``              ``is_valid_pose`` rejects overlap with an obstacle or a robot, and a
                            centre over VOID or off the map; touching is fine
``landing``                 ``land`` puts z at the chosen floor's height; floors do not collide
``falling``                 driving over VOID makes the robot fall (z drops, keeps dropping)
``absent_robots``           an absent robot is not moved and collides with nothing
``reset``                   ``reset`` zeroes velocities and flags; robots block nothing until
                            placed again
``fast_paths``              the optional float twins (``get_pose_floats``,
                            ``get_velocity_floats``) give exactly the numbers of the methods
                            they mirror, wherever the task would read them
``determinism``             the same actions from the same state give the same result, also
                            after ``reset``
==========================  ===================================================================

Tolerances are stated with each check: a robot may end a step overlapping an obstacle or
another robot by at most :data:`OVERLAP_TOLERANCE` (1 mm), positions read back after
``set_pose`` agree to :data:`POSE_TOLERANCE`, and open-space motion to
:data:`MOTION_TOLERANCE`. Overlap with obstacles is measured by :func:`obstacle_distance`,
an exact reference that backend tests may use too.
"""

from pointnav_core.testing.conformance.common import (
    MOTION_TOLERANCE,
    OVERLAP_TOLERANCE,
    POSE_TOLERANCE,
    ConformanceError,
    obstacle_distance,
)
from pointnav_core.testing.conformance.runner import (
    CHECKS,
    Check,
    CheckResult,
    assert_conforms,
    backend_factory,
    format_report,
    get_check,
    run_checks,
)

__all__ = [
    "CHECKS",
    "MOTION_TOLERANCE",
    "OVERLAP_TOLERANCE",
    "POSE_TOLERANCE",
    "Check",
    "CheckResult",
    "ConformanceError",
    "assert_conforms",
    "backend_factory",
    "format_report",
    "get_check",
    "obstacle_distance",
    "run_checks",
]
