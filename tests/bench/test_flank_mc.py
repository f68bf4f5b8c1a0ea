"""bench/flank_mc.py, the random walk that checks Cycles' shading of a thick side-lit cloud
(docs/lighting.md): it agrees with what is known of it in the limits, so its 0.09 for a
sphere 90 optical depths across can be set against Cycles' 0.11.

- Every photon leaves the sphere (albedo 1: nothing is absorbed) well before the event cap.
- A thick sphere is dark on its far side, a thin one is not: the far/lit ratio falls as the
  optical radius grows (1, 5, 45), and at 45 with g 0.85 it lies in [0.05, 0.15]
  (measured 0.086-0.092 with 400,000 photons; here 100,000, seed 3).
- The Lambertian reference is 0 on the far half with the sun on the x axis (the terminator).
"""
import importlib.util
import pathlib

spec = importlib.util.spec_from_file_location(
    "flank_mc", pathlib.Path(__file__).resolve().parents[2] / "bench" / "flank_mc.py")
flank_mc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(flank_mc)


def test_thick_sphere_is_dark_behind_and_thin_one_is_not():
    runs = {tau: flank_mc.run(tau, 0.85, 100_000 if tau == 45 else 20_000, seed=3) for tau in (1.0, 5.0, 45.0)}
    for tau, r in runs.items():
        assert r["still_inside"] == 0, (tau, r)
    ratios = [runs[t]["far_over_lit"] for t in (1.0, 5.0, 45.0)]
    assert ratios[0] > ratios[1] > ratios[2], ratios
    assert 0.05 <= ratios[2] <= 0.15, runs[45.0]
    assert runs[45.0]["lambert_far_over_lit"] == 0.0, runs[45.0]
