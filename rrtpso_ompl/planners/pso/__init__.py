"""The particle swarm of the paper (eqs. 4-5) and the swarm over a path's waypoints.

- :mod:`.swarm`: :func:`minimize`, a vectorised swarm over any cost (no OMPL, no geometry);
- :mod:`.path_optimizer`: :func:`optimize_path`, the swarm moving a path's interior waypoints,
  every candidate exactly collision-checked, never returning a longer or invalid path.

Used by RRTstarPSO, the PSO baseline and the ``+pso`` post-pass of any planner.
"""
