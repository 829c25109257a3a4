"""Human motion capture (BVH, C3D) to humanoid robot joint trajectories.

The Python face of the Rust library ``retarget``: the same solver, robots and configs as the
``retarget`` command line tool, with the GIL released while it works.

>>> import retarget
>>> r = retarget.Retargeter("unitree_g1")
>>> motion = r.retarget_bvh("walk.bvh")            # doctest: +SKIP
>>> motion.qpos.shape, motion.fps                   # doctest: +SKIP
>>> retarget.report(motion)["frames"]               # doctest: +SKIP
>>> motion.save("walk.npz")                         # doctest: +SKIP

``retarget.gmr`` mirrors GMR's API (``GeneralMotionRetargeting``, ``load_bvh_file``) so that
code written for GMR runs by changing one import.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterable, List, Optional, Union

from . import _native
from ._native import Motion, RetargetError, Retargeter, shipped_robots

__all__ = [
    "Motion",
    "RetargetError",
    "Retargeter",
    "batch",
    "gmr",
    "report",
    "shipped_robots",
]
__version__: str = _native.__version__

PathLike = Union[str, "os.PathLike[str]"]


def report(motion: Motion) -> Dict[str, Any]:
    """The quality report of ``motion`` (what ``retarget report`` prints) as a dict: tracking
    errors, joint limits and speeds, foot sliding and penetration, ground penetration,
    self-collision, skating against the source's contacts, the root's acceleration
    (``root_acceleration``), jitter over every velocity coordinate (``jitter``) and the
    dynamics check (``dynamics``; ``None`` with ``dynamics_unavailable`` saying why).
    Definitions: docs/metrics.md."""
    return json.loads(motion.report_json())


def batch(
    paths: Iterable[PathLike],
    robot: str,
    out_dir: PathLike,
    jobs: Optional[int] = None,
    *,
    config: Optional[PathLike] = None,
    mode: str = "default",
    format: str = "npz",
    human_height: Optional[float] = None,
) -> List[Dict[str, Any]]:
    """Retargets BVH files onto ``robot`` in parallel on Rust threads (``jobs``, default one
    per core), writing ``out_dir/<stem>.<format>``. Returns one dict per file, in order:
    ``input``, ``output``, then ``frames``, ``seconds`` and ``inferred``, or ``error`` for a
    clip that failed (the others go on)."""
    return _native.batch(
        [os.fspath(p) for p in paths],
        robot,
        os.fspath(out_dir),
        0 if jobs is None else int(jobs),
        config=None if config is None else os.fspath(config),
        mode=mode,
        format=format,
        human_height=human_height,
    )


def __getattr__(name: str) -> Any:
    # `retarget.gmr` is imported on first use (PEP 562): it needs numpy, whose import (about
    # 0.2 s) a script that only converts files never pays; `Motion`'s arrays import it too.
    if name == "gmr":
        import importlib

        return importlib.import_module(f"{__name__}.gmr")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
