"""The procedural render's level of detail: with Cloud Noise's LOD Pixel Angle set,
the OSL density at a shading point equals the native core's density with the
footprint (distance to the camera) x (pixel angle) — the same octave count
(docs/model.md §5: L(f, s), the last octave fading) the bake uses for a voxel of
that size.

Values are read as in test_osl_parity.py (one triangle per point, its generated
coordinates as an attribute, Cycles bakes Cloud Main's Density to the vertices and
the first corner is read), except that each triangle's first vertex sits at its
own distance from the scene camera, from 0.05 to 80 scene units, so that the octave
counts sweep from all (5; 8.7 of 12) down to 1 with every fractional fade between.

Tolerance: that of the parity test, max |OSL − native| ≤ 1e-4 × (density range
of the set). A control keeps the test from passing with the LOD ignored: the OSL
values must differ from the full-detail native density by far more than that.
(With the pixel angle 0 the shaders equal the core at full detail:
test_osl_parity.py, unchanged.)
"""
import json

import blender_nodes
import numpy as np
import pytest
from test_osl_parity import REL_TOL, full_values, sample_points

PIXEL_ANGLE = 0.0044  # radians per pixel: footprints from 2.2e-4 to 0.35 scene units
NEAR, FAR = 0.05, 80.0
CAMERA = (0.5, -0.25, 1.0)


def lod_sets():
    return {"defaults": {},
            "preset_cumulus": {"preset": "cumulus"},
            "high_detail": {"preset": "cumulus", "noise_detail": 12.0, "noise_whisp": 0.8, "noise_scale": 3.0}}


def placed_points(scene, generated, distances):
    """One triangle per point; its first vertex at `distances[i]` from CAMERA (along a
    fixed direction fanned out a little so triangles do not coincide), all three
    vertices carrying the point's G. Returns (object, colour attribute, first vertices)."""
    import bpy

    n = len(generated)
    k = np.arange(n)
    direction = np.stack([np.cos(0.001 * k), np.sin(0.001 * k), np.full(n, 0.3)], -1)
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    first = np.asarray(CAMERA) + direction * distances[:, None]
    verts = np.repeat(first, 3, axis=0)
    verts[1::3, 0] += 0.004
    verts[2::3, 1] += 0.004
    me = bpy.data.meshes.new("lod_points")
    me.from_pydata([tuple(v) for v in verts], [], [(3 * i, 3 * i + 1, 3 * i + 2) for i in range(n)])
    me.update()
    g = me.attributes.new("cg_generated", "FLOAT_VECTOR", "POINT")
    g.data.foreach_set("vector", np.repeat(generated, 3, axis=0).astype(np.float32).ravel())
    ob = bpy.data.objects.new("lod_points", me)
    scene.collection.objects.link(ob)
    attr = me.color_attributes.new("density", "FLOAT_COLOR", "POINT")
    me.color_attributes.active_color = attr
    # the positions Cycles sees: the mesh's float32 coordinates
    co = np.empty(len(me.vertices) * 3, dtype=np.float32)
    me.vertices.foreach_get("co", co)
    return ob, attr, co.reshape(-1, 3, 3)[:, 0].astype(np.float64)


def osl_density_lod(scene, values, points, distances, tmpdir):
    """Bake Cloud Main's Density at `points` (local frame), LOD Pixel Angle PIXEL_ANGLE;
    returns (densities, the first vertices' distances to the camera)."""
    import bpy

    box = np.asarray(values["box_size"], dtype=np.float32)
    generated = (points / box + np.float32(0.5)).astype(np.float32)
    ob, attr, first = placed_points(scene, generated, distances)
    mat = bpy.data.materials.new("lod")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    source = nt.nodes.new("ShaderNodeAttribute")
    source.attribute_name = "cg_generated"
    main, noise = blender_nodes.cloud_density_nodes(nt, values, source.outputs["Vector"], "EXTERNAL", tmpdir)
    noise.inputs["lod_pixel_angle"].default_value = PIXEL_ANGLE
    emission = nt.nodes.new("ShaderNodeEmission")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(main.outputs["Density"], emission.inputs["Color"])
    nt.links.new(emission.outputs[0], out.inputs["Surface"])
    ob.data.materials.append(mat)
    for o in scene.objects:
        o.select_set(o == ob)
    bpy.context.view_layer.objects.active = ob
    scene.cycles.samples = 1
    bpy.ops.object.bake(type="EMIT", target="VERTEX_COLORS")
    colours = np.empty(len(attr.data) * 4, dtype=np.float32)
    attr.data.foreach_get("color", colours)
    bpy.data.objects.remove(ob)
    return colours.reshape(-1, 3, 4)[:, 0, 0], np.linalg.norm(first - np.asarray(CAMERA), axis=-1)


@pytest.fixture
def camera_scene(empty_scene):
    import bpy

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = CAMERA
    cam.rotation_euler = (0.7, 0.2, -1.1)  # any orientation: only the distance counts
    empty_scene.collection.objects.link(cam)
    empty_scene.camera = cam
    return empty_scene


@pytest.mark.parametrize("name", list(lod_sets()))
def test_osl_lod_matches_native_at_the_same_octaves(camera_scene, tmp_path, name):
    import cloudgen_native

    values = full_values(lod_sets()[name])
    osl, nat, full, pts, dist = [], [], [], [], []
    for plane in sample_points(values["box_size"]):
        distances = np.geomspace(NEAR, FAR, len(plane))
        d_osl, d_cam = osl_density_lod(camera_scene, values, plane, distances, str(tmp_path))
        osl.append(d_osl)
        dist.append(d_cam)
        nat.append(np.concatenate([cloudgen_native.density(values, plane[i:i + 1], 1, float(d_cam[i] * PIXEL_ANGLE))
                                   for i in range(len(plane))]))
        full.append(cloudgen_native.density(values, plane))
        pts.append(plane)
    osl, nat, full = np.concatenate(osl), np.concatenate(nat), np.concatenate(full)
    pts, dist = np.concatenate(pts), np.concatenate(dist)
    span = float(nat.max() - nat.min())
    err = np.abs(osl.astype(np.float64) - nat)
    worst = int(err.argmax())
    rel = float(err.max() / span)
    lod_effect = float(np.abs(osl.astype(np.float64) - full).max() / span)
    fp = 2.5 * values["overall_scale"] * 2.0 * values["noise_scale"]  # the gradient noise's cells per unit
    octaves = np.clip(1 + np.log2(0.5 / (fp * dist * PIXEL_ANGLE)), 1, values["noise_detail"])
    figures = {"points": len(nat), "nonzero": int((nat > 0).sum()), "range": span, "max_abs": float(err.max()),
               "max_rel": rel, "lod_effect_rel": lod_effect,
               "perlin_octaves": [float(octaves.min()), float(octaves.max())]}
    print(f"\nlod parity {name}: {json.dumps(figures)}")
    assert np.all(np.isfinite(osl)) and np.all(osl >= 0), f"{name}: OSL density not finite/non-negative"
    fading = int(((octaves > 1) & (octaves < values["noise_detail"])).sum())
    assert octaves.min() == 1 and octaves.max() >= min(values["noise_detail"], 8) and fading > 1000, \
        f"{name}: the sweep misses octaves: {octaves.min():.3g}..{octaves.max():.3g}, {fading} fading"
    assert (nat > 0).sum() > 50, f"{name}: too few non-empty points to compare ({(nat > 0).sum()})"
    assert rel <= REL_TOL, (f"{name}: max |OSL-native| = {err.max():.3g} at local point {pts[worst]}, "
                            f"distance {dist[worst]:.5g} (footprint {dist[worst] * PIXEL_ANGLE:.4g}): "
                            f"OSL {osl[worst]:.6g}, native {nat[worst]:.6g} = {rel:.3g} of the range "
                            f"{span:.4g} > {REL_TOL}; parameters: {values}")
    assert lod_effect > 100 * REL_TOL, (f"{name}: the LOD changed the density by only {lod_effect:.3g} of "
                                        f"the range: is LOD Pixel Angle reaching the shader?")
