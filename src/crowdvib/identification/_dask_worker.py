"""A dask worker plugin, apart so that ``distributed`` is imported only when a cluster is used."""

import signal
import threading

from distributed import WorkerPlugin


class IgnoreInterrupts(WorkerPlugin):
    """The worker process ignores SIGINT: Ctrl-C reaches the whole process group, and the study's
    parent alone handles it (cancels the tasks, closes the cluster)."""

    idempotent = True

    def setup(self, worker):
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)
