"""appmode's benchmarks, run from the repository's top: `python -m bench.run_all` (every
one, one table) or `python -m bench.NAME` (one); docs/benchmarks.md has the figures."""
