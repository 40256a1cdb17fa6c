"""Rewrite every figure the documentation states from fresh runs of the commands that print
them: ``make docs`` (``python -m tests.docs.regenerate``).

In order: the figures in prose and the generated blocks (``tests/docs/stated.py``); the
output lines of every ``console`` block of the README and docs/*.md (their commands as the
pages now write them); the pictures commands draw (``stated.PICTURES``) and the walk-through's
screenshots (``tests/docs/screenshots.py``, skipped with the reason when Chromium is
missing). Figures are written exactly as the commands print them now (the tests allow one
unit of the last digit, ``figures.agree``); a picture is replaced only when it differs.
Every command runs once, in one scratch folder. Prints what changed; exits 1 when a figure
cannot be placed (its words changed: edit the page or ``tests/docs/stated.py``) or a
command does not exit as the page says.
"""

from __future__ import annotations

import argparse
import re
import shutil
import sys
import tempfile
from pathlib import Path

from tests.docs import console, screenshots, stated
from tests.docs.figures import REPO, Block, Stated, Workspace, agree

PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]


def restate_figures(text: str, figure: Stated, workspace: Workspace, log: list[str]) -> str:
    """``text`` with ``figure``'s numbers as its command prints them now."""
    match = figure.find(text)
    fresh = figure.fresh(workspace)
    out = text
    for group in range(len(fresh), 0, -1):
        old, new = match.group(group), fresh[group - 1]
        if old != new:
            log.append(f"{figure.page}: {old} -> {new}   ({'; '.join(figure.commands)})")
            out = out[: match.start(group)] + new + out[match.end(group) :]
    return out


def render_block(text: str, block: Block, workspace: Workspace, log: list[str]) -> str:
    """``text`` with ``block``'s generated text rendered from a fresh run."""
    start, end = block.span(text)
    fresh = block.render(workspace.ok(block.command))
    if text[start:end] == fresh:
        return text
    problem = agree(text[start:end], fresh) or "within the tolerance"
    log.append(f"{block.page}: {block.name} rewritten ({problem[:160]}...)   ({block.command})")
    return text[:start] + fresh + text[end:]


def refresh_console(text: str, page: str, workspace: Workspace, log: list[str]) -> str:
    """``text`` with the output lines of its ``console`` blocks as their commands print now."""
    problems: list[str] = []

    def block(match: re.Match[str]) -> str:
        lines = match.group(1).splitlines()
        starts = [i for i, line in enumerate(lines) if line.startswith("$ ")]
        for k, at in enumerate(starts):
            end = starts[k + 1] if k + 1 < len(starts) else len(lines)
            command = console.commands(f"```console\n{chr(10).join(lines[at:end])}\n```\n")[0]
            done = workspace.run(command.line)
            if done.returncode != command.exit_code:
                problems.append(
                    f"{page}: `{command.line}` exits {done.returncode}, the page says "
                    f"{command.exit_code}\n{done.stdout}{done.stderr}"
                )
                continue
            fresh, lost = console.refreshed(command.shown, done.stdout)
            problems.extend(f"{page}: `{command.line}` no longer prints {line!r}" for line in lost)
            for i, (old, new) in enumerate(zip(command.shown, fresh, strict=True)):
                if old != new:
                    log.append(f"{page}: {old}\n    -> {new}")
                    lines[at + 1 + i] = new
        return "```console\n" + "".join(line + "\n" for line in lines) + "```"

    out = console.BLOCK.sub(block, text)
    if problems:
        raise RuntimeError("\n".join(problems))
    return out


def replace_if_differs(fresh: Path, name: str, log: list[str]) -> None:
    """Copy ``fresh`` over docs/``name`` when the two pictures differ."""
    target = REPO / "docs" / name
    share = screenshots.difference(target, fresh) if target.exists() else 1.0
    if share > screenshots.DIFFERING / 4:
        shutil.copyfile(fresh, target)
        log.append(f"docs/{name}: replaced ({share:.1%} of its drawn pixels differed)")


def refresh_pictures(workspace: Workspace, log: list[str]) -> None:
    """Draw the pictures of docs/ that commands draw; replace those that differ."""
    for picture in stated.PICTURES:
        replace_if_differs(picture.make(workspace), picture.name, log)


def refresh_screenshots(workspace: Workspace, log: list[str]) -> None:
    """Take the docs' screenshots of the pages the commands write; replace those that differ."""
    why = screenshots.unavailable()
    if why is not None:
        log.append(f"screenshots NOT regenerated: {why}")
        return
    for shot in stated.SHOTS:
        workspace.ok(shot.command)
    folder = workspace.root / "screenshots"
    folder.mkdir(exist_ok=True)
    for name, fresh in screenshots.take(stated.SHOTS, workspace.root, folder).items():
        replace_if_differs(fresh, name, log)


def regenerate(workspace: Workspace, *, pictures: bool = True) -> list[str]:
    """Rewrite the pages' figures in place; what changed, one line each."""
    log: list[str] = []
    for path in PAGES:
        page = str(path.relative_to(REPO))
        text = original = path.read_text(encoding="utf-8")
        for figure in stated.STATED:
            if figure.page == page:
                text = restate_figures(text, figure, workspace, log)
        for generated in stated.BLOCKS:
            if generated.page == page:
                text = render_block(text, generated, workspace, log)
        if text != original:
            path.write_text(text, encoding="utf-8")
    for path in PAGES:
        page = str(path.relative_to(REPO))
        text = path.read_text(encoding="utf-8")
        fresh = refresh_console(text, page, workspace, log)
        if fresh != text:
            path.write_text(fresh, encoding="utf-8")
    if pictures:
        refresh_pictures(workspace, log)
        refresh_screenshots(workspace, log)
    return log


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.docs.regenerate", description=__doc__)
    parser.add_argument("--no-pictures", action="store_true", help="leave the PNGs alone")
    parser.add_argument("--keep", type=Path, help="run in this folder and keep its runs")
    parser.add_argument(
        "--reuse", action="store_true", help="with --keep: take what a command printed there before"
    )
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="trackplan-docs-") as scratch:
        root = args.keep or Path(scratch)
        root.mkdir(parents=True, exist_ok=True)
        try:
            log = regenerate(Workspace(root, reuse=args.reuse), pictures=not args.no_pictures)
        except (LookupError, RuntimeError, ValueError) as error:
            print(f"make docs: {error}", file=sys.stderr)
            return 1
    print("\n".join(log) if log else "every figure already as the commands print it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
