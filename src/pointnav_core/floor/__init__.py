"""One floor as a grid: cell classes, world <-> cell conversion, exact disc clearance, and
uniform draws of usable cells within reach, the grid formats read from files (OmniGibson images, MovingAI ``.map``, ROS map_server).
"""

from pointnav_core.floor.collision import TOUCH_TOL, FloorCollision, convex_corners
from pointnav_core.floor.draw import draw_cell
from pointnav_core.floor.loaders import read_movingai, read_trav_png
from pointnav_core.floor.maps import CELL_CLASSES, FREE, OBSTACLE, VOID, TraversableMap
from pointnav_core.floor.reachability import disconnected, reach_labels
from pointnav_core.floor.ros_maps import RosMap, read_ros_map, write_ros_map

__all__ = [
    "CELL_CLASSES",
    "FREE",
    "OBSTACLE",
    "TOUCH_TOL",
    "VOID",
    "FloorCollision",
    "RosMap",
    "TraversableMap",
    "convex_corners",
    "disconnected",
    "draw_cell",
    "reach_labels",
    "read_movingai",
    "read_ros_map",
    "read_trav_png",
    "write_ros_map",
]
