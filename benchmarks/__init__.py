"""Benchmarks: each module ``bench_*.py`` has ``main()`` printing ratios against references
measured in the same run. Run all with ``python -m benchmarks`` (``make bench``) or one with
``python -m benchmarks.bench_kinematics``.

``best_time`` is the one timer they share."""

import time
from collections.abc import Callable


def best_time(function: Callable[[], object], repeats: int = 5) -> float:
    """Shortest CPU time of this process over ``repeats`` calls after a warm-up call, s.

    CPU time, not wall time: on a shared machine the wall time of a serial kernel measures
    the other load as much as the kernel.
    """
    function()
    times = []
    for _ in range(repeats):
        start = time.process_time()
        function()
        times.append(time.process_time() - start)
    return min(times)
