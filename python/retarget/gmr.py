"""GMR's API over ``retarget``: change ``general_motion_retargeting`` to ``retarget.gmr``.

>>> from retarget.gmr import GeneralMotionRetargeting as GMR, load_bvh_file
>>> frames, height = load_bvh_file("walk.bvh", format="lafan1")          # doctest: +SKIP
>>> gmr = GMR(src_human="bvh_lafan1", tgt_robot="unitree_g1", actual_human_height=height)  # doctest: +SKIP
>>> qpos = gmr.retarget(frames[0])                                      # doctest: +SKIP

``GeneralMotionRetargeting.retarget`` is GMR's per-frame solve reproduced exactly (the same
targets, weights, damping, stopping rule and exact QP; our parity test holds it to 1e-6 rad of
GMR's own output on the LAFAN1 walk). ``load_bvh_file`` returns what GMR's loader returns; ``load_optitrack_fbx_motion_file`` reads
an ``.fbx`` file itself into the frames GMR's FBX path (FBX SDK + poselib pickle) hands over.

SMPL-X (AMASS): ``load_smplx_file`` and ``get_smplx_data_offline_fast`` return what GMR's do
(the human data to 1e-6 m of GMR's own, float32 smplx), and ``src_human="smplx"`` takes GMR's
``smplx_to_*`` config of the robot (``IK_CONFIG_DICT["smplx"]``):

>>> from retarget.gmr import load_smplx_file, get_smplx_data_offline_fast       # doctest: +SKIP
>>> data, body_model, output, height = load_smplx_file("walk_stageii.npz", "body_models")  # doctest: +SKIP
>>> frames, fps = get_smplx_data_offline_fast(data, body_model, output, tgt_fps=30)  # doctest: +SKIP

Robots and sources: ``tgt_robot`` is any of GMR's 18 robot keys; the models of
``NOT_SHIPPED_ROBOTS`` are not shipped (their licence), and naming one raises
``RetargetError`` saying where GMR's model is and how to pass it (``Retargeter("model.xml")``
in ``retarget``). ``src_human`` is any of GMR master's sources whose config GMR has for that
robot (``IK_CONFIG_DICT``, GMR's own files byte-identical in ``configs/gmr/``): frames come
from ``load_bvh_file`` (``bvh_lafan1``, ``bvh_nokov``), ``load_smplx_file`` (``smplx``) and
``load_optitrack_fbx_motion_file`` (``fbx``, ``fbx_offline``); ``bvh_xsens``, ``xsens_mvn``
and ``xrobot`` have no loader here (an Xsens BVH export's joint names, GMR's live Xsens MVN
and XRoboToolkit streams): pass their frames yourself. A source GMR has no config for
raises ``KeyError``.

Differences: the solver is
exact whatever ``solver`` names (GMR: daqp); ``use_velocity_limit`` changes nothing (GMR passes
its velocity limits into mink's ``safety_break`` argument, so GMR never applies them either);
nothing is printed (``verbose``); there is no MuJoCo model (``model``, ``configuration``).
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Mapping, Sequence, Tuple

import numpy as np

from . import _native

__all__ = [
    "GeneralMotionRetargeting",
    "load_bvh_file",
    "load_fbx_file",
    "load_optitrack_fbx_motion_file",
    "load_smplx_file",
    "get_smplx_data_offline_fast",
]

#: GMR's ``src_human`` names we have configs for, by robot: GMR's ``IK_CONFIG_DICT`` for
#: the shipped robots (paths in the repository; the table is ``retarget::shipped::CONFIGS``).
IK_CONFIG_DICT: Dict[str, Dict[str, str]] = {}
for _source, _robot, _path in _native.gmr_configs():
    IK_CONFIG_DICT.setdefault(_source, {})[_robot] = _path

#: GMR's robot keys whose models are not shipped: ``{key: (reason, upstream path in GMR)}``.
NOT_SHIPPED_ROBOTS: Dict[str, Tuple[str, str]] = {
    key: (reason, upstream) for key, reason, upstream in _native.not_shipped_robots()
}

#: GMR master's ``src_human`` names (its ``IK_CONFIG_DICT`` keys).
GMR_SOURCES = ("smplx", "bvh_lafan1", "bvh_nokov", "bvh_xsens", "fbx", "fbx_offline", "xrobot", "xsens_mvn")

HumanData = Mapping[str, Sequence[Any]]


def load_bvh_file(bvh_file: "os.PathLike[str] | str", format: str = "lafan1") -> Tuple[List[Dict[str, List[np.ndarray]]], float]:
    """GMR's ``general_motion_retargeting.utils.lafan1.load_bvh_file``.

    Returns ``(frames, human_height)``: per frame a dict ``{body: [position, orientation]}``
    with every joint of the file (End Sites left out) and ``LeftFootMod``/``RightFootMod``
    (the foot's position with the toe's orientation; the toe is ``LeftToe`` for
    ``format="lafan1"``, ``LeftToeBase`` for ``"nokov"``). Positions are metres (the file in
    centimetres) with Z up (the file's Y up turned +90° about X), orientations w x y z.
    ``human_height`` is GMR's constant 1.75. ``format="soma"`` is GMR pull request #169's SOMA
    loader (BONES-SEED; not merged in GMR): no foot bodies, turned to face +X, 1.70 m.
    """
    return _native.load_bvh_gmr(os.fspath(bvh_file), format)


def load_optitrack_fbx_motion_file(motion_file: "os.PathLike[str] | str", take: "str | int | None" = None) -> List[Dict[str, List[np.ndarray]]]:
    """GMR's ``scripts/fbx_offline_to_robot.py`` loader, for an ``.fbx`` file itself.

    GMR reads FBX only through Autodesk's FBX SDK and poselib (``fbx_importer.py`` writes a
    pickle of frames, which this function loads in GMR). Here the FBX file is read directly
    and the frames are the same shape: per frame a dict ``{joint: [position, orientation]}``
    of every skeleton joint (named as in the file), positions in metres with Z up,
    orientations w x y z. ``take``: a take name or index (default: the take with the most
    motion). The file's axes and unit are applied; a figure that is not human-sized is
    scaled by its proportions, as ``Retargeter.retarget_fbx`` reads it.
    """
    return load_fbx_file(motion_file, take)[0]


def load_fbx_file(fbx_file: "os.PathLike[str] | str", take: "str | int | None" = None) -> Tuple[List[Dict[str, List[np.ndarray]]], float]:
    """``(frames, fps)`` of one take of an FBX file (see ``load_optitrack_fbx_motion_file``)."""
    frames, fps, _name = _native.load_fbx_frames(os.fspath(fbx_file), take)
    return frames, fps


class SmplxBodyModel:
    """What ``load_smplx_file`` returns in place of smplx's body model: where the model files
    are (the folder holding ``smplx/``, or one model ``.npz``) and the gender used."""

    def __init__(self, path: "os.PathLike[str] | str", gender: str) -> None:
        self.path = os.fspath(path)
        self.gender = gender

    def __repr__(self) -> str:
        return f"SmplxBodyModel({self.path!r}, gender={self.gender!r})"


class SmplxOutput:
    """What ``load_smplx_file`` returns in place of smplx's output: the motion file it poses
    (``get_smplx_data_offline_fast`` computes the joints from it)."""

    def __init__(self, smplx_file: "os.PathLike[str] | str") -> None:
        self.smplx_file = os.fspath(smplx_file)


def load_smplx_file(
    smplx_file: "os.PathLike[str] | str", smplx_body_model_path: "os.PathLike[str] | str"
) -> Tuple[Any, SmplxBodyModel, SmplxOutput, float]:
    """GMR's ``general_motion_retargeting.utils.smpl.load_smplx_file``.

    Returns ``(smplx_data, body_model, smplx_output, human_height)``: the file's arrays
    (``numpy.load``), the body model (``smplx_body_model_path`` is the folder that holds
    ``smplx/SMPLX_NEUTRAL.npz`` etc., as for ``smplx.create``; the gender is the file's), the
    posed output (computed lazily by ``get_smplx_data_offline_fast``) and GMR's subject height
    ``1.66 + 0.1 * betas[0]``.
    """
    smplx_data = np.load(os.fspath(smplx_file))
    betas = np.asarray(smplx_data["betas"], dtype=float).reshape(-1)
    human_height = 1.66 + 0.1 * float(betas[0]) if betas.size else 1.66
    body_model = SmplxBodyModel(smplx_body_model_path, str(smplx_data["gender"]))
    return smplx_data, body_model, SmplxOutput(smplx_file), human_height


def get_smplx_data_offline_fast(
    smplx_data: Any, body_model: SmplxBodyModel, smplx_output: SmplxOutput, tgt_fps: float = 30
) -> Tuple[List[Dict[str, Tuple[np.ndarray, np.ndarray]]], float]:
    """GMR's ``get_smplx_data_offline_fast``: per frame ``{joint: (position, wxyz quaternion)}``
    for the model's 55 joints, resampled to ``tgt_fps`` as GMR does (frame skip, linear
    positions, slerped local rotations chained again), and the resulting rate."""
    del smplx_data  # the arrays are read again from the file, by the library
    frames, fps, _ = _native.load_smplx_gmr(
        smplx_output.smplx_file, body_model.path, float(tgt_fps), body_model.gender
    )
    return frames, fps


class GeneralMotionRetargeting:
    """GMR's ``GeneralMotionRetargeting``: ``retarget(human_data)`` solves one frame,
    warm-started from the previous one, and returns the robot's ``qpos``."""

    def __init__(
        self,
        src_human: str,
        tgt_robot: str,
        actual_human_height: "float | None" = None,
        solver: str = "daqp",
        damping: float = 5e-1,
        verbose: bool = True,
        use_velocity_limit: bool = False,
    ) -> None:
        if src_human not in GMR_SOURCES:
            raise KeyError(f"src_human {src_human!r}: not one of GMR's sources {list(GMR_SOURCES)}")
        if tgt_robot in NOT_SHIPPED_ROBOTS:
            _native.Retargeter(tgt_robot)  # raises RetargetError: where to get the model
        if tgt_robot not in IK_CONFIG_DICT.get(src_human, {}):
            having = sorted(IK_CONFIG_DICT.get(src_human, {}))
            raise KeyError(
                f"src_human {src_human!r}, tgt_robot {tgt_robot!r}: no {src_human} config ships for "
                f"{tgt_robot} (GMR has none either); robots with one: {having}"
            )
        if damping != 5e-1:
            raise NotImplementedError("damping other than GMR's default 0.5")
        self.src_human = src_human
        self.tgt_robot = tgt_robot
        self.solver = solver
        self.damping = damping
        self.verbose = verbose
        self.max_iter = 10
        self._retargeter = _native.Retargeter(tgt_robot, mode="gmr", human_height=actual_human_height)
        self._retargeter.select_config(src_human)
        ik_config = json.loads(self._retargeter.config_json())
        ratio = 1.0 if actual_human_height is None else actual_human_height / ik_config["human_height_assumption"]
        self.ik_match_table1 = ik_config["ik_match_table1"]
        self.ik_match_table2 = ik_config["ik_match_table2"]
        self.human_root_name = ik_config["human_root_name"]
        self.robot_root_name = ik_config["robot_root_name"]
        self.use_ik_match_table1 = ik_config["use_ik_match_table1"]
        self.use_ik_match_table2 = ik_config["use_ik_match_table2"]
        self.human_scale_table = {k: v * ratio for k, v in ik_config["human_scale_table"].items()}
        self.ground = ik_config["ground_height"] * np.array([0, 0, 1])
        self.robot_dof_names = {name: 6 + i for i, name in enumerate(self._retargeter.joint_names)}
        self.robot_body_names = {"world": 0, **{name: i + 1 for i, name in enumerate(self._retargeter.body_names)}}
        self.scaled_human_data: Dict[str, Tuple[np.ndarray, np.ndarray]] = {}
        self.ground_offset = 0.0

    def retarget(self, human_data: HumanData, offset_to_ground: bool = False) -> np.ndarray:
        """Solves one frame ``{body: (position, wxyz quaternion)}`` and returns ``qpos``
        (root position, root quaternion w x y z, joints in MJCF order)."""
        if offset_to_ground:
            raise NotImplementedError("offset_to_ground=True")
        qpos = self._retargeter.step(human_data)
        self.scaled_human_data = dict(self._retargeter.last_targets())
        return qpos

    def set_ground_offset(self, ground_offset: float) -> None:
        """GMR's ground offset; only 0 (GMR's default) is supported."""
        if ground_offset != 0.0:
            raise NotImplementedError("a non-zero ground offset")
        self.ground_offset = ground_offset
