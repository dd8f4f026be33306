"""MapRaster's lattice queries: the thin disc's sub-cells against the whole-box transform."""

from __future__ import annotations

import numpy as np
import pytest

from rrtpso_ompl.model.raster import Lattice, MapRaster


@pytest.mark.parametrize("k", [4, 6, 16])
@pytest.mark.parametrize("clearance", [0.0, 0.1, 0.25, 0.3, 0.45, 0.7, 1.0])
def test_thin_free_cells_agree_with_the_exact_transform(k, clearance):
    rng = np.random.default_rng(k * 100 + round(clearance * 100))
    raster = MapRaster(rng.random((14, 11)) < 0.25, (2.0, -1.0), 0.5)
    c = clearance * raster.resolution
    i0, j0, n0, n1 = 3, 2, 8, 7
    near = rng.random((n0, n1)) < 0.7
    box = Lattice((2.0 + i0 * 0.5, -1.0 + j0 * 0.5), 0.5 / k, n0 * k, n1 * k)
    want = raster.free_cells(box, c) if c > 0 else ~raster.blocked_on(box)
    got = raster.thin_free_cells(i0, j0, near, k, c)
    asked = np.repeat(np.repeat(near, k, axis=0), k, axis=1)
    assert got.shape == want.shape
    assert np.array_equal(got, want & asked)


def test_thin_free_cells_refuse_a_clearance_over_a_cell():
    raster = MapRaster(np.zeros((4, 4), dtype=bool), (0.0, 0.0), 1.0)
    with pytest.raises(ValueError, match="at most one map cell"):
        raster.thin_free_cells(0, 0, np.ones((2, 2), dtype=bool), 4, 1.5)
