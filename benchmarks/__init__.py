"""Benchmarks: each module ``bench_*.py`` has ``main()`` printing ratios against references
measured in the same run. Run all with ``python -m benchmarks`` (``make bench``) or one with
``python -m benchmarks.bench_kinematics``."""
