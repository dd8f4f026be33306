"""Why the spatial index is a uniform grid and not ``shapely.STRtree``: per-call costs from Python
on 10,000 lattice circles (the worlds of benchmarks/scaling.py), random segments up to 200 long in
1000 x 1000. Quoted in docs/design.md.

Usage::

    python benchmarks/index_choice.py
"""

from __future__ import annotations

import sys
import time

import numpy as np
import shapely

from rrtpso_ompl.model import World


def main() -> int:
    rng = np.random.default_rng(0)
    k, cell, n = 100, 10.0, 10_000
    ij = np.array([(i, j) for i in range(k) for j in range(k)])
    c = (ij + 0.5 + rng.uniform(-0.25, 0.25, (n, 2))) * cell
    r = rng.uniform(0.15, 0.3, n) * cell
    world = World(((0, 0), (1000, 1000)), np.column_stack([c, r]), robot_radius=0.5)
    tree = shapely.STRtree(shapely.buffer(shapely.points(c), r + 0.5, quad_segs=4))
    m = 5000
    a = rng.uniform(0, 1000, (m, 2))
    ang, length = rng.uniform(0, 2 * np.pi, m), rng.uniform(0, 200, m)
    b = np.clip(a + np.column_stack([np.cos(ang), np.sin(ang)]) * length[:, None], 0, 1000)
    pairs = list(zip(a.tolist(), b.tolist(), strict=True))

    def per_call(fn) -> float:
        t = time.perf_counter()
        fn()
        return (time.perf_counter() - t) / m * 1e6

    lines = [shapely.LineString([p, q]) for p, q in pairs]
    rows = {
        "LineString per query": per_call(lambda: [shapely.LineString([p, q]) for p, q in pairs]),
        "STRtree query per segment": per_call(lambda: [tree.query(g) for g in lines]),
        "STRtree bulk query per segment": per_call(
            lambda: tree.query(shapely.linestrings(np.stack([a, b], axis=1)))
        ),
        "grid motion_free (exact) per segment": per_call(
            lambda: [world.motion_free(*p, *q) for p, q in pairs]
        ),
        "grid segments_free (exact, vectorised) per segment": per_call(
            lambda: world.segments_free(a, b)
        ),
    }
    for name, us in rows.items():
        print(f"{name}: {us:.1f} us")
    return 0


if __name__ == "__main__":
    sys.exit(main())
