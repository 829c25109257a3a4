//! The compiled kinematic model: MuJoCo's `mjModel` restricted to what kinematics needs, in
//! MuJoCo's order (bodies depth-first, parents first; joints, geoms and sites by body).

use nalgebra::{UnitQuaternion, Vector3};

/// Joint types (MuJoCo's `mjtJoint`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointType {
    /// 7 qpos (x, y, z, qw, qx, qy, qz), 6 dofs (linear in the world frame, angular in the body frame).
    Free,
    /// 4 qpos (unit quaternion, w first), 3 dofs (angular in the body frame).
    Ball,
    /// 1 qpos, 1 dof: translation along `axis`.
    Slide,
    /// 1 qpos, 1 dof: rotation about `axis` through `pos`.
    Hinge,
}

impl JointType {
    /// Number of `qpos` entries.
    #[must_use]
    pub const fn nq(self) -> usize {
        match self {
            JointType::Free => 7,
            JointType::Ball => 4,
            JointType::Slide | JointType::Hinge => 1,
        }
    }

    /// Number of degrees of freedom (`qvel` entries).
    #[must_use]
    pub const fn nv(self) -> usize {
        match self {
            JointType::Free => 6,
            JointType::Ball => 3,
            JointType::Slide | JointType::Hinge => 1,
        }
    }

    /// MuJoCo's keyword.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            JointType::Free => "free",
            JointType::Ball => "ball",
            JointType::Slide => "slide",
            JointType::Hinge => "hinge",
        }
    }
}

/// Geom types (MuJoCo's `mjtGeom`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GeomType {
    Plane,
    Hfield,
    Sphere,
    Capsule,
    Ellipsoid,
    Cylinder,
    Box,
    Mesh,
    Sdf,
}

/// A body. `pos`/`quat` place its frame in its parent's frame (MuJoCo `body_pos`/`body_quat`,
/// `<frame>` elements already folded in). `bodies[0]` is the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Empty when the MJCF gives none.
    pub name: String,
    /// Parent body id (`0` for the world itself).
    pub parent: usize,
    pub pos: Vector3<f64>,
    pub quat: UnitQuaternion<f64>,
    /// First joint of this body (joints of a body are contiguous).
    pub jnt_adr: usize,
    /// Number of joints of this body.
    pub jnt_num: usize,
    /// First dof of this body.
    pub dof_adr: usize,
    /// Number of dofs of this body.
    pub dof_num: usize,
    /// Mass and inertia as MuJoCo compiles them from the file's `<inertial>` (MuJoCo's
    /// `body_mass`, `body_ipos`, `body_iquat`, `body_inertia`; URDF static links fused in).
    /// `None` for the world and where MuJoCo takes them from the geoms, which is not done
    /// here: no `<inertial>`, `inertiafromgeom="true"`, and the other cases the URDF reader
    /// lists; with `settotalmass`, `None` everywhere unless every body has one.
    pub inertial: Option<Inertial>,
}

/// A body's mass and its inertia in the principal frame (MuJoCo's `body_ipos`, `body_iquat`,
/// `body_inertia`, `body_mass`). A full tensor (`fullinertia`, URDF `<inertia>`, fused links)
/// is diagonalised with the moments largest first, as MuJoCo does; the axes may then differ
/// from its `body_iquat` in sign (and among equal moments), the tensor `R diag Rᵀ` being the
/// same.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertial {
    /// kg.
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub pos: Vector3<f64>,
    /// Principal axes in the body frame.
    pub quat: UnitQuaternion<f64>,
    /// Principal moments of inertia about the centre of mass (kg m²).
    pub diag: Vector3<f64>,
}

impl Inertial {
    /// Half sizes of the uniform box with this mass and these principal moments, along the
    /// principal axes: `a² = 6 (I_y + I_z − I_x) / m` for the full side `a` along x, and so on.
    /// `None` for a massless body or moments that no box has (the triangle inequality fails
    /// by more than rounding).
    #[must_use]
    pub fn equivalent_box(&self) -> Option<Vector3<f64>> {
        let [x, y, z] = [self.diag.x, self.diag.y, self.diag.z];
        let m = self.mass;
        if m.is_nan() || m <= 0.0 {
            return None;
        }
        let side = |a: f64, b: f64, c: f64| {
            let sq = 6.0 * (b + c - a) / m;
            (sq > 0.0 && sq.is_finite()).then(|| sq.sqrt() / 2.0)
        };
        Some(Vector3::new(side(x, y, z)?, side(y, z, x)?, side(z, x, y)?))
    }
}

/// A joint, in the frame of its body.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Empty when the MJCF gives none.
    pub name: String,
    pub kind: JointType,
    pub body: usize,
    pub qpos_adr: usize,
    pub dof_adr: usize,
    /// `Some` iff the joint is limited; radians for hinge and ball (ball: `[0, max angle]`),
    /// metres for slide.
    pub range: Option<[f64; 2]>,
    /// Unit axis in the body frame (hinge, slide; `(0, 0, 1)` for ball and free).
    pub axis: Vector3<f64>,
    /// Anchor in the body frame.
    pub pos: Vector3<f64>,
    /// Published speed limit (rad/s for hinge, m/s for slide), when the robot's description
    /// gives one (URDF `<limit velocity>`; MJCF has no such attribute, so `None` there unless
    /// the caller sets it).
    pub velocity_limit: Option<f64>,
}

impl Joint {
    /// Where the joint's orientation quaternion `(w, x, y, z)` starts in `qpos`: after a free
    /// joint's position, at a ball joint's address; `None` for hinges and slides.
    #[must_use]
    pub const fn quat_adr(&self) -> Option<usize> {
        match self.kind {
            JointType::Free => Some(self.qpos_adr + 3),
            JointType::Ball => Some(self.qpos_adr),
            JointType::Hinge | JointType::Slide => None,
        }
    }
}

/// A geom, placed in its body's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Geom {
    pub name: String,
    pub body: usize,
    pub kind: GeomType,
    /// MuJoCo `geom_size` (unused entries 0; capsule/cylinder `fromto` sets the half length).
    pub size: [f64; 3],
    pub pos: Vector3<f64>,
    pub quat: UnitQuaternion<f64>,
    /// Mesh asset name of a mesh geom. Its pose is kept as written: MuJoCo additionally moves
    /// mesh geoms to the mesh's inertial frame, which needs the mesh file and is not done here.
    pub mesh: Option<String>,
    /// MuJoCo `geom_contype`: the collision bitmask (default 1). Two geoms may collide when
    /// `contype1 & conaffinity2` or `contype2 & conaffinity1` is non-zero.
    pub contype: i32,
    /// MuJoCo `geom_conaffinity` (default 1).
    pub conaffinity: i32,
}

/// A site, placed in its body's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Site {
    pub name: String,
    pub body: usize,
    pub kind: GeomType,
    pub size: [f64; 3],
    pub pos: Vector3<f64>,
    pub quat: UnitQuaternion<f64>,
}

/// The kinematic model. Build it with [`Model::from_file`] or [`Model::from_xml_str`].
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// `<mujoco model="...">`, empty when absent.
    pub name: String,
    /// Number of generalised coordinates (`qpos`).
    pub nq: usize,
    /// Number of degrees of freedom (`qvel`).
    pub nv: usize,
    pub bodies: Vec<Body>,
    pub joints: Vec<Joint>,
    pub geoms: Vec<Geom>,
    pub sites: Vec<Site>,
    /// Default configuration (free: body pos and quat; ball: identity; hinge, slide: `ref`).
    pub qpos0: Vec<f64>,
    /// `<contact><exclude body1 body2>`: body pairs whose geoms never collide (body ids, as
    /// written; MuJoCo `exclude_signature`).
    pub contact_excludes: Vec<[usize; 2]>,
    /// `<contact><pair geom1 geom2>`: geom pairs that always go to collision checking, whatever
    /// the filters say (geom ids, as written; MuJoCo `pair_geom1`/`pair_geom2`).
    pub contact_pairs: Vec<[usize; 2]>,
    /// `<option><flag filterparent>` (default enabled): geoms of a body and of its parent do
    /// not collide unless the parent is the world (MuJoCo `mjDSBL_FILTERPARENT` off).
    pub filter_parent: bool,
    /// Joint of each dof.
    pub(crate) dof_joint: Vec<usize>,
    /// Previous dof on the path to the world (MuJoCo `dof_parentid`).
    pub(crate) dof_parent: Vec<Option<usize>>,
    /// Last dof on the path from a body to the world (its own or an ancestor's).
    pub(crate) body_last_dof: Vec<Option<usize>>,
    /// Per joint: anchor at the body origin (skips the off-centre correction in FK).
    pub(crate) jnt_pos_zero: Vec<bool>,
    /// Geom and site orientations as matrices.
    pub(crate) geom_mat: Vec<nalgebra::Matrix3<f64>>,
    pub(crate) site_mat: Vec<nalgebra::Matrix3<f64>>,
}

impl Model {
    /// Id of the body called `name`.
    #[must_use]
    pub fn body_id(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Id of the joint called `name`.
    #[must_use]
    pub fn joint_id(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| !j.name.is_empty() && j.name == name)
    }

    /// Id of the geom called `name`.
    #[must_use]
    pub fn geom_id(&self, name: &str) -> Option<usize> {
        self.geoms.iter().position(|g| !g.name.is_empty() && g.name == name)
    }

    /// Id of the site called `name`.
    #[must_use]
    pub fn site_id(&self, name: &str) -> Option<usize> {
        self.sites.iter().position(|s| !s.name.is_empty() && s.name == name)
    }

    /// Geom `g` for messages: its name, or `geom {g}` when it has none.
    #[must_use]
    pub fn geom_label(&self, g: usize) -> String {
        match self.geoms.get(g).map(|geom| geom.name.as_str()) {
            Some("") | None => format!("geom {g}"),
            Some(name) => name.to_owned(),
        }
    }

    /// Number of bodies including the world.
    #[must_use]
    pub fn nbody(&self) -> usize {
        self.bodies.len()
    }

    /// Per dof, the previous dof on its path to the world (MuJoCo `dof_parentid`; `None` for
    /// the first dof of a tree): the dof tree that sparse factorisations of the mass-like
    /// matrices follow.
    #[must_use]
    pub fn dof_parents(&self) -> &[Option<usize>] {
        &self.dof_parent
    }

    /// The dofs that move `body` (MuJoCo's dof ancestor chain), from the body towards the world.
    pub fn body_dofs(&self, body: usize) -> impl Iterator<Item = usize> + '_ {
        let start = self.body_last_dof.get(body).copied().flatten();
        std::iter::successors(start, |&d| self.dof_parent.get(d).copied().flatten())
    }

    /// `body` and every body below it, breadth first: the body, its children, their children,
    /// each generation in body order. Empty for a body that does not exist.
    #[must_use]
    pub fn subtree(&self, body: usize) -> Vec<usize> {
        if body >= self.bodies.len() {
            return Vec::new();
        }
        let mut out = vec![body];
        let mut next = 0;
        while let Some(&b) = out.get(next) {
            let children = self.bodies.iter().enumerate().skip(1).filter(|(_, c)| c.parent == b);
            out.extend(children.map(|(c, _)| c));
            next += 1;
        }
        out
    }

    /// The bodies above `body`, its parent first and the world (0) last; none for the world
    /// or a body that does not exist.
    pub fn ancestors(&self, body: usize) -> impl Iterator<Item = usize> + '_ {
        let parent = |b: usize| self.bodies.get(b).map(|x| x.parent).filter(|_| b != 0);
        // A tree is at most `nbody` deep: the bound keeps a malformed parent loop finite.
        std::iter::successors(parent(body), move |&b| parent(b)).take(self.bodies.len())
    }

    /// Whether `ancestor` is `body` or one of the bodies above it (the world is everyone's).
    #[must_use]
    pub fn is_ancestor_or_self(&self, ancestor: usize, body: usize) -> bool {
        ancestor == body || self.ancestors(body).any(|b| b == ancestor)
    }

    /// The joint a dof belongs to. Panics if `dof >= nv`.
    #[must_use]
    // A caller's out-of-range dof is a bug, like slice indexing (documented above).
    #[allow(clippy::indexing_slicing)]
    pub fn dof_joint(&self, dof: usize) -> usize {
        self.dof_joint[dof]
    }
}

impl Model {
    /// `alignfree`: a free body without children gets its inertial frame as its body frame
    /// (geoms and sites re-expressed in it, `qpos0` the new pose). A body whose inertia MuJoCo
    /// takes from its geoms is left as it is (its inertial frame is not computed here).
    pub(crate) fn align_to_inertia(&mut self, id: usize) {
        let Some(body) = self.bodies.get_mut(id) else { return };
        let Some(i) = body.inertial else { return };
        let (pos, quat) = (body.pos + body.quat * i.pos, body.quat * i.quat);
        let inverse = i.quat.inverse();
        body.pos = pos;
        body.quat = quat;
        body.inertial =
            Some(Inertial { pos: Vector3::zeros(), quat: UnitQuaternion::identity(), ..i });
        for g in self.geoms.iter_mut().filter(|g| g.body == id) {
            g.pos = inverse * (g.pos - i.pos);
            g.quat = inverse * g.quat;
        }
        for s in self.sites.iter_mut().filter(|s| s.body == id) {
            s.pos = inverse * (s.pos - i.pos);
            s.quat = inverse * s.quat;
        }
        for j in self.joints.iter().filter(|j| j.body == id && j.kind == JointType::Free) {
            let a = j.qpos_adr;
            if let Some(q) = self.qpos0.get_mut(a..a + 7) {
                q.copy_from_slice(&[pos.x, pos.y, pos.z, quat.w, quat.i, quat.j, quat.k]);
            }
        }
    }
}

/// The free joint [`Model::add_floating_base`] gave a model without one.
#[derive(Debug, Clone, PartialEq)]
pub struct FloatingBase {
    /// The body that carries it.
    pub body: usize,
    /// Its name: `<body>_free_joint`, as MuJoCo names the one it adds to a URDF's root link.
    pub joint: String,
}

impl Model {
    /// Whether some joint is free (a floating base).
    #[must_use]
    pub fn has_free_joint(&self) -> bool {
        self.joints.iter().any(|j| j.kind == JointType::Free)
    }

    /// The body that holds the robot: the child of the world whose subtree has the most
    /// joints (the first of equals); `None` when no child of the world has a jointless body
    /// of its own at the top (a free joint needs a body without other joints).
    #[must_use]
    pub fn root_body(&self) -> Option<usize> {
        let mut joints_below = vec![0usize; self.bodies.len()];
        for b in (1..self.bodies.len()).rev() {
            let body = self.bodies.get(b)?;
            let own = body.jnt_num + joints_below.get(b).copied().unwrap_or(0);
            if let Some(j) = joints_below.get_mut(b) {
                *j = own;
            }
            if body.parent != b {
                if let Some(p) = joints_below.get_mut(body.parent).filter(|_| body.parent != 0) {
                    *p += own;
                }
            }
        }
        (1..self.bodies.len())
            .filter(|&b| self.bodies.get(b).is_some_and(|body| body.parent == 0))
            .max_by_key(|&b| (joints_below.get(b).copied().unwrap_or(0), std::cmp::Reverse(b)))
            .filter(|&b| self.bodies.get(b).is_some_and(|body| body.jnt_num == 0))
    }

    /// A floating base for a model without one (MJCF whose free joint the user's code adds,
    /// dm_control style; a URDF read with [`crate::UrdfBase::Fixed`]): a free joint on
    /// [`Model::root_body`], placed at `pos`, `quat` in the world (its `qpos0` and the body's
    /// frame, as MuJoCo makes a free body's). `None` when the model has a free joint already
    /// or no such root body. Joints, dofs and `qpos` after it move up, as if it had been
    /// written in the file.
    pub fn add_floating_base(
        &mut self,
        pos: Vector3<f64>,
        quat: UnitQuaternion<f64>,
    ) -> Option<FloatingBase> {
        if self.has_free_joint() {
            return None;
        }
        let body = self.root_body()?;
        let name = match self.bodies.get(body).map(|b| b.name.as_str()) {
            Some("") | None => format!("body{body}_free_joint"),
            Some(n) => format!("{n}_free_joint"),
        };
        // Each joint's qpos0, to lay them out again.
        let mut values: Vec<Vec<f64>> = self
            .joints
            .iter()
            .map(|j| {
                self.qpos0.get(j.qpos_adr..j.qpos_adr + j.kind.nq()).unwrap_or_default().to_vec()
            })
            .collect();
        let at = self.bodies.get(body)?.jnt_adr;
        let free = Joint {
            name: name.clone(),
            kind: JointType::Free,
            body,
            qpos_adr: 0,
            dof_adr: 0,
            range: None,
            axis: Vector3::z(),
            pos: Vector3::zeros(),
            velocity_limit: None,
        };
        self.joints.insert(at, free);
        values.insert(at, vec![pos.x, pos.y, pos.z, quat.w, quat.i, quat.j, quat.k]);
        if let Some(b) = self.bodies.get_mut(body) {
            b.pos = pos;
            b.quat = quat;
        }
        self.lay_out_joints(&values);
        Some(FloatingBase { body, joint: name })
    }

    /// Addresses of joints, dofs and `qpos` from the joint list (joints grouped by body in
    /// body order), with `values[j]` the `qpos0` of joint `j`.
    fn lay_out_joints(&mut self, values: &[Vec<f64>]) {
        let (mut nq, mut nv) = (0, 0);
        self.qpos0.clear();
        self.dof_joint.clear();
        self.dof_parent.clear();
        self.body_last_dof = vec![None; self.bodies.len()];
        let mut next_joint = 0;
        for b in 0..self.bodies.len() {
            let parent = self.bodies.get(b).map_or(0, |body| body.parent);
            let mut last =
                if b == 0 { None } else { self.body_last_dof.get(parent).copied().flatten() };
            let (jnt_adr, dof_adr) = (next_joint, nv);
            while let Some(joint) = self.joints.get_mut(next_joint).filter(|j| j.body == b) {
                joint.qpos_adr = nq;
                joint.dof_adr = nv;
                nq += joint.kind.nq();
                for _ in 0..joint.kind.nv() {
                    self.dof_joint.push(next_joint);
                    self.dof_parent.push(last);
                    last = Some(nv);
                    nv += 1;
                }
                self.qpos0.extend(values.get(next_joint).into_iter().flatten());
                next_joint += 1;
            }
            if let Some(slot) = self.body_last_dof.get_mut(b) {
                *slot = last;
            }
            if let Some(body) = self.bodies.get_mut(b) {
                body.jnt_adr = jnt_adr;
                body.jnt_num = next_joint - jnt_adr;
                body.dof_adr = dof_adr;
                body.dof_num = nv - dof_adr;
            }
        }
        self.nq = nq;
        self.nv = nv;
        self.jnt_pos_zero = self.joints.iter().map(|j| j.pos == Vector3::zeros()).collect();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// world ─ torso ─┬─ left ─ left_foot
    ///                ├─ right ─ right_foot
    ///                └─ head
    const TREE: &str = r#"<mujoco><worldbody>
      <body name="torso"><freejoint/><geom size="0.1"/>
        <body name="left"><geom size="0.1"/><body name="left_foot"><geom size="0.1"/></body></body>
        <body name="right"><geom size="0.1"/><body name="right_foot"><geom size="0.1"/></body></body>
        <body name="head"><geom size="0.1"/></body>
      </body>
      <body name="other"><geom size="0.1"/></body>
    </worldbody></mujoco>"#;

    fn ids(model: &Model, names: &[&str]) -> Vec<usize> {
        names.iter().map(|n| model.body_id(n).unwrap()).collect()
    }

    #[test]
    fn subtree_is_breadth_first_with_each_generation_in_body_order() {
        let m = Model::from_xml_str(TREE, None).unwrap();
        let torso = m.body_id("torso").unwrap();
        let want = ids(&m, &["torso", "left", "right", "head", "left_foot", "right_foot"]);
        assert_eq!(m.subtree(torso), want);
        let foot = m.body_id("left_foot").unwrap();
        assert_eq!(m.subtree(foot), vec![foot]);
        assert_eq!(m.subtree(0).len(), m.nbody());
        assert!(m.subtree(m.nbody()).is_empty());
    }

    #[test]
    fn ancestors_run_from_the_parent_to_the_world() {
        let m = Model::from_xml_str(TREE, None).unwrap();
        let foot = m.body_id("right_foot").unwrap();
        let want = ids(&m, &["right", "torso"]).into_iter().chain([0]).collect::<Vec<_>>();
        assert_eq!(m.ancestors(foot).collect::<Vec<_>>(), want);
        assert_eq!(m.ancestors(0).count(), 0);
        assert_eq!(m.ancestors(m.nbody()).count(), 0);
    }

    #[test]
    fn is_ancestor_or_self_follows_the_parents_only() {
        let m = Model::from_xml_str(TREE, None).unwrap();
        let [torso, left, foot, right, other] =
            ["torso", "left", "left_foot", "right", "other"].map(|n| m.body_id(n).unwrap());
        assert!(m.is_ancestor_or_self(torso, foot));
        assert!(m.is_ancestor_or_self(left, foot));
        assert!(m.is_ancestor_or_self(foot, foot));
        assert!(m.is_ancestor_or_self(0, foot));
        assert!(!m.is_ancestor_or_self(foot, left));
        assert!(!m.is_ancestor_or_self(right, foot));
        assert!(!m.is_ancestor_or_self(other, foot));
        assert!(!m.is_ancestor_or_self(torso, 0));
    }
}
