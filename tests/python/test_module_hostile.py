"""The Python module with hostile inputs (issue 15): sizes that would not fit in
memory are refused with MemoryError before any copy (a broadcast view of 10^9
points once took 16 GB and minutes), names from the caller are shown in at most
~100 characters, odd dtypes and layouts are converted or refused, never a crash
of the interpreter (which may be Blender's).

Documented results: NaN, +-Inf and far points are outside the box, density 0;
complex input is converted by numpy (imaginary part dropped, numpy warns);
object arrays of numbers are converted, of anything else refused (ValueError).
Tolerance: exact. Timeouts are not asserted."""
import os
import warnings

import numpy as np
import pytest

cn = pytest.importorskip("cloudgen_native")

PHYS = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.int64, np.float16])
def test_points_beyond_memory_refused_before_copy(dtype):
    n = max(PHYS // 4, 10**9)  # 16 bytes a point: twice the budget of half the memory
    points = np.broadcast_to(np.zeros(3, dtype), (n, 3))  # no memory of its own
    with pytest.raises(MemoryError, match="points") as info:
        cn.density({}, points)
    assert "GiB" in str(info.value) and len(str(info.value)) < 300, str(info.value)


def test_points_near_the_limit_still_work():
    points = np.broadcast_to(np.zeros(3, np.float32), (100000, 3))
    assert cn.density({}, points).shape == (100000,)


def test_long_names_shown_briefly():
    for params in ({"k" * 10**7: 1}, {"preset": "p" * 10**7}):
        with pytest.raises(ValueError) as info:
            cn.density(params, np.zeros((1, 3)))
        assert len(str(info.value)) < 400, f"a {len(str(info.value))}-character message"


def test_nonfinite_points_give_zero_and_odd_dtypes():
    pts = np.array([[np.nan, 0, 0], [np.inf, 0, 0], [0, -np.inf, 0], [0, 0, 1e38]])
    assert np.array_equal(cn.density({}, pts), np.zeros(4, np.float32))
    ref = cn.density({}, np.zeros((2, 3), np.float32))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert np.array_equal(cn.density({}, np.zeros((2, 3), complex)), ref)
    assert np.array_equal(cn.density({}, np.zeros((2, 3), object)), ref)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        cn.density({}, np.array([["a", "b", "c"]], object))
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        cn.density({}, np.zeros((2, 3), "U3"))


def test_deep_and_huge_values_refused():
    deep = []
    for _ in range(100000):
        deep = [deep]
    with pytest.raises((TypeError, ValueError)) as info:
        cn.density({"density": deep}, np.zeros((1, 3)))
    assert len(str(info.value)) < 400
    with pytest.raises((TypeError, ValueError)):
        cn.density({"box_size": list(range(10**6))}, np.zeros((1, 3)))
