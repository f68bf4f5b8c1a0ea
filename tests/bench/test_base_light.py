"""bench/base_light.py's regions: on a synthetic frame (a blue sky, a white cloud 40 columns
wide whose bottom 6 rows are a grey base close to the sky's luminance, speckle noise), the
cloud is found where it differs from the sky in colour, the flank rows sit a third of the way
up each middle column's run, and the base rows are the run's lowest 5, inside the grey base.
The frame: 120 x 100 px, the cloud in rows 30..79 (50 rows), columns 40..79.
"""
import importlib.util
import pathlib

import numpy as np

spec = importlib.util.spec_from_file_location(
    "base_light", pathlib.Path(__file__).resolve().parents[2] / "bench" / "base_light.py")
base_light = importlib.util.module_from_spec(spec)
spec.loader.exec_module(base_light)

TOP, BOTTOM, LEFT, RIGHT = 30, 79, 40, 79


def frame(seed=4):
    rng = np.random.default_rng(seed)
    sky = np.zeros((100, 120, 3))
    sky[...] = (0.3, 0.5, 0.9)
    cloud = sky.copy()
    cloud[TOP:BOTTOM + 1, LEFT:RIGHT + 1] = (3.0, 3.0, 3.0)
    grey = base_light.luminance(np.array((0.3, 0.5, 0.9)))  # the base: as bright as the sky, not as blue
    cloud[BOTTOM - 5:BOTTOM + 1, LEFT:RIGHT + 1] = grey
    noise = rng.normal(1.0, 0.05, cloud.shape)
    return cloud * noise, sky * rng.normal(1.0, 0.05, sky.shape)


def test_regions_find_flank_and_base_of_the_main_cloud():
    everything, without_main = frame()
    flank, base = base_light.regions(everything, without_main)
    cols = sorted({c for _, c in base})
    assert LEFT + 10 <= cols[0] and cols[-1] <= RIGHT - 10, cols  # the middle fifth of the cloud's columns
    base_rows = {r for r, _ in base}
    # the blur moves the run's ends by at most 2 rows (tolerance 2: the 5x5 box)
    assert all(BOTTOM - 6 <= r <= BOTTOM + 2 for r in base_rows), sorted(base_rows)
    flank_rows = {r for r, _ in flank}
    third = BOTTOM - (BOTTOM - TOP) // 3
    assert all(abs(r - third) <= 4 for r in flank_rows), (sorted(flank_rows), third)
    lum = base_light.luminance(everything)
    rows, cols = zip(*base)
    frows, fcols = zip(*flank)
    assert lum[rows, cols].mean() < 0.5 * lum[frows, fcols].mean(), "the base rows are not in the grey base"
