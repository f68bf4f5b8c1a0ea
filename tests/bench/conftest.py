"""tests/bench: the accuracy bench's pure-Python parts (bench/accuracy). Puts
bench/ on sys.path so the tests import `accuracy.metrics`, `accuracy.pareto`,
`accuracy.report`."""
import pathlib
import sys

BENCH = pathlib.Path(__file__).resolve().parents[2] / "bench"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))
