#!/usr/bin/env python3
"""Writes the small test robots of crates/retarget/tests/auto.rs (run from this folder).

One humanoid, 1.3 m, in five variants the recogniser must handle or refuse:
- numbered.xml: bodies link1..., joints joint1... (no name says anything);
- facing_y.xml: numbered too, and turned to face +y at qpos0;
- fingers.xml: named, with three two-link fingers on each hand and an IMU and a camera;
- wheeled.xml: the feet replaced by wheels (continuous joints): not a biped;
- armless.xml: no arms: not a two-armed biped.
"""

counter = {"body": 0, "joint": 0}


def name(kind, given, numbered):
    counter[kind] += 1
    return f"{'link' if kind == 'body' else 'joint'}{counter[kind]}" if numbered else given


# Every body weighs something: MuJoCo refuses moving bodies without mass and inertia.
INERTIAL = '<inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/>'


def body(given, pos, inner, numbered, quat=None):
    q = f' quat="{quat}"' if quat else ""
    return f'<body name="{name("body", given, numbered)}" pos="{pos}"{q}>{INERTIAL}{inner}</body>'


def hinge(given, axis, lo, hi, numbered):
    rng = f' range="{lo} {hi}"' if lo is not None else ""
    return f'<joint name="{name("joint", given, numbered)}" axis="{axis}"{rng}/>'


def capsule(a, b, r=0.03):
    return f'<geom type="capsule" fromto="{a} {b}" size="{r}" contype="0" conaffinity="0"/>'


def leg(side, y, numbered, wheel):
    s = side[0]
    if wheel:
        foot = body(f"{side}_wheel", "0 0 -0.35",
                    hinge(f"{side}_wheel_joint", "0 1 0", None, None, numbered)
                    + '<geom type="cylinder" size="0.08 0.02" quat="0.7071 0.7071 0 0" pos="0 0 -0.02"/>',
                    numbered)
    else:
        foot = body(f"{side}_ankle_pitch", "0 0 -0.35",
                    hinge(f"{s}_ankle_pitch", "0 1 0", -0.8, 0.8, numbered)
                    + body(f"{side}_foot", "0 0 0",
                           hinge(f"{s}_ankle_roll", "1 0 0", -0.4, 0.4, numbered)
                           + '<geom type="box" size="0.1 0.04 0.02" pos="0.04 0 -0.05"/>',
                           numbered),
                    numbered)
    knee = body(f"{side}_shin", "0 0 -0.35",
                hinge(f"{s}_knee", "0 1 0", 0.0, 2.4, numbered)
                + capsule("0 0 0", "0 0 -0.33") + foot, numbered)
    hip = body(f"{side}_hip_pitch", f"0 {y} -0.05",
               hinge(f"{s}_hip_pitch", "0 1 0", -2.0, 2.0, numbered)
               + body(f"{side}_hip_roll", "0 0 0",
                      hinge(f"{s}_hip_roll", "1 0 0", -0.5, 0.8 if y > 0 else 0.5, numbered)
                      + body(f"{side}_thigh", "0 0 0",
                             hinge(f"{s}_hip_yaw", "0 0 1", -1.0, 1.0, numbered)
                             + capsule("0 0 0", "0 0 -0.33") + knee, numbered),
                      numbered),
               numbered)
    return hip


def arm(side, y, numbered, fingers):
    s = side[0]
    hand_inner = ""
    if fingers:
        for k, dy in enumerate([-0.02, 0.0, 0.02]):
            hand_inner += body(f"{side}_finger{k}_1", f"0 {dy} -0.06",
                               hinge(f"{s}_finger{k}_1", "0 1 0", 0.0, 1.5, numbered)
                               + body(f"{side}_finger{k}_2", "0 0 -0.03",
                                      hinge(f"{s}_finger{k}_2", "0 1 0", 0.0, 1.5, numbered),
                                      numbered),
                               numbered)
    else:
        hand_inner = body(f"{side}_hand_tip", "0 0 -0.08", "", numbered)
    wrist = body(f"{side}_wrist", "0 0 -0.22",
                 hinge(f"{s}_wrist_pitch", "0 1 0", -1.0, 1.0, numbered)
                 + capsule("0 0 0", "0 0 -0.05", 0.02) + hand_inner, numbered)
    elbow = body(f"{side}_elbow", "0 0 -0.25",
                 hinge(f"{s}_elbow", "0 1 0", -2.5, 0.0, numbered)
                 + capsule("0 0 0", "0 0 -0.2") + wrist, numbered)
    return body(f"{side}_shoulder_pitch", f"0 {y} 0.3",
                hinge(f"{s}_shoulder_pitch", "0 1 0", -3.0, 3.0, numbered)
                + body(f"{side}_shoulder_roll", "0 0 0",
                       hinge(f"{s}_shoulder_roll", "1 0 0", -1.5, 1.5, numbered)
                       + body(f"{side}_upper_arm", "0 0 0",
                              hinge(f"{s}_shoulder_yaw", "0 0 1", -1.5, 1.5, numbered)
                              + capsule("0 0 0", "0 0 -0.23") + elbow, numbered),
                       numbered),
                numbered)


def robot(numbered=False, quat=None, fingers=False, wheel=False, arms=True):
    counter.update(body=0, joint=0)
    extras = ""
    if fingers:
        extras = (body("imu", "0 0 0.1", "", numbered)
                  + body("camera_link", "0.05 0 0.52", "", numbered))
    upper = body("torso", "0 0 0.1",
                 hinge("waist_yaw", "0 0 1", -1.0, 1.0, numbered)
                 + capsule("0 0 0", "0 0 0.3", 0.08)
                 + (arm("left", 0.18, numbered, fingers) + arm("right", -0.18, numbered, fingers)
                    if arms else "")
                 + body("head", "0 0 0.42", '<geom type="sphere" size="0.09" contype="0" conaffinity="0"/>', numbered)
                 + extras,
                 numbered)
    base = body("pelvis", "0 0 0.85",
                '<freejoint name="root"/><geom type="box" size="0.08 0.12 0.06" contype="0" conaffinity="0"/>'
                + leg("left", 0.09, numbered, wheel) + leg("right", -0.09, numbered, wheel) + upper,
                numbered, quat)
    return ('<mujoco model="small">\n  <compiler angle="radian"/>\n  <worldbody>\n    '
            '<geom name="floor" type="plane" size="5 5 0.1"/>\n    ' + base
            + "\n  </worldbody>\n</mujoco>\n")


for file, kw in [
    ("numbered.xml", dict(numbered=True)),
    ("facing_y.xml", dict(numbered=True, quat="0.70710678 0 0 0.70710678")),
    ("fingers.xml", dict(fingers=True)),
    ("wheeled.xml", dict(wheel=True)),
    ("armless.xml", dict(arms=False)),
]:
    with open(file, "w") as f:
        f.write(robot(**kw))
