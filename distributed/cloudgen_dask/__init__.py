"""cloudgen_dask: bakes that outgrow one machine, on Dask distributed.

    python -m cloudgen_dask bake [runner options] [cloudgen bake options]
    python -m cloudgen_dask render scene.blend --frames 1-48 --chunks 4 --output //render/f_####

A bake is split into units — a frame of a sequence, or a brick (a contiguous
range of a grid's 8^3 tiles, `cloudgen bake --brick I/N`) of one large grid —
that Dask workers run with the `cloudgen` CLI. Units are keyed by the core's
bake key: a rerun or a resumed run skips every unit whose output already holds
its key. Every output is written atomically by the CLI and read back before it
counts, so a worker killed mid-unit loses nothing (Dask runs the unit again
elsewhere). Bricks are joined with `cloudgen merge`. docs/distributed.md has
the details and the measurements.
"""
