"""Numbers as the controller languages write them: fixed point, never an exponent, never
``-0``.

KRL, RAPID, TP and URScript all read fixed-point decimals; they differ only in how many
trailing zeros they keep (TP all of them, KRL and URScript at least one decimal, RAPID
none). :func:`fixed` prints every one of them.
"""

from __future__ import annotations


def fixed(value: float, decimals: int, *, keep: int | None = None) -> str:
    """``value`` rounded to ``decimals`` decimals in fixed point.

    Parameters
    ----------
    value
        The number.
    decimals
        Decimals printed (rounded half to even, as Python's format does).
    keep
        None: keep every decimal (``1.500``); else drop trailing zeros down to ``keep``
        decimals (``keep=1``: ``1.5``, ``2.0``; ``keep=0``: ``1.5``, ``2``).

    Returns
    -------
    str
        The literal; a value that rounds to zero prints without a sign.
    """
    text = f"{float(value):.{decimals}f}"
    if float(text) == 0.0:
        text = f"{0.0:.{decimals}f}"
    if keep is None or "." not in text:
        return text
    whole, fraction = text.split(".")
    fraction = fraction.rstrip("0").ljust(keep, "0")
    return f"{whole}.{fraction}" if fraction else whole


__all__ = ["fixed"]
