"""Top-down drawing of a floor, its robots and the task's markers, and frames out of
environments onto disk (PNG, GIF). Imports Pillow only to write files.
"""

from pointnav_core.render.top_down import TopDownRenderer
from pointnav_core.utils.lazy import lazy_exports

__all__ = ["TopDownRenderer", "record_episode", "render_env", "save_gif", "save_png"]


# The recording functions load Pillow, so they are imported on first access.
__getattr__, __dir__ = lazy_exports(
    "pointnav_core.render",
    {name: "pointnav_core.render.recording" for name in ("record_episode", "render_env", "save_gif", "save_png")},
    globals(),
)
