"""The Python package gives exactly what the CLI writes: same solver, same writers."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import retarget


@pytest.fixture(scope="module")
def walk_outputs(tmp_path_factory, cli, walk):
    out = tmp_path_factory.mktemp("walk")
    subprocess.run([str(cli), "--bvh", str(walk), "--robot", "unitree_g1", "-o", str(out / "cli.npz")],
                   check=True, capture_output=True)
    motion = retarget.Retargeter("unitree_g1").retarget_bvh(walk)
    motion.save(out / "py.npz")
    return np.load(out / "cli.npz"), motion, np.load(out / "py.npz")


def test_bvh_motion_equals_the_clis_npz(walk_outputs):
    cli, motion, saved = walk_outputs
    arrays = motion.to_dict()
    assert sorted(arrays) == sorted(cli.files)
    for key in cli.files:
        assert arrays[key].dtype == cli[key].dtype, key
        assert arrays[key].shape == cli[key].shape, key
        assert np.array_equal(arrays[key], cli[key]), key
        assert np.array_equal(saved[key], cli[key]), key
    for key in ("qpos", "joint_pos", "joint_vel", "body_pos_w", "body_quat_w", "body_lin_vel_w",
                "body_ang_vel_w", "target_pos", "target_quat", "contact_left", "contact_right"):
        assert np.array_equal(getattr(motion, key), cli[key]), key
    assert motion.fps == cli["fps"][0]
    assert motion.joint_names == list(cli["joint_names"])
    assert motion.body_names == list(cli["body_names"])
    assert motion.target_body_names == list(cli["target_body_names"])
    assert motion.robot == str(cli["robot"])
    assert len(motion) == cli["qpos"].shape[0] == 7184


def test_arrays_are_read_only_views(walk_outputs):
    _, motion, _ = walk_outputs
    qpos = motion.qpos
    assert not qpos.flags.writeable
    assert qpos is motion.qpos or np.shares_memory(qpos, motion.qpos)
    with pytest.raises(ValueError):
        qpos[0, 0] = 1.0
    assert "config configs/gmr/bvh_lafan1_to_g1.json" in motion.inferred
    reweigh = motion.stages["reweigh"]  # GMR's G1 config holds the pelvis under the legs
    offset, share = reweigh["pelvis_offset"], reweigh["share"]
    assert 0.01 < offset < 0.03 and share > 0.5, motion.stages
    height, source = motion.human_height
    assert 1.6 < height < 1.9 and source


def test_c3d_and_every_format_equal_the_cli(tmp_path, cli, shared, root):
    c3d = shared / "data/c3d/c3dorg_s00_Vicon_pyCGM2_Walking01.c3d"
    config = root / "configs/c3d_plugingait_to_unitree_g1.json"
    motion = retarget.Retargeter("unitree_g1").retarget_c3d(c3d, config)
    assert len(motion) == 493
    for ext in ("npz", "csv", "pkl", "json"):
        subprocess.run([str(cli), "--c3d", str(c3d), "--config", str(config), "--robot", "unitree_g1",
                        "-o", str(tmp_path / f"cli.{ext}")], check=True, capture_output=True)
        motion.save(tmp_path / f"py.{ext}")
        assert (tmp_path / f"py.{ext}").read_bytes() == (tmp_path / f"cli.{ext}").read_bytes(), ext
    motion.save(tmp_path / "named", format="csv")
    assert (tmp_path / "named").read_bytes() == (tmp_path / "cli.csv").read_bytes()


def test_report_is_the_clis(tmp_path, cli, walk_outputs):
    _, motion, _ = walk_outputs
    report = retarget.report(motion)
    assert report["frames"] == 7184 and report["robot"] == "unitree_g1"
    motion.save(tmp_path / "walk.npz")
    subprocess.run([str(cli), "report", str(tmp_path / "walk.npz"), "--json", str(tmp_path / "r.json")],
                   check=True, capture_output=True)
    import json
    expected = json.loads((tmp_path / "r.json").read_text())
    assert report["joint_limits"] == expected["joint_limits"]
    assert report["ground_penetration"] == expected["ground_penetration"]
    assert report["self_collision"] == expected["self_collision"]
    # Motion over time (issue 30): the root's acceleration and its target's, jitter over nv,
    # the dynamics check.
    for key in ("root_acceleration", "jitter", "dynamics", "dynamics_unavailable"):
        assert report[key] == expected[key], key
    assert report["root_acceleration"]["target"]["mean_mps2"] > 0
    assert report["jitter"]["coordinates"] == 35 and report["dynamics"]["frames"] == 7180
