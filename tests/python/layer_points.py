"""Shared by the layer-shape tests (test_layer_cells.py, test_sheet_cap.py): random points at one
height of a layer preset's box, and the share of them that is cloud."""
import cloudgen_native as cn
import numpy as np

POINTS = 20000
INNER = 0.3  # of the half-width: inside the sheet's inner half, where its horizontal term is 0


def preset_values(name, **over):
    """The preset's full parameter set (defaults filled in), with `over` applied."""
    values = dict(cn.defaults(), **cn.presets()[name]["params"])
    values.update(over)
    return values


def points_at(values, height, rng, extent=INNER):
    """POINTS random points at `height` of the box (0 its floor, 1 its top), within `extent` of
    each half-width."""
    bx, by, bz = values["box_size"]
    return np.stack([rng.uniform(-extent, extent, POINTS) * bx / 2, rng.uniform(-extent, extent, POINTS) * by / 2,
                     np.full(POINTS, (height - 0.5) * bz)], axis=1)


def cloud_share(values, height, rng):
    """The share of the inner half's points at `height` where the density is > 0."""
    return float((cn.density(values, points_at(values, height, rng)) > 0).mean())
