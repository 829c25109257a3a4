"""SMPL-X and SMPL+H input from Python (issue 31), on the synthetic body models and AMASS-layout
motions of ``reference/smpl``: ``Retargeter.retarget_smplx`` equals the CLI's output, arrays
equal files, and the ``retarget.gmr`` shim's SMPL-X loader returns GMR's human data."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import retarget
from retarget.gmr import GeneralMotionRetargeting as GMR
from retarget.gmr import get_smplx_data_offline_fast, load_smplx_file


@pytest.fixture(scope="module")
def smpl(shared):
    return shared / "reference/smpl"


def test_file_equals_cli_and_arrays_equal_file(smpl, cli, tmp_path):
    walk = smpl / "motions/smplh_walk_poses.npz"
    models = smpl / "body_models"
    r = retarget.Retargeter("unitree_g1")
    motion = r.retarget_smplx(walk, body_model=models)
    assert "SMPL+H body model" in motion.inferred and "configs/gmr/smplx_to_g1.json" in motion.inferred
    out = tmp_path / "walk.npz"
    subprocess.run([str(cli), "--smplx", str(walk), "--robot", "unitree_g1", "--body-model",
                    str(models), "-o", str(out)], check=True, capture_output=True)
    assert np.array_equal(np.load(out)["qpos"], motion.qpos)
    data = np.load(walk)
    arrays = r.retarget_smplx(body_model=models, poses=data["poses"], trans=data["trans"],
                              betas=data["betas"], fps=float(data["mocap_framerate"]),
                              gender="neutral")
    assert np.array_equal(arrays.qpos, motion.qpos)
    with pytest.raises(retarget.RetargetError, match="no SMPL-X body model"):
        r.retarget_smplx(smpl / "motions/smplx_walk_stageii.npz", body_model=tmp_path)
    with pytest.raises(ValueError, match="165"):
        r.retarget_smplx(body_model=models, poses=np.zeros((3, 10)), trans=np.zeros((3, 3)), fps=30)


def test_gmr_shim_loads_what_gmr_loads_and_solves_as_gmr(smpl):
    ref = np.load(smpl / "gmr_outputs/gmr_unitree_g1_smplx_walk.npz")
    data, body_model, output, height = load_smplx_file(smpl / "motions/smplx_walk_stageii.npz",
                                                       smpl / "body_models")
    assert height == pytest.approx(float(ref["human_height"]))
    assert body_model.gender == "neutral" and data["poses"].shape == (7197, 165)
    frames, fps = get_smplx_data_offline_fast(data, body_model, output, tgt_fps=30)
    assert fps == pytest.approx(float(ref["fps"]), abs=1e-12)
    assert len(frames) == ref["human_pos"].shape[0]
    names = list(ref["joint_names"])
    assert list(frames[0]) == names
    pos = np.array([[f[n][0] for n in names] for f in frames])
    assert np.abs(pos - ref["human_pos"]).max() < 1e-5
    gmr = GMR(src_human="smplx", tgt_robot="unitree_g1", actual_human_height=height)
    qpos = np.array([gmr.retarget(frames[i]) for i in range(1, 301)])
    assert np.abs(qpos - ref["qpos"][:300]).max() < 1e-5
