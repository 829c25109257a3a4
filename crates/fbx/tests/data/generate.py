#!/usr/bin/env python3
"""Writes the small FBX files of `crates/fbx/tests/formats.rs` (run from this folder).

No public ASCII FBX with an animated human exists (`../shared/data/fbx/README.md`), so these
are written here, as the FBX SDK writes ASCII files, with linear keys whose values the tests
compute by hand:

- `mixamo_zup_7400_ascii.fbx`: FBX 7.4 ASCII, Z up (3ds Max's axes), centimetres, 30 fps,
  a `mixamorig:` skeleton under a Null, a camera (no skeleton), a prop with a pre-rotation
  and a rotation pivot, and two takes: `idle` (a little spine sway) and `walk` (the hips
  forward at 1 m/s, legs and arms swinging): `walk` has the most motion.
- `biped_6100_ascii.fbx`: FBX 6.1 ASCII (keys under `Takes`), Y up, a 3ds Max Biped
  (`Bip01 L Thigh`), one take starting at frame 0.
- error cases: `no_skeleton_7400_ascii.fbx` (a camera and a mesh), `no_animation_7400_ascii.fbx`
  (a skeleton, no take), `empty_take_7400_ascii.fbx` (a take without keys), and
  `default_rate_7400_ascii.fbx` (TimeMode 0).

Pure Python, no dependencies; the output is deterministic.
"""

import math

KTIME = 46186158000  # FBX ticks per second

# The body in centimetres, Z up, facing -Y (the front axis points at the viewer): joint,
# parent, offset. The subject's left is +X.
BODY = [
    ("Hips", None, (0, 0, 100)),
    ("Spine", "Hips", (0, 0, 10)),
    ("Spine1", "Spine", (0, 0, 10)),
    ("Spine2", "Spine1", (0, 0, 10)),
    ("Neck", "Spine2", (0, 0, 15)),
    ("Head", "Neck", (0, 0, 10)),
    ("HeadTop_End", "Head", (0, 0, 18)),
]
for side, sx in (("Left", 1), ("Right", -1)):
    BODY += [
        (f"{side}Shoulder", "Spine2", (3 * sx, 0, 12)),
        (f"{side}Arm", f"{side}Shoulder", (12 * sx, 0, 0)),
        (f"{side}ForeArm", f"{side}Arm", (28 * sx, 0, 0)),
        (f"{side}Hand", f"{side}ForeArm", (25 * sx, 0, 0)),
        (f"{side}HandIndex1", f"{side}Hand", (8 * sx, 0, 0)),
        (f"{side}UpLeg", "Hips", (9 * sx, 0, -5)),
        (f"{side}Leg", f"{side}UpLeg", (0, 0, -43)),
        (f"{side}Foot", f"{side}Leg", (0, 0, -42)),
        (f"{side}ToeBase", f"{side}Foot", (0, -12, -8)),
        (f"{side}Toe_End", f"{side}ToeBase", (0, -6, 0)),
    ]


def num(v):
    """A number as the SDK writes it (shortest that round-trips, no trailing .0)."""
    text = repr(float(v))
    return text[:-2] if text.endswith(".0") else text


def walk_curves(duration, step=0.1):
    """Per (joint, property, axis): key times (s) and values of the `walk` take."""
    times = [round(k * step, 10) for k in range(int(round(duration / step)) + 1)]
    out = {
        ("Hips", "T", 0): [0.0 for t in times],
        ("Hips", "T", 1): [-100.0 * t for t in times],
        ("Hips", "T", 2): [100.0 + 2.0 * math.sin(2 * math.pi * t) for t in times],
    }
    for side, sign in (("Left", 1), ("Right", -1)):
        swing = [25.0 * sign * math.sin(math.pi * t) for t in times]
        out[(f"{side}UpLeg", "R", 0)] = swing
        out[(f"{side}Leg", "R", 0)] = [-20.0 * max(0.0, -s / 25.0) for s in swing]
        out[(f"{side}Arm", "R", 0)] = [-0.6 * s for s in swing]
        out[(f"{side}Arm", "R", 1)] = [-60.0 * sign for _ in times]
    return times, out


def idle_curves(duration, step=0.25):
    times = [round(k * step, 10) for k in range(int(round(duration / step)) + 1)]
    return times, {("Spine", "R", 0): [2.0 * math.sin(2 * math.pi * t) for t in times]}


def header(version, up, front, front_sign, coord, unit, time_mode):
    major, minor = version // 1000, version // 100 % 10
    return f"""; FBX {major}.{minor}.0 project file
; written by crates/fbx/tests/data/generate.py
; ----------------------------------------------------

FBXHeaderExtension:  {{
\tFBXHeaderVersion: 1003
\tFBXVersion: {version}
\tCreator: "retarget tests/data/generate.py"
\tSceneInfo: "SceneInfo::GlobalInfo", "UserData" {{
\t\tType: "UserData"
\t\tVersion: 100
\t\tProperties70:  {{
\t\t\tP: "Original|ApplicationVendor", "KString", "", "", "retarget"
\t\t\tP: "Original|ApplicationName", "KString", "", "", "generate.py"
\t\t\tP: "Original|ApplicationVersion", "KString", "", "", "1"
\t\t}}
\t}}
}}
GlobalSettings:  {{
\tVersion: 1000
\tProperties70:  {{
\t\tP: "UpAxis", "int", "Integer", "",{up}
\t\tP: "UpAxisSign", "int", "Integer", "",1
\t\tP: "FrontAxis", "int", "Integer", "",{front}
\t\tP: "FrontAxisSign", "int", "Integer", "",{front_sign}
\t\tP: "CoordAxis", "int", "Integer", "",{coord}
\t\tP: "CoordAxisSign", "int", "Integer", "",1
\t\tP: "UnitScaleFactor", "double", "Number", "",{num(unit)}
\t\tP: "TimeMode", "enum", "", "",{time_mode}
\t\tP: "CustomFrameRate", "double", "Number", "",-1
\t}}
}}
"""


class Writer74:
    """Objects and connections of an FBX 7.4 ASCII file."""

    def __init__(self):
        self.objects = []
        self.connections = []
        self.next_id = 1000

    def new_id(self):
        self.next_id += 1
        return self.next_id

    def model(self, name, kind, parent, props):
        mid, aid = self.new_id(), self.new_id()
        attr = {"LimbNode": "LimbNode", "Null": "Null", "Camera": "Camera"}[kind]
        flags = {"LimbNode": "Skeleton", "Null": "Null", "Camera": "Camera"}[kind]
        self.objects.append(
            f'\tNodeAttribute: {aid}, "NodeAttribute::", "{attr}" {{\n\t\tTypeFlags: "{flags}"\n\t}}\n'
        )
        lines = "".join(f'\t\t\tP: {p}\n' for p in props)
        self.objects.append(
            f'\tModel: {mid}, "Model::{name}", "{kind}" {{\n\t\tVersion: 232\n'
            f'\t\tProperties70:  {{\n{lines}\t\t}}\n\t\tShading: T\n\t\tCulling: "CullingOff"\n\t}}\n'
        )
        self.connections.append(f'\tC: "OO",{aid},{mid}\n')
        self.connections.append(f'\tC: "OO",{mid},{parent if parent is not None else 0}\n')
        return mid

    def mesh(self, name):
        gid, mid = self.new_id(), self.new_id()
        self.objects.append(
            f'\tGeometry: {gid}, "Geometry::{name}", "Mesh" {{\n'
            f'\t\tVertices: *9 {{\n\t\t\ta: 0,0,0,1,0,0,0,1,0\n\t\t}}\n'
            f'\t\tPolygonVertexIndex: *3 {{\n\t\t\ta: 0,1,-3\n\t\t}}\n\t\tGeometryVersion: 124\n\t}}\n'
        )
        self.objects.append(f'\tModel: {mid}, "Model::{name}", "Mesh" {{\n\t\tVersion: 232\n\t}}\n')
        self.connections.append(f'\tC: "OO",{gid},{mid}\n\tC: "OO",{mid},0\n')

    def take(self, name, start, stop, times, curves, models):
        sid, lid = self.new_id(), self.new_id()
        self.objects.append(
            f'\tAnimationStack: {sid}, "AnimStack::{name}", "" {{\n\t\tProperties70:  {{\n'
            f'\t\t\tP: "LocalStart", "KTime", "Time", "",{round(start * KTIME)}\n'
            f'\t\t\tP: "LocalStop", "KTime", "Time", "",{round(stop * KTIME)}\n'
            f'\t\t\tP: "ReferenceStart", "KTime", "Time", "",{round(start * KTIME)}\n'
            f'\t\t\tP: "ReferenceStop", "KTime", "Time", "",{round(stop * KTIME)}\n'
            f"\t\t}}\n\t}}\n"
        )
        self.objects.append(f'\tAnimationLayer: {lid}, "AnimLayer::BaseLayer", "" {{\n\t}}\n')
        self.connections.append(f'\tC: "OO",{lid},{sid}\n')
        nodes = {}
        for (joint, prop, axis), values in sorted(curves.items()):
            key = (joint, prop)
            if key not in nodes:
                nid = self.new_id()
                nodes[key] = nid
                full = {"T": "Lcl Translation", "R": "Lcl Rotation"}[prop]
                self.objects.append(
                    f'\tAnimationCurveNode: {nid}, "AnimCurveNode::{prop}", "" {{\n\t\tProperties70:  {{\n'
                    f'\t\t\tP: "d|X", "Number", "", "A",0\n\t\t\tP: "d|Y", "Number", "", "A",0\n'
                    f'\t\t\tP: "d|Z", "Number", "", "A",0\n\t\t}}\n\t}}\n'
                )
                self.connections.append(f'\tC: "OO",{nid},{lid}\n')
                self.connections.append(f'\tC: "OP",{nid},{models[joint]}, "{full}"\n')
            cid = self.new_id()
            n = len(times)
            ktimes = ",".join(str(round(t * KTIME)) for t in times)
            kvalues = ",".join(num(v) for v in values)
            self.objects.append(
                f'\tAnimationCurve: {cid}, "AnimCurve::", "" {{\n\t\tDefault: {num(values[0])}\n'
                f"\t\tKeyVer: 4009\n\t\tKeyTime: *{n} {{\n\t\t\ta: {ktimes}\n\t\t}}\n"
                f"\t\tKeyValueFloat: *{n} {{\n\t\t\ta: {kvalues}\n\t\t}}\n"
                # 4: linear interpolation (FbxAnimCurveDef::eInterpolationLinear)
                f"\t\tKeyAttrFlags: *1 {{\n\t\t\ta: 4\n\t\t}}\n"
                f"\t\tKeyAttrDataFloat: *4 {{\n\t\t\ta: 0,0,218434821,0\n\t\t}}\n"
                f"\t\tKeyAttrRefCount: *1 {{\n\t\t\ta: {n}\n\t\t}}\n\t}}\n"
            )
            self.connections.append(f'\tC: "OP",{cid},{nodes[key]}, "d|{"XYZ"[axis]}"\n')

    def text(self, head):
        return (
            head
            + "\nObjects:  {\n"
            + "".join(self.objects)
            + "}\n\nConnections:  {\n"
            + "".join(self.connections)
            + "}\n"
        )


def lcl(offset):
    return f'"Lcl Translation", "Lcl Translation", "", "A",{",".join(num(v) for v in offset)}'


def skeleton74(w, prefix="mixamorig:", props=None):
    """The body under a Null `Armature`; returns model ids by joint name."""
    armature = w.model("Armature", "Null", None, [])
    ids = {}
    for name, parent, offset in BODY:
        extra = (props or {}).get(name, [])
        ids[name] = w.model(
            prefix + name, "LimbNode", ids.get(parent, armature), [lcl(offset)] + extra
        )
    return ids


def mixamo_zup():
    w = Writer74()
    w.model("Camera01", "Camera", None, [lcl((0, -500, 150))])
    ids = skeleton74(w)
    # A prop on the hips: pre-rotation 90° about Z, Lcl Rotation (30, 20, 0), rotation pivot
    # (0, 5, 0); its tip 10 cm along its x axis. The tests compute both by FBX's formula.
    prop = w.model(
        "PropRoot",
        "Null",
        ids["Hips"],
        [
            lcl((0, 0, 20)),
            '"PreRotation", "Vector3D", "Vector", "",0,0,90',
            '"Lcl Rotation", "Lcl Rotation", "", "A",30,20,0',
            '"RotationPivot", "Vector3D", "Vector", "",0,5,0',
            '"RotationActive", "bool", "", "",1',
        ],
    )
    w.model("PropTip", "Null", prop, [lcl((10, 0, 0))])
    models = {name: ids[name] for name in ids}
    times, curves = idle_curves(1.0)
    w.take("idle", 0.0, 1.0, times, curves, models)
    times, curves = walk_curves(2.0)
    w.take("walk", 0.0, 2.0, times, curves, models)
    # Z up, front -Y, right +X (3ds Max), centimetres, 30 fps.
    return w.text(header(7400, 2, 1, -1, 0, 1.0, 6))


def no_skeleton():
    w = Writer74()
    w.model("Camera01", "Camera", None, [lcl((0, -500, 150))])
    w.mesh("Ground")
    return w.text(header(7400, 1, 2, 1, 0, 1.0, 6))


def no_animation():
    w = Writer74()
    skeleton74(w)
    return w.text(header(7400, 2, 1, -1, 0, 1.0, 6))


def empty_take():
    w = Writer74()
    ids = skeleton74(w)
    w.take("still", 0.0, 1.0, [], {}, ids)
    return w.text(header(7400, 2, 1, -1, 0, 1.0, 6))


def default_rate():
    w = Writer74()
    ids = skeleton74(w)
    times, curves = walk_curves(1.0)
    w.take("Take 001", 0.0, 1.0, times, curves, ids)
    return w.text(header(7400, 2, 1, -1, 0, 1.0, 0))


# FBX 6.1: models by name, Properties60, keys under Takes (Key: time,value,L,...).
BIPED = {
    "Hips": "Bip01 Pelvis",
    "Spine": "Bip01 Spine",
    "Spine1": "Bip01 Spine1",
    "Spine2": "Bip01 Spine2",
    "Neck": "Bip01 Neck",
    "Head": "Bip01 Head",
    "HeadTop_End": "Bip01 HeadNub",
}
for _side, _l in (("Left", "L"), ("Right", "R")):
    BIPED.update(
        {
            f"{_side}Shoulder": f"Bip01 {_l} Clavicle",
            f"{_side}Arm": f"Bip01 {_l} UpperArm",
            f"{_side}ForeArm": f"Bip01 {_l} Forearm",
            f"{_side}Hand": f"Bip01 {_l} Hand",
            f"{_side}HandIndex1": f"Bip01 {_l} Finger0",
            f"{_side}UpLeg": f"Bip01 {_l} Thigh",
            f"{_side}Leg": f"Bip01 {_l} Calf",
            f"{_side}Foot": f"Bip01 {_l} Foot",
            f"{_side}ToeBase": f"Bip01 {_l} Toe0",
            f"{_side}Toe_End": f"Bip01 {_l} Toe0Nub",
        }
    )


def y_up(v):
    """Body coordinates (Z up, front -Y) in a Y-up file (front +Z): (x, y, z) -> (x, z, -y)."""
    return (v[0], v[2], -v[1])


def biped_6100():
    objects, connects = [], []
    for name, parent, offset in BODY:
        offset = y_up(offset)
        objects.append(
            f'\tModel: "Model::{BIPED[name]}", "Limb" {{\n\t\tVersion: 232\n\t\tProperties60:  {{\n'
            f'\t\t\tProperty: "Lcl Translation", "Lcl Translation", "A+",{",".join(num(v) for v in offset)}\n'
            f'\t\t\tProperty: "Lcl Rotation", "Lcl Rotation", "A+",0,0,0\n'
            f'\t\t\tProperty: "Lcl Scaling", "Lcl Scaling", "A+",1,1,1\n'
            f'\t\t}}\n\t\tMultiLayer: 0\n\t\tMultiTake: 1\n\t\tShading: Y\n\t\tCulling: "CullingOff"\n'
            f'\t\tTypeFlags: "Skeleton"\n\t}}\n'
        )
        target = f"Model::{BIPED[parent]}" if parent else "Model::Scene"
        connects.append(f'\tConnect: "OO", "Model::{BIPED[name]}", "{target}"\n')
    times, curves = walk_curves(1.0)
    by_joint = {}
    for (joint, prop, axis), values in curves.items():
        if prop == "T":
            # Body axes to the Y-up file's: x stays, y (forward −) becomes −z, z becomes y.
            axis, values = {0: (0, values), 1: (2, [-v for v in values]), 2: (1, values)}[axis]
        else:
            # Rotations about the body's x axis stay about x (the file's x is the body's).
            if axis == 1:
                axis, values = 2, [-v for v in values]
        by_joint.setdefault(joint, {}).setdefault(prop, {})[axis] = values
    take = []
    for joint in (name for name, _, _ in BODY):
        if joint not in by_joint:
            continue
        channels = []
        for prop, layer in (("T", 1), ("R", 2)):
            axes = by_joint[joint].get(prop)
            if not axes:
                continue
            rest = dict(zip("XYZ", y_up(next(o for n, _, o in BODY if n == joint)))) if prop == "T" else {}
            body = []
            for axis in range(3):
                values = axes.get(axis)
                if values is None:
                    default = rest.get("XYZ"[axis], 0.0)
                    body.append(f'\t\t\t\t\tChannel: "{"XYZ"[axis]}" {{\n\t\t\t\t\t\tDefault: {num(default)}\n\t\t\t\t\t}}\n')
                    continue
                keys = ",".join(f"{round(t * KTIME)},{num(v)},L" for t, v in zip(times, values))
                body.append(
                    f'\t\t\t\t\tChannel: "{"XYZ"[axis]}" {{\n\t\t\t\t\t\tDefault: {num(values[0])}\n'
                    f"\t\t\t\t\t\tKeyVer: 4005\n\t\t\t\t\t\tKeyCount: {len(times)}\n"
                    f"\t\t\t\t\t\tKey: {keys}\n\t\t\t\t\t}}\n"
                )
            channels.append(f'\t\t\t\tChannel: "{prop}" {{\n{"".join(body)}\t\t\t\t\tLayerType: {layer}\n\t\t\t\t}}\n')
        take.append(
            f'\t\tModel: "Model::{BIPED[joint]}" {{\n\t\t\tVersion: 1.1\n'
            f'\t\t\tChannel: "Transform" {{\n{"".join(channels)}\t\t\t}}\n\t\t}}\n'
        )
    return f"""; FBX 6.1.0 project file
; written by crates/fbx/tests/data/generate.py
; ----------------------------------------------------

FBXHeaderExtension:  {{
\tFBXHeaderVersion: 1003
\tFBXVersion: 6100
\tCreator: "retarget tests/data/generate.py"
}}
Definitions:  {{
\tVersion: 100
\tCount: {len(BODY)}
\tObjectType: "Model" {{
\t\tCount: {len(BODY)}
\t}}
}}
Objects:  {{
{"".join(objects)}\tGlobalSettings:  {{
\t\tVersion: 1000
\t\tProperties60:  {{
\t\t\tProperty: "UpAxis", "int", "",1
\t\t\tProperty: "UpAxisSign", "int", "",1
\t\t\tProperty: "FrontAxis", "int", "",2
\t\t\tProperty: "FrontAxisSign", "int", "",1
\t\t\tProperty: "CoordAxis", "int", "",0
\t\t\tProperty: "CoordAxisSign", "int", "",1
\t\t\tProperty: "UnitScaleFactor", "double", "",1
\t\t}}
\t}}
}}
Connections:  {{
{"".join(connects)}}}
Takes:  {{
\tCurrent: "Take 001"
\tTake: "Take 001" {{
\t\tFileName: "Take_001.tak"
\t\tLocalTime: 0,{KTIME}
\t\tReferenceTime: 0,{KTIME}
{"".join(take)}\t}}
}}
Version5:  {{
\tSettings:  {{
\t\tFrameRate: "30"
\t\tTimeFormat: 1
\t}}
}}
"""


FILES = {
    "mixamo_zup_7400_ascii.fbx": mixamo_zup,
    "biped_6100_ascii.fbx": biped_6100,
    "no_skeleton_7400_ascii.fbx": no_skeleton,
    "no_animation_7400_ascii.fbx": no_animation,
    "empty_take_7400_ascii.fbx": empty_take,
    "default_rate_7400_ascii.fbx": default_rate,
}

if __name__ == "__main__":
    for name, make in FILES.items():
        with open(name, "w", newline="\n") as f:
            f.write(make())
        print("wrote", name)
