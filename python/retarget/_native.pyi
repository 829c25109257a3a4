"""Type stubs of the extension module ``retarget._native`` (Rust, PyO3)."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
Vec = Union[Sequence[float], npt.NDArray[np.float64]]
#: GMR's ``human_data``: per body name ``(position xyz in m, orientation w x y z)``.
HumanData = Mapping[str, Sequence[Vec]]

class RetargetError(ValueError):
    """A bad file, config, robot or option (the message says which)."""

class Motion:
    """A retargeted clip; arrays are read-only numpy views named as in the saved ``.npz``."""

    @property
    def fps(self) -> float: ...
    @property
    def qpos(self) -> npt.NDArray[np.float64]:
        """T × nq: root position, root quaternion w x y z, joints in MJCF order."""
    @property
    def joint_pos(self) -> npt.NDArray[np.float64]:
        """T × (nq − 7)."""
    @property
    def joint_vel(self) -> npt.NDArray[np.float64]:
        """T × (nq − 7)."""
    @property
    def body_pos_w(self) -> npt.NDArray[np.float64]:
        """T × B × 3, world frame."""
    @property
    def body_quat_w(self) -> npt.NDArray[np.float64]:
        """T × B × 4, w x y z."""
    @property
    def body_lin_vel_w(self) -> npt.NDArray[np.float64]:
        """T × B × 3."""
    @property
    def body_ang_vel_w(self) -> npt.NDArray[np.float64]:
        """T × B × 3."""
    @property
    def target_pos(self) -> Optional[npt.NDArray[np.float64]]:
        """T × K × 3: the IK targets tracked."""
    @property
    def target_quat(self) -> Optional[npt.NDArray[np.float64]]:
        """T × K × 4, w x y z."""
    @property
    def contact_left(self) -> Optional[npt.NDArray[np.bool_]]:
        """Per frame: the source's left foot on the floor (``None`` when unknown)."""
    @property
    def contact_right(self) -> Optional[npt.NDArray[np.bool_]]:
        """Per frame: the source's right foot on the floor (``None`` when unknown)."""
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def body_names(self) -> List[str]: ...
    @property
    def target_body_names(self) -> List[str]: ...
    @property
    def robot(self) -> str: ...
    @property
    def human_height(self) -> Tuple[float, str]:
        """Subject height used (m) and where it came from."""
    @property
    def inferred(self) -> str:
        """Up axis, unit and roles inferred from the source; the config used."""
    @property
    def solve_seconds(self) -> float: ...
    @property
    def stages(self) -> Dict[str, Dict[str, Any]]:
        """What the default solve's stages said, ``{stage: {key: value}}`` in the order they
        ran (only stages with something to say), each with its one-line ``"summary"``:
        ``"treadmill"`` (``belt_mps``, ``heading_rad``: the source's feet slid back on its
        floor, an in-place loop, and it was walked forward) and ``"reweigh"``
        (``pelvis_offset`` in m, ``share`` 0 to 1)."""
    @property
    def backward(self) -> Tuple[int, int]:
        """Frames taken from the backward first pass (``mode="both_ways"``; 0 otherwise)
        and the stretches they form."""
    def to_dict(self) -> Dict[str, np.ndarray]:
        """Every array of the ``.npz`` exactly as ``numpy.load`` gives it."""
    def save(self, path: PathLike, format: Optional[str] = None) -> None:
        """Writes ``.npz``, ``.csv`` (Unitree), ``.pkl`` (GMR) or ``.json`` (by extension)."""
    def report_json(self) -> str:
        """The quality report as JSON text (see ``retarget.report``)."""
    def __len__(self) -> int: ...

class Retargeter:
    """Retargets human motion onto one robot (a shipped key or an MJCF/URDF path)."""

    def __init__(
        self,
        robot: str,
        config: Optional[PathLike] = None,
        *,
        mode: str = "default",
        human_height: Optional[float] = None,
        fps: float = 30.0,
    ) -> None:
        """``mode``: ``"default"`` (the trajectory solve: planted feet, constraints, smooth accelerations, dynamics), ``"gmr"`` (GMR's
        exact solve), ``"causal"`` (what ``step`` runs, on a whole clip) or ``"both_ways"``
        (the default, also solved backwards where that tracks better: ``--both-ways``)."""
    @property
    def robot(self) -> str: ...
    @property
    def nq(self) -> int: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def body_names(self) -> List[str]: ...
    def config_json(self) -> str:
        """The config frames use (``step``, ``retarget_frames``), as JSON text."""
    def retarget_bvh(self, path: PathLike) -> Motion: ...
    def retarget_fbx(self, path: PathLike, take: Optional[Union[str, int]] = None) -> Motion:
        """One take (name or index; default: the one with the most motion)."""
    def retarget_smplx(
        self,
        path: Optional[PathLike] = None,
        *,
        body_model: Optional[PathLike] = None,
        gender: Optional[str] = None,
        poses: Optional[npt.ArrayLike] = None,
        trans: Optional[npt.ArrayLike] = None,
        betas: Optional[npt.ArrayLike] = None,
        fps: Optional[float] = None,
    ) -> Motion:
        """An AMASS motion (SMPL-X ``*_stageii.npz`` or SMPL+H ``*_poses.npz``), or its
        parameters as arrays (``poses`` N × 165 / N × 156 axis-angle, ``trans`` N × 3,
        ``betas``, ``fps``); the body model folder from ``body_model`` or
        ``$RETARGET_BODY_MODELS``."""
    def select_config(self, source: str) -> None:
        """Use the shipped config of GMR's ``src_human`` ``source`` (``gmr_configs``)."""
    def retarget_c3d(self, path: PathLike, config: PathLike) -> Motion:
        """With a marker-driven IK config (``marker_bodies`` + IK tables)."""
    def retarget_frames(self, frames: Sequence[HumanData], fps: float = 30.0) -> Motion:
        """A clip given as GMR ``human_data`` frames."""
    def step(self, frame: HumanData) -> npt.NDArray[np.float64]:
        """One streamed frame → ``qpos`` (warm-started; the causal solve)."""
    def reset(self) -> None:
        """The next ``step`` starts a new stream."""
    def last_targets(self) -> Dict[str, Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """The last streamed frame's targets (GMR's ``scaled_human_data``)."""

def load_bvh_gmr(path: PathLike, format: str = "lafan1") -> Tuple[List[Dict[str, List[npt.NDArray[np.float64]]]], float]: ...
def load_fbx_frames(path: PathLike, take: Optional[Union[str, int]] = None) -> Tuple[List[Dict[str, List[npt.NDArray[np.float64]]]], float, str]: ...
def load_smplx_gmr(
    path: PathLike, body_model: Optional[PathLike], tgt_fps: float = 30.0, gender: Optional[str] = None
) -> Tuple[List[Dict[str, Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]], float, float]:
    """GMR's SMPL-X human data resampled to ``tgt_fps``: ``(frames, fps, human_height)``."""
def batch(
    paths: Sequence[PathLike],
    robot: str,
    out_dir: PathLike,
    jobs: int = 0,
    *,
    config: Optional[PathLike] = None,
    mode: str = "default",
    format: str = "npz",
    human_height: Optional[float] = None,
) -> List[Dict[str, Any]]: ...
def shipped_robots() -> List[str]: ...
def gmr_configs() -> List[Tuple[str, str, str]]:
    """The shipped configs as ``(source, robot, path)`` (GMR's ``IK_CONFIG_DICT``)."""
def not_shipped_robots() -> List[Tuple[str, str, str]]:
    """GMR's robot keys not shipped, as ``(key, reason, upstream path in GMR)``."""
