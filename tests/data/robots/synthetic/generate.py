#!/usr/bin/env python3
"""Writes the small robots of each class that issue 34 names (run from this folder): one
humanoid (1.3 m, or 0.45 m for the servo class), written in the forms real files take.

- legacy_coordinate_local.xml: an older MJCF, `<compiler coordinate="local" angle="degree">`,
  capsules by `fromto`, inertia from geoms;
- urdf_mujoco_block.urdf: a URDF prepared for MuJoCo: `<mujoco><compiler discardvisual="false"
  fusestatic="true" balanceinertia="true" strippath="false" meshdir="../meshes"/></mujoco>`,
  visuals as primitives, a fixed IMU link;
- fixed_base.xml: no free joint (dm_control style: the user's code adds it);
- fixed_base_y_up.xml: no free joint, and lying along +y at qpos0 (Y up, as dm_control's CMU
  humanoid);
- unlimited_ankle_roll.xml: the ankle roll hinge has no range;
- kid_servo.xml: a 0.45 m servo humanoid: arms start with the shoulder pitch, no wrist, the
  forearm body's origin at the elbow, every range symmetric;
- cluttered.xml: a full-size humanoid with sensors, cameras, a lidar, passive toe links and
  five-fingered hands (44 hinges).
"""

import math

INERTIAL = (0.5, 0.002)


class Body:
    def __init__(self, name, pos, joints=(), geoms=(), children=(), mass=INERTIAL[0]):
        self.name, self.pos, self.joints = name, pos, list(joints)
        self.geoms, self.children, self.mass = list(geoms), list(children), mass


def capsule(a, b, r=0.03, visual=False):
    return ("capsule", a, b, r, visual)


def box(pos, half, visual=False):
    return ("box", pos, half, visual)


def sphere(pos, r, visual=False):
    return ("sphere", pos, r, visual)


def leg(side, y, ankle_limited=True, toes=False, scale=1.0):
    s = side[0]
    L = lambda v: tuple(x * scale for x in v)
    toe = []
    if toes:
        # A passive toe link: a hinge with a range, no motor (Cassie and Digit have such).
        toe = [Body(f"{side}_toe", L((0.1, 0, -0.05)), [(f"{s}_toe_passive", "0 1 0", (-0.5, 0.5))],
                    [box(L((0.03, 0, -0.01)), L((0.03, 0.04, 0.01)))], mass=0.1)]
    foot = Body(f"{side}_foot", (0, 0, 0),
                [(f"{s}_ankle_roll", "1 0 0", (-0.4, 0.4) if ankle_limited else None)],
                [box(L((0.04, 0, -0.05)), L((0.1, 0.04, 0.02)))], toe)
    ankle = Body(f"{side}_ankle_pitch", L((0, 0, -0.35)), [(f"{s}_ankle_pitch", "0 1 0", (-0.8, 0.8))],
                 [], [foot])
    shin = Body(f"{side}_shin", L((0, 0, -0.35)), [(f"{s}_knee", "0 1 0", (0.0, 2.4))],
                [capsule((0, 0, 0), L((0, 0, -0.33)), 0.03 * scale)], [ankle])
    thigh = Body(f"{side}_thigh", (0, 0, 0), [(f"{s}_hip_yaw", "0 0 1", (-1.0, 1.0))],
                 [capsule((0, 0, 0), L((0, 0, -0.33)), 0.04 * scale)], [shin])
    roll = Body(f"{side}_hip_roll", (0, 0, 0), [(f"{s}_hip_roll", "1 0 0", (-0.5, 0.8) if y > 0 else (-0.8, 0.5))],
                [], [thigh])
    return Body(f"{side}_hip_pitch", L((0, y, -0.05)), [(f"{s}_hip_pitch", "0 1 0", (-2.0, 2.0))], [], [roll])


def finger(side, s, k, dy, dz):
    tip = Body(f"{side}_finger{k}_3", (0, 0, -0.025), [(f"{s}_finger{k}_3", "0 1 0", (0.0, 1.5))],
               [capsule((0, 0, 0), (0, 0, -0.02), 0.006)], mass=0.01)
    mid = Body(f"{side}_finger{k}_2", (0, 0, -0.03), [(f"{s}_finger{k}_2", "0 1 0", (0.0, 1.5))],
               [capsule((0, 0, 0), (0, 0, -0.025), 0.007)], [tip], mass=0.01)
    return Body(f"{side}_finger{k}_1", (dz, dy, -0.07), [(f"{s}_finger{k}_1", "0 1 0", (0.0, 1.5))],
                [capsule((0, 0, 0), (0, 0, -0.03), 0.008)], [mid], mass=0.01)


def arm(side, y, fingers=False):
    s = side[0]
    if fingers:
        hand_kids = [finger(side, s, k, dy, 0.0) for k, dy in enumerate((-0.03, -0.015, 0.0, 0.015))]
        hand_kids.append(finger(side, s, 4, 0.03 if y > 0 else -0.03, 0.02))
    else:
        hand_kids = [Body(f"{side}_hand_tip", (0, 0, -0.08), [], [], mass=0.05)]
    hand = Body(f"{side}_wrist", (0, 0, -0.22), [(f"{s}_wrist_pitch", "0 1 0", (-1.0, 1.0))],
                [capsule((0, 0, 0), (0, 0, -0.05), 0.02)], hand_kids)
    elbow = Body(f"{side}_elbow", (0, 0, -0.25), [(f"{s}_elbow", "0 1 0", (-2.5, 0.0))],
                 [capsule((0, 0, 0), (0, 0, -0.2))], [hand])
    upper = Body(f"{side}_upper_arm", (0, 0, 0), [(f"{s}_shoulder_yaw", "0 0 1", (-1.5, 1.5))],
                 [capsule((0, 0, 0), (0, 0, -0.23))], [elbow])
    roll = Body(f"{side}_shoulder_roll", (0, 0, 0), [(f"{s}_shoulder_roll", "1 0 0", (-1.5, 1.5))], [], [upper])
    return Body(f"{side}_shoulder_pitch", (0, y, 0.3), [(f"{s}_shoulder_pitch", "0 1 0", (-3.0, 3.0))], [], [roll])


def servo_arm(side, y):
    # Shoulder pitch first, then roll; the forearm body starts at the elbow and nothing
    # follows it (no wrist, no hand body). Ranges symmetric, as servos have them.
    s = side[0]
    r = (-2.8, 2.8)
    fore = Body(f"{side}_el_link", (0, 0, -0.09), [(f"{s}_el", "0 1 0", r)],
                [capsule((0, 0, -0.01), (0, 0, -0.12), 0.016)], mass=0.05)
    roll = Body(f"{side}_sho_roll_link", (0, 0.02 * (1 if y > 0 else -1), 0), [(f"{s}_sho_roll", "-1 0 0", r)],
                [capsule((0, 0, -0.01), (0, 0, -0.08), 0.018)], [fore], mass=0.15)
    return Body(f"{side}_sho_pitch_link", (0, y, 0.11), [(f"{s}_sho_pitch", "0 1 0", r)],
                [box((0, 0, 0), (0.012, 0.012, 0.012))], [roll], mass=0.02)


def servo_leg(side, y):
    s = side[0]
    r = (-2.8, 2.8)
    sgn = 1 if y > 0 else -1
    foot = Body(f"{side}_ank_roll_link", (0, 0, 0), [(f"{s}_ank_roll", "1 0 0", r)],
                [box((0.01, 0.005 * sgn, -0.03), (0.06, 0.035, 0.005))], mass=0.07)
    ankle = Body(f"{side}_ank_pitch_link", (0, 0, -0.11), [(f"{s}_ank_pitch", f"0 {-sgn} 0", r)], [], [foot], mass=0.18)
    knee = Body(f"{side}_knee_link", (0, 0, -0.11), [(f"{s}_knee", f"0 {sgn} 0", r)],
                [capsule((0, 0, -0.01), (0, 0, -0.1), 0.02)], [ankle], mass=0.04)
    pitch = Body(f"{side}_hip_pitch_link", (0, 0, 0), [(f"{s}_hip_pitch", f"0 {sgn} 0", r)],
                 [capsule((0, 0, -0.01), (0, 0, -0.1), 0.022)], [knee], mass=0.12)
    roll = Body(f"{side}_hip_roll_link", (0, 0, -0.03), [(f"{s}_hip_roll", "-1 0 0", r)], [], [pitch], mass=0.18)
    return Body(f"{side}_hip_yaw_link", (0, y, 0), [(f"{s}_hip_yaw", "0 0 -1", r)], [], [roll], mass=0.02)


def humanoid(ankle_limited=True, fingers=False, extras=False, toes=False):
    torso_kids = [arm("left", 0.18, fingers), arm("right", -0.18, fingers),
                  Body("head", (0, 0, 0.42), [("neck_yaw", "0 0 1", (-1.0, 1.0))],
                       [sphere((0, 0, 0), 0.09)],
                       [Body("head_camera", (0.08, 0, 0.02), [], [box((0, 0, 0), (0.01, 0.03, 0.01), True)], mass=0.05),
                        Body("lidar_link", (0, 0, 0.1), [], [sphere((0, 0, 0), 0.03, True)], mass=0.1)]
                       if extras else [])]
    if extras:
        torso_kids += [Body("imu_link", (0, 0, 0.05), [], [], mass=0.02),
                       Body("chest_realsense", (0.09, 0, 0.25), [], [box((0, 0, 0), (0.01, 0.05, 0.015), True)], mass=0.08),
                       Body("battery", (-0.08, 0, 0.15), [], [box((0, 0, 0), (0.03, 0.08, 0.08))], mass=2.0)]
    torso = Body("torso", (0, 0, 0.1), [("waist_yaw", "0 0 1", (-1.0, 1.0))],
                 [capsule((0, 0, 0), (0, 0, 0.3), 0.08)], torso_kids)
    kids = [leg("left", 0.09, ankle_limited, toes), leg("right", -0.09, ankle_limited, toes), torso]
    return Body("pelvis", (0, 0, 0.85), [], [box((0, 0, 0), (0.08, 0.12, 0.06))], kids, mass=3.0)


def servo_humanoid():
    head = Body("head_pan_link", (0, 0, 0.1365), [("head_pan", "0 0 1", (-2.8, 2.8))],
                [sphere((0, 0, 0.04), 0.045)], mass=0.14)
    kids = [servo_leg("left", 0.035), servo_leg("right", -0.035),
            servo_arm("left", 0.06), servo_arm("right", -0.06), head]
    return Body("body_link", (0, 0, 0.29), [], [box((-0.01, 0, 0.06), (0.045, 0.065, 0.07))], kids, mass=1.3)


def fmt(v):
    return " ".join(f"{x:.6g}" for x in v)


def mjcf_geom(g, legacy):
    kind = g[0]
    vis = ' contype="0" conaffinity="0" group="1"' if g[-1] else ""
    if kind == "capsule":
        _, a, b, r, _ = g
        return f'<geom type="capsule" fromto="{fmt(a)} {fmt(b)}" size="{r}"{vis}/>'
    if kind == "box":
        _, pos, half, _ = g
        return f'<geom type="box" pos="{fmt(pos)}" size="{fmt(half)}"{vis}/>'
    _, pos, r, _ = g
    return f'<geom type="sphere" pos="{fmt(pos)}" size="{r}"{vis}/>'


def mjcf_body(b, depth, free, legacy, quat=None):
    pad = "  " * depth
    q = f' quat="{quat}"' if quat else ""
    out = [f'{pad}<body name="{b.name}" pos="{fmt(b.pos)}"{q}>']
    if not legacy:
        i = INERTIAL[1] * b.mass
        out.append(f'{pad}  <inertial pos="0 0 0" mass="{b.mass}" diaginertia="{i:.6g} {i:.6g} {i:.6g}"/>')
    if free:
        out.append(f'{pad}  <freejoint name="root"/>')
    for name, axis, rng in b.joints:
        if rng is None:
            r = ""
        elif legacy:
            r = f' range="{math.degrees(rng[0]):.4g} {math.degrees(rng[1]):.4g}"'
        else:
            r = f' range="{rng[0]} {rng[1]}"'
        out.append(f'{pad}  <joint name="{name}" axis="{axis}"{r}/>')
    geoms = b.geoms
    if legacy and not geoms:
        # Mass from geoms: every body has one (the joint housings).
        geoms = [sphere((0, 0, 0), 0.03)]
    out += [pad + "  " + mjcf_geom(g, legacy) for g in geoms]
    for c in b.children:
        out += mjcf_body(c, depth + 1, False, legacy)
    out.append(f"{pad}</body>")
    return out


def mjcf(root, model, free=True, legacy=False, quat=None, comment=""):
    compiler = ('<compiler coordinate="local" angle="degree" inertiafromgeom="true"/>'
                if legacy else '<compiler angle="radian"/>')
    lines = [f"<!-- {comment} -->", f'<mujoco model="{model}">', f"  {compiler}", "  <worldbody>",
             '    <geom name="floor" type="plane" size="5 5 0.1"/>']
    lines += mjcf_body(root, 2, free, legacy, quat)
    lines += ["  </worldbody>", "</mujoco>", ""]
    return "\n".join(lines)


def urdf_geometry(g):
    kind = g[0]
    if kind == "capsule":
        _, a, b, r, _ = g
        d = [y - x for x, y in zip(a, b)]
        length = math.sqrt(sum(x * x for x in d))
        mid = [(x + y) / 2 for x, y in zip(a, b)]
        # A vertical capsule (every capsule here is along z): a cylinder of its length.
        return mid, f'<cylinder radius="{r}" length="{length:.6g}"/>'
    if kind == "box":
        _, pos, half, _ = g
        return pos, f'<box size="{fmt([2 * h for h in half])}"/>'
    _, pos, r, _ = g
    return pos, f'<sphere radius="{r}"/>'


def urdf(root, model, comment):
    links, joints = [], []

    def walk(b, parent):
        i = INERTIAL[1] * b.mass
        elems = [f'    <inertial><mass value="{b.mass}"/><inertia ixx="{i:.6g}" iyy="{i:.6g}" izz="{i:.6g}" ixy="0" ixz="0" iyz="0"/></inertial>']
        for g in b.geoms:
            pos, geo = urdf_geometry(g)
            tag = "visual" if g[-1] else "collision"
            elems.append(f'    <{tag}><origin xyz="{fmt(pos)}"/><geometry>{geo}</geometry></{tag}>')
            if tag == "collision":
                # The visual a mesh would be, here a primitive.
                elems.append(f'    <visual><origin xyz="{fmt(pos)}"/><geometry>{geo}</geometry></visual>')
        links.append(f'  <link name="{b.name}">\n' + "\n".join(elems) + "\n  </link>")
        # Several joints on one body become a chain of links (URDF: one joint per link).
        prev, pos = parent, b.pos
        for k, (name, axis, rng) in enumerate(b.joints):
            child = b.name if k == len(b.joints) - 1 else f"{b.name}_{k}"
            if child != b.name:
                links.append(f'  <link name="{child}"><inertial><mass value="0.01"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>')
            if prev is not None:
                limit = (f'<limit lower="{rng[0]}" upper="{rng[1]}" effort="10" velocity="8"/>'
                         if rng else "")
                kind = "revolute" if rng else "continuous"
                joints.append(f'  <joint name="{name}" type="{kind}"><parent link="{prev}"/><child link="{child}"/>'
                              f'<origin xyz="{fmt(pos)}"/><axis xyz="{axis}"/>{limit}</joint>')
            prev, pos = child, (0, 0, 0)
        if not b.joints and parent is not None:
            joints.append(f'  <joint name="{b.name}_fixed" type="fixed"><parent link="{parent}"/><child link="{b.name}"/>'
                          f'<origin xyz="{fmt(b.pos)}"/></joint>')
        for c in b.children:
            walk(c, b.name)

    walk(root, None)
    joints.append('  <joint name="imu_fixed" type="fixed"><parent link="torso"/><child link="imu_link"/><origin xyz="0 0 0.05"/></joint>')
    links.append('  <link name="imu_link"/>')
    return (f'<?xml version="1.0"?>\n<!-- {comment} -->\n<robot name="{model}">\n'
            '  <mujoco>\n    <compiler meshdir="../meshes" discardvisual="false" fusestatic="true" '
            'balanceinertia="true" strippath="false"/>\n  </mujoco>\n'
            + "\n".join(links + joints) + "\n</robot>\n")


def main():
    gen = "written by tests/data/robots/synthetic/generate.py"
    files = {
        "legacy_coordinate_local.xml": mjcf(humanoid(), "legacy", legacy=True, comment=gen),
        "urdf_mujoco_block.urdf": urdf(humanoid(), "urdf_block", gen),
        "fixed_base.xml": mjcf(humanoid(), "fixed_base", free=False, comment=gen),
        "fixed_base_y_up.xml": mjcf(humanoid(), "fixed_base_y_up", free=False,
                                    quat="0.7071068 0.7071068 0 0", comment=gen),
        "unlimited_ankle_roll.xml": mjcf(humanoid(ankle_limited=False), "unlimited_ankle",
                                         comment=gen),
        "kid_servo.xml": mjcf(servo_humanoid(), "kid_servo", comment=gen),
        "cluttered.xml": mjcf(humanoid(fingers=True, extras=True, toes=True), "cluttered",
                              comment=gen),
    }
    for name, text in files.items():
        with open(name, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
