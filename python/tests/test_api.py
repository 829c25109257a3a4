"""The rest of the package: errors, batch on the Rust thread pool, the GIL released during
solves, the quickstart example."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import retarget


def test_errors_are_python_exceptions(tmp_path):
    with pytest.raises(retarget.RetargetError, match="unknown robot"):
        retarget.Retargeter("no_such_robot")
    with pytest.raises(FileNotFoundError):
        retarget.Retargeter("unitree_g1").retarget_bvh(tmp_path / "missing.bvh")
    (tmp_path / "bad.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    with pytest.raises(retarget.RetargetError, match="bad.bvh"):
        retarget.Retargeter("unitree_g1").retarget_bvh(tmp_path / "bad.bvh")
    with pytest.raises(ValueError, match="mode"):
        retarget.Retargeter("unitree_g1", mode="fast")
    assert "unitree_g1" in retarget.shipped_robots()


def test_import_is_light_and_gmr_loads_on_first_use():
    code = ("import sys, retarget; assert 'numpy' not in sys.modules, 'numpy imported'; "
            "from retarget.gmr import load_bvh_file; assert retarget.gmr.load_bvh_file is load_bvh_file; "
            "assert 'numpy' in sys.modules; retarget.gmr.GeneralMotionRetargeting")
    subprocess.run([sys.executable, "-c", code], check=True)
    with pytest.raises(AttributeError, match="no_such_name"):
        retarget.no_such_name


def test_robots_and_configs_from_files(root, shared):
    robot = root / "robots/unitree_g1/unitree_g1.xml"
    config = root / "configs/gmr/bvh_lafan1_to_g1.json"
    from_files = retarget.Retargeter(robot=str(robot), config=str(config), mode="gmr")
    shipped = retarget.Retargeter("unitree_g1", mode="gmr")
    assert from_files.robot == "unitree_g1" and from_files.nq == shipped.nq == 36
    bvh = shared / "data/bvh/bandai_dataset-1_walk_normal_001.bvh"
    a = retarget.Retargeter("unitree_g1").retarget_bvh(bvh)
    assert "derived" in a.inferred  # Bandai names: a config derived from the roles


def test_batch_runs_on_rust_threads_and_isolates_failures(tmp_path, shared):
    clips = [shared / f"data/bvh/bandai_dataset-1_{name}_normal_001.bvh" for name in ("walk", "run", "kick")]
    bogus = tmp_path / "bogus.bvh"
    bogus.write_text("not a bvh")
    rows = retarget.batch([*clips, bogus], "unitree_g1", tmp_path / "out", jobs=2)
    assert [row["input"] for row in rows] == [str(p) for p in (*clips, bogus)]
    assert all("error" not in row for row in rows[:3]) and "bogus.bvh" in rows[3]["error"]
    single = retarget.Retargeter("unitree_g1").retarget_bvh(clips[1])
    out = np.load(tmp_path / "out" / f"{clips[1].stem}.npz")
    assert rows[1]["frames"] == len(single) == out["qpos"].shape[0]
    assert np.array_equal(out["qpos"], single.qpos)


def test_the_gil_is_released_while_solving(walk):
    retargeter = retarget.Retargeter("unitree_g1", mode="gmr")
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)

    thread = threading.Thread(target=count)
    thread.start()
    started = time.perf_counter()
    retargeter.retarget_bvh(walk)
    elapsed = time.perf_counter() - started
    done.set()
    thread.join()
    # A held GIL would freeze the counter for the whole solve (~1 s); released, it ticks on.
    assert ticks > 0.1 * elapsed / 0.001, (ticks, elapsed)


def test_quickstart_example_runs(tmp_path, root, walk):
    result = subprocess.run([sys.executable, str(root / "examples/python_quickstart.py"), str(walk)],
                            cwd=tmp_path, capture_output=True, text=True, check=True)
    assert "Motion(robot=\"unitree_g1\", frames=7184" in result.stdout
    saved = np.load(tmp_path / "walk_g1.npz")
    assert saved["qpos"].shape == (7184, 36)


def test_both_ways_takes_a_stuck_hip_from_the_backward_pass(shared):
    """The PM01's right hip goes over into its other branch in the Bandai kick and stays there
    in the default solve; solved both ways it does not (as `retarget --both-ways`)."""
    kick = shared / "data/bvh/bandai_dataset-1_kick_normal_001.bvh"
    over = {}
    for mode in ("default", "both_ways"):
        motion = retarget.Retargeter("engineai_pm01", mode=mode).retarget_bvh(kick)
        yaw = motion.joint_pos[:, motion.joint_names.index("J08_HIP_YAW_R")]
        over[mode] = int((np.abs(yaw) > np.radians(150)).sum())
        frames, stretches = motion.backward
        assert (frames > 0 and stretches > 0) == (mode == "both_ways"), motion.backward
    assert over["default"] > 100 and over["both_ways"] == 0, over


def test_an_in_place_loop_is_walked_forward_and_says_so(shared, walk):
    """The XNA dude's FBX walk cycle slides its feet back along its floor (an in-place loop):
    the default solve walks it forward at that speed and its ``treadmill`` stage says so; the
    LAFAN1 walk, on a floor that stays put, has no such stage."""
    fbx = shared / "data/fbx/xna_dude_walk_fbxsdk2017.fbx"
    motion = retarget.Retargeter("unitree_g1").retarget_fbx(str(fbx))
    belt = motion.stages["treadmill"]
    assert 0.8 < belt["belt_mps"] < 1.2, belt
    assert belt["summary"].startswith("the source's feet slide back"), belt
    travel = np.linalg.norm(motion.qpos[-1, :2] - motion.qpos[0, :2])
    assert travel > 0.8, travel
    assert "treadmill" not in retarget.Retargeter("unitree_g1").retarget_bvh(str(walk)).stages
