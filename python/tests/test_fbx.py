"""FBX input from Python: ``Retargeter.retarget_fbx`` and the GMR shim's FBX loader, on our
fixtures (``crates/fbx/tests/data``) and the shared files (the CLI's numbers)."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

import retarget
from retarget.gmr import load_fbx_file, load_optitrack_fbx_motion_file


@pytest.fixture(scope="session")
def fixtures(root):
    return root / "crates/fbx/tests/data"


def test_a_take_by_name_index_or_the_most_motion(fixtures):
    r = retarget.Retargeter("unitree_g1")
    clip = fixtures / "mixamo_zup_7400_ascii.fbx"
    walk = r.retarget_fbx(clip)
    assert len(walk) == 61 and walk.inferred.startswith("take `walk` (the most motion of 2 takes)")
    idle = r.retarget_fbx(clip, take="idle")
    assert len(idle) == 31 and "take `idle` (asked for)" in idle.inferred
    assert np.array_equal(r.retarget_fbx(clip, take=0).qpos, idle.qpos)
    with pytest.raises(retarget.RetargetError, match=r"unknown take `run`; the file's takes: 0 `idle`, 1 `walk`"):
        r.retarget_fbx(clip, take="run")
    with pytest.raises(TypeError, match="take"):
        r.retarget_fbx(clip, take=1.5)
    with pytest.raises(FileNotFoundError):
        r.retarget_fbx(fixtures / "missing.fbx")
    with pytest.raises(retarget.RetargetError, match="no_animation_7400_ascii.fbx: no animation"):
        r.retarget_fbx(fixtures / "no_animation_7400_ascii.fbx")


def test_gmr_loader_gives_world_poses_in_metres_z_up(fixtures):
    clip = fixtures / "mixamo_zup_7400_ascii.fbx"
    frames = load_optitrack_fbx_motion_file(clip)
    same, fps = load_fbx_file(clip, take="walk")
    assert fps == 30.0 and len(frames) == len(same) == 61
    for k, frame in enumerate(frames):
        position, quat = frame["mixamorig:Hips"]
        t = k / 30.0
        # The walk's hips (generate.py): forward along -Y at 1 m/s, 1 m up, linear keys.
        key = lambda i: np.array([0.0, -i * 0.1, 1.0 + 0.02 * math.sin(2 * math.pi * i * 0.1)])
        i, a = math.floor(t / 0.1 + 1e-9), t / 0.1 - math.floor(t / 0.1 + 1e-9)
        assert np.allclose(position, key(i) * (1 - a) + key(i + 1) * a, atol=1e-9), k
        assert quat.shape == (4,) and abs(np.linalg.norm(quat) - 1) < 1e-12
    assert "LeftFootMod" not in frames[0], "the file's joints only"
    idle, _ = load_fbx_file(clip, take=0)
    assert len(idle) == 31


def test_python_equals_the_cli_on_a_shared_file(tmp_path, shared, cli):
    fbx = shared / "data/fbx/ufbx_kenney_character_maya2023.fbx"
    out = tmp_path / "kenney.npz"
    subprocess.run([str(cli), "--fbx", str(fbx), "--robot", "booster_t1_29dof", "-o", str(out)], check=True, capture_output=True)
    motion = retarget.Retargeter("booster_t1_29dof").retarget_fbx(fbx)
    assert np.array_equal(np.load(out)["qpos"], motion.qpos)
    rows = retarget.batch([fbx], "unitree_g1", tmp_path / "batch")
    assert rows[0]["frames"] == 21 and rows[0]["inferred"].startswith("take `Take 001`")
