"""Sequence bakes that compute only what changes ("Bake Frame Range").

The cloud's parameters are read at every frame of the range (scene.frame_set,
then the same params-from-object code a single bake uses: keyframed and driven
sliders as of that frame, the box and location as animated) and passed to
`cloudgen bake --sequence FILE.json --update`. The CLI bakes a frame only when
its density field (cloudgen_native.field_key) differs from an earlier frame's
(else it copies that frame's file) and keeps an existing file whose stored bake
key is unchanged. The scene's frame is restored afterwards.

Time: each frame bakes the Time the render uses at that frame — the slider's
value, or frame / fps when "Time from Frame" is on — so a cloud without wind,
evolution or keyframes bakes once however long the range.
"""


def frame_params(scene, cloud, first: int, last: int, params_of) -> list:
    """[{"frame": f, "params": params_of(cloud)}] for f in first..last, with the scene at
    frame f; the current frame (and subframe) restored afterwards, also on error."""
    frame, subframe = scene.frame_current, scene.frame_subframe
    out = []
    try:
        for f in range(int(first), int(last) + 1):
            scene.frame_set(f)
            out.append({"frame": f, "params": params_of(cloud)})
    finally:
        scene.frame_set(frame, subframe=subframe)
    return out


def sequence_object(frames: list, fps: float) -> dict:
    """The --sequence file's contents."""
    return {"fps": float(fps), "frames": frames}


def summary(result, frames) -> str:
    """'5 frames: 1 baked, 4 copied, 0 kept' from a BakeResult."""
    n = frames[1] - frames[0] + 1 if frames else 1
    return f"{n} frame{'s' if n != 1 else ''}: {result.counts()}"
