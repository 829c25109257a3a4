//! Naming conventions of human skeletons, as data: the one place to add the next one.
//!
//! A convention lists, per body part, the joint names it uses. Sided parts write the side as
//! a placeholder that stands for both sides: `{Left}` (`Left`/`Right`), `{left}`
//! (`left`/`right`), `{L}` (`L`/`R`), `{l}` (`l`/`r`), and French `{gauche}`
//! (`gauche`/`droit`) and `{gauche_f}` (`gauche`/`droite`, for feminine nouns). Names are
//! compared after [`normalise`]: namespace (`mixamorig:`) and exporter prefixes
//! (`mixamorig_`, `DEF-`, `Bip01 `, Xsens' `j`) removed, case, accents and separators
//! ignored. So `Bip01 L Thigh`, `L Thigh` and `l_thigh` are the same name, and so are `tête`
//! and `Tete`.
//!
//! Names only choose among what the hierarchy allows ([`crate::recognise`]): the same name means
//! different parts in different conventions (`LeftShoulder` is the clavicle in Mixamo and the
//! upper arm in CMU's 3ds Max release and in Xsens' joint naming; `L_Foot` is SMPL's toe), and
//! the convention that names most of the skeleton is consulted first.

use crate::roles::{Part, Role, Side};

/// One naming convention: where it comes from and the names it gives each part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Convention {
    pub name: &'static str,
    /// Where skeletons named this way come from.
    pub source: &'static str,
    /// Names per part, preferred first (see the module docs for the side placeholders).
    pub parts: &'static [(Part, &'static [&'static str])],
}

use Part::{
    Chest, Clavicle, Foot, Forearm, Hand, Head, Neck, Pelvis, Shin, Spine, Thigh, Toe, UpperArm,
};

/// Every convention we know, most specific first (ties in how much of a skeleton two
/// conventions name go to the earlier one).
pub const CONVENTIONS: &[Convention] = &[
    Convention {
        name: "LAFAN1 / Mixamo / HumanIK / Rokoko / Perception Neuron",
        source: "Ubisoft LAFAN1, Adobe Mixamo (mixamorig:, mixamorig_), Autodesk HumanIK, \
                 Rokoko Studio, Perception Neuron (Spine3, LeftInHandIndex)",
        parts: &[
            (Pelvis, &["Hips"]),
            (Spine, &["Spine"]),
            (Chest, &["Spine3", "Spine2"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["{Left}Shoulder"]),
            (UpperArm, &["{Left}Arm"]),
            (Forearm, &["{Left}ForeArm"]),
            (Hand, &["{Left}Hand"]),
            (Thigh, &["{Left}UpLeg"]),
            (Shin, &["{Left}Leg"]),
            (Foot, &["{Left}Foot"]),
            (Toe, &["{Left}Toe", "{Left}ToeBase"]),
        ],
    },
    Convention {
        name: "CMU (MotionBuilder-friendly BVH)",
        source: "CMU motion capture database, MotionBuilder-friendly release (LHipJoint, \
                 LowerBack, Neck1)",
        parts: &[
            (Pelvis, &["Hips"]),
            (Spine, &["LowerBack", "Spine"]),
            (Chest, &["Spine1"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["{Left}Shoulder"]),
            (UpperArm, &["{Left}Arm"]),
            (Forearm, &["{Left}ForeArm"]),
            (Hand, &["{Left}Hand"]),
            (Thigh, &["{Left}UpLeg"]),
            (Shin, &["{Left}Leg"]),
            (Foot, &["{Left}Foot"]),
            (Toe, &["{Left}ToeBase"]),
        ],
    },
    Convention {
        name: "Xsens MVN (joints)",
        source: "Xsens MVN BVH exports named by joint (Hips, Chest…Chest4, LeftCollar, \
                 LeftHip, LeftKnee, LeftAnkle, LeftShoulder = upper arm; jL5S1, jT9T8)",
        parts: &[
            (Pelvis, &["Hips", "Pelvis"]),
            (Spine, &["Chest", "L5S1", "L4L3"]),
            (Chest, &["Chest4", "T9T8"]),
            (Neck, &["Neck", "T1C7"]),
            (Head, &["Head", "C1Head"]),
            (Clavicle, &["{Left}Collar", "{Left}T4Shoulder"]),
            (UpperArm, &["{Left}Shoulder"]),
            (Forearm, &["{Left}Elbow"]),
            (Hand, &["{Left}Wrist"]),
            (Thigh, &["{Left}Hip"]),
            (Shin, &["{Left}Knee"]),
            (Foot, &["{Left}Ankle"]),
            (Toe, &["{Left}Toe", "{Left}BallFoot"]),
        ],
    },
    Convention {
        name: "CMU (3ds Max-friendly BVH) / Biovision",
        source: "CMU motion capture database, 3ds Max-friendly release (cgspeed); classic \
                 Biovision files (LeftCollar, LeftShoulder = upper arm, LeftHip = thigh)",
        parts: &[
            (Pelvis, &["Hips"]),
            (Spine, &["lowerback", "Chest"]),
            (Chest, &["Chest2"]),
            (Neck, &["lowerneck", "Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["{Left}Collar"]),
            (UpperArm, &["{Left}Shoulder", "{Left}UpArm"]),
            (Forearm, &["{Left}Elbow", "{Left}LowArm"]),
            (Hand, &["{Left}Wrist", "{Left}Hand"]),
            (Thigh, &["{Left}Hip", "{Left}UpLeg"]),
            (Shin, &["{Left}Knee", "{Left}LowLeg"]),
            (Foot, &["{Left}Ankle", "{Left}Foot"]),
            (Toe, &["{Left}Toe"]),
        ],
    },
    Convention {
        name: "SOMA (NVIDIA soma-retargeter, BONES-SEED)",
        source: "NVIDIA's SOMA uniform skeleton, the BVH of BONES-SEED and soma-retargeter \
                 (Root on the floor, Hips, Spine1, Spine2, Chest, Neck1, Neck2; LeftLeg = \
                 thigh, LeftShin = shin, LeftShoulder = clavicle; leaf joints such as HeadEnd \
                 and LeftToeEnd are joints, not End Sites)",
        parts: &[
            (Pelvis, &["Hips"]),
            (Spine, &["Spine1"]),
            (Chest, &["Chest"]),
            (Neck, &["Neck1"]),
            (Head, &["Head"]),
            (Clavicle, &["{Left}Shoulder"]),
            (UpperArm, &["{Left}Arm"]),
            (Forearm, &["{Left}ForeArm"]),
            (Hand, &["{Left}Hand"]),
            (Thigh, &["{Left}Leg"]),
            (Shin, &["{Left}Shin"]),
            (Foot, &["{Left}Foot"]),
            (Toe, &["{Left}ToeBase"]),
        ],
    },
    Convention {
        name: "Bandai Namco",
        source: "Bandai Namco Research motion dataset (joint_Root, UpperLeg_L, Toes_L, six \
                 channels on every joint)",
        parts: &[
            (Pelvis, &["Hips"]),
            (Spine, &["Spine"]),
            (Chest, &["Chest"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["Shoulder_{L}"]),
            (UpperArm, &["UpperArm_{L}"]),
            (Forearm, &["LowerArm_{L}"]),
            (Hand, &["Hand_{L}"]),
            (Thigh, &["UpperLeg_{L}"]),
            (Shin, &["LowerLeg_{L}"]),
            (Foot, &["Foot_{L}"]),
            (Toe, &["Toes_{L}"]),
        ],
    },
    Convention {
        name: "MakeHuman",
        source: "MakeHuman's default skeleton (Root carrying the translation, Hips beside \
                 Spine1 carrying the legs, UpLeg_L, LoLeg_L, UpArm_L, LoArm_L)",
        parts: &[
            (Pelvis, &["Hips", "Root"]),
            (Spine, &["Spine1"]),
            (Chest, &["Spine3", "Spine2"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["Clavicle_{L}", "Shoulder_{L}"]),
            (UpperArm, &["UpArm_{L}"]),
            (Forearm, &["LoArm_{L}"]),
            (Hand, &["Hand_{L}"]),
            (Thigh, &["UpLeg_{L}"]),
            (Shin, &["LoLeg_{L}"]),
            (Foot, &["Foot_{L}"]),
            (Toe, &["Toe_{L}"]),
        ],
    },
    Convention {
        name: "Xsens MVN (segments)",
        source: "Xsens MVN exports named by segment (Pelvis, L5, L3, T12, T8, LeftShoulder = \
                 clavicle, LeftUpperArm)",
        parts: &[
            (Pelvis, &["Pelvis"]),
            (Spine, &["L5", "L3"]),
            (Chest, &["T8"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["{Left}Shoulder"]),
            (UpperArm, &["{Left}UpperArm"]),
            (Forearm, &["{Left}ForeArm"]),
            (Hand, &["{Left}Hand"]),
            (Thigh, &["{Left}UpperLeg"]),
            (Shin, &["{Left}LowerLeg"]),
            (Foot, &["{Left}Foot"]),
            (Toe, &["{Left}Toe"]),
        ],
    },
    Convention {
        name: "3ds Max Biped",
        source: "Autodesk 3ds Max Biped (Bip01 / Bip001 prefix; thighs under Bip01 Spine, \
                 clavicles under Bip01 Neck)",
        parts: &[
            (Pelvis, &["Pelvis"]),
            (Spine, &["Spine"]),
            (Chest, &["Spine3", "Spine2", "Spine1"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["{L} Clavicle"]),
            (UpperArm, &["{L} UpperArm"]),
            (Forearm, &["{L} Forearm"]),
            (Hand, &["{L} Hand"]),
            (Thigh, &["{L} Thigh"]),
            (Shin, &["{L} Calf"]),
            (Foot, &["{L} Foot"]),
            (Toe, &["{L} Toe0"]),
        ],
    },
    Convention {
        name: "Daz / Poser",
        source: "Daz Studio and Poser figures (hip, abdomen, chest, lCollar, lShldr, the style \
                 of the classic jump.bvh)",
        parts: &[
            (Pelvis, &["hip"]),
            (Spine, &["abdomen", "abdomenLower"]),
            (Chest, &["chest", "chestUpper"]),
            (Neck, &["neck", "neckLower"]),
            (Head, &["head"]),
            (Clavicle, &["{l}Collar"]),
            (UpperArm, &["{l}Shldr", "{l}ShldrBend"]),
            (Forearm, &["{l}ForeArm", "{l}ForearmBend"]),
            (Hand, &["{l}Hand"]),
            (Thigh, &["{l}Thigh", "{l}ThighBend"]),
            (Shin, &["{l}Shin"]),
            (Foot, &["{l}Foot"]),
            (Toe, &["{l}Toe"]),
        ],
    },
    Convention {
        name: "Unreal Mannequin",
        source: "Unreal Engine 4/5 mannequin (pelvis, spine_01, thigh_l, calf_l, ball_l)",
        parts: &[
            (Pelvis, &["pelvis"]),
            (Spine, &["spine_01"]),
            (Chest, &["spine_05", "spine_03"]),
            (Neck, &["neck_01"]),
            (Head, &["head"]),
            (Clavicle, &["clavicle_{l}"]),
            (UpperArm, &["upperarm_{l}"]),
            (Forearm, &["lowerarm_{l}"]),
            (Hand, &["hand_{l}"]),
            (Thigh, &["thigh_{l}"]),
            (Shin, &["calf_{l}"]),
            (Foot, &["foot_{l}"]),
            (Toe, &["ball_{l}"]),
        ],
    },
    Convention {
        name: "Rigify",
        source: "Blender Rigify deform bones (DEF- prefix; thigh.L, shin.L, upper_arm.L)",
        parts: &[
            (Pelvis, &["spine", "pelvis"]),
            (Spine, &["spine.001"]),
            (Chest, &["spine.003"]),
            (Neck, &["spine.004", "neck"]),
            (Head, &["spine.006", "head"]),
            (Clavicle, &["shoulder.{L}"]),
            (UpperArm, &["upper_arm.{L}"]),
            (Forearm, &["forearm.{L}"]),
            (Hand, &["hand.{L}"]),
            (Thigh, &["thigh.{L}"]),
            (Shin, &["shin.{L}"]),
            (Foot, &["foot.{L}"]),
            (Toe, &["toe.{L}"]),
        ],
    },
    Convention {
        name: "ASF (Acclaim, CMU)",
        source: "skeletons converted from Acclaim ASF/AMC, as CMU's (lfemur, ltibia, lhumerus, \
                 lradius)",
        parts: &[
            (Pelvis, &["root", "hip"]),
            (Spine, &["lowerback", "upperback"]),
            (Chest, &["thorax"]),
            (Neck, &["lowerneck", "upperneck"]),
            (Head, &["head"]),
            (Clavicle, &["{l}clavicle"]),
            (UpperArm, &["{l}humerus"]),
            (Forearm, &["{l}radius"]),
            (Hand, &["{l}wrist"]),
            (Thigh, &["{l}femur"]),
            (Shin, &["{l}tibia"]),
            (Foot, &["{l}foot"]),
            (Toe, &["{l}toes"]),
        ],
    },
    Convention {
        name: "SMPL",
        source: "SMPL / SMPL-X body models (L_Hip or left_hip; L_Shoulder = upper arm, \
                 L_Foot = toe)",
        parts: &[
            (Pelvis, &["Pelvis"]),
            (Spine, &["Spine1"]),
            (Chest, &["Spine3"]),
            (Neck, &["Neck"]),
            (Head, &["Head"]),
            (Clavicle, &["{L}_Collar", "{left}_collar"]),
            (UpperArm, &["{L}_Shoulder", "{left}_shoulder"]),
            (Forearm, &["{L}_Elbow", "{left}_elbow"]),
            (Hand, &["{L}_Wrist", "{left}_wrist"]),
            (Thigh, &["{L}_Hip", "{left}_hip"]),
            (Shin, &["{L}_Knee", "{left}_knee"]),
            (Foot, &["{L}_Ankle", "{left}_ankle"]),
            (Toe, &["{L}_Foot", "{left}_foot"]),
        ],
    },
    Convention {
        name: "French (Blender rigs)",
        source: "hand-made French rigs, as the Blender barbarian of ufbx's test files \
                 (bassin, torse, tête, bras droit, main droite, jambe gauche, pied gauche)",
        parts: &[
            (Pelvis, &["bassin", "hanches"]),
            (Spine, &["colonne", "dos", "ventre"]),
            (Chest, &["torse", "poitrine", "thorax"]),
            (Neck, &["cou"]),
            (Head, &["tête"]),
            (Clavicle, &["clavicule {gauche_f}", "épaule {gauche_f}"]),
            (UpperArm, &["bras {gauche}"]),
            (Forearm, &["avant-bras {gauche}", "coude {gauche}"]),
            (Hand, &["main {gauche_f}", "poignet {gauche}"]),
            (Thigh, &["cuisse {gauche_f}", "jambe {gauche_f}"]),
            (Shin, &["tibia {gauche}", "mollet {gauche}", "genou {gauche}"]),
            (Foot, &["pied {gauche}", "cheville {gauche_f}"]),
            (Toe, &["orteils {gauche}", "orteil {gauche}"]),
        ],
    },
    Convention {
        name: "plain anatomical names",
        source: "hand-made and game skeletons (pelvis, clavicle, upperarm, lowerarm, calf)",
        parts: &[
            (Pelvis, &["pelvis", "hips", "hip"]),
            (Spine, &["spine", "abdomen", "waist"]),
            (Chest, &["chest", "upperchest", "torso"]),
            (Neck, &["neck"]),
            (Head, &["head"]),
            (Clavicle, &["{Left}Clavicle", "{Left}Collar"]),
            (UpperArm, &["{Left}UpperArm"]),
            (Forearm, &["{Left}Forearm", "{Left}LowerArm"]),
            (Hand, &["{Left}Hand"]),
            (Thigh, &["{Left}Thigh", "{Left}UpperLeg"]),
            (Shin, &["{Left}Shin", "{Left}Calf", "{Left}LowerLeg"]),
            (Foot, &["{Left}Foot"]),
            (Toe, &["{Left}Toes", "{Left}Toe"]),
        ],
    },
];

/// Words that mark a joint as no part of the body's chains: twist and roll helpers, IK
/// targets and rig controls (exported as bones by Maya rigs: `HipsCtrl`, `LeftFootCtrl`,
/// `LeftKneePole`), props (`arme droite`: French for weapon). Joints whose name has one of
/// these as a word are skipped when the recogniser walks down a limb (fingers, face and
/// other side branches are told apart by the hierarchy instead).
pub const IGNORED_WORDS: &[&str] = &[
    "twist", "roll", "ik", "ctrl", "control", "pole", "prop", "weapon", "sword", "gun", "arme",
    "helper", "holster", "attach",
];

/// Whether a joint name marks the top of the head (`HeadTop_End`, `head_top`).
pub(crate) fn names_the_top(name: &str) -> bool {
    name.to_ascii_lowercase().contains("top")
}

/// Whether a joint name says it ends its chain, as an End Site does: its last word is `End`
/// (`HeadEnd`, `LeftToeEnd`, `HeadTop_End`). SOMA writes such ends as joints with channels.
pub(crate) fn names_an_end(name: &str) -> bool {
    words(name).last().is_some_and(|w| w.eq_ignore_ascii_case("end"))
}

/// Exporter prefixes removed before comparing names (after the namespace, `mixamorig:`).
const PREFIXES: &[&str] = &[
    "mixamorig_",
    "mixamorig",
    "def-",
    "def_",
    "bip001 ",
    "bip001_",
    "bip01 ",
    "bip01_",
    "cc_base_",
];

/// A joint name reduced for comparison: the part after the last `:` (namespaces), without
/// an exporter prefix (`mixamorig_`, `DEF-`, `Bip01 `, `CC_Base_`, Xsens' `j` before a
/// capital), lowercase, Latin accents removed (`ê` → `e`), letters and digits only.
#[must_use]
pub fn normalise(name: &str) -> String {
    let name = name.rsplit(':').next().unwrap_or(name);
    let lower: String = name.chars().flat_map(char::to_lowercase).map(fold).collect();
    let mut rest: &str = &lower;
    for prefix in PREFIXES {
        if let Some(stripped) = rest.strip_prefix(prefix) {
            rest = stripped;
            break;
        }
    }
    // Xsens' joint names: `jLeftHip`, `jL5S1`.
    let bytes = name.as_bytes();
    if rest.len() == lower.len()
        && bytes.len() > 2
        && bytes.first() == Some(&b'j')
        && bytes.get(1).is_some_and(u8::is_ascii_uppercase)
    {
        rest = rest.get(1..).unwrap_or(rest);
    }
    rest.chars().filter(char::is_ascii_alphanumeric).collect()
}

/// A lowercase Latin letter without its accent (`ê` → `e`, `ç` → `c`); others unchanged.
fn fold(c: char) -> char {
    match c {
        'à' | 'á' | 'â' | 'ã' | 'ä' | 'å' => 'a',
        'ç' => 'c',
        'è' | 'é' | 'ê' | 'ë' => 'e',
        'ì' | 'í' | 'î' | 'ï' => 'i',
        'ñ' => 'n',
        'ò' | 'ó' | 'ô' | 'õ' | 'ö' | 'ø' => 'o',
        'ù' | 'ú' | 'û' | 'ü' => 'u',
        'ý' | 'ÿ' => 'y',
        other => other,
    }
}

/// A name pattern with its side placeholder filled in for `side` (the pattern as given when
/// it has none).
#[must_use]
pub fn instantiate(pattern: &str, side: Option<Side>) -> String {
    // Every placeholder starts with a brace; most patterns have none.
    if !pattern.contains('{') {
        return pattern.to_owned();
    }
    let fill = |left: &str, right: &str| match side {
        Some(Side::Right) => right.to_owned(),
        _ => left.to_owned(),
    };
    pattern
        .replace("{Left}", &fill("Left", "Right"))
        .replace("{left}", &fill("left", "right"))
        .replace("{L}", &fill("L", "R"))
        .replace("{l}", &fill("l", "r"))
        .replace("{gauche_f}", &fill("gauche", "droite"))
        .replace("{gauche}", &fill("gauche", "droit"))
}

/// A name match: which role a convention gives the name, and how well (the index of the
/// pattern in its part's list: 0 is the convention's first choice).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NameMatch {
    pub(crate) role: Role,
    pub(crate) convention: usize,
    pub(crate) preference: usize,
}

/// Every role a normalised name has in every convention.
pub(crate) fn matches(normalised: &str) -> Vec<NameMatch> {
    table().iter().filter(|(name, _)| name == normalised).map(|(_, m)| *m).collect()
}

/// Every pattern of every convention, normalised for both sides, built once.
fn table() -> &'static [(String, NameMatch)] {
    static TABLE: std::sync::OnceLock<Vec<(String, NameMatch)>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut out = Vec::new();
        for (c, convention) in CONVENTIONS.iter().enumerate() {
            for &(part, patterns) in convention.parts {
                for (preference, pattern) in patterns.iter().enumerate() {
                    for &side in part.sides() {
                        if let Some(role) = Role::new(part, side) {
                            let name = normalise(&instantiate(pattern, side));
                            out.push((name, NameMatch { role, convention: c, preference }));
                        }
                    }
                }
            }
        }
        out
    })
}

/// The side a name states, from any convention's role names or from a `Left`/`Right`/`L`/`R`
/// word at either end (`LeftHandIndex1`, `RHipJoint`, `hand.L`); `None` if it states none.
pub(crate) fn side_of(name: &str, normalised_matches: &[NameMatch]) -> Option<Side> {
    if let Some(side) = normalised_matches.iter().find_map(|m| m.role.side()) {
        return Some(side);
    }
    let name = name.rsplit(':').next().unwrap_or(name);
    let words = words(name);
    let side = |w: &str| match w.to_ascii_lowercase().as_str() {
        "left" | "l" | "gauche" => Some(Side::Left),
        "right" | "r" | "droit" | "droite" => Some(Side::Right),
        _ => None,
    };
    let first = words.first().and_then(|w| side(w));
    let last = words.last().and_then(|w| side(w));
    match (first, last) {
        (Some(s), _) | (None, Some(s)) => Some(s),
        _ => None,
    }
}

/// Whether a joint name marks a helper, IK target or prop ([`IGNORED_WORDS`]).
pub(crate) fn is_ignored(name: &str) -> bool {
    words(name).iter().any(|w| IGNORED_WORDS.iter().any(|i| w.to_ascii_lowercase().starts_with(i)))
}

/// Words of a name: split at non-alphanumerics and at lower→upper case changes
/// (`LeftUpLeg` → Left Up Leg; `LHipJoint` → L Hip Joint; `thigh.L` → thigh L).
fn words(name: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let chars: Vec<char> = name.chars().collect();
    let mut current = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_ascii_alphanumeric() {
            if !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            continue;
        }
        let prev = i.checked_sub(1).and_then(|p| chars.get(p)).copied();
        let next = chars.get(i + 1).copied();
        let boundary = c.is_ascii_uppercase()
            && prev.is_some_and(|p| {
                p.is_ascii_lowercase()
                    || (p.is_ascii_uppercase() && next.is_some_and(|n| n.is_ascii_lowercase()))
            });
        if boundary && !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
        current.push(c);
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// Example names for a role, one per convention pattern, deduplicated (for error messages).
#[must_use]
pub fn examples(role: Role) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for convention in CONVENTIONS {
        for &(part, patterns) in convention.parts {
            if part != role.part() {
                continue;
            }
            for pattern in patterns {
                let name = instantiate(pattern, role.side());
                if !out.contains(&name) {
                    out.push(name);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_normalise_across_exporters() {
        assert_eq!(normalise("mixamorig:LeftUpLeg"), "leftupleg");
        assert_eq!(normalise("mixamorig_LeftUpLeg"), "leftupleg");
        assert_eq!(normalise("Bip01 L Thigh"), "lthigh");
        assert_eq!(normalise("DEF-thigh.L"), "thighl");
        assert_eq!(normalise("jLeftHip"), "lefthip");
        assert_eq!(normalise("joint12"), "joint12");
        assert_eq!(normalise("spine_01"), "spine01");
        assert_eq!(normalise("tête"), "tete");
        assert_eq!(normalise("TÊTE"), "tete");
        assert_eq!(normalise("bras droit"), "brasdroit");
    }

    #[test]
    fn fbx_rigs_are_named() {
        let roles = |name: &str| -> Vec<Role> {
            matches(&normalise(name)).into_iter().map(|m| m.role).collect()
        };
        assert!(roles("mixamorig:LeftUpLeg").contains(&Role::LeftThigh));
        assert!(roles("Bip01 L Thigh").contains(&Role::LeftThigh));
        assert!(roles("Lefthand").contains(&Role::LeftHand), "Lefthand as LeftHand");
        assert!(roles("tête").contains(&Role::Head));
        assert!(roles("bras droit").contains(&Role::RightUpperArm));
        assert!(roles("main droite").contains(&Role::RightHand));
        assert!(roles("jambe gauche").contains(&Role::LeftThigh));
        assert!(roles("pied gauche").contains(&Role::LeftFoot));
        let side = |n: &str| side_of(n, &matches(&normalise(n)));
        assert_eq!(side("arme droite"), Some(Side::Right));
        assert_eq!(side("pagne avant"), None);
        for control in ["HipsCtrl", "LeftFootCtrl", "LeftFootIK", "LeftKneePole", "arme droite"] {
            assert!(is_ignored(control), "{control}");
        }
        assert!(!is_ignored("Armature"));
        assert!(!is_ignored("LeftArm"));
    }

    #[test]
    fn the_same_name_means_different_parts_in_different_conventions() {
        let roles = |name: &str| -> Vec<(Role, &str)> {
            matches(&normalise(name))
                .into_iter()
                .map(|m| (m.role, CONVENTIONS[m.convention].name))
                .collect()
        };
        let shoulder = roles("LeftShoulder");
        assert!(shoulder.contains(&(Role::LeftClavicle, CONVENTIONS[0].name)));
        assert!(shoulder.contains(&(Role::LeftUpperArm, "Xsens MVN (joints)")));
        assert!(roles("L_Foot").contains(&(Role::LeftToe, "SMPL")));
        assert!(roles("lFoot").contains(&(Role::LeftFoot, "Daz / Poser")));
        assert_eq!(roles("Bip01 R Calf"), [(Role::RightShin, "3ds Max Biped")]);
        assert!(roles("LeftLeg").contains(&(Role::LeftShin, CONVENTIONS[0].name)));
        assert!(roles("LeftLeg")
            .contains(&(Role::LeftThigh, "SOMA (NVIDIA soma-retargeter, BONES-SEED)")));
        assert!(roles("LeftHandIndex1").is_empty());
        assert!(roles("HeadTop_End").is_empty());
    }

    #[test]
    fn sides_and_ignored_words() {
        let side = |n: &str| side_of(n, &matches(&normalise(n)));
        assert_eq!(side("LeftHandIndex1"), Some(Side::Left));
        assert_eq!(side("RHipJoint"), Some(Side::Right));
        assert_eq!(side("hand.L"), Some(Side::Left));
        assert_eq!(side("lowerback"), None);
        assert_eq!(side("joint7"), None);
        assert!(names_an_end("HeadEnd") && names_an_end("HeadTop_End") && names_an_end("toe_end"));
        assert!(!names_an_end("Legend") && !names_an_end("LeftHand"));
        assert!(is_ignored("upperarm_twist_01_l"));
        assert!(is_ignored("Bip01 L UpArmTwist"));
        assert!(is_ignored("ik_foot_l"));
        assert!(!is_ignored("LeftUpLeg"));
        assert!(!is_ignored("kick"));
        assert_eq!(examples(Role::RightThigh)[0], "RightUpLeg");
        assert!(examples(Role::LeftShin).contains(&"L Calf".to_owned()));
    }
}
