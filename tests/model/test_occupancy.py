"""Occupancy-grid maps: the map_server reader, merged cells, exact checks, bad maps."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from helpers import PROBLEMS, _corridor, _map, _pgm
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from rrtpso_ompl.errors import ProblemError
from rrtpso_ompl.model import World, load_problem, problem_from_dict
from rrtpso_ompl.model.occupancy import OCCUPIED, UNKNOWN, load_map, merge_cells, read_pgm

FREE_STATE = 0


# ----------------------------------------------------------------------------------------------
# The reader
# ----------------------------------------------------------------------------------------------
def test_trinary_thresholds_are_inclusive_and_negate_flips(tmp_path):
    # p = (255 - v) / 255: 0 -> 1.0, 254 -> 0.004, 205 -> 0.19608 (just above 0.196),
    # 160 -> 0.373 (below 100/255 = 0.392)
    img = np.array([[0, 254, 205, 160, 155]], dtype=np.uint8)
    m = load_map(_map(tmp_path, img, occupied_thresh=100 / 255, free_thresh=0.196))
    # 155 gives exactly 100/255: on the occupied threshold, so occupied (>=)
    assert m.state.tolist() == [[OCCUPIED, FREE_STATE, UNKNOWN, UNKNOWN, OCCUPIED]]
    m = load_map(_map(tmp_path, img, name="n", negate=1, free_thresh=50 / 255))
    # negate: p = v / 255; 0 -> free, 254 -> occupied, 205 -> 0.80 occupied, 160 and 155 ->
    # 0.63 and 0.61, unknown
    assert m.state.tolist() == [[FREE_STATE, OCCUPIED, OCCUPIED, UNKNOWN, UNKNOWN]]


def test_ascii_and_16_bit_pgm_read_like_binary(tmp_path):
    img = np.array([[0, 254, 205], [254, 254, 0]], dtype=np.uint8)
    _pgm(tmp_path / "a.pgm", img, binary=False)
    _pgm(tmp_path / "b.pgm", img.astype(np.uint16) * 257, maxval=65535)
    a = load_map(_map(tmp_path, img, name="a", image="a.pgm"))
    b = load_map(_map(tmp_path, img, name="b", image="b.pgm"))
    c = load_map(_map(tmp_path, img, name="c"))
    assert a.state.tolist() == b.state.tolist() == c.state.tolist()
    assert read_pgm(tmp_path / "b.pgm")[1] == 65535


def test_scale_and_raw_modes(tmp_path):
    img = np.array([[0, 254, 150]], dtype=np.uint8)  # 150: p = 0.41, between the thresholds
    scale = load_map(_map(tmp_path, img, mode="scale"))
    assert scale.state.tolist() == [[OCCUPIED, FREE_STATE, UNKNOWN]]
    raw = np.array([[0, 100, 50, 255, 10]], dtype=np.uint8)  # percent; 255 unknown
    m = load_map(_map(tmp_path, raw, name="r", mode="raw", negate=1))  # negate ignored
    assert m.state.tolist() == [[FREE_STATE, OCCUPIED, UNKNOWN, UNKNOWN, FREE_STATE]]


def test_png_colour_is_averaged_and_alpha_below_255_is_unknown(tmp_path):
    rgba = np.zeros((2, 3, 4), dtype=np.uint8)
    rgba[..., 3] = 255
    rgba[0, 0, :3] = (254, 254, 254)  # free
    rgba[0, 1, :3] = (0, 0, 30)  # mean 10: occupied
    rgba[0, 2, :3] = (254, 254, 254)
    rgba[0, 2, 3] = 254  # translucent: unknown
    rgba[1, :, :3] = (255, 255, 0)  # mean 170: p = 0.33, unknown
    Image.fromarray(rgba, "RGBA").save(tmp_path / "c.png")
    m = load_map(_map(tmp_path, None, name="c", image="c.png"))
    assert m.state.tolist() == [[FREE_STATE, OCCUPIED, UNKNOWN], [UNKNOWN] * 3]
    grey = np.array([[0, 254], [254, 0]], dtype=np.uint8)
    Image.fromarray(grey, "L").save(tmp_path / "g.bmp")
    assert load_map(_map(tmp_path, None, name="g", image="g.bmp")).state.tolist() == [
        [OCCUPIED, FREE_STATE],
        [FREE_STATE, OCCUPIED],
    ]


def test_origin_odd_sizes_and_row_zero_on_top(tmp_path):
    img = np.full((5, 7), 254, dtype=np.uint8)
    img[0, 6] = 0  # top-right pixel
    m = load_map(_map(tmp_path, img, origin=[-3.25, 10.0, 0.0]))
    assert m.extent == ((-3.25, 10.0), (-3.25 + 3.5, 12.5))
    assert m.boxes.tolist() == [[-3.25 + 3.0, 12.0, -3.25 + 3.5, 12.5]]
    assert m.cell_box(0, 6) == tuple(m.boxes[0])


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 9), st.integers(1, 9), st.integers(0, 2**31 - 1))
def test_merged_boxes_cover_exactly_the_blocked_cells(h, w, seed):
    blocked = np.random.default_rng(seed).random((h, w)) < 0.45
    boxes = merge_cells(blocked, 0.5, (1.0, -2.0))
    rows, cols = np.nonzero(blocked)
    x0, y0 = 1.0 + cols * 0.5, -2.0 + (h - 1 - rows) * 0.5
    cells = shapely.box(x0, y0, x0 + 0.5, y0 + 0.5)
    union = shapely.union_all(cells)
    mine = shapely.union_all([shapely.box(*b) for b in boxes])
    assert sum((b[2] - b[0]) * (b[3] - b[1]) for b in boxes) == pytest.approx(union.area)
    assert mine.symmetric_difference(union).area == pytest.approx(0.0, abs=1e-12)


# ----------------------------------------------------------------------------------------------
# Exactness against the union of the blocked squares
# ----------------------------------------------------------------------------------------------
def _random_map_world(tmp_path, seed: int, radius: float):
    rng = np.random.default_rng(seed)
    img = np.where(rng.random((30, 40)) < 0.08, 0, 254).astype(np.uint8)
    img[rng.integers(0, 30, 3)] = 0  # a few solid rows: long boxes
    path = _map(tmp_path, img, name=f"w{seed}", resolution=0.25)
    prob = tmp_path / f"p{seed}.yaml"
    prob.write_text(
        f"map: {path}\nstart: [0.0, 0.0]\ngoal: [0.0, 0.0]\nrobot: {{radius: {radius}}}\n"
        "obstacles: []\n"
    )
    m = load_map(path)
    squares = shapely.union_all([shapely.box(*b) for b in m.boxes])
    return m, squares


@pytest.mark.parametrize("radius", [0.0, 0.3])
def test_segment_checks_agree_with_shapely_on_the_blocked_squares(tmp_path, radius):
    m, squares = _random_map_world(tmp_path, 3, radius)
    world = World(m.extent, boxes=m.boxes, robot_radius=radius)
    rng = np.random.default_rng(7)
    (x0, y0), (x1, y1) = m.extent
    a = rng.uniform((x0, y0), (x1, y1), (3000, 2))
    b = a + rng.normal(scale=1.5, size=(3000, 2))
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    d = shapely.distance(lines, squares)
    want = d >= radius if radius > 0 else ~shapely.intersects(lines, squares)
    clear = np.abs(d - radius) > 1e-7  # leave out exact grazes, decided by the tolerance
    got = world.segments_free(a, b)
    scalar = np.array([world.motion_free(*p, *q) for p, q in zip(a, b, strict=True)])
    assert np.array_equal(got[clear], want[clear])
    assert np.array_equal(scalar[clear], want[clear])
    assert want.any() and (~want).any()


# ----------------------------------------------------------------------------------------------
# Problems on maps: loader, bad input, every command
# ----------------------------------------------------------------------------------------------
def test_a_map_problem_takes_bounds_and_units_from_the_map(tmp_path):
    p = load_problem(_corridor(tmp_path))
    assert p.bounds == ((0.0, 0.0), (10.0, 5.0)) and p.units == "m"
    assert p.map.counts()["unknown"] == 6
    free = load_problem(_corridor(tmp_path, map={"file": "corridor.yaml", "unknown": "free"}))
    assert len(free.map_boxes) < len(p.map_boxes)
    # Bounds beyond the map: the outside is unknown space, blocked.
    big = load_problem(_corridor(tmp_path, bounds=[[-5, -5], [15, 10]]))
    assert World.from_problem(big).point_free(-2.0, -2.0) is False


@pytest.mark.parametrize(
    ("change", "key", "words"),
    [
        ({"goal": [5.2, 2.2]}, "goal", "lies in the occupied map cell at image row 5, column 10"),
        ({"start": [0.7, 3.0]}, "start", "overlaps the occupied map cell"),
        ({"goal": [7.5, 4.0]}, "goal", "unknown map cell"),
        ({"map": {"file": "corridor.yaml", "unknown": "maybe"}}, "map.unknown", "obstacle or free"),
        ({"map": "nothere.yaml"}, "", "no such file"),
    ],
)
def test_bad_map_problems_name_the_file_key_and_cell(tmp_path, change, key, words):
    with pytest.raises(ProblemError) as exc:
        load_problem(_corridor(tmp_path, **change))
    assert key in str(exc.value) and words in str(exc.value)


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"P5\n4 4\n255\n\x00", "truncated"),
        (b"P2\n2 2\n255\n0 1 x 3\n", "integers"),
        (b"P5\n99999 99999\n255\n", "more than"),
        (b"\x89PNG\r\n\x1a\nnot really", "cannot read"),
    ],
)
def test_unreadable_images_are_clear_errors(tmp_path, content, words):
    (tmp_path / "m.pgm").write_bytes(content)
    _map(tmp_path, None, image="m.pgm")
    with pytest.raises(ProblemError) as exc:
        load_map(tmp_path / "m.yaml")
    assert "image" in str(exc.value) and words in str(exc.value)


def test_the_library_maps_load_and_the_big_one_stays_small():
    p = load_problem(PROBLEMS / "maps" / "warehouse_aisles.yaml")
    assert p.map.shape == (1700, 1000)
    counts = p.map.counts()
    assert counts["unknown"] > 0 and counts["blocked"] > 100_000
    assert counts["boxes"] < counts["blocked"] / 50  # merged
    for name in ("office_corridor", "lab_clutter"):
        assert load_problem(PROBLEMS / "maps" / f"{name}.yaml").map.counts()["unknown"] > 0


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 2**31 - 1),
    st.sampled_from([0.0, 0.15, 0.4]),
    st.lists(st.tuples(*[st.floats(-0.5, 6.5, allow_nan=False)] * 4), min_size=1, max_size=8),
)
def test_exact_check_agrees_with_shapely_on_random_maps(seed, radius, segments):
    """Hypothesis: random blocked cells at 0.5 m, random segments; the index-backed scalar and
    vectorised checks agree with shapely's distance to the union of the blocked squares."""
    blocked = np.random.default_rng(seed).random((12, 12)) < 0.2
    boxes = merge_cells(blocked, 0.5, (0.0, 0.0))
    if not len(boxes):
        return
    world = World(((0.0, 0.0), (6.0, 6.0)), boxes=boxes, robot_radius=radius)
    union = shapely.union_all([shapely.box(*b) for b in boxes])
    a = np.array([s[:2] for s in segments])
    b = np.array([s[2:] for s in segments])
    d = shapely.distance(shapely.linestrings(np.stack([a, b], axis=1)), union)
    want = d >= radius if radius > 0 else ~shapely.intersects(
        shapely.linestrings(np.stack([a, b], axis=1)), union)  # fmt: skip
    clear = np.abs(d - radius) > 1e-7
    got = world.segments_free(a, b)
    scalar = np.array([world.motion_free(*p, *q) for p, q in zip(a, b, strict=True)])
    assert np.array_equal(got[clear], want[clear])
    assert np.array_equal(scalar[clear], want[clear])


# ----------------------------------------------------------------------------------------------
# Values that would be read as something else (issue 22)
# ----------------------------------------------------------------------------------------------
def test_pgm_pixel_values_outside_0_to_maxval_are_refused(tmp_path):
    # "-1" once read as 255 (free): a wall drawn with -1 vanished without a word.
    (tmp_path / "neg.pgm").write_text("P2\n2 2\n255\n0 -1\n255 255\n")
    with pytest.raises(ValueError, match=r"pixel 1 \(row 0, column 1\) is -1"):
        read_pgm(tmp_path / "neg.pgm")
    (tmp_path / "big.pgm").write_text("P2\n2 2\n100\n0 1\n101 2\n")
    with pytest.raises(ValueError, match="exceeds maxval 100"):
        read_pgm(tmp_path / "big.pgm")


def _map_text(tmp_path, resolution: str) -> str:
    """A 4 x 4 free map whose resolution is written as given (JSON would write 1e-09, which
    YAML 1.1 reads as text)."""
    _pgm(tmp_path / "m.pgm", np.full((4, 4), 254, dtype=np.uint8))
    (tmp_path / "m.yaml").write_text(f"image: m.pgm\nresolution: {resolution}\norigin: [0, 0, 0]\n")
    return str(tmp_path / "m.yaml")


@pytest.mark.parametrize(
    ("resolution", "words"),
    [
        ("1.0e+12", "resolution: must be at most 1e+09 (the largest length"),
        ("1.0e+9", "4 cells of 1e+09 from origin 0 reach x = 4e+09, beyond +-1e+09"),
        ("1e-3", "(YAML reads 1e-3 as text, not a number: write 0.001)"),
        ("0", "resolution: must be > 0"),
    ],
    ids=["too-large", "extent", "yaml-text", "zero"],
)
def test_a_resolution_out_of_range_says_why(tmp_path, resolution, words):
    with pytest.raises(ProblemError) as exc:
        load_map(_map_text(tmp_path, resolution))
    assert words in str(exc.value)


def test_a_map_too_fine_for_its_bounds_is_refused_at_the_documented_minimum(tmp_path):
    """1e-9 m cells give a 4e-9 m map: under the smallest side a workspace may have (1e-6), and
    RRTstarPSO then reported "exact" one cell short of the goal."""
    _map_text(tmp_path, "1.0e-9")
    doc = {"map": "m.yaml", "start": [5e-10, 5e-10], "goal": [3.5e-9, 3.5e-9],
           "robot": {"radius": 0}}  # fmt: skip
    with pytest.raises(ProblemError) as exc:
        problem_from_dict(doc, str(tmp_path / "p.yaml"))
    assert exc.value.key == "map" and "each must be at least 1e-06" in str(exc.value)
    # With bounds of a plannable size the same fine map is fine.
    doc["bounds"] = [[0, 0], [1e-6, 1e-6]]
    assert problem_from_dict(doc, str(tmp_path / "p.yaml")).map.resolution == 1e-9


def test_a_denormal_segment_is_measured_without_overflow_warnings():
    """The case hypothesis found: a segment 2e-313 long, its ends numpy scalars. Its direction
    divides to inf, which the clipping handles; numpy scalars warned of an overflow."""
    import warnings

    from rrtpso_ompl.model.geometry import segment_box_distance_xy

    a = np.float64(0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = segment_box_distance_xy(a, a, a, np.float64(2.2250738585e-313), -1.0, 1.0, 1.0, 2.0)
    assert d == pytest.approx(1.0)
