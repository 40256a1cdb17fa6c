"""Reading STEP parts with OpenCascade: the shipped parts and a part of a few hundred faces.

Run with ``python -m benchmarks cad``. For each part it prints the faces and edges, the time
of :func:`trackplan.io.step_part.read_step_part` (best of :data:`REPEATS`, OCP already
imported: reading the file, transferring its shapes and numbering and measuring every face
and edge), of listing it (``part_listing``, what ``trackplan part --json`` prints), and of
``trackplan part FILE --json`` as a fresh process (wall time, OCP's import included). The
part of a few hundred faces, ``plate-holes.step`` (306 faces, 912 edges), is made by
``cases/parts/make_parts.py --bench`` into a temporary folder.

The bound (issue 34): reading a part of a few hundred faces takes at most :data:`BOUND` s.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PARTS = REPO / "cases" / "parts"
SHIPPED = ("pipe-plate.step", "t-joint.step", "saddle.step")
REPEATS = 3
BOUND = 2.0
"""s: reading a STEP part of a few hundred faces."""


def _best(run: object, repeats: int = REPEATS) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()  # type: ignore[operator]
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    from trackplan.cad.seams import CadSeam, FaceRef, derive_seam
    from trackplan.cli.parts import part_listing
    from trackplan.io.step_part import _occ, read_step_part

    start = time.perf_counter()
    _occ()
    print(f"importing OCP: {time.perf_counter() - start:.3f} s (once per process)")
    with tempfile.TemporaryDirectory() as folder:
        subprocess.run(
            [sys.executable, str(PARTS / "make_parts.py"), "--bench", folder],
            capture_output=True,
            check=True,
        )
        files = [PARTS / name for name in SHIPPED] + [Path(folder) / "plate-holes.step"]
        print(
            f"{'part':18} {'faces':>6} {'edges':>6} {'read s':>8} {'list s':>8} "
            f"{'seam s':>8} {'CLI s':>7}"
        )
        worst = 0.0
        for file in files:
            part = read_step_part(file)
            read = _best(lambda file=file: read_step_part(file))
            listing = _best(lambda part=part: part_listing(part))
            # a seam of the part: the edges its first two faces with a shared edge join
            a, b = next(edge.faces for edge in part.edges if len(edge.faces) == 2)
            spec = CadSeam(between=(FaceRef(face=a), FaceRef(face=b)))
            seam = _best(lambda part=part, spec=spec: derive_seam(part, spec, 0.0005))
            start = time.perf_counter()
            subprocess.run(
                [sys.executable, "-m", "trackplan", "part", str(file), "--json"],
                capture_output=True,
                check=True,
            )
            cli = time.perf_counter() - start
            print(
                f"{file.name:18} {len(part.faces):6d} {len(part.edges):6d} {read:8.3f} "
                f"{listing:8.4f} {seam:8.4f} {cli:7.2f}"
            )
            if len(part.faces) >= 100:
                worst = max(worst, read + listing + seam)
        verdict = "within" if worst <= BOUND else "OVER"
        print(
            f"a part of a few hundred faces: read, listed and a seam derived in {worst:.3f} s, "
            f"{verdict} "
            f"the {BOUND:.0f} s bound"
        )


if __name__ == "__main__":
    main()
