"""The corridor stage's orchestration within its time: the lattice sized by the time, a map
searched whole (with the corner lattice's routes, or its shortest route alone) or coarse-to-fine,
a thin disc through the map's own cells, circles alone by the taut string of a fine lattice's
route, shapes through bands of marked cells, the centre route as the last resort."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import time
from typing import Any

import numpy as np
from scipy import ndimage

from ....model.geometry import path_length
from ....model.raster import Lattice
from ....model.world import MarkingStopped
from .corner_routes import CORNER_CELLS_PER_SECOND, CORNER_REACH, corner_routes
from .funnel import channel_portals, free_rectangles, funnel, rectangle_channel
from .paths import CorridorResult, centre_route, route_and_funnel
from .routes import ALTERNATIVE_APART, ALTERNATIVE_SLACK, alternative_routes, channel, lattice_route
from .taut import circles_alone, taut_string

#: Lattice cells the corridor stage builds, searches and funnels per second, on the safe side
#: (measured on the reference machine: 2-3 million on maps, fewer among many shapes).
CELLS_PER_SECOND = 1_000_000
#: The lattice's cells in an iteration-bounded run (no time limit: the same lattice on any
#: machine).
REPRODUCIBLE_CORRIDOR_CELLS = 65_536


#: The refinement searches the cells within this many coarse cells of the coarse path.
BAND_CELLS = 3.0


#: Lattice cells per second a map's cells are marked free or not (array work over the whole
#: lattice; the search itself stays in the band), on the safe side.
MARK_CELLS_PER_SECOND = 8_000_000


#: Lattice cells of a map routed (with alternatives) and funnelled whole per second, on the safe
#: side (measured 1.0-1.3 million on 256 x 256 mazes and random maps). A map whose lattice fits
#: in the time left at this rate is searched whole: pooling its cells into a coarse lattice opens
#: gaps through walls one cell thick, and the coarse routes then miss a maze's only corridor.
DIRECT_CELLS_PER_SECOND = 1_200_000


#: Lattice cells of a map per second its shortest route alone is found and funnelled (no
#: alternatives, no corner lattice), on the safe side (measured 2-4 million on 256 x 256 mazes,
#: caves and random maps).
LEAN_CELLS_PER_SECOND = 2_000_000


#: Lattice cells per second :func:`centre_route` builds and routes over among shapes, on the
#: safe side (measured 0.6-1 million among 10,000 circles).
CENTRE_CELLS_PER_SECOND = 600_000


#: Cells of the small lattice on which the cost of marking cells among shapes is measured.
MARKING_PROBE_CELLS = 1_600


#: Probes of the marking cost (the fastest counts).
MARKING_PROBES = 3


#: The share of the stage's time the probe may take: obstacles so detailed that marking the
#: probe's cells takes longer leave no time for a lattice worth routing on (the stage gives up).
MARKING_PROBE_SHARE = 0.1


#: Among shapes, the share of the stage's time for the bands of wholly free cells; the rest is
#: kept for :func:`centre_route` in case they hold no route.
SHAPE_BAND_SHARE = 0.5


#: Among shapes, fine cells per coarse cell side in the bands.
SHAPE_SPLIT = 4


#: For a disc narrower than a map cell, the most fine cells per map cell side in the bands
#: (:func:`_disc_corridors`): at 16, gaps are kept open for a radius up to 7/16 of a cell
#: (wider discs through the free cell centres of the band).
THIN_SPLIT = 16


def find_corridor_path(
    model: Any,
    start,
    goal,
    seconds: float | None,
    max_cells: int = 4_194_304,
    terminate=None,
    alternatives: int = 3,
    no_route_seconds: float | None = None,
) -> CorridorResult:
    """The corridor stage within ``seconds`` (None: no limit but ``max_cells``).

    A map whose fine lattice fits the time (:data:`DIRECT_CELLS_PER_SECOND`) is searched whole
    (:func:`route_and_funnel`), with the corner lattice's routes where their band fits
    (:mod:`.corner_routes`). A disc narrower than a map cell whose lattice would close one-cell
    gaps goes through :func:`_disc_corridors` first (a wider disc whose doors the lattice
    closes, after). Otherwise:

    1. **Coarse routes** on a lattice small enough to route on in a third of the time
       (:data:`CELLS_PER_SECOND`), its cells open generously (a map's when any fine cell they
       pool is wholly free; among shapes when their centre is free): no passage the fine cells
       keep is closed. The shortest route and ``alternatives`` through other corridors.
    2. **A fine route in each corridor**, best first: the fine cells within :data:`BAND_CELLS`
       coarse cells of it (marked in a box round the band: the work follows the band), the route
       over them and its funnel path. The shortest valid path wins.

    A map lattice that fits only by ``no_route_seconds`` is searched by its shortest route alone
    (:data:`LEAN_CELLS_PER_SECOND`). With no route yet, the search may go on until
    ``no_route_seconds`` (nothing is left for the later stages to refine meanwhile): a map's
    whole fine lattice if it fits, then, for free
    space too thin for any wholly free fine cell, :func:`centre_route`.

    Marking a lattice's cells stops at the deadline too (:meth:`World.marking_stops
    <rrtpso_ompl.model.World.marking_stops>`): a marking cut short gives no cells, and the
    stage ends with the best path it had.
    """
    t0 = time.perf_counter()
    end = None if seconds is None else t0 + seconds
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    stages: dict[str, float] = {}
    out_of_time = _Deadline(end, terminate)
    if end is not None and no_route_seconds is not None:
        out_of_time.grace_end = max(end, t0 + no_route_seconds)
    with _marking_stops(model, out_of_time):
        try:
            result = _search(model, start, goal, seconds, max_cells, alternatives,
                             no_route_seconds, out_of_time, t0, stages)  # fmt: skip
        except MarkingStopped:
            result = CorridorResult(None, reason="out of time marking the lattice's cells")
    t1 = time.perf_counter()
    result = _tautened(model, result, terminate)  # a centre route's too
    stages["taut"] = stages.get("taut", 0.0) + time.perf_counter() - t1
    return dataclasses.replace(result, time=time.perf_counter() - t0, stages=stages)


def _tautened(model, result: CorridorResult, terminate) -> CorridorResult:
    """Among circles, ``result`` with its path replaced by the taut string of its homotopy
    (:func:`.taut.taut_string`, which declines other worlds) where that is shorter: the funnel
    runs through cells wholly free, up to a cell off every circle (among 10,000 circles +3 % in
    the right corridor, taut +0.7 %). A bounded step, stopped by ``terminate`` (the outer
    deadline)."""
    if result.path is None or getattr(model, "raster", None) is not None:
        return result
    taut = taut_string(model, np.asarray(result.path), terminate)
    if taut is None or not path_length(taut) < result.length:
        return result
    return dataclasses.replace(result, path=taut, length=path_length(taut))


def _marking_stops(model, stop):
    """``model.marking_stops(stop)`` where the model has it (the World, the space information's
    adapter), else nothing."""
    marking_stops = getattr(model, "marking_stops", None)
    return contextlib.nullcontext() if marking_stops is None else marking_stops(stop)


def _search(model, start, goal, seconds, max_cells, alternatives, no_route_seconds, out_of_time,
            t0, stages) -> CorridorResult:  # fmt: skip
    """:func:`search`'s steps (a marking cut short raises :class:`MarkingStopped`)."""
    end = out_of_time.end
    terminate = out_of_time.terminate
    left = out_of_time.left
    on_map = getattr(model, "raster", None) is not None
    # Among shapes the wholly free cells may miss gaps narrower than a cell (a dense field of
    # circles): time is kept for the route through free cell centres.
    first = (out_of_time if on_map or end is None
             else _Deadline(t0 + SHAPE_BAND_SHARE * seconds, terminate))  # fmt: skip
    if circles_alone(model):  # the string of a fine lattice's route, no bands
        taut = _taut_routes(model, start, goal, max_cells, out_of_time, stages)
        if taut.path is not None:
            return taut
    # Among shapes the cost of marking a cell grows with the obstacles' detail (a polygon of
    # 10,000 vertices marks 100,000 cells a second, a few circles millions): measured first.
    rate = CELLS_PER_SECOND
    if not on_map and end is not None:
        rate = _marking_rate(model, seconds)
        if rate is None:
            return CorridorResult(None, reason="marking cells is too slow for the time (the "
                                  "obstacles are too detailed)")  # fmt: skip
    result, fine_cells, route_cells = _coarse_tries(
        model, start, goal, max_cells, alternatives, out_of_time, first, t0, stages, rate
    )
    if result.path is None and end is not None and no_route_seconds is not None:
        out_of_time.end = max(end, t0 + no_route_seconds)
        if on_map and not out_of_time():  # the whole fine lattice, if it now fits
            result = _map_corridors(model, fine_cells, route_cells, start, goal, 0, out_of_time,
                                    t0, stages, left)  # fmt: skip
    if result.path is None and not out_of_time():
        per_second = min(CENTRE_CELLS_PER_SECOND, 0.5 * rate)
        cells = min(max_cells, int(per_second * left())) if end else 1 << 18
        thin = centre_route(model, start, goal, max(cells, 4096), out_of_time)
        if thin.path is not None:
            result = thin
    if result.path is None and not on_map and end is not None and not out_of_time():
        # Among shapes the first tries had half the stage's time; with no route yet, the coarse
        # lattice again as the no-route time affords it (among 10,000 circles a lattice of 26,000
        # cells found no route at the fine level, nor the centre route, with a second left).
        again, _, _ = _coarse_tries(model, start, goal, max_cells, alternatives, out_of_time,
                                    out_of_time, t0, stages, rate)  # fmt: skip
        if again.path is not None:
            result = again
    return result


#: Among circles alone, lattice cells :func:`_taut_routes` marks, routes and pulls taut per
#: second, on the safe side (10,000 circles: 1.1-1.5 million from 125,000 to 2 million cells).
TAUT_CELLS_PER_SECOND = 1_200_000

#: Share of the time left the first lattice of :func:`_taut_routes` is sized to.
TAUT_FIRST_SHARE = 0.7


def _taut_routes(model, start, goal, max_cells, out_of_time, stages) -> CorridorResult:
    """Among circles alone: the taut string (:func:`.taut.taut_string`) of the shortest route on
    the lattice of free cell centres, as fine as :data:`TAUT_FIRST_SHARE` of the time left
    affords, then on lattices twice as fine while one fits; the shortest string.

    The string does not need the route's cells to be wholly free, only the side it passes each
    circle: no bands of finer cells, and the time goes into a finer lattice, whose shortest
    route picks the corridor better (10,000 circles, the route's taut string over the optimum:
    1.0047 on 500,000 cells, 1.0015 on 800,000, 1.0006 on 1.5 million; the best of 17 routes
    through other corridors on 140,000 cells: 1.0124). No string (a route but no convergence,
    no route at all): no path, and the bands take over.
    """
    left = out_of_time.left
    cells = max_cells
    if out_of_time.end is not None:
        cells = int(min(max_cells, TAUT_FIRST_SHARE * TAUT_CELLS_PER_SECOND * left()))
    best = CorridorResult(None, reason="no taut string of a route")
    t0 = time.perf_counter()
    while cells >= 1024:  # at most log2(max_cells) rounds: the cells double each time
        t1 = time.perf_counter()
        lat = model.lattice(cells)
        try:
            opened = model.centres_free(lat)
        except MarkingStopped:
            break
        ends = _joined_ends(opened, lat.cell_of(start), lat.cell_of(goal))
        route = None if ends is None else lattice_route(opened, ends[0], ends[1])
        if route is not None and not out_of_time():
            centres = np.asarray(lat.origin) + (np.asarray(route) + 0.5) * lat.h
            reference = np.vstack([start, centres, goal])
            string = taut_string(model, reference, out_of_time)
            if string is not None and path_length(string) < best.length:
                best = CorridorResult(string, path_length(string), lattice=lat, routes=1,
                                      route_cells=len(route))  # fmt: skip
        took = time.perf_counter() - t1
        if out_of_time.end is None or cells >= max_cells or left() < 2.5 * took:
            break
        cells = min(2 * cells, max_cells)
    stages["taut_routes"] = time.perf_counter() - t0
    return best


def _marking_rate(model, seconds: float) -> float | None:
    """Lattice cells per second ``model`` marks (its free cell centres), measured on a small
    lattice, the fastest of :data:`MARKING_PROBES` (one probe of a few milliseconds varied
    fourfold from run to run, and the lattice with it); at most :data:`CELLS_PER_SECOND`. None
    when the probes take more than :data:`MARKING_PROBE_SHARE` of ``seconds`` (they are
    stopped there)."""
    probe = model.lattice(MARKING_PROBE_CELLS)
    end = time.perf_counter() + MARKING_PROBE_SHARE * seconds
    outer = getattr(model, "mark_stop", None)

    def stop() -> bool:
        return time.perf_counter() >= end or bool(outer is not None and outer())

    fastest = math.inf
    try:
        with _marking_stops(model, stop):
            for _ in range(MARKING_PROBES):
                t = time.perf_counter()
                model.centres_free(probe)
                fastest = min(fastest, time.perf_counter() - t)
                if time.perf_counter() + fastest >= end:
                    break  # no time for another probe: one is enough
    except MarkingStopped:
        if not math.isfinite(fastest):
            return None
    return min(CELLS_PER_SECOND, probe.n_cells / max(fastest, 1e-6))


def _coarse_tries(model, start, goal, max_cells, alternatives, out_of_time, first, t0, stages,
                  rate=CELLS_PER_SECOND):  # fmt: skip
    """:func:`search`'s tries until a path, ``first()`` or too little time: when no corridor
    held a route at the fine level (the coarse lattice joined cells that do not join), twice the
    coarse cells, while a try as long again fits twice over. The last result, the fine and the
    coarse lattice's cells."""
    left = out_of_time.left
    on_map = getattr(model, "raster", None) is not None
    route_cells = int(min(max_cells, max(min(CELLS_PER_SECOND, rate) * left() / 3.0, 1024)))
    fine_cells = 0
    while True:  # at most log2(max_cells) rounds: the coarse cells double each time
        t1 = time.perf_counter()
        if on_map:
            fine_cells = _map_fine_cells(model, max_cells, left(), out_of_time.grace_left())
            result = _map_corridors(model, fine_cells, route_cells, start, goal, alternatives,
                                    out_of_time, t0, stages, left, max_cells)  # fmt: skip
        else:
            result = _shape_corridors(model, route_cells, max_cells, start, goal, alternatives,
                                      first, t0, stages, rate)  # fmt: skip
        took = time.perf_counter() - t1
        if result.path is not None or route_cells >= max_cells or first() or left() < 4.0 * took:
            return result, fine_cells, route_cells
        route_cells = min(2 * route_cells, max_cells)


#: Cells of a band's box (:func:`_disc_corridors`) marked, routed and wrapped a second, on the
#: safe side (a box of 970,000 cells: 0.17-0.20 s).
BOX_CELLS_PER_SECOND = 4_000_000

#: A disc's fine lattice may be the map's own cells on maps of at least this many cells
#: (:func:`_map_fine_cells`).
DISC_OWN_CELLS = 1 << 20


def _map_fine_cells(model, max_cells: int, seconds: float, grace_seconds: float) -> int:
    """The fine lattice's cells on a map: as many as marking affords in ``seconds``
    (:data:`MARK_CELLS_PER_SECOND`), or the map's own cells (up to ``max_cells``) on a map alone
    when marking them and their shortest route fit ``grace_seconds``
    (:data:`LEAN_CELLS_PER_SECOND`; a point robot's cells are read off the raster at no cost).

    Coarser cells close passages: one-cell doors for a point robot (on a 1024 x 1024 city map
    the 2 x 2-cell lattice kept 26 % of the cells free, the map's own 35 %), and for a disc up to
    a cell along every wall, which on a warehouse of 2 million cells at 5 cm left the best
    corridor closed (its path +1.35 % on cells of 10 cm, +0.24 % on the map's own). On smaller
    maps (:data:`DISC_OWN_CELLS`) the time's lattice with alternatives measured better for a
    disc (a 192,000-cell lab at 0.25 s: +0.3 % against the own cells' shortest route's +0.9 %,
    a corridor of nearly equal lattice length). Where the route does not fit, the map's cells
    would be pooled for coarse routes, which measured worse than the time's lattice (a
    596 x 397 house plan at 0.1 s: 2 of 4 queries unsolved)."""
    cells = int(min(max_cells, max(0.4 * MARK_CELLS_PER_SECOND * seconds, 4096)))
    if not _map_alone(model):
        return cells
    own = model.lattice(max_cells, split=1).n_cells
    marking = 0.0
    if model.robot_radius > 0.0:
        if own < DISC_OWN_CELLS:
            return cells
        marking = own / MARK_CELLS_PER_SECOND
    return max(cells, own) if marking + own / LEAN_CELLS_PER_SECOND <= grace_seconds else cells


def _map_alone(model) -> bool:
    """Whether ``model`` is a map with no other obstacles (its free cells read off the raster)."""
    if getattr(model, "raster", None) is None:
        return False
    shapes = getattr(model, "non_raster_index", None)
    return shapes is not None and not shapes.n_obstacles


def _map_corridors(model, fine_cells, route_cells, start, goal, alternatives, terminate, t0,
                   stages, left, max_cells=None) -> CorridorResult:  # fmt: skip
    """:func:`search` on a map: the fine cells marked once, searched whole when the time
    ``left()`` affords it (:data:`DIRECT_CELLS_PER_SECOND`), else by its shortest route alone if
    that fits by the no-route time (:data:`LEAN_CELLS_PER_SECOND`), else pooled into a coarse
    lattice. A thin disc whose gaps this lattice closes first goes through
    :func:`_disc_corridors`, as does a wider one the lattice finds no route for."""
    fine = model.lattice(fine_cells)
    if fine.nx < 2 or fine.ny < 2:
        return CorridorResult(None, reason="the lattice is too small")
    grace = _Deadline(terminate.grace_end, terminate.terminate)
    if _closes_thin_gaps(model, fine):
        # No route yet (the lattice of this time would close the gaps): up to the grace time.
        # The map's own cells (marked off the raster) at any size the user's ``max_cells`` allows.
        own = fine_cells if max_cells is None else max(max_cells, fine_cells)
        thin = _disc_corridors(model, own, start, goal, alternatives, grace, t0, stages)
        if thin.path is not None or terminate():
            return thin
    free = model.free_cells(fine)
    stages["cells"] = time.perf_counter() - t0
    k = max(1, math.ceil(math.sqrt(fine.n_cells / route_cells)))
    nx, ny = fine.nx // k, fine.ny // k
    if k == 1 or nx < 2 or ny < 2 or fine.n_cells <= DIRECT_CELLS_PER_SECOND * left():
        result = route_and_funnel(model, fine, free, start, goal, alternatives, terminate, t0,
                                  stages, corner_reach=CORNER_REACH)  # fmt: skip
    elif fine.n_cells <= LEAN_CELLS_PER_SECOND * terminate.grace_left() and not (
        _may_pool(model, fine) and _pooling_keeps_walls(free, k)
    ):
        # Too little time for the whole lattice with alternatives, enough for its shortest route
        # by the time a stage with no route may take: better than pooling, which opens gaps
        # through walls a cell thick (in a 256 x 256 maze at 0.1 s every coarse route then
        # failed at the fine level and left no time; on 1024 x 1024 maps pooling measured worse
        # too). Pooled corridors, ranked by their taut length, where the walls are thicker than
        # the pooling and the lattice is not one of the map's own cells kept for their exact
        # corridors (:func:`_may_pool`).
        result = route_and_funnel(model, fine, free, start, goal, 0, grace, t0, stages)
    else:
        result = _pooled_corridors(model, fine, free, k, start, goal, alternatives, terminate,
                                   t0, stages)  # fmt: skip
    if result.path is None and model.robot_radius > 0.0 and not grace():
        # A disc's doors closed by this lattice's cells (too coarse for the time): routes over
        # the map's cells whose centre keeps the radius, each searched again on finer cells.
        wide = _disc_corridors(model, fine_cells, start, goal, alternatives, grace, t0, stages)
        if wide.path is not None:
            return wide
    return result


def _may_pool(model, fine: Lattice) -> bool:
    """Whether the map lattice ``fine`` may be pooled for coarse routes (when its walls survive
    the pooling) rather than searched by its shortest route alone: when it is coarser than the
    map, or a disc's on a map under :data:`DISC_OWN_CELLS` cells; not the map's own cells kept
    for their exact corridors (a point robot's; a disc's on a larger map). Measured at 0.25 s:
    among the aisles of a 1.7-million-cell warehouse (cells of 3 x 3) pooled 1.033 of the
    optimum against the lean 1.054, a 192,000-cell lab with a disc 1.003 against 1.009; on the
    2-million-cell warehouse at 2 s the lean route over the own cells 1.0024, pooled 1.010."""
    if fine.h > model.raster.resolution:
        return True
    return model.robot_radius > 0.0 and fine.n_cells < DISC_OWN_CELLS


#: Pooling keeps a lattice's walls when the coarse cells it blocks wholly hold at least this
#: share of the blocked fine cells (walls about twice the pooling thick, or thicker).
POOLED_WALL_SHARE = 0.5


def _pooling_keeps_walls(free: np.ndarray, k: int) -> bool:
    """Whether pooling ``k`` x ``k`` cells of ``free`` (open when any is free) keeps most of its
    walls (:data:`POOLED_WALL_SHARE`): thin walls vanish in the pooling, and coarse routes
    through them then fail at the fine level."""
    nx, ny = free.shape[0] // k, free.shape[1] // k
    blocked = ~free[: nx * k, : ny * k]
    kept = blocked.reshape(nx, k, ny, k).all(axis=(1, 3)).sum() * k * k
    return bool(kept >= POOLED_WALL_SHARE * blocked.sum())


def _closes_thin_gaps(model, lat: Lattice) -> bool:
    """Whether ``model`` is a map alone with a disc robot narrower than a map cell, and the
    cells of ``lat`` wholly free for it miss a gap one map cell wide: no whole cell of ``lat``
    fits between ``r`` and ``res - r`` across it (``lat`` is aligned with the map's cells)."""
    raster = getattr(model, "raster", None)
    r = model.robot_radius
    if raster is None or not 0.0 < 2.0 * r < raster.resolution or not _map_alone(model):
        return False
    res, h = raster.resolution, lat.h
    if h >= res:
        return True
    first = math.ceil(r / h - 1e-9)  # the first fine line at least r from the wall
    return (first + 1) * h > res - r + 1e-9 * res


def _disc_corridors(model, max_cells, start, goal, alternatives, terminate, t0,
                    stages) -> CorridorResult:  # fmt: skip
    """A disc robot on a map: corridors over the map's own cells, each searched again on cells
    fine enough for the gaps the disc fits through, marked in its band only.

    The lattice of cells wholly free *for the disc* closes a gap one map cell wide (free width
    ``res - 2 r`` for the robot's centre) unless a whole fine cell fits in that width: at a
    quarter of a map cell, not for a radius over a quarter cell. With the radius under half a
    map cell (a *thin* disc), two blocked cells close the way between them exactly when they
    touch (any other pair is a cell apart, more than ``2 r``): the disc's corridors are the
    point robot's, the routes over the map's free cells (a diagonal needs a free cell beside
    it), each searched again on cells of at most half the gap's free width (:data:`THIN_SPLIT`
    at most per map cell, :meth:`MapRaster.thin_free_cells
    <rrtpso_ompl.model.raster.MapRaster.thin_free_cells>`). A wider disc is routed over the map
    cells whose centre keeps its radius (a door's middle cells do), each route searched again
    on cells a quarter of a map cell; with a path in hand, a band only when its box fits the time
    left (one of 970,000 cells begun with 0.05 s left ran 0.08 s over). None for other worlds.
    """
    raster = getattr(model, "raster", None)
    r = model.robot_radius
    if raster is None or not r > 0.0:
        return CorridorResult(None, reason="not a disc on a map")
    coarse = model.lattice(max_cells, split=1)
    point = model.point_free_cells(coarse)
    if point is None or coarse.h != raster.resolution or coarse.nx < 2 or coarse.ny < 2:
        return CorridorResult(None, reason="not a map alone at its own cells")
    if coarse.n_cells > LEAN_CELLS_PER_SECOND * terminate.grace_left():
        return CorridorResult(None, reason="too little time to route over the map's cells")
    thin = 2.0 * r < raster.resolution
    if thin:
        k = min(
            THIN_SPLIT, max(4, math.ceil(2.0 * raster.resolution / (raster.resolution - 2 * r)))
        )
        opened = point
    else:
        k, opened = 4, model.centres_free(coarse)
    # The coarse cells are the map's: their index in the map's cell grid.
    mi = round((coarse.origin[0] - raster.origin[0]) / raster.resolution)
    mj = round((coarse.origin[1] - raster.origin[1]) / raster.resolution)

    def fine_band(r0, r1, c0, c1, mask):
        if quick.path is not None and mask.size * k * k > BOX_CELLS_PER_SECOND * terminate.left():
            raise MarkingStopped  # marking and wrapping its box cannot be stopped midway
        box = Lattice((coarse.origin[0] + r0 * coarse.h, coarse.origin[1] + c0 * coarse.h),
                      coarse.h / k, (r1 - r0) * k, (c1 - c0) * k)  # fmt: skip
        if thin:  # marked in the band's cells only (a diagonal band's box may be most of the map)
            return box, raster.thin_free_cells(mi + r0, mj + c0, mask, k, model.threshold), k
        return box, model.free_cells(box, np.repeat(np.repeat(mask, k, axis=0), k, axis=1)), k

    quick = CorridorResult(None)
    t1 = time.perf_counter()
    if thin:
        # First the shortest route over the map's cells wrapped round its wall corners (cheap:
        # the map's own cells), then, while twice its time is left, the bands' finer searches.
        quick = route_and_funnel(model, coarse, point, start, goal, 0, terminate, t0, stages)
        if quick.path is not None and terminate.left() < 2.0 * (time.perf_counter() - t1):
            return quick
    banded = _corridors(model, coarse, opened, fine_band, start, goal, alternatives, terminate,
                        t0, stages, band_cells=1)  # fmt: skip
    return banded if banded.path is not None and banded.length < quick.length else quick


def _pooled_corridors(model, fine, free, k, start, goal, alternatives, terminate, t0,
                      stages) -> CorridorResult:  # fmt: skip
    """Corridors on the coarse lattice pooling ``k`` x ``k`` fine cells (open when any is wholly
    free: no passage of the fine lattice is closed), each searched again on the fine cells."""
    nx, ny = fine.nx // k, fine.ny // k
    pooled = free[: nx * k, : ny * k].reshape(nx, k, ny, k).any(axis=(1, 3))
    coarse = Lattice(fine.origin, fine.h * k, nx, ny)

    def fine_band(r0, r1, c0, c1, mask):
        i0, i1, j0, j1 = r0 * k, r1 * k, c0 * k, c1 * k
        box = Lattice((fine.origin[0] + i0 * fine.h, fine.origin[1] + j0 * fine.h), fine.h,
                      i1 - i0, j1 - j0)  # fmt: skip
        return box, free[i0:i1, j0:j1], k

    return _corridors(model, coarse, pooled, fine_band, start, goal, alternatives, terminate,
                      t0, stages)  # fmt: skip


def _shape_corridors(model, route_cells, max_cells, start, goal, alternatives, terminate, t0,
                     stages, rate=CELLS_PER_SECOND) -> CorridorResult:  # fmt: skip
    """:func:`search` among shapes: coarse cells open when their centre is free, fine cells
    (:data:`SHAPE_SPLIT` per coarse side) marked in each band's box only."""
    coarse = model.lattice(route_cells)
    if coarse.nx < 2 or coarse.ny < 2:
        return CorridorResult(None, reason="the lattice is too small")
    opened = model.centres_free(coarse)
    stages["cells"] = time.perf_counter() - t0

    def fine_band(r0, r1, c0, c1, mask):
        cells = int(mask.sum())
        # As fine as the time left affords: the band's cells are routed and funnelled too.
        afford = max_cells
        if terminate.end is not None:
            afford = min(afford, rate * max(terminate.end - time.perf_counter(), 0.0))
        k = SHAPE_SPLIT
        while k > 1 and cells * k * k > afford:
            k -= 1
        box = Lattice((coarse.origin[0] + r0 * coarse.h, coarse.origin[1] + c0 * coarse.h),
                      coarse.h / k, (r1 - r0) * k, (c1 - c0) * k)  # fmt: skip
        near = np.repeat(np.repeat(mask, k, axis=0), k, axis=1)
        return box, model.free_cells(box, near), k

    return _corridors(model, coarse, opened, fine_band, start, goal, alternatives, terminate,
                      t0, stages)  # fmt: skip


def _corridors(model, coarse: Lattice, opened, fine_band, start, goal, alternatives, terminate,
               t0, stages, band_cells: float = BAND_CELLS) -> CorridorResult:  # fmt: skip
    """Coarse routes over ``opened``, then the funnel path of the fine route in each one's band
    (``fine_band(r0, r1, c0, c1)`` gives, for a box of coarse cells, its fine lattice, which of
    its cells are wholly free and the fine cells per coarse side); the shortest valid one."""
    nx, ny = coarse.nx, coarse.ny
    ends = _joined_ends(opened, coarse.cell_of(start), coarse.cell_of(goal))
    if ends is None:
        return CorridorResult(None, lattice=coarse, reason="start or goal is not next to "
                              "a free lattice cell joined to the other's")  # fmt: skip
    t1 = time.perf_counter()
    if coarse.n_cells > 0.5 * DIRECT_CELLS_PER_SECOND * terminate.left():
        alternatives = 0  # too little time for them and the bands (a thin disc's coarse cells
        # are the map's)
    apart = max(3.0, ALTERNATIVE_APART * math.hypot(nx, ny))
    routes = alternative_routes(opened, ends[0], ends[1], alternatives, ALTERNATIVE_SLACK, apart)
    reach = _reach(coarse.n_cells, terminate.left)
    if routes and reach:  # corridors told apart by their taut lengths (:mod:`.corner_routes`)
        at = [(cell, coarse.centre(cell)) for cell in ends]
        routes += corner_routes(coarse, opened, at, alternatives, ALTERNATIVE_SLACK, apart, reach)
    routes = _by_taut_length(coarse, opened, routes, ends)
    stages["coarse_route"] = time.perf_counter() - t1
    best = None
    grow = math.ceil(band_cells)
    for route in routes:
        if terminate():
            break
        mask = np.zeros((nx, ny), dtype=bool)
        mask[tuple(np.array(route).T)] = True
        mask = ndimage.binary_dilation(mask, iterations=grow)
        rows, cols = np.nonzero(mask)
        r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
        try:
            box, free, k = fine_band(r0, r1, c0, c1, mask[r0:r1, c0:c1])
            near = np.repeat(np.repeat(mask[r0:r1, c0:c1], k, axis=0), k, axis=1)
            result = route_and_funnel(model, box, free & near, start, goal, 0, terminate, t0,
                                       stages, corner_reach=CORNER_REACH)  # fmt: skip
            if result.path is None and not terminate():
                # The corridor's gaps are narrower than wholly free fine cells: through the
                # centres of the fine cells that are free, every segment checked.
                result = centre_route(model, start, goal, 0, terminate, box, near)
        except MarkingStopped:
            break  # out of time in this corridor: the best of those before it
        # Corridors compared by their taut strings among circles (the funnel's cells distort).
        result = _tautened(model, result, getattr(terminate, "terminate", None))
        if result.path is not None and (best is None or result.length < best.length):
            best = result
    if best is None:
        return CorridorResult(None, lattice=coarse, reason="no route through the lattice")
    return dataclasses.replace(best, routes=len(routes))


def _by_taut_length(lat: Lattice, opened, routes, ends):
    """``routes`` in the order of their taut length through the coarse cells (the funnel between
    the end cells' centres), shortest first: the fine searches go to the likeliest first."""
    if len(routes) < 2:
        return routes
    rects, label = free_rectangles(opened)
    a, b = np.asarray(lat.centre(ends[0])), np.asarray(lat.centre(ends[1]))
    lengths = []
    for route in routes:
        seq = rectangle_channel(channel(route), label)
        path = funnel(a, b, channel_portals(seq, rects, lat, 0.0))
        lengths.append(float(np.hypot(*np.diff(path, axis=0).T).sum()))
    return [routes[i] for i in np.argsort(lengths, kind="stable")]


def _reach(cells: int, left) -> int:
    """The corner lattice's reach for a search over ``cells`` cells with ``left()`` seconds:
    :data:`CORNER_REACH` when it fits (:data:`CORNER_CELLS_PER_SECOND`), else 0 (none)."""
    return CORNER_REACH if cells <= CORNER_CELLS_PER_SECOND * left() else 0


class _Deadline:
    """A termination test: ``terminate()``, or the clock past ``end``; :meth:`grace` the same
    with ``grace_end`` (later) for a step that improves a path already found."""

    def __init__(self, end: float | None, terminate=None) -> None:
        self.end, self.terminate = end, terminate
        self.grace_end = end

    def left(self) -> float:
        """Seconds until ``end`` (infinite without one)."""
        return math.inf if self.end is None else max(self.end - time.perf_counter(), 0.0)

    def grace_left(self) -> float:
        """Seconds until ``grace_end`` (infinite without one)."""
        if self.grace_end is None:
            return math.inf
        return max(self.grace_end - time.perf_counter(), 0.0)

    def grace(self) -> bool:
        return bool(self.terminate is not None and self.terminate()) or (
            self.grace_end is not None and time.perf_counter() >= self.grace_end
        )

    def __call__(self) -> bool:
        return bool(self.terminate is not None and self.terminate()) or (
            self.end is not None and time.perf_counter() >= self.end
        )


def _joined_ends(opened: np.ndarray, s_cell, g_cell, reach: int = 2):
    """Open cells near ``s_cell`` and ``g_cell`` (each itself when open, else within ``reach``,
    Manhattan) that a route joins, nearest first: ``(start's, goal's)``, or None.

    The lattice's routes join exactly the edge-connected open cells (a diagonal or knight's
    move needs the cells beside it), so a component label decides; the nearest open cell alone
    may be a dead end (among 10,000 circles the start's was walled in on a lattice of 70,000
    cells, and the stage found no route at all).
    """
    label, _ = ndimage.label(opened)  # edge-connected
    near = []
    for cell in (s_cell, g_cell):
        i0, j0 = max(cell[0] - reach, 0), max(cell[1] - reach, 0)
        found = np.argwhere(opened[i0 : cell[0] + reach + 1, j0 : cell[1] + reach + 1])
        found += (i0, j0)
        found = found[np.abs(found - cell).sum(axis=1) <= reach]
        near.append(found[np.argsort(np.abs(found - cell).sum(axis=1), kind="stable")])
    best = None
    for a in near[0]:
        for b in near[1]:
            if label[tuple(a)] == label[tuple(b)]:
                cost = np.abs(a - s_cell).sum() + np.abs(b - g_cell).sum()
                if best is None or cost < best[0]:
                    best = (cost, tuple(int(c) for c in a), tuple(int(c) for c in b))
    return None if best is None else best[1:]
