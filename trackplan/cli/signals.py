"""SIGINT and SIGTERM as one way to stop a command: both raise :class:`Stopped`.

Python turns SIGINT into :class:`KeyboardInterrupt` but lets SIGTERM kill the process
with nothing written. While :func:`stop_on_signals` is active both raise :class:`Stopped`
(a ``KeyboardInterrupt``), so the placement search stops, plans the best placement found
and the run is written as for Ctrl-C; the exit code then says which signal it was.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)

_raised: list[int] = []
"""Signals :func:`stop_on_signals` turned into :class:`Stopped`, in order (process-wide,
as signal handlers are)."""


def forget_stops() -> None:
    """Forget earlier stops (a new command starts)."""
    _raised.clear()


def last_stop() -> int | None:
    """The signal behind the latest :class:`Stopped`, or None."""
    return _raised[-1] if _raised else None


class Stopped(KeyboardInterrupt):
    """A stop signal arrived; ``signum`` says which."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


class SignalLog:
    """The first stop signal received while :func:`stop_on_signals` was active, if any.

    While :attr:`deferring` is set, the first signal is only recorded: the placement search
    polls :meth:`raise_if_stopped` after each generation. Raising from the handler itself
    could land inside a compiled (numba) kernel, which turns the exception into a
    ``SystemError``. A second signal, or one outside deferral, raises at once.
    """

    def __init__(self) -> None:
        self.first: int | None = None
        self.deferring = False

    def raise_if_stopped(self) -> None:
        """Raise :class:`Stopped` if a signal was recorded."""
        if self.first is not None:
            _raised.append(self.first)
            raise Stopped(self.first)

    @property
    def exit_code(self) -> int:
        """128 + the first signal's number (130 for SIGINT, 143 for SIGTERM)."""
        return 128 + (self.first if self.first is not None else signal.SIGINT)


@contextmanager
def stop_on_signals() -> Iterator[SignalLog]:
    """Raise :class:`Stopped` on SIGINT and SIGTERM inside the block.

    Outside the main thread (where handlers cannot be set) the block runs unchanged.
    """
    log = SignalLog()

    def handler(signum: int, frame: FrameType | None) -> None:
        if log.first is None:
            log.first = signum
            if log.deferring:
                return
        _raised.append(signum)
        raise Stopped(signum)

    try:
        previous = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    except ValueError:  # not the main thread
        yield log
        return
    try:
        yield log
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def stopped_by_signal(exc: BaseException) -> Stopped | KeyboardInterrupt | None:
    """The interrupt behind an exception: itself, or one in its chain of causes.

    A signal handled while a compiled kernel runs surfaces as a ``SystemError`` whose
    cause is the interrupt.
    """
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        if isinstance(current, KeyboardInterrupt):
            return current
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return None
