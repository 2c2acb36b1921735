"""Running a campaign's walk jobs: on one Dask cluster for the whole run (a LocalCluster on
this machine, or ``--scheduler``), or without Dask on a local pool of processes."""

from __future__ import annotations

import multiprocessing
import os
import signal
import uuid
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures import as_completed as done

from workstation.campaign.jobs import WalkJob, run_walk


class Executor:
    """Runs lists of walk jobs for one campaign run, on one Dask cluster started at the first
    list with work and closed at the end (issue #50 item 9: each of the four passes started its
    own LocalCluster — three dashboard URLs in one run). Used as a context manager; called with
    a list, it yields each job's result as it finishes."""

    def __init__(self, scheduler, workers, say):
        self.scheduler, self.workers, self.say = scheduler, workers, say
        self.client = self.cluster = None

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *_exc) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def __call__(self, todo: list[WalkJob]):
        if not todo:
            return
        try:
            from distributed import as_completed
        except ImportError:
            yield from self._pool(todo)
            return
        client = self._client()
        futures = [client.submit(run_walk, j, key=f"walk-{uuid.uuid4().hex[:8]}-{j.key}",
                                 pure=False) for j in todo]  # fmt: skip
        for fut in as_completed(futures):
            try:
                yield fut.result()
            except Exception as e:  # noqa: BLE001 - a worker lost: record and go on
                yield {"key": "?", "status": "failed", "error": str(e), "seconds": 0.0,
                       "digest": "", "building": "?", "walk": "?"}  # fmt: skip

    def map(self, fn, args: list[tuple]) -> list:
        """``fn(*a)`` for each of ``args``, in order: on the Dask cluster when this run started
        one (the building's floors placed together on the workers: walks/joint_floors.py),
        else here — a pool of processes is not started for it."""
        if self.client is None:
            return [fn(*a) for a in args]
        futures = [self.client.submit(fn, *a, key=f"floor-{uuid.uuid4().hex[:8]}", pure=False)
                   for a in args]  # fmt: skip
        return self.client.gather(futures)

    def _pool(self, todo: list[WalkJob]):
        n = self.workers or os.cpu_count() or 1
        self.say(
            f"Dask is not installed (pip install workstation[campaign]): a local pool of {n} processes"
        )
        # spawned, not forked: a child forked after this process ran an OpenMP kernel (numba,
        # the report's 1-NN) is killed by GNU OpenMP when it runs one too (the map pass does)
        with ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"),
                                 initializer=_ignore_ctrl_c) as pool:  # fmt: skip
            for f in done([pool.submit(run_walk, j) for j in todo]):
                yield f.result()

    def _client(self):
        from distributed import Client, LocalCluster

        if self.client is not None:
            return self.client
        if self.scheduler:
            self.client = Client(self.scheduler)
            self.say(f"Dask scheduler {self.scheduler}; dashboard {self.client.dashboard_link}")
            return self.client
        n = self.workers or os.cpu_count() or 1
        # the workers' own logs only when critical: a walk's failure comes back with its result,
        # and closing the cluster between passes made a worker's heartbeat print a traceback.
        # Started with Ctrl+C ignored (a child keeps it): Ctrl+C in a terminal reaches every
        # process of the group, and each worker printed a KeyboardInterrupt traceback; this
        # process stops them as it stops.
        before = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            self.cluster = LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                dashboard_address="127.0.0.1:0", silence_logs=50,
            )  # fmt: skip
        finally:
            signal.signal(signal.SIGINT, before)
        self.client = Client(self.cluster)
        self.say(
            f"Dask LocalCluster, {n} workers; dashboard {self.client.dashboard_link} "
            "(this machine only)"
        )
        return self.client


def _ignore_ctrl_c() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
