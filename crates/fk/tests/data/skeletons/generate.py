#!/usr/bin/env python3
"""Writes the small BVH skeletons of `crates/fk/tests/roles.rs` (run from this folder).

One body, described once in body coordinates (metres; x = the subject's left, y = up,
z = forward), is written in several naming conventions, hierarchies, units, up axes and rest
poses. Most files have four frames: the subject walks forward, turns a little and bends both
knees, so that the motion shows which way it faces. Two carry a whole gait cycle of several
seconds for the retargeting tests (`gait`): a walk (MakeHuman) and a sprint (Biovision), legs
and arms swinging in opposition, the stance foot held still on the floor. Pure Python, no
dependencies.
"""

import math

# Joint positions of the left side and the trunk, standing with the arms down.
BODY = {
    "pelvis": (0.0, 0.95, 0.0),
    "spine": (0.0, 1.05, -0.01),
    "chest": (0.0, 1.28, 0.0),
    "neck": (0.0, 1.48, 0.0),
    "head": (0.0, 1.60, 0.02),
    "head_end": (0.0, 1.75, 0.02),
    "clavicle": (0.02, 1.44, 0.04),
    "upper_arm": (0.18, 1.43, 0.0),
    "forearm": (0.19, 1.14, -0.01),
    "hand": (0.19, 0.89, 0.02),
    "hand_end": (0.19, 0.80, 0.03),
    "thigh": (0.09, 0.91, 0.0),
    "shin": (0.09, 0.49, 0.01),
    "foot": (0.09, 0.08, -0.03),
    "toe": (0.09, 0.02, 0.10),
    "toe_end": (0.09, 0.01, 0.16),
}

ARMS = {
    "down": None,
    "t": {"forearm": (0.48, 1.43, 0.0), "hand": (0.74, 1.43, 0.0), "hand_end": (0.83, 1.43, 0.0)},
    "a": {
        "forearm": (0.18 + 0.212, 1.43 - 0.212, 0.0),
        "hand": (0.392 + 0.184, 1.218 - 0.184, 0.0),
        "hand_end": (0.576 + 0.064, 1.034 - 0.064, 0.0),
    },
}


def point(key, side="l", arms="down", body=None):
    """Body point `key` on `side` ('l' or 'r'; ignored for the trunk) of `body` (`BODY` when
    None). Extra points near a hand (`hand_end:tip`) move with the arm pose."""
    base = key.split(":")[0]
    p = (body or BODY)[key]
    if body is None and ARMS[arms] and base in ARMS[arms]:
        p = add(ARMS[arms][base], sub(p, BODY[base]))
    return (-p[0], p[1], p[2]) if side == "r" else p


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def mat_vec(m, v):
    return tuple(sum(m[i][k] * v[k] for k in range(3)) for i in range(3))


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(m):
    return [[m[j][i] for j in range(3)] for i in range(3)]


def rot(axis, degrees):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return {
        "x": [[1, 0, 0], [0, c, -s], [0, s, c]],
        "y": [[c, 0, s], [0, 1, 0], [-s, 0, c]],
        "z": [[c, -s, 0], [s, c, 0], [0, 0, 1]],
    }[axis]


def euler_zxy(m):
    """Degrees (z, x, y) with m = Rz · Rx · Ry (channels `Zrotation Xrotation Yrotation`)."""
    x = math.asin(max(-1.0, min(1.0, m[2][1])))
    z = math.atan2(-m[0][1], m[1][1])
    y = math.atan2(-m[2][0], m[2][2])
    return tuple(math.degrees(v) for v in (z, x, y))


def euler_zyx(m):
    """Degrees (z, y, x) with m = Rz · Ry · Rx (channels `Zrotation Yrotation Xrotation`, as
    HumanML3D's converters write them)."""
    y = math.asin(max(-1.0, min(1.0, -m[2][0])))
    x = math.atan2(m[2][1], m[2][2])
    z = math.atan2(m[1][0], m[0][0])
    return tuple(math.degrees(v) for v in (z, y, x))


EULER = {"zxy": euler_zxy, "zyx": euler_zyx}
ROTATION_CHANNELS = {"zxy": "Zrotation Xrotation Yrotation", "zyx": "Zrotation Yrotation Xrotation"}

# Body → file axes: columns are where the body's left, up and forward go.
Y_UP = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]  # BVH norm: facing +Z, left = +X
Z_UP_FACE_Y = [[-1, 0, 0], [0, 0, 1], [0, 1, 0]]  # 3ds Max / Unreal: up +Z, facing +Y
Z_UP_FACE_NEG_Y = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]  # Blender / MakeHuman: up +Z, facing -Y

# Gaits: stride frequency (Hz), hip swing and knee flexion amplitudes (degrees), arm swing,
# elbow flexion, vertical bounce (m, for flight phases), duration (s) and frame rate (30 fps
# unless said; HumanML3D's is 20).
GAITS = {
    "walk": dict(freq=0.9, hip=24.0, hip_bias=4.0, knee_stance=8.0, knee_swing=55.0, ankle=12.0,
                 arm=18.0, elbow=15.0, bounce=0.0, seconds=6.0),
    "walk20": dict(freq=0.9, hip=24.0, hip_bias=4.0, knee_stance=8.0, knee_swing=55.0,
                   ankle=12.0, arm=18.0, elbow=15.0, bounce=0.0, seconds=3.0, fps=20.0),
    "sprint": dict(freq=1.45, hip=38.0, hip_bias=6.0, knee_stance=15.0, knee_swing=105.0,
                   ankle=20.0, arm=45.0, elbow=85.0, bounce=0.05, seconds=5.0),
}


def gait_pose(g, phase, arms_down=0.0):
    """Per (part, side): the joint's rotation in body axes at gait phase `phase` (radians of the
    left leg's cycle; the right leg half a cycle later, each arm with the other leg).
    `arms_down`: degrees that bring the upper arms from the zero pose down to the sides (a
    T zero pose: about 80), so that every frame turns the shoulders and elbows."""
    out = {}
    for side, offset in (("l", 0.0), ("r", math.pi)):
        p = phase + offset
        swing = max(0.0, math.cos(p))  # the hip moving forward: the swing phase
        down = rot("z", -arms_down if side == "l" else arms_down)
        out[("thigh", side)] = rot("x", -(g["hip"] * math.sin(p) + g["hip_bias"]))
        out[("shin", side)] = rot("x", g["knee_stance"] + g["knee_swing"] * swing ** 2)
        out[("foot", side)] = rot("x", -g["ankle"] * math.sin(p + 0.6))
        out[("upper_arm", side)] = mat_mul(rot("x", g["arm"] * math.sin(p)), down)
        elbow = rot("x", -(g["elbow"] + 0.3 * g["elbow"] * swing))
        out[("forearm", side)] = mat_mul(mat_mul(transpose(down), elbow), down)
    return out


def foot_points(pose, side, body=None):
    """Ankle and toe (body coordinates, pelvis at its rest point) under `pose`."""
    hip = point("thigh", side, body=body)
    r = pose[("thigh", side)]
    knee = add(hip, mat_vec(r, sub(point("shin", side, body=body), hip)))
    r = mat_mul(r, pose[("shin", side)])
    ankle = add(knee, mat_vec(r, sub(point("foot", side, body=body), point("shin", side, body=body))))
    r = mat_mul(r, pose[("foot", side)])
    toe = add(ankle, mat_vec(r, sub(point("toe", side, body=body), point("foot", side, body=body))))
    return ankle, toe


def gait_frames(name, body=None, arms_down=0.0):
    """Root translation (body axes), yaw (degrees) and joint rotations per frame (the gait's
    `fps`, 30 unless it says): the lowest foot point on the floor, the stance foot not
    sliding, a slow turn to the left."""
    g = GAITS[name]
    fps = g.get("fps", 30.0)
    frames = []
    forward, speed = 0.0, None
    previous = None
    for k in range(int(g["seconds"] * fps)):
        phase = 2 * math.pi * g["freq"] * k / fps
        pose = gait_pose(g, phase, arms_down)
        feet = {s: foot_points(pose, s, body) for s in "lr"}
        # Height above the floor of each foot: ankle 8 cm, toe 2 cm when standing.
        low = {s: min(feet[s][0][1] - 0.08, feet[s][1][1] - 0.02) for s in "lr"}
        stance = min(low, key=low.get)
        lift = -low[stance] + g["bounce"] * max(0.0, math.sin(2 * phase)) ** 2
        ahead = max(feet[stance][0][2], feet[stance][1][2])
        if previous is not None and previous[0] == stance:
            step = previous[1] - ahead  # the stance foot stays put: the body moves over it
            speed = step if speed is None else 0.8 * speed + 0.2 * step
            forward += step if g["bounce"] == 0.0 or low[stance] < 0.01 else speed
        elif speed is not None:
            forward += speed
        previous = (stance, ahead)
        root = add(point("pelvis", body=body), (0.0, lift, forward))
        frames.append((root, 5.0 * k / fps, pose))
    return frames


def write(path, joints, shins, axes=Y_UP, unit=0.01, arms="down", yaw=0.0, lying=False,
          gait=None, body=None, arms_down=0.0, root_offset=None, rotation_order="zxy", zero_ends=False):
    """`joints`: (name, parent or None, body point key, side); End Sites are named None and
    placed at their point (at the joint itself with `zero_ends`). `shins`: names of the joints
    that bend as knees. `gait`: a whole gait cycle (see `GAITS`) instead of the four frames.
    `body`: the body's points (`BODY` when None), `arms_down` as in `gait_pose`.
    `root_offset`: the root's OFFSET (body coordinates) when it is not where the root stands;
    its position channels still say where it is. `rotation_order`: "zxy" or "zyx"."""
    axes = mat_mul(rot("y", 0) if axes is None else axes, rot("y", yaw))
    # A zero pose lying on its back along +X: offsets turned by r0, undone by the root.
    r0 = rot("z", -90) if lying else rot("x", 0)
    pos = {}
    for name, parent, key, side in joints:
        pos[(name, parent)] = point(key, side, arms, body)
    lines = ["HIERARCHY"]
    children = {}
    for j in joints:
        children.setdefault(j[1], []).append(j)
    order = []

    def emit(joint, depth, parent_point):
        name, parent, key, side = joint
        p = pos[(name, parent)]
        offset = p if parent is None else sub(p, parent_point)
        if parent is None and root_offset is not None:
            offset = root_offset
        if name is None and zero_ends:
            offset = (0.0, 0.0, 0.0)
        offset = mat_vec(axes, offset)
        if parent is not None:
            offset = mat_vec(r0, offset)
        offset = tuple(v / unit for v in offset)
        pad = "  " * depth
        if name is None:
            lines.append(f"{pad}End Site")
        else:
            lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(pad + "{")
        lines.append(pad + "  OFFSET " + " ".join(f"{v:.6f}" for v in offset))
        if name is not None:
            if parent is None:
                chans = "6 Xposition Yposition Zposition " + ROTATION_CHANNELS[rotation_order]
            else:
                chans = "3 " + ROTATION_CHANNELS[rotation_order]
            lines.append(pad + "  CHANNELS " + chans)
            order.append(name)
            for child in children.get(name, []):
                emit(child, depth + 1, p)
        lines.append(pad + "}")

    emit(children[None][0], 0, None)
    rows = []
    parts = {name: (key.split(":")[0], side) for name, _, key, side in joints if name}
    euler = EULER[rotation_order]
    for root, turn_deg, pose in (gait_frames(gait, body, arms_down) if gait else []):
        row = []
        for name in order:
            if name == order[0]:
                row += [v / unit for v in mat_vec(axes, root)]
                turn = mat_mul(mat_mul(axes, rot("y", turn_deg)), transpose(axes))
                row += euler(mat_mul(turn, transpose(r0)))
            elif parts[name] in pose:
                local = mat_mul(mat_mul(axes, pose[parts[name]]), transpose(axes))
                row += euler(mat_mul(mat_mul(r0, local), transpose(r0)))
            else:
                row += [0.0, 0.0, 0.0]
        rows.append(" ".join(f"{v:.6f}" for v in row))
    for k in range(0 if gait else 4):
        row = []
        for name in order:
            if name == order[0]:
                root = add(point(joints[0][2]), (0.0, 0.0, 0.1 * k))
                row += [v / unit for v in mat_vec(axes, root)]
                turn = mat_mul(mat_mul(axes, rot("y", 5.0 * k)), transpose(axes))
                row += euler(mat_mul(turn, transpose(r0)))
            elif name in shins:
                bend = mat_mul(mat_mul(axes, rot("x", 10.0 + 8.0 * k)), transpose(axes))
                row += euler(mat_mul(mat_mul(r0, bend), transpose(r0)))
            else:
                row += [0.0, 0.0, 0.0]
        rows.append(" ".join(f"{v:.6f}" for v in row))
    fps = GAITS[gait].get("fps", 30.0) if gait else 30.0
    lines += ["MOTION", f"Frames: {len(rows)}", f"Frame Time: {1.0 / fps:.6f}"] + rows
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def limbs(names, trunk_parent_leg, trunk_parent_arm, sides=("l", "r"), end_hand=True,
          end_toe=True, twist=None):
    """Arms and legs from `names[(part, side)]` (None: no such joint)."""
    out = []
    for s in sides:
        chain = [(p, names.get((p, s))) for p in ("clavicle", "upper_arm", "forearm", "hand")]
        parent = trunk_parent_arm
        for part, name in chain:
            if name:
                out.append((name, parent, part, s))
                parent = name
        if end_hand:
            out.append((None, parent, "hand_end", s))
    for s in sides:
        parent = trunk_parent_leg
        for part in ("thigh", "shin", "foot", "toe"):
            name = names.get((part, s))
            if name:
                out.append((name, parent, part, s))
                parent = name
        if end_toe:
            out.append((None, parent, "toe_end", s))
    return out


def sided(pattern, parts):
    """{(part, side): pattern with {S} → L/R, {s} → l/r, {Side} → Left/Right, {side}}."""
    out = {}
    for part, word in parts.items():
        for s in ("l", "r"):
            out[(part, s)] = (
                pattern.replace("{W}", word)
                .replace("{S}", s.upper())
                .replace("{s}", s)
                .replace("{Side}", "Left" if s == "l" else "Right")
                .replace("{side}", "left" if s == "l" else "right")
            )
    return out


def trunk(names, keys=("pelvis", "spine", "chest", "neck", "head")):
    out = []
    parent = None
    for key, name in zip(keys, names):
        out.append((name, parent, key, "l"))
        parent = name
    out.append((None, parent, "head_end", "l"))
    return out


def xsens():
    # MVN's BVH export: Hips, Chest…Chest4, LeftCollar, LeftShoulder = upper arm, LeftHip.
    names = sided("{Side}{W}", {
        "clavicle": "Collar", "upper_arm": "Shoulder", "forearm": "Elbow", "hand": "Wrist",
        "thigh": "Hip", "shin": "Knee", "foot": "Ankle", "toe": "Toe"})
    joints = [("Hips", None, "pelvis", "l"), ("Chest", "Hips", "spine", "l"),
              ("Chest2", "Chest", "spine:2", "l"), ("Chest3", "Chest2", "spine:3", "l"),
              ("Chest4", "Chest3", "chest", "l"), ("Neck", "Chest4", "neck", "l"),
              ("Head", "Neck", "head", "l"), (None, "Head", "head_end", "l")]
    joints += limbs(names, "Hips", "Chest4")
    return joints, ["LeftKnee", "RightKnee"]


def biped():
    names = sided("Bip01 {S} {W}", {
        "clavicle": "Clavicle", "upper_arm": "UpperArm", "forearm": "Forearm", "hand": "Hand",
        "thigh": "Thigh", "shin": "Calf", "foot": "Foot", "toe": "Toe0"})
    joints = [("Bip01", None, "pelvis", "l"), ("Bip01 Pelvis", "Bip01", "pelvis", "l"),
              ("Bip01 Spine", "Bip01 Pelvis", "spine", "l"),
              ("Bip01 Spine1", "Bip01 Spine", "spine:1", "l"),
              ("Bip01 Spine2", "Bip01 Spine1", "chest", "l"),
              ("Bip01 Neck", "Bip01 Spine2", "neck", "l"),
              ("Bip01 Head", "Bip01 Neck", "head", "l"), (None, "Bip01 Head", "head_end", "l")]
    # Biped: thighs under Bip01 Spine, clavicles under Bip01 Neck, twist helpers as leaves.
    joints += limbs(names, "Bip01 Spine", "Bip01 Neck")
    for s in "LR":
        joints.append((f"Bip01 {s} UpArmTwist", f"Bip01 {s} UpperArm", "forearm:twist",
                       s.lower()))
        joints.append((None, f"Bip01 {s} UpArmTwist", "forearm:twist", s.lower()))
    return joints, ["Bip01 L Calf", "Bip01 R Calf"]


def daz():
    names = sided("{s}{W}", {
        "clavicle": "Collar", "upper_arm": "Shldr", "forearm": "ForeArm", "hand": "Hand",
        "thigh": "Thigh", "shin": "Shin", "foot": "Foot"})
    joints = trunk(["hip", "abdomen", "chest", "neck", "head"])
    joints += limbs(names, "hip", "chest")
    # Poser's buttocks: a joint at the hip point with the thigh at zero offset below it.
    out = []
    for j in joints:
        if j[0] in ("lThigh", "rThigh"):
            s = j[0][0]
            out.append((f"{s}Buttock", "hip", "thigh", s))
            out.append((j[0], f"{s}Buttock", "thigh", s))
        else:
            out.append(j)
    return out, ["lShin", "rShin"]


def unreal():
    names = sided("{W}_{s}", {
        "clavicle": "clavicle", "upper_arm": "upperarm", "forearm": "lowerarm", "hand": "hand",
        "thigh": "thigh", "shin": "calf", "foot": "foot", "toe": "ball"})
    joints = [("root", None, "pelvis:floor", "l"), ("pelvis", "root", "pelvis", "l"),
              ("spine_01", "pelvis", "spine", "l"), ("spine_02", "spine_01", "spine:2", "l"),
              ("spine_03", "spine_02", "chest", "l"), ("neck_01", "spine_03", "neck", "l"),
              ("head", "neck_01", "head", "l"), (None, "head", "head_end", "l")]
    joints += limbs(names, "pelvis", "spine_03", end_hand=False)
    for s in "lr":
        for finger, tip in (("index", "hand_end:i"), ("middle", "hand_end:m")):
            joints.append((f"{finger}_01_{s}", f"hand_{s}", "hand_end", s))
            joints.append((None, f"{finger}_01_{s}", tip, s))
        joints.append((f"upperarm_twist_01_{s}", f"upperarm_{s}", "forearm:twist", s))
        joints.append((f"calf_twist_01_{s}", f"calf_{s}", "foot:twist", s))
    joints += [("ik_foot_root", "root", "pelvis:floor", "l"),
               ("ik_foot_l", "ik_foot_root", "foot", "l"), ("ik_foot_r", "ik_foot_root", "foot", "r"),
               ("ik_hand_root", "root", "pelvis:floor", "l"),
               ("ik_hand_gun", "ik_hand_root", "hand", "r"),
               ("ik_hand_l", "ik_hand_gun", "hand", "l"), ("ik_hand_r", "ik_hand_gun", "hand", "r")]
    return joints, ["calf_l", "calf_r"]


def smpl():
    names = sided("{S}_{W}", {
        "clavicle": "Collar", "upper_arm": "Shoulder", "forearm": "Elbow", "hand": "Wrist",
        "thigh": "Hip", "shin": "Knee", "foot": "Ankle", "toe": "Foot"})
    joints = [("Pelvis", None, "pelvis", "l"), ("Spine1", "Pelvis", "spine", "l"),
              ("Spine2", "Spine1", "spine:2", "l"), ("Spine3", "Spine2", "chest", "l"),
              ("Neck", "Spine3", "neck", "l"), ("Head", "Neck", "head", "l"),
              (None, "Head", "head_end", "l")]
    joints += limbs(names, "Pelvis", "Spine3", end_hand=False)
    for s in "LR":
        joints.append((f"{s}_Hand", f"{s}_Wrist", "hand_end", s.lower()))
        joints.append((None, f"{s}_Hand", "hand_end:tip", s.lower()))
    return joints, ["L_Knee", "R_Knee"]


def asf():
    names = sided("{s}{W}", {
        "clavicle": "clavicle", "upper_arm": "humerus", "forearm": "radius", "hand": "wrist",
        "thigh": "femur", "shin": "tibia", "foot": "foot", "toe": "toes"})
    joints = [("root", None, "pelvis", "l"), ("lowerback", "root", "spine", "l"),
              ("upperback", "lowerback", "spine:2", "l"), ("thorax", "upperback", "chest", "l"),
              ("lowerneck", "thorax", "neck", "l"), ("upperneck", "lowerneck", "neck:2", "l"),
              ("head", "upperneck", "head", "l"), (None, "head", "head_end", "l")]
    joints += limbs(names, "root", "thorax", end_hand=False)
    out = []
    for j in joints:
        if j[0] in ("lfemur", "rfemur"):
            # amc2bvh: lhipjoint sits on the root, lfemur at the hip.
            s = j[0][0]
            out.append((f"{s}hipjoint", "root", "pelvis", s))
            out.append((j[0], f"{s}hipjoint", "thigh", s))
        else:
            out.append(j)
    for s in "lr":
        out += [(f"{s}hand", f"{s}wrist", "hand:hand", s),
                (f"{s}fingers", f"{s}hand", "hand_end", s), (None, f"{s}fingers", "hand_end:tip", s),
                (f"{s}thumb", f"{s}hand", "hand_end:thumb", s),
                (None, f"{s}thumb", "hand_end:thumbtip", s)]
    return out, ["ltibia", "rtibia"]


def rokoko():
    # Rokoko / Perception Neuron with fingers (LeftInHandIndex) and face joints.
    names = sided("{Side}{W}", {
        "clavicle": "Shoulder", "upper_arm": "Arm", "forearm": "ForeArm", "hand": "Hand",
        "thigh": "UpLeg", "shin": "Leg", "foot": "Foot", "toe": "ToeBase"})
    joints = [("Hips", None, "pelvis", "l"), ("Spine", "Hips", "spine", "l"),
              ("Spine1", "Spine", "spine:1", "l"), ("Spine2", "Spine1", "spine:2", "l"),
              ("Spine3", "Spine2", "chest", "l"), ("Neck", "Spine3", "neck", "l"),
              ("Neck1", "Neck", "neck:1", "l"), ("Head", "Neck1", "head", "l"),
              ("HeadEnd", "Head", "head_end", "l"), (None, "HeadEnd", "head_end", "l"),
              ("LeftEye", "Head", "head:eye", "l"), (None, "LeftEye", "head:eyetip", "l"),
              ("RightEye", "Head", "head:eye", "r"), (None, "RightEye", "head:eyetip", "r"),
              ("Jaw", "Head", "head:jaw", "l"), (None, "Jaw", "head:chin", "l")]
    joints += limbs(names, "Hips", "Spine3", end_hand=False)
    for side, s in (("Left", "l"), ("Right", "r")):
        for finger in ("Index", "Middle", "Ring"):
            joints += [(f"{side}InHand{finger}", f"{side}Hand", "hand:in", s),
                       (f"{side}Hand{finger}1", f"{side}InHand{finger}", "hand_end", s),
                       (f"{side}Hand{finger}2", f"{side}Hand{finger}1", "hand_end:2", s),
                       (None, f"{side}Hand{finger}2", "hand_end:tip", s)]
        joints += [(f"{side}HandThumb1", f"{side}Hand", "hand_end:thumb", s),
                   (None, f"{side}HandThumb1", "hand_end:thumbtip", s)]
    return joints, ["LeftLeg", "RightLeg"]


def unnamed():
    # joint1 … joint20, children in no anatomical order (right before left, neck first).
    plan = [("pelvis", None, "l"), ("thigh", "pelvis", "r"), ("shin", "thigh.r", "r"),
            ("foot", "shin.r", "r"), ("toe", "foot.r", "r"), ("chest", "pelvis", "l"),
            ("neck", "chest", "l"), ("head", "neck", "l"), ("clavicle", "chest", "r"),
            ("upper_arm", "clavicle.r", "r"), ("forearm", "upper_arm.r", "r"),
            ("hand", "forearm.r", "r"), ("clavicle", "chest", "l"),
            ("upper_arm", "clavicle.l", "l"), ("forearm", "upper_arm.l", "l"),
            ("hand", "forearm.l", "l"), ("thigh", "pelvis", "l"), ("shin", "thigh.l", "l"),
            ("foot", "shin.l", "l"), ("toe", "foot.l", "l")]
    trunk_parts = {"pelvis", "chest", "neck", "head"}
    key = {}
    joints = []
    for i, (part, parent, s) in enumerate(plan):
        name = f"joint{i + 1}"
        key[part if part in trunk_parts else f"{part}.{s}"] = name
        parent_name = None if parent is None else key[parent]
        joints.append((name, parent_name, part, s))
    ends = [(key["head"], "head_end", "l"), (key["hand.r"], "hand_end", "r"),
            (key["hand.l"], "hand_end", "l"), (key["toe.r"], "toe_end", "r"),
            (key["toe.l"], "toe_end", "l")]
    joints += [(None, parent, k, s) for parent, k, s in ends]
    return joints, [key["shin.l"], key["shin.r"]], key


def mixamo(prefix="mixamorig_", fingers=False, prop=None):
    names = sided(prefix + "{Side}{W}", {
        "clavicle": "Shoulder", "upper_arm": "Arm", "forearm": "ForeArm", "hand": "Hand",
        "thigh": "UpLeg", "shin": "Leg", "foot": "Foot", "toe": "ToeBase"})
    joints = trunk([prefix + n for n in ("Hips", "Spine", "Spine2", "Neck", "Head")])
    joints += limbs(names, prefix + "Hips", prefix + "Spine2", end_hand=not fingers)
    if fingers:
        for side, s in (("Left", "l"), ("Right", "r")):
            for finger, tip in (("Index1", "hand_end:i"), ("Middle1", "hand_end:m")):
                joints += [(f"{prefix}{side}Hand{finger}", f"{prefix}{side}Hand", "hand_end", s),
                           (None, f"{prefix}{side}Hand{finger}", tip, s)]
    if prop:
        joints += [(prop, f"{prefix}RightHand", "hand:grip", "r"),
                   (None, prop, "hand:poletip", "r")]
    return joints, [prefix + "LeftLeg", prefix + "RightLeg"]


def rigify_def():
    # Blender Rigify deform bones: DEF- prefix, limbs split in two (thigh.L, thigh.L.001),
    # pelvis side bones and breasts as extra chains.
    joints = [("DEF-spine", None, "pelvis", "l")]
    for s in "LR":
        side = s.lower()
        joints += [(f"DEF-pelvis.{s}", "DEF-spine", "pelvis", side),
                   (None, f"DEF-pelvis.{s}", "pelvis:side", side)]
        chain = [("thigh", "thigh"), ("thigh.001", "thigh:mid"), ("shin", "shin"),
                 ("shin.001", "shin:mid"), ("foot", "foot"), ("toe", "toe")]
        parent = "DEF-spine"
        for bone, key in chain:
            name = f"DEF-{bone.split('.')[0]}.{s}" + (".001" if "." in bone else "")
            joints.append((name, parent, key, side))
            parent = name
        joints.append((None, parent, "toe_end", side))
    spine = [("DEF-spine.001", "spine"), ("DEF-spine.002", "spine:2"),
             ("DEF-spine.003", "chest"), ("DEF-spine.004", "neck"), ("DEF-spine.005", "neck:2"),
             ("DEF-spine.006", "head")]
    parent = "DEF-spine"
    for name, key in spine:
        joints.append((name, parent, key, "l"))
        parent = name
    joints.append((None, parent, "head_end", "l"))
    for s in "LR":
        side = s.lower()
        chain = [("shoulder", "clavicle"), ("upper_arm", "upper_arm"),
                 ("upper_arm.001", "upper_arm:mid"), ("forearm", "forearm"),
                 ("forearm.001", "forearm:mid"), ("hand", "hand")]
        parent = "DEF-spine.003"
        for bone, key in chain:
            name = f"DEF-{bone.split('.')[0]}.{s}" + (".001" if "." in bone else "")
            joints.append((name, parent, key, side))
            parent = name
        joints.append((None, parent, "hand_end", side))
        joints += [(f"DEF-breast.{s}", "DEF-spine.003", "chest:breast", side),
                   (None, f"DEF-breast.{s}", "chest:nipple", side)]
    return joints, ["DEF-shin.L", "DEF-shin.R"]


def cmu_motionbuilder():
    # CMU's MotionBuilder-friendly release: LHipJoint on the hips, LowerBack, Neck1,
    # LeftFingerBase and LThumb under the hand.
    names = sided("{Side}{W}", {
        "clavicle": "Shoulder", "upper_arm": "Arm", "forearm": "ForeArm", "hand": "Hand",
        "thigh": "UpLeg", "shin": "Leg", "foot": "Foot", "toe": "ToeBase"})
    joints = [("Hips", None, "pelvis", "l"), ("LowerBack", "Hips", "pelvis", "l"),
              ("Spine", "LowerBack", "spine", "l"), ("Spine1", "Spine", "chest", "l"),
              ("Neck", "Spine1", "neck", "l"), ("Neck1", "Neck", "neck:1", "l"),
              ("Head", "Neck1", "head", "l"), (None, "Head", "head_end", "l")]
    out = []
    for j in limbs(names, "Hips", "Spine1", end_hand=False):
        if j[0] in ("LeftUpLeg", "RightUpLeg"):
            joint = f"{j[0][0]}HipJoint"
            out += [(joint, "Hips", "pelvis", j[3]), (j[0], joint, "thigh", j[3])]
        else:
            out.append(j)
    for side, s in (("Left", "l"), ("Right", "r")):
        out += [(f"{side}FingerBase", f"{side}Hand", "hand_end", s),
                (f"{side}HandIndex1", f"{side}FingerBase", "hand_end:2", s),
                (None, f"{side}HandIndex1", "hand_end:tip", s),
                (f"{side[0]}Thumb", f"{side}Hand", "hand_end:thumb", s),
                (None, f"{side[0]}Thumb", "hand_end:thumbtip", s)]
    return joints + out, ["LeftLeg", "RightLeg"]


def makehuman():
    # MakeHuman's default skeleton as Blender exports it (Z up, decimetres): `Root` carries the
    # translation, `Hips` beside `Spine1` carries the legs through midline helpers `__UpLeg_L`,
    # eyes and jaw under `Head`.
    names = sided("{W}_{S}", {
        "clavicle": "Clavicle", "upper_arm": "UpArm", "forearm": "LoArm", "hand": "Hand",
        "thigh": "UpLeg", "shin": "LoLeg", "foot": "Foot", "toe": "Toe"})
    joints = [("Root", None, "pelvis", "l"), ("Hips", "Root", "pelvis", "l"),
              ("Spine1", "Root", "spine", "l"), ("Spine2", "Spine1", "spine:2", "l"),
              ("Spine3", "Spine2", "chest", "l"), ("Neck", "Spine3", "neck", "l"),
              ("Head", "Neck", "head", "l"), (None, "Head", "head_end", "l"),
              ("Eye_L", "Head", "head:eye", "l"), (None, "Eye_L", "head:eyetip", "l"),
              ("Eye_R", "Head", "head:eye", "r"), (None, "Eye_R", "head:eyetip", "r"),
              ("Jaw", "Head", "head:jaw", "l"), (None, "Jaw", "head:chin", "l")]
    out = []
    for j in limbs(names, "Hips", "Spine3"):
        if j[0] in ("UpLeg_L", "UpLeg_R"):
            helper = f"__{j[0]}"
            out += [(helper, "Hips", "pelvis", j[3]), (j[0], helper, "thigh", j[3])]
        else:
            out.append(j)
    return joints + out, ["LoLeg_L", "LoLeg_R"]


def biovision():
    # The classic 18-joint Biovision skeleton (LeftUpArm, LeftLowArm, LeftUpLeg, LeftLowLeg;
    # inches, arms down), no toe joint: the foot ends in an End Site at the toes.
    names = sided("{Side}{W}", {
        "clavicle": "Collar", "upper_arm": "UpArm", "forearm": "LowArm", "hand": "Hand",
        "thigh": "UpLeg", "shin": "LowLeg", "foot": "Foot"})
    joints = [("Hips", None, "pelvis", "l"), ("Chest", "Hips", "spine", "l"),
              ("Neck", "Chest", "neck", "l"), ("Head", "Neck", "head", "l"),
              (None, "Head", "head_end", "l")]
    out = []
    for j in limbs(names, "Hips", "Chest"):
        # The End Site after the foot sits at the toes.
        out.append((None, j[1], "toe", j[3]) if j[0] is None and j[2] == "toe_end" else j)
    return joints + out, ["LeftLowLeg", "RightLowLeg"]


# SMPL's template body (joint positions of the mean shape, rounded to 1 cm; x = left, y = up,
# z = forward, feet on the floor), in its T zero pose. HumanML3D's "joints to BVH" converters
# (momask's and T2M-GPT's `joints2bvh`, `smpl2bvh`) take their OFFSETs from it.
SMPL_BODY = {
    "pelvis": (0.0, 0.94, 0.03), "spine": (0.0, 1.05, 0.0), "spine:2": (0.0, 1.18, 0.0),
    "chest": (0.0, 1.24, 0.03), "neck": (0.0, 1.45, -0.02), "head": (0.0, 1.52, 0.04),
    "clavicle": (0.08, 1.36, -0.01), "upper_arm": (0.17, 1.39, -0.02),
    "forearm": (0.43, 1.38, -0.04), "hand": (0.68, 1.39, -0.04),
    "thigh": (0.07, 0.85, 0.02), "shin": (0.10, 0.47, 0.02), "foot": (0.09, 0.08, -0.03),
    "toe": (0.12, 0.02, 0.09),
}
# Where the template's pelvis is in the body model's own coordinates: the root OFFSET these
# converters write, while the root's position channels carry the pelvis's world position.
SMPL_PELVIS_IN_MODEL = (0.0, -0.22, 0.03)


def smpl_22(names):
    """SMPL's first 22 joints as HumanML3D has them (no hands: the wrists end the arms, the
    toes (`L_Foot`) the legs, the head the trunk, each with an End Site at the joint), written
    children in SMPL's joint order: hips before the spine, the neck before the collars.
    `names[key]` for the trunk, `names[(key, side)]` for the limbs."""
    joints = [(names["pelvis"], None, "pelvis", "l")]
    for s in "lr":
        parent = names["pelvis"]
        for key in ("thigh", "shin", "foot", "toe"):
            joints.append((names[(key, s)], parent, key, s))
            parent = names[(key, s)]
        joints.append((None, parent, "toe", s))
    parent = names["pelvis"]
    for key in ("spine", "spine:2", "chest", "neck", "head"):
        joints.append((names[key], parent, key, "l"))
        parent = names[key]
    joints.append((None, parent, "head", "l"))
    for s in "lr":
        parent = names["chest"]
        for key in ("clavicle", "upper_arm", "forearm", "hand"):
            joints.append((names[(key, s)], parent, key, s))
            parent = names[(key, s)]
        joints.append((None, parent, "hand", s))
    return joints, [names[("shin", "l")], names[("shin", "r")]]


def humanml3d_smpl():
    # SMPL's own joint names (`smpl2bvh`, HumanML3D's joint list: Pelvis, L_Hip, Spine1, …).
    names = sided("{S}_{W}", {
        "clavicle": "Collar", "upper_arm": "Shoulder", "forearm": "Elbow", "hand": "Wrist",
        "thigh": "Hip", "shin": "Knee", "foot": "Ankle", "toe": "Foot"})
    names.update({"pelvis": "Pelvis", "spine": "Spine1", "spine:2": "Spine2",
                  "chest": "Spine3", "neck": "Neck", "head": "Head"})
    return smpl_22(names)


def hik_joints2bvh():
    # HumanIK names on SMPL's 22 joints, metres (momask's `joints2bvh` template names the toe
    # `LeftToe`; HumanIK's own name is `LeftToeBase`).
    names = sided("{Side}{W}", {
        "clavicle": "Shoulder", "upper_arm": "Arm", "forearm": "ForeArm", "hand": "Hand",
        "thigh": "UpLeg", "shin": "Leg", "foot": "Foot", "toe": "ToeBase"})
    names.update({"pelvis": "Hips", "spine": "Spine", "spine:2": "Spine1", "chest": "Spine2",
                  "neck": "Neck", "head": "Head"})
    return smpl_22(names)


def unrecognisable():
    # A robot arm: one chain, nothing like a body.
    joints = [("base", None, "pelvis", "l"), ("link1", "base", "spine", "l"),
              ("link2", "link1", "chest", "l"), ("link3", "link2", "neck", "l"),
              ("gripper", "link3", "head", "l"), (None, "gripper", "head_end", "l")]
    return joints, []


# Extra points (body coordinates) for helpers, fingers, props and face joints.
EXTRA = {
    "pelvis:floor": (0.0, 0.0, 0.0),
    "spine:1": (0.0, 1.12, -0.01), "spine:2": (0.0, 1.18, -0.01), "spine:3": (0.0, 1.23, 0.0),
    "neck:1": (0.0, 1.54, 0.01), "neck:2": (0.0, 1.54, 0.01),
    "forearm:twist": (0.185, 1.28, -0.005), "foot:twist": (0.09, 0.28, 0.0),
    "hand_end:i": (0.20, 0.81, 0.05), "hand_end:m": (0.19, 0.80, 0.03),
    "hand_end:2": (0.19, 0.77, 0.03), "hand_end:tip": (0.19, 0.74, 0.03),
    "hand_end:thumb": (0.17, 0.85, 0.06), "hand_end:thumbtip": (0.16, 0.81, 0.09),
    "hand:hand": (0.19, 0.87, 0.02), "hand:in": (0.19, 0.86, 0.03),
    "hand:grip": (0.19, 0.86, 0.04), "hand:poletip": (0.19, 0.86, 1.54),
    "head:eye": (0.03, 1.66, 0.09), "head:eyetip": (0.03, 1.66, 0.10),
    "head:jaw": (0.0, 1.60, 0.05), "head:chin": (0.0, 1.56, 0.10),
    "pelvis:side": (0.12, 0.95, 0.0), "thigh:mid": (0.09, 0.70, 0.005),
    "shin:mid": (0.09, 0.285, -0.01), "upper_arm:mid": (0.185, 1.285, -0.005),
    "forearm:mid": (0.19, 1.015, 0.005), "chest:breast": (0.1, 1.30, 0.08),
    "chest:nipple": (0.1, 1.30, 0.12),
}
for k, v in EXTRA.items():
    BODY[k] = v


def main():
    write("xsens_mvn.bvh", *xsens(), arms="t")
    write("biped_zup_inches.bvh", *biped(), axes=Z_UP_FACE_Y, unit=0.0254)
    write("daz_poser_apose.bvh", *daz(), arms="a")
    write("unreal_zup.bvh", *unreal(), axes=Z_UP_FACE_Y)
    write("smpl_metres.bvh", *smpl(), unit=1.0, arms="t")
    write("asf_millimetres.bvh", *asf(), unit=0.001)
    write("rokoko_fingers_face.bvh", *rokoko())
    joints, shins, _ = unnamed()
    write("unnamed_joints.bvh", joints, shins, yaw=130.0)
    write("mixamo_zero_pose_lying.bvh", *mixamo(), lying=True)
    write("mixamo_prop_in_hand.bvh", *mixamo(prefix="", fingers=True, prop="Object01"))
    write("rigify_def_segments.bvh", *rigify_def(), unit=1.0)
    write("cmu_motionbuilder.bvh", *cmu_motionbuilder())
    write("unrecognisable_chain.bvh", *unrecognisable())
    write("makehuman_zup_decimetres_walk.bvh", *makehuman(), axes=Z_UP_FACE_NEG_Y, unit=0.1,
          gait="walk")
    write("biovision_inches_sprint.bvh", *biovision(), unit=0.0254, gait="sprint")
    # HumanML3D's converters: metres, Y up, SMPL's T zero pose (every frame turns the arms
    # down), the root OFFSET where SMPL's model has its pelvis, `Zrotation Yrotation
    # Xrotation`, End Sites at their joints, 20 fps.
    humanml3d = dict(unit=1.0, gait="walk20", body=SMPL_BODY, arms_down=80.0,
                     root_offset=SMPL_PELVIS_IN_MODEL, rotation_order="zyx", zero_ends=True)
    write("humanml3d_smpl_walk.bvh", *humanml3d_smpl(), **humanml3d)
    write("hik_metres_walk.bvh", *hik_joints2bvh(), **humanml3d)


if __name__ == "__main__":
    main()
