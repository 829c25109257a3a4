"""``retarget.gmr`` reproduces GMR on the shared LAFAN1 walk (GMR 62ecdff's own output, see
``reference/gmr_outputs/README.md``): qpos to 1e-6 rad on every frame, as the Rust parity
test, and the targets GMR tracked (``scaled_human_data``) to 1e-9."""

from __future__ import annotations

import numpy as np
import pytest

from retarget.gmr import GeneralMotionRetargeting as GMR
from retarget.gmr import load_bvh_file


@pytest.fixture(scope="module")
def reference(shared):
    return np.load(shared / "reference/gmr_outputs/unitree_g1_lafan1_walk.npz")


@pytest.fixture(scope="module")
def loaded(shared):
    return load_bvh_file(shared / "data/bvh/lafan1_take_via_bvhtools_test.bvh", format="lafan1")


def test_loader_returns_what_gmrs_returns(loaded):
    frames, height = loaded
    assert height == 1.75
    assert isinstance(frames, list) and len(frames) == 7184
    frame = frames[0]
    assert isinstance(frame, dict)
    names = list(frame)
    # The file's joints in order (no End Sites), then GMR's two foot bodies.
    assert names[:5] == ["Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToe"]
    assert names[-2:] == ["LeftFootMod", "RightFootMod"] and len(names) == 22 + 2
    pos, quat = frame["Hips"]
    assert isinstance(frame["Hips"], list)
    assert pos.shape == (3,) and quat.shape == (4,) and pos.dtype == np.float64
    assert abs(np.linalg.norm(quat) - 1.0) < 1e-12
    # LeftFootMod: LeftFoot's position, LeftToe's orientation.
    assert np.array_equal(frame["LeftFootMod"][0], frame["LeftFoot"][0])
    assert np.array_equal(frame["LeftFootMod"][1], frame["LeftToe"][1])
    # Metres, Z up: the hips about a metre above the feet.
    assert 0.7 < pos[2] - frame["LeftFoot"][0][2] < 1.1
    with pytest.raises(ValueError, match="Invalid format"):
        load_bvh_file("whatever.bvh", format="fbx")


def test_soma_loader_is_gmr_pr169s(shared):
    # GMR pull request #169's SOMA loader (BONES-SEED; not merged in GMR): 1.70 m, no foot bodies.
    frames, height = load_bvh_file(shared / "data/soma/Neutral_walk_forward_002__A057.bvh", format="soma")
    assert height == 1.70 and len(frames) == 1088
    names = list(frames[0])
    assert "LeftFootMod" not in names and "LeftShin" in names and names[0] == "Root"
    hips, foot = frames[0]["Hips"][0], frames[0]["LeftFoot"][0]
    assert 0.7 < hips[2] - foot[2] < 1.1  # metres, Z up


def test_retarget_reproduces_gmrs_output(loaded, reference):
    frames, height = loaded
    gmr = GMR(src_human="bvh_lafan1", tgt_robot="unitree_g1", actual_human_height=height)
    human_names = list(reference["human_body_names"])
    qpos, target_pos, target_quat = [], [], []
    for frame in frames:
        q = gmr.retarget(frame)
        assert isinstance(q, np.ndarray) and q.shape == (36,)
        qpos.append(q)
        scaled = gmr.scaled_human_data
        target_pos.append([scaled[h][0] for h in human_names])
        target_quat.append([scaled[h][1] for h in human_names])
    qpos = np.array(qpos)
    assert qpos.shape == reference["qpos"].shape
    worst = np.abs(qpos - reference["qpos"]).max()
    print(f"GMR shim: max |qpos - GMR| = {worst:.3e} rad over {len(frames)} frames")
    assert worst <= 1e-6
    assert np.abs(np.array(target_pos) - reference["targets_pos"]).max() <= 1e-9
    quat = np.array(target_quat)
    same = np.abs(quat - reference["targets_quat"]).max(axis=-1)
    flipped = np.abs(quat + reference["targets_quat"]).max(axis=-1)
    assert np.minimum(same, flipped).max() <= 1e-9


def test_gmrs_attributes_and_refusals():
    gmr = GMR(src_human="bvh_lafan1", tgt_robot="unitree_g1", actual_human_height=1.75 * 1.1)
    assert gmr.human_root_name == "Hips" and gmr.robot_root_name == "pelvis"
    assert set(gmr.ik_match_table1) >= {"pelvis", "left_ankle_roll_link"}
    unscaled = GMR(src_human="bvh_lafan1", tgt_robot="unitree_g1", actual_human_height=1.75)
    for body, scale in gmr.human_scale_table.items():
        assert scale == pytest.approx(unscaled.human_scale_table[body] * 1.1)
    assert gmr.robot_body_names["world"] == 0 and gmr.robot_dof_names["left_hip_pitch_joint"] == 6
    with pytest.raises(KeyError):
        GMR(src_human="bvh_lafan1", tgt_robot="pnd_adam_lite")  # GMR has no LAFAN1 config either
    with pytest.raises(KeyError):
        GMR(src_human="bvh_lafan1", tgt_robot="no_such_robot")
    with pytest.raises(NotImplementedError):
        gmr.retarget({}, offset_to_ground=True)


#: GMR master's 18 robot keys (``ROBOT_XML_DICT``).
GMR_ROBOTS = [
    "unitree_g1", "unitree_g1_with_hands", "unitree_h1", "unitree_h1_2", "booster_t1",
    "booster_t1_29dof", "booster_k1", "stanford_toddy", "fourier_n1", "engineai_pm01",
    "hightorque_hi", "galaxea_r1pro", "kuavo_s45", "berkeley_humanoid_lite", "pnd_adam_lite",
    "tienkung", "pal_talos", "fourier_gr3",
]


def test_every_gmr_robot_key_is_accepted_or_refused_with_where_to_get_it():
    from retarget import RetargetError
    from retarget.gmr import IK_CONFIG_DICT, NOT_SHIPPED_ROBOTS

    shipped = set(_native_keys())
    assert shipped | set(NOT_SHIPPED_ROBOTS) == set(GMR_ROBOTS)
    for key in GMR_ROBOTS:
        sources = [s for s, robots in IK_CONFIG_DICT.items() if key in robots]
        if key in NOT_SHIPPED_ROBOTS:
            with pytest.raises(RetargetError, match=key) as error:
                GMR(src_human="smplx", tgt_robot=key)
            upstream = NOT_SHIPPED_ROBOTS[key][1]
            assert upstream in str(error.value) and "--robot path/to/" in str(error.value)
            continue
        for source in sources:
            gmr = GMR(src_human=source, tgt_robot=key)
            assert gmr.robot_dof_names, (source, key)


def test_every_gmr_source_with_a_config():
    from retarget.gmr import IK_CONFIG_DICT

    # GMR master's IK_CONFIG_DICT for the G1: every source has its config.
    for source in ["smplx", "bvh_lafan1", "bvh_nokov", "bvh_xsens", "fbx", "fbx_offline", "xrobot", "xsens_mvn"]:
        assert "unitree_g1" in IK_CONFIG_DICT[source], source
        assert GMR(src_human=source, tgt_robot="unitree_g1").human_root_name
    with pytest.raises(KeyError, match="not one of GMR's sources"):
        GMR(src_human="bvh_soma", tgt_robot="unitree_g1")  # an unmerged GMR pull request


def _native_keys():
    from retarget import _native

    return _native.shipped_robots()
