"""Retarget a BVH onto the Unitree G1 from Python: `python examples/python_quickstart.py [BVH]`."""
import sys

import retarget

bvh = sys.argv[1] if len(sys.argv) > 1 else "data/samples/lafan1_walk.bvh"
motion = retarget.Retargeter("unitree_g1").retarget_bvh(bvh)  # planted feet, constraints
print(motion, motion.qpos.shape, motion.joint_names[:3])
quality = retarget.report(motion)
print("joint limit violations:", quality["joint_limits"]["violations"])
motion.save("walk_g1.npz")  # BeyondMimic's keys; .csv (Unitree) and .pkl (GMR) work too
