"""The task runner of the studies: independent, seeded tasks stored one file each so that a study
resumes where it stopped (``tasks``: :class:`TaskStore`, :func:`run_tasks`), run on the executor
``engine`` gives (this process, crowdvib's pool of worker processes ``_pool``, or a dask cluster).
"""

from .engine import study_executor
from .tasks import TaskStore, run_tasks

__all__ = ["TaskStore", "run_tasks", "study_executor"]
