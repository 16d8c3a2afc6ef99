"""Where runs execute: a local process pool, or Ray tasks."""

from __future__ import annotations

import concurrent.futures
import itertools
import multiprocessing
from collections.abc import Callable, Iterable
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from impulse.sweep._constants import FAILED, WORKER_FAILURE
from impulse.sweep._worker import _run_task, _worker_start


class _LocalBackend:
    """A process pool on this machine (``spawn`` start method, so it is safe with threads and on
    every platform). ``function(task) -> row`` runs each task (a module-level function, which
    must never raise): a sweep's run by default, a take for ``impulse.takes``."""

    def __init__(
        self, workers: int, function: Callable[[dict[str, Any]], dict[str, Any]] = _run_task
    ):
        self.workers = workers
        self.function = function
        self.pool = self._new_pool()
        self.pending: dict[concurrent.futures.Future, dict[str, Any]] = {}

    def _new_pool(self) -> concurrent.futures.ProcessPoolExecutor:
        return concurrent.futures.ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_worker_start,
        )

    def run(self, tasks: Iterable[dict[str, Any]]):
        """Yields each task's row as it finishes, at most ``4 × workers`` tasks in flight."""
        tasks = iter(tasks)
        pending = self.pending = {}
        limit = 4 * self.workers
        while True:
            for task in itertools.islice(tasks, max(0, limit - len(pending))):
                pending[self.pool.submit(self.function, task)] = task
            if not pending:
                return
            done, _ = concurrent.futures.wait(
                pending, return_when=concurrent.futures.FIRST_COMPLETED
            )
            suspects = []
            for future in done:
                task = pending.pop(future)
                try:
                    yield future.result()
                except BrokenProcessPool:
                    suspects.append(task)
                except Exception as failure:  # the task could not be sent or its row returned
                    yield _failed_row(task, failure)
            if suspects:
                # A worker process died (killed, out of memory, a crash in native code) and took
                # the pool with it: every run in flight is a suspect. Each runs again alone, in
                # its own process, so that only the culprit is recorded as failed.
                suspects += pending.values()
                pending.clear()
                self.pool.shutdown(wait=True, cancel_futures=True)
                for task in suspects:
                    yield self._run_alone(task)
                self.pool = self._new_pool()

    def _run_alone(self, task: dict[str, Any]) -> dict[str, Any]:
        pool = concurrent.futures.ProcessPoolExecutor(
            max_workers=1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_worker_start,
        )
        try:
            return pool.submit(self.function, task).result()
        except BrokenProcessPool:
            return _failed_row(task, RuntimeError("the worker process running this run died"))
        except Exception as failure:
            return _failed_row(task, failure)
        finally:
            pool.shutdown(wait=True)

    def close(self, cancel: bool = False) -> None:
        """Shuts the pool down: after the tasks in flight finish, or with ``cancel`` (an
        interrupt, a search that has its takes) at once, the queued tasks cancelled and the
        running ones ended with their worker processes."""
        if cancel:
            # The pool has no public way to end a running task: its worker processes are
            # terminated (the pool then breaks, which shutdown handles). The queued futures are
            # left to shutdown to cancel: one cancelled here stays among the pool's pending
            # work, and when the broken pool then sets its exception, Python 3.11's executor
            # thread dies of InvalidStateError and shutdown can wait for ever.
            for process in list((getattr(self.pool, "_processes", None) or {}).values()):
                process.terminate()
        self.pool.shutdown(wait=True, cancel_futures=cancel)


class _RayBackend:
    """Ray tasks, one per run (``num_cpus=1`` each). Starts a local Ray (``address=None``) or
    joins a cluster (``address="auto"``, ``"ray://head:10001"``) unless Ray is already
    initialised; shuts down only a Ray it started. ``function`` as for the local pool."""

    def __init__(
        self,
        workers: int | None,
        address: str | None,
        function: Callable[[dict[str, Any]], dict[str, Any]] = _run_task,
    ):
        import ray

        self.ray = ray
        self.started = False
        if not ray.is_initialized():
            options: dict[str, Any] = {
                "address": address,
                "include_dashboard": False,
                "log_to_driver": False,
            }
            if address is None and workers is not None:
                options["num_cpus"] = workers
            ray.init(**options)
            self.started = True
        self.workers = workers or max(1, int(ray.available_resources().get("CPU", 1)))
        # No automatic retry: a run is deterministic, a failure would repeat.
        self.remote = ray.remote(num_cpus=1, max_retries=0)(function)
        self.pending: dict[Any, dict[str, Any]] = {}

    def run(self, tasks: Iterable[dict[str, Any]]):
        ray = self.ray
        tasks = iter(tasks)
        pending = self.pending = {}
        limit = 4 * self.workers
        while True:
            for task in itertools.islice(tasks, max(0, limit - len(pending))):
                pending[self.remote.remote(task)] = task
            if not pending:
                return
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                task = pending.pop(ref)
                try:
                    yield ray.get(ref)
                except Exception as failure:  # the worker died, or the task could not run
                    yield _failed_row(task, failure)

    def close(self, cancel: bool = False) -> None:
        """Shuts down a Ray this backend started; with ``cancel``, first cancels the tasks in
        flight (forcing their workers to exit)."""
        if cancel:
            for ref in self.pending:
                try:
                    self.ray.cancel(ref, force=True)
                except Exception:  # already finished, or the cluster is gone
                    pass
        if self.started:
            self.ray.shutdown()


def _failed_row(task: dict[str, Any], failure: BaseException) -> dict[str, Any]:
    return {
        "run_key": task["key"],
        "status": FAILED,
        "error": f"{WORKER_FAILURE}{type(failure).__name__}: {failure}",
    }
