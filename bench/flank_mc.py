"""Independent check of a side-lit cloud's shading: how bright is the side of a thick,
forward-scattering sphere turned away from the sun, against the side facing it? A plain
Monte Carlo random walk (numpy, no Cycles): a sphere of optical radius TAU (extinction
TAU per radius), albedo 1, Henyey-Greenstein phase g, lit by a parallel beam travelling
along -x (the sun at +x), seen by a camera far away on -y (90° from the sun, as the
gallery's side view). Each scattering event adds its next-event estimate toward the
camera (phase x transmittance to the sphere's edge along -y) to an image of the disc;
the result is the mean radiance over the sunlit half (x > 0.2) against the far half
(x < -0.2), within 0.8 of the radius (the rim left out), and the same for a white
Lambertian sphere (the analytic terminator: 0 on the far half).

Usage: .venv/bin/python bench/flank_mc.py [--tau 45] [--g 0.85] [--photons 40000] [--seed 1]
Prints one JSON line. docs/lighting.md quotes the result next to the Cycles measurement.
"""
import argparse
import json
import math

import numpy as np

PIX = 64  # image of the disc, PIX x PIX over [-1, 1]^2 in (x, z)


def exit_distance(p, d):
    """Distance from p (inside the unit sphere) along unit d to the sphere's surface."""
    b = np.einsum("ij,ij->i", p, d)
    c = np.einsum("ij,ij->i", p, p) - 1.0
    return -b + np.sqrt(np.maximum(b * b - c, 0.0))


def hg_sample(d, g, rng):
    """New unit directions scattered from unit directions d by Henyey-Greenstein g."""
    n = d.shape[0]
    u = rng.random(n)
    if abs(g) < 1e-6:
        cos = 1.0 - 2.0 * u
    else:
        s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
        cos = (1.0 + g * g - s * s) / (2.0 * g)
    cos = np.clip(cos, -1.0, 1.0)
    sin = np.sqrt(1.0 - cos * cos)
    phi = 2.0 * math.pi * rng.random(n)
    # an orthonormal frame around d
    a = np.where(np.abs(d[:, :1]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
    t1 = np.cross(d, a)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(d, t1)
    return (cos[:, None] * d + (sin * np.cos(phi))[:, None] * t1 + (sin * np.sin(phi))[:, None] * t2)


def hg_value(cos, g):
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * cos) ** 1.5)


def run(tau, g, photons, seed, sun_elevation=0.0, max_events=20000):
    rng = np.random.default_rng(seed)
    # entry points: uniform over the disc seen by the sun, on the sunlit hemisphere
    r = np.sqrt(rng.random(photons))
    a = 2.0 * math.pi * rng.random(photons)
    y, z = r * np.cos(a), r * np.sin(a)
    p = np.stack([np.sqrt(1.0 - y * y - z * z), y, z], axis=1)
    d = np.tile(np.array([[-1.0, 0.0, 0.0]]), (photons, 1))
    # the sun raised by sun_elevation above the x axis (about y): the beam comes down toward -x
    e = math.radians(sun_elevation)
    rot = np.array([[math.cos(e), 0.0, -math.sin(e)], [0.0, 1.0, 0.0], [math.sin(e), 0.0, math.cos(e)]])
    p, d = p @ rot.T, d @ rot.T
    to_cam = np.array([[0.0, -1.0, 0.0]])
    image = np.zeros((PIX, PIX))
    events = 0
    alive = np.arange(photons)
    while alive.size and events < max_events:
        pa, da = p[alive], d[alive]
        step = -np.log(1.0 - rng.random(alive.size)) / tau
        out = step >= exit_distance(pa, da)
        pa = pa + step[:, None] * da
        keep = ~out
        alive, pa, da = alive[keep], pa[keep], da[keep]
        if not alive.size:
            break
        # next event toward the camera: phase x transmittance to the edge along -y
        w = hg_value(np.einsum("ij,ij->i", da, np.broadcast_to(to_cam, da.shape)), g) * np.exp(
            -tau * exit_distance(pa, np.broadcast_to(to_cam, pa.shape)))
        ix = np.clip(((pa[:, 0] + 1.0) * 0.5 * PIX).astype(int), 0, PIX - 1)
        iz = np.clip(((pa[:, 2] + 1.0) * 0.5 * PIX).astype(int), 0, PIX - 1)
        np.add.at(image, (iz, ix), w)
        d[alive] = hg_sample(da, g, rng)
        p[alive] = pa
        events += 1
    xs = (np.arange(PIX) + 0.5) / PIX * 2.0 - 1.0
    X, Z = np.meshgrid(xs, xs)
    inner = X * X + Z * Z < 0.8 ** 2
    lit, far = inner & (X > 0.2), inner & (X < -0.2)
    # a white Lambertian sphere under the same beam, seen from -y: radiance ∝ max(n·sun, 0)
    lamb = np.maximum(X * math.cos(e) + Z * math.sin(e), 0.0)  # normal (x, -sqrt(1-x²-z²), z) · sun
    return {
        "tau_radius": tau, "g": g, "sun_elevation": sun_elevation, "photons": photons, "seed": seed, "events": events,
        "still_inside": int(alive.size),
        "far_over_lit": float(image[far].mean() / image[lit].mean()),
        "lambert_far_over_lit": float(lamb[far].mean() / lamb[lit].mean()),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tau", type=float, default=45.0, help="optical radius (default 45: 90 across)")
    ap.add_argument("--g", type=float, default=0.85, help="Henyey-Greenstein g (default 0.85, Mie's)")
    ap.add_argument("--photons", type=int, default=40000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sun-elevation", type=float, default=0.0, help="degrees above the x axis (default 0)")
    a = ap.parse_args()
    print(json.dumps(run(a.tau, a.g, a.photons, a.seed, a.sun_elevation)))


if __name__ == "__main__":
    main()
