r"""The exact shortest path for a disc robot among circles, polygons and map cells (the reference
optimum).

The robot is a disc of radius ``R`` whose centre must stay in the bounds. In its configuration
space every obstacle grows by ``R``: a circle of radius ``r`` becomes a circle of radius ``r + R``
and a polygon (a box, a map's blocked cells) becomes the polygon with rounded corners, each convex
corner the centre of a circle of radius ``R``. A shortest path in such a space consists of straight
segments tangent to these circles and arcs along them (the tangent or "reduced visibility" graph;
LaValle, *Planning Algorithms*, 2006, section 6.2.4; Latombe 1991 for the polygonal case):

1. **Circles**: the start and the goal (radius 0), every obstacle circle (``r + R``), every convex
   vertex of a polygon and every convex corner of the union of the boxes (``R``). When the boxes
   lie on one lattice (a map's merged cells), the corners come straight from the cells: the grid
   points where exactly one of the four cells around is blocked. A vertex's circle carries its
   *cone*: a path wraps it only between the outward normals of its two edges (a quarter circle
   at a map corner), elsewhere it would enter an edge's offset. The cone's ends belong to it,
   with room for round-off: a path along an edge leaves and reaches its vertices exactly there.
2. **A\* over tangents, built as it goes.** A node is a tangent point on a circle and the sense
   (clockwise or counter-clockwise) in which the path wraps that circle; from it the path follows
   the circle in that sense and leaves along a common tangent (two outer and two inner per pair of
   circles) to another circle. An edge (arc, then tangent) is kept when the arc and the tangent
   segment are free: exact distances to the candidate obstacles the spatial index names, the
   bounds for the arc's extreme points (no test where nothing else is near the circle).
3. **A conservative raster** (:mod:`.free_grid`): the cells that may hold a free configuration,
   a superset of the free space. Breadth-first step counts over them from the start's cell and
   the goal's give *geodesic lower bounds* (a maze's corridors, not the straight line), used as
   A\*'s heuristic and for pruning; they also prove a problem unsolvable when the goal's cell is
   not reached. A raster that went into blocks of cells for its size alone is searched again
   cell by cell when the point's path (below) shows that the blocks lost the map's walls. On a
   map of narrow corridors, where a disc's gates between cells are short,
   the bound through those gates (:mod:`..gates`: within a few percent of a disc's path in
   one-cell corridors, where the raster's is a fifth short) is the larger one. The heuristic is
   admissible but not consistent, so a node whose cost improves after its expansion is expanded
   again; A\* with an admissible heuristic and re-expansion returns the optimum.
4. **Pruning that keeps exactness.** The search runs in rounds of growing bounds ``C`` (multiples
   of the lower bound at the start): a circle that no path within ``C`` can touch (the geodesic
   ellipse ``LB_start + LB_goal <= C``) is never a candidate, nor is a tangent that no path within
   ``C`` can use; a round that finds nothing proves the optimum longer than its bound, and the next
   looks further. On a map alone without the gates, the point's shortest path between the query's
   points (the interval search below) bounds the disc's from below and proves it unsolvable when
   there is none; its length plus ``R`` times its turning, a guess within 4 % of the disc's
   optimum on the mazes measured, places the first round's bound (a guess can cost a round,
   never the answer). A tangent
   is free or not whatever node leaves along it, so each circle's free tangents are found once, for
   a batch of circles at a time (those A\* will likely expand next), through filters that each drop
   only what could not be used, cheapest first: circle pairs beyond the bound (a batch meets only
   the circles, sorted by their bound to the goal, that leave room for a path through it; on a
   map's cells alone, only the centres within reach of straight runs from its own, :mod:`.sight`);
   pairs whose step counts differ by more than a free segment between them allows (the counts
   change by at most a step per cell along a free segment); directions outside the cones; pairs in
   the shadow of the discs near the first circle; tangents beyond the bound; then the exact tests
   (obstacles near the circle first, then the world's), with the raster's sound rejection (a sample
   in a cell where nothing is free) in between on maps.
5. **Dominance.** Where a circle's arc is free, a node reached at no more cost earlier on the
   arc, in the same sense, covers a later one: the later one is not expanded.

Every edge is a piece of a valid path (touching an obstacle is allowed, as everywhere in this
package), so the result is never shorter than the true optimum; and the true optimum is a path of
this graph, which the search covers within its final bound, so the result is exact up to
floating-point round-off. The box bounds add no circles: from inside, the box is convex, and so is
every corner where an obstacle meets it, and a shortest path bends only around corners that are
convex seen from the obstacle.

The free configuration space is closed (touching allowed). For a point robot (``R = 0``) a path
grazing a polygon corner would touch it with zero clearance, which the package's segment test
counts as entering; the corners are therefore rounded with a radius of twice the touch tolerance
(``2e-9`` of the workspace size), which changes the length by less than that. Two map cells that
touch only at a corner therefore close the diagonal between them.

A turned map (its cells squares of a :class:`~rrtpso_ompl.model.geometry.GridFrame`) is solved
in its grid coordinates when every free configuration lies in the map's rectangle (unknown space
blocks and the map lies in the bounds: the frame's ``confined``): there the rectangle is the
bounds, the cells keep their lattice, and the circles and polygons turn with the query; a
rotation keeps lengths, and the pieces of the path turn back. Otherwise the turned cells become
polygons in the world's coordinates: as exact, slower on large maps (no lattice).

**A point robot on a map alone** (no circles or polygons, no goal disc) is searched without the
tangent graph, whose size grows with the wall corners (183,000 on a 1024 x 1024 maze of one-cell
corridors, which it did not finish in 300 s): A* over intervals of a mesh of the free cells'
rectangles, in the manner of Polyanya (:mod:`.intervals`, :mod:`.mesh`), and the path it finds
redrawn round the rounded corners; the same answers to 4e-15 on the benchmarks' map queries.

Nothing here imports OMPL: :func:`shortest_path_in_world` needs only a
:class:`~rrtpso_ompl.model.World` and a query.

The package's rooms: :mod:`.query` (the entry points and the rounds), :mod:`.result` (pieces
and results), :mod:`.circles` (step 1), :mod:`.search` (A*, steps 2 and 5), :mod:`.graph` (the
free tangents of step 4, found as A* asks), :mod:`.shadows` (the shadow filter), :mod:`.sight`
(the reach of straight runs on a map), the geometry
of :mod:`.tangents` and :mod:`.arcs`, and for a point robot on a map :mod:`.mesh` and
:mod:`.intervals`. The names below are imported on first use
(:mod:`rrtpso_ompl.lazy`).
"""

from ...lazy import export_lazily

__all__ = [
    "MAX_NODES",
    "OptimumResult",
    "OptimumTooLarge",
    "Piece",
    "shortest_path",
    "shortest_path_in_world",
]

export_lazily(
    __name__,
    {
        "MAX_NODES": ".result",
        "OptimumResult": ".result",
        "OptimumTooLarge": ".result",
        "Piece": ".result",
        "shortest_path": ".query",
        "shortest_path_in_world": ".query",
    },
)
