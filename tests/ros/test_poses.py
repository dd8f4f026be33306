import numpy as np
import pytest

from rrtpso_ompl.ros.poses import dense_poses


def test_poses_are_no_farther_apart_than_the_resolution_and_keep_every_waypoint():
    path = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 0.0], [3.0, 4.1], [0.2, 4.1]])
    poses = dense_poses(path, 0.25)
    gaps = np.hypot(*np.diff(poses.xy, axis=0).T)
    assert gaps.max() <= 0.25 + 1e-12
    assert gaps.min() > 0.0
    for w in path:
        assert np.hypot(*(poses.xy - w).T).min() < 1e-12
    # Each pose faces along its segment; the last keeps the last segment's heading.
    assert poses.yaw[0] == 0.0
    assert poses.yaw[-1] == pytest.approx(np.pi)
    on_second = (poses.xy[:, 0] == 3.0) & (poses.xy[:, 1] < 4.1)
    assert np.allclose(poses.yaw[on_second][1:], np.pi / 2)


def test_a_goal_heading_turns_the_last_pose_only():
    poses = dense_poses([[0, 0], [1, 0]], 0.1, goal_yaw=0.5)
    assert len(poses) == 11
    assert poses.yaw[-1] == 0.5
    assert np.all(poses.yaw[:-1] == 0.0)


def test_the_pose_count_is_bounded():
    with pytest.raises(ValueError, match="exceed the bound"):
        dense_poses([[0, 0], [1e6, 0]], 1e-3)
    with pytest.raises(ValueError, match="positive"):
        dense_poses([[0, 0], [1, 0]], 0.0)


@pytest.mark.parametrize("frame_id", ["map", "my frame: x", "f" * 90])
def test_the_nav_path_yaml_is_what_pyyaml_writes_character_for_character(frame_id):
    """``--path-out``'s YAML is written directly (PyYAML took 8 s for 17,940 poses): it must be
    the very text ``yaml.safe_dump`` writes, for tiny, huge, negative-zero and ordinary
    coordinates, any heading, a frame that needs quoting, a stamp with nanoseconds, and no pose."""
    import yaml

    from rrtpso_ompl.ros.nav_path import nav_path, nav_path_yaml
    from rrtpso_ompl.ros.poses import Poses

    rng = np.random.default_rng(7)
    for scale in (1e-8, 1.0, 1e7):
        xy = rng.standard_normal((50, 2)) * scale
        xy[0] = (-0.0, 1e-300)
        doc = nav_path(Poses(xy=xy, yaw=rng.uniform(-4.0, 4.0, 50)), frame_id, 12.345678)
        assert nav_path_yaml(doc) == yaml.safe_dump(doc, sort_keys=False, default_flow_style=None)
    empty = nav_path(Poses(xy=np.zeros((0, 2)), yaw=np.zeros(0)), frame_id)
    assert nav_path_yaml(empty) == yaml.safe_dump(empty, sort_keys=False, default_flow_style=None)
