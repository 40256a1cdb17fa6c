"""glibc's allocator settings for processes that run placement searches."""

from __future__ import annotations

import ctypes
import ctypes.util

MALLOC_MMAP_THRESHOLD = 64 * 2**20
"""Bytes: glibc serves smaller allocations from its heap instead of fresh mmaps."""


def keep_freed_memory() -> None:
    """Let glibc reuse freed memory for the batched arrays instead of mapping them anew.

    By default glibc maps every allocation above 128 KiB (raised only gradually) and
    unmaps it on free, so each generation of the placement search page-faults its (B, M, …)
    arrays in again: measured 1.1 s of a 4 s search. The CLI and the study workers own their
    processes, so they set a fixed 64 MiB threshold; elsewhere (not glibc) this does nothing.
    """
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        m_trim_threshold, m_mmap_threshold = -1, -3  # mallopt parameters, <malloc.h>
        libc.mallopt(m_mmap_threshold, MALLOC_MMAP_THRESHOLD)
        libc.mallopt(m_trim_threshold, 2 * MALLOC_MMAP_THRESHOLD)
    except (OSError, AttributeError):
        pass
