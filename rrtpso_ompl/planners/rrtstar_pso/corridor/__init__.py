"""The corridor stage of RRTstarPSO: which way round the obstacles, decided before RRT* grows.

A sampling planner commits to a corridor (a homotopy class) by chance: its first path goes through
whichever door, aisle or gap its tree happened to cross first, and a local optimiser such as the
swarm can shorten a path but never move it to another corridor. This stage looks at every
corridor at once, at the resolution of a lattice:

1. **Lattice.** Square cells over the workspace (about ``max_cells`` of them; aligned with an
   occupancy map's own cells), each marked free when the robot's centre may be *anywhere* in it
   (:meth:`~rrtpso_ompl.model.World.free_cells`: exact for maps, conservative for circles and
   polygons; through the validity checker otherwise).
2. **Route.** Dijkstra's algorithm over the free cells, 16-connected (the 8 neighbours and the
   knight's moves, so a route deviates from a straight line by at most 2.7 % in length), from the
   start's cell to the goal's. A diagonal or knight's move needs the cells it passes free, so
   consecutive cells of a route always share an edge once the passed cells are inserted.
3. **Funnel.** The route's cells form a channel, a strip of squares each sharing an edge (a
   *portal*) with the next; the shortest path from start to goal inside the channel is found in
   one pass by the funnel algorithm (Lee and Preparata 1984; Mononen's "simple stupid funnel").
   It bends only at portal end points, the corners of the channel, exactly where a taut string
   would: on a map with 1-cell corridors it is the exact shortest path within 1e-4.

4. **Taut lengths decide.** The cell lattice rates a corridor by its staircase of cell moves: along
   one-cell corridors a diagonal costs as two axis moves, so of many corridors of nearly equal
   lattice length (aisles between racks, crossed diagonally) it cannot tell which the taut
   string makes shortest. Where the time affords, the routes of a second lattice are added, over
   the cells' *corners* with moves up to four cells in any of 48 directions
   (:mod:`.corner_routes`: within 0.8 % of any straight line however narrow the corridor),
   searched over the cells of the routes within 15 % of the shortest; every route is funnelled
   and the shortest checked path wins.
5. **A disc narrower than a map cell.** The cells wholly free for the disc close every gap one
   map cell wide once the disc is wider than a quarter cell. With the radius under half a cell,
   two blocked cells close the way between them exactly when they touch, so the corridors are
   the point robot's: routes over the map's free cells, each searched again on cells fine enough
   for the gap (:func:`.search._disc_corridors`) and wrapped round the wall corners.
6. **Among circles, the taut string.** Wholly free cells keep up to a cell off every circle;
   each corridor's path becomes the shortest path passing every circle on the same side
   (:mod:`.taut`), and corridors are compared by it. Among circles alone the string needs only
   the side a route passes each circle: the stage first pulls taut the shortest route over the
   free cell centres of a lattice as fine as its time affords, without bands
   (:func:`.search._taut_routes`); the bands take over when that gives no string.

The path stays inside cells that are wholly free, so it is valid without further checks; it is
checked once anyway (exactly, or through the user's checker, whose lattice answers are not
conservative). Its cost is a few array operations and one sparse-graph search: milliseconds on a
map of 65,000 cells.

The stage's rooms: :mod:`.search` (the orchestration within the time), :mod:`.paths` (one
search on one lattice), :mod:`.routes` (routes on the lattice of free cells), :mod:`.funnel`
(the taut path in a channel), :mod:`.corners` (a disc robot round wall corners),
:mod:`.corner_routes` (routes between cell corners, near their taut length); the graph over the
cells is :mod:`rrtpso_ompl.model.grid_graph`'s.
"""

from .corner_routes import CORNER_BAND_SLACK, CORNER_CELLS_PER_SECOND, CORNER_REACH
from .funnel import free_rectangles, funnel
from .paths import CENTRE_ROUTE_ROUNDS, CorridorResult, centre_route, corridor_path
from .routes import (
    ALTERNATIVE_APART,
    ALTERNATIVE_SLACK,
    alternative_routes,
    band,
    channel,
    lattice_graph,
    lattice_route,
)
from .search import (
    BAND_CELLS,
    CELLS_PER_SECOND,
    CENTRE_CELLS_PER_SECOND,
    DIRECT_CELLS_PER_SECOND,
    LEAN_CELLS_PER_SECOND,
    REPRODUCIBLE_CORRIDOR_CELLS,
    SHAPE_BAND_SHARE,
    SHAPE_SPLIT,
    THIN_SPLIT,
    find_corridor_path,
)
from .taut import circles_alone

__all__ = [
    "ALTERNATIVE_APART",
    "ALTERNATIVE_SLACK",
    "BAND_CELLS",
    "CELLS_PER_SECOND",
    "CENTRE_CELLS_PER_SECOND",
    "CENTRE_ROUTE_ROUNDS",
    "CORNER_BAND_SLACK",
    "CORNER_CELLS_PER_SECOND",
    "CORNER_REACH",
    "DIRECT_CELLS_PER_SECOND",
    "LEAN_CELLS_PER_SECOND",
    "REPRODUCIBLE_CORRIDOR_CELLS",
    "SHAPE_BAND_SHARE",
    "SHAPE_SPLIT",
    "THIN_SPLIT",
    "CorridorResult",
    "alternative_routes",
    "band",
    "centre_route",
    "channel",
    "circles_alone",
    "corridor_path",
    "find_corridor_path",
    "free_rectangles",
    "funnel",
    "lattice_graph",
    "lattice_route",
]
