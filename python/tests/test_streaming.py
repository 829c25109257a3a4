"""``Retargeter.step`` (one frame at a time, warm-started) equals the clip path with the same
causal options, exactly: GMR's solve, and the default solve's causal part (its hard
constraints without planting or smoothing, which need the future)."""

from __future__ import annotations

import numpy as np
import pytest

import retarget
from retarget.gmr import load_bvh_file


@pytest.fixture(scope="module")
def frames(walk):
    frames, _ = load_bvh_file(walk)
    return frames[:900]


@pytest.mark.parametrize("mode", ["gmr", "causal"])
def test_step_equals_the_clip(frames, mode):
    clip = retarget.Retargeter("unitree_g1", mode=mode).retarget_frames(frames, fps=30.0)
    streamer = retarget.Retargeter("unitree_g1", mode=mode, fps=30.0)
    streamed = np.array([streamer.step(frame) for frame in frames])
    assert streamed.shape == clip.qpos.shape == (900, 36)
    assert np.array_equal(streamed, clip.qpos)
    # Reset: a new stream from the home pose, the same numbers.
    streamer.reset()
    assert np.array_equal(streamer.step(frames[0]), clip.qpos[0])


def test_the_default_mode_streams_its_causal_part(frames):
    causal = retarget.Retargeter("unitree_g1", mode="causal").retarget_frames(frames)
    default = retarget.Retargeter("unitree_g1")
    streamed = np.array([default.step(frame) for frame in frames])
    assert np.array_equal(streamed, causal.qpos)
    planted = default.retarget_frames(frames)
    # The source's contacts are labelled in every mode; only the default solve plants on them.
    assert causal.contact_left is not None and causal.contact_left.any()
    assert np.array_equal(planted.contact_left, causal.contact_left)
    assert np.array_equal(planted.contact_right, causal.contact_right)
    assert np.abs(planted.qpos - causal.qpos).max() > 1e-3


def test_frames_take_lists_tuples_and_arrays(frames):
    a = retarget.Retargeter("unitree_g1", mode="gmr")
    b = retarget.Retargeter("unitree_g1", mode="gmr")
    for frame in frames[:5]:
        as_lists = {name: ([*map(float, p)], tuple(map(float, q))) for name, (p, q) in frame.items()}
        assert np.array_equal(a.step(frame), b.step(as_lists))
    with pytest.raises(ValueError, match="LeftHand"):
        a.step({k: v for k, v in frames[5].items() if k != "LeftHand"})
    with pytest.raises(ValueError, match="Hips"):
        a.step({**frames[5], "Hips": ([0.0, 0.0], [1.0, 0.0, 0.0, 0.0])})
