"""Program names made valid identifiers of a controller language.

Every language here takes letters, digits and underscores, starting with a letter; KRL
allows at most 24 characters and FANUC wants upper case (and 8 characters in a TP program
name on older controllers; trackplan keeps the language limit each writer states).
"""

from __future__ import annotations

import re
import unicodedata

from trackplan.errors import CaseError


def program_identifier(
    name: str, *, max_length: int | None = None, upper: bool = False, key: str = "name"
) -> str:
    """``name`` as a valid identifier: letters, digits, ``_``, starting with a letter.

    Accents are dropped (``Naht_ü`` → ``Naht_u``), every other character becomes ``_``,
    runs of ``_`` collapse, leading digits and underscores are removed, and the result is
    cut to ``max_length``.

    Parameters
    ----------
    name
        The program name asked for (``--name`` or the case name).
    max_length
        The language's longest identifier, or None.
    upper
        Upper-case the result (FANUC).
    key
        The option named in the error.

    Returns
    -------
    str
        The identifier.

    Raises
    ------
    CaseError
        When nothing of ``name`` is left that starts with a letter.
    """
    ascii_name = unicodedata.normalize("NFKD", name).encode("ascii", "ignore").decode("ascii")
    cleaned = re.sub(r"[^A-Za-z0-9_]+", "_", ascii_name)
    cleaned = re.sub(r"_+", "_", cleaned)
    cleaned = re.sub(r"^[^A-Za-z]+", "", cleaned)
    if max_length is not None:
        cleaned = cleaned[:max_length]
    cleaned = cleaned.rstrip("_") or cleaned
    if not cleaned:
        raise CaseError(
            f"{name!r} cannot be made a program name (letters, digits and _, starting with "
            "a letter): give --name",
            key=key,
        )
    return cleaned.upper() if upper else cleaned


SPELLED = {
    "ß": "ss",
    "·": "*",
    "×": "x",
    "≤": "<=",
    "≥": ">=",
    "±": "+/-",
    "°": " deg",
    "−": "-",
    "–": "-",
    "—": "-",
    "→": "->",
    "≈": "~",
    "µ": "u",
    "π": "pi",
    "’": "'",
    "“": '"',
    "”": '"',
}
"""Symbols the headers use, spelled in ASCII."""


def ascii_comment(text: str) -> str:
    """``text`` as one line of ASCII for a program comment.

    Controllers read program files as ASCII or a single-byte code page (KRL Windows-1252,
    RAPID ISO 8859-1, URControl "extended ASCII"), so symbols are spelled out
    (:data:`SPELLED`), accents dropped, any other character becomes ``?`` and line breaks
    become spaces (a comment stays on its line).
    """
    text = " ".join(text.splitlines())
    for symbol, spelled in SPELLED.items():
        text = text.replace(symbol, spelled)
    decomposed = unicodedata.normalize("NFKD", text)
    return "".join(c if ord(c) < 128 else "?" for c in decomposed if not unicodedata.combining(c))


__all__ = ["SPELLED", "ascii_comment", "program_identifier"]
