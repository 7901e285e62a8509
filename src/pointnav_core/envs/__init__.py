"""The environments: ``PointNav-v0`` (Gymnasium, one robot), ``MultiPointNav-v0``
(PettingZoo, many robots), their shared configuration (:class:`EnvConfig`), dataset
wrappers, and registration with both libraries.

The names load Gymnasium or PettingZoo, so they are imported on first access.
"""

from pointnav_core.utils.lazy import lazy_exports

__all__ = [
    "DatasetEpisodes",
    "EnvConfig",
    "MultiPointNavEnv",
    "ParallelDatasetEpisodes",
    "PointNavEnv",
    "TaskStepLimit",
    "env",
    "parallel_env",
    "raw_env",
    "register_envs",
]

__getattr__, __dir__ = lazy_exports(
    "pointnav_core.envs",
    {
        "PointNavEnv": "pointnav_core.envs.pointnav",
        "TaskStepLimit": "pointnav_core.envs.pointnav",
        "MultiPointNavEnv": "pointnav_core.envs.multi_pointnav",
        "parallel_env": "pointnav_core.envs.multi_pointnav",
        "env": "pointnav_core.envs.multi_pointnav",
        "raw_env": "pointnav_core.envs.multi_pointnav",
        "EnvConfig": "pointnav_core.envs.config",
        "DatasetEpisodes": "pointnav_core.envs.dataset_wrappers",
        "ParallelDatasetEpisodes": "pointnav_core.envs.dataset_wrappers",
        "register_envs": "pointnav_core.envs.registration",
    },
    globals(),
)
