"""Top-down drawing of a floor, its robots and the task's markers, and frames out of
environments onto disk (PNG, GIF). Imports Pillow only to write files.
"""

from pointnav_core.render.top_down import TopDownRenderer

__all__ = ["TopDownRenderer", "record_episode", "render_env", "save_gif", "save_png"]


def __getattr__(name: str):
    if name in {"record_episode", "render_env", "save_gif", "save_png"}:
        from pointnav_core.render import recording

        return getattr(recording, name)
    raise AttributeError(f"module 'pointnav_core.render' has no attribute {name!r}")
