"""The workers' settings: no statistical profiler, a slower event-loop check, a clean close."""

from __future__ import annotations

import logging

import pytest

from trackplan.study.preload import PROFILER_CALLBACKS, stop_profiler
from trackplan.study.runner import LOCAL_CLUSTER_CONFIG, local_cluster


def _profiler_after_stop(dask_worker) -> tuple[list[bool], list[bool]]:  # type: ignore[no-untyped-def]
    """Which profiler callbacks the worker had (running), and which remain after the stop."""
    had = [
        name in dask_worker.periodic_callbacks and dask_worker.periodic_callbacks[name].is_running()
        for name in PROFILER_CALLBACKS
    ]
    callbacks = [dask_worker.periodic_callbacks[name] for name in PROFILER_CALLBACKS]
    stop_profiler(dask_worker)
    left = [
        name in dask_worker.periodic_callbacks or callback.is_running()
        for name, callback in zip(PROFILER_CALLBACKS, callbacks, strict=True)
    ]
    return had, left


def test_stop_profiler_removes_and_stops_the_workers_profiler(client) -> None:
    # The in-process cluster's worker runs Dask's profiler; these are its callbacks' names.
    (result,) = client.run(_profiler_after_stop).values()
    had, left = result
    assert had == [True, True]
    assert left == [False, False]


class _Records(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


def _settings(dask_worker) -> tuple[str, list[bool]]:  # type: ignore[no-untyped-def]
    import dask

    return (
        dask.config.get("distributed.admin.tick.interval"),
        [name in dask_worker.periodic_callbacks for name in PROFILER_CALLBACKS],
    )


@pytest.mark.slow
def test_local_cluster_workers_run_without_profiler_and_close_without_being_killed() -> None:
    from distributed import Client

    records = _Records()
    nanny_log = logging.getLogger("distributed.nanny")
    nanny_log.addHandler(records)
    try:
        with local_cluster(2) as cluster, Client(cluster) as client:
            settings = list(client.run(_settings).values())
    finally:
        nanny_log.removeHandler(records)
    interval = LOCAL_CLUSTER_CONFIG["distributed.admin.tick.interval"]
    assert settings == [(interval, [False, False])] * 2
    assert not [message for message in records.messages if "still alive" in message]
