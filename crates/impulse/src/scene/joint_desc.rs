//! Joints in the scene format (`docs/scene-format.md`, "Joints"): [`JointDesc`], its checks
//! (the rules of `World::insert_joint`, with the field path), and its conversion into a
//! [`JointBuilder`].

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::error::{FieldPath, SceneError, SceneErrorKind};
use crate::body::{BodyHandle, BodyKind};
use crate::joint::rules::{JointProblem, anchor_reach, check_dofs, check_options};
use crate::joint::{
    AxisMode, JointAxis, JointBuilder, JointDof, JointKind, JointStiffness, Motor, MotorMode,
    Spring,
};

/// A body named by a joint: its index in `bodies`, or its `name`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum BodyName {
    /// Index in the scene's `bodies`.
    Index(usize),
    /// A body's `name`.
    Name(String),
}

/// A degree of freedom in a scene file: `"locked"`, `"free"`, or limits, with an optional
/// spring and motor (`{"limits": [lo, hi], "spring": {...}, "motor": {...}}`; a missing
/// `limits` is free).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum DofDesc {
    /// `"locked"` or `"free"`.
    Mode(DofMode),
    /// Limits, spring and motor.
    Detailed {
        /// [lower, upper] (m or rad).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        limits: Option<[f32; 2]>,
        /// A spring.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        spring: Option<Spring>,
        /// A motor.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        motor: Option<MotorDesc>,
    },
}

/// `"locked"` or `"free"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DofMode {
    /// Locked.
    Locked,
    /// Free.
    Free,
}

/// A motor in a scene file: `velocity` (m/s or rad/s), or `position` with `hertz` and
/// `damping_ratio`; and `max_force` (N or N·m).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorDesc {
    /// Target velocity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<f32>,
    /// Target position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<f32>,
    /// A position motor's frequency (Hz); default 5.
    #[serde(default = "default_servo_hertz")]
    pub hertz: f32,
    /// A position motor's damping ratio; default 1.
    #[serde(default = "default_damping")]
    pub damping_ratio: f32,
    /// Largest force or torque.
    pub max_force: f32,
}

fn default_servo_hertz() -> f32 {
    5.0
}

fn default_damping() -> f32 {
    1.0
}

/// A joint's softer repair in a scene file (absent: stiff).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StiffnessDesc {
    /// Frequency (Hz) > 0.
    pub hertz: f32,
    /// Damping ratio ≥ 0.
    pub damping_ratio: f32,
}

/// A joint in a scene file. Frames: `anchor` (a world point, both bodies) or `anchor_a` and
/// `anchor_b` (each body's frame, from its origin; or, for a distance joint, `world_anchors`:
/// one world point per body); `axis` (world) or `axis_a` and `axis_b` (each body's frame);
/// placed at the bodies' initial poses.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDesc {
    /// Kind.
    #[serde(rename = "type")]
    pub kind: JointKind,
    /// Name shown in errors and events.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Body A.
    pub body_a: BodyName,
    /// Body B.
    pub body_b: BodyName,
    /// World anchor of both bodies (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<[f32; 3]>,
    /// World anchors, one per body (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world_anchors: Option<[[f32; 3]; 2]>,
    /// A's anchor in A's frame (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_a: Option<[f32; 3]>,
    /// B's anchor in B's frame (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_b: Option<[f32; 3]>,
    /// The joint axis in the world.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f32; 3]>,
    /// The axis in A's frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_a: Option<[f32; 3]>,
    /// The axis in B's frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_b: Option<[f32; 3]>,
    /// Limits of the kind's main degree of freedom ([`JointBuilder::main_dof`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<[f32; 2]>,
    /// Spring on the main degree of freedom.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring: Option<Spring>,
    /// Motor on the main degree of freedom.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor: Option<MotorDesc>,
    /// Degrees of freedom by name (`linear_x` … `angular_z`), over the kind's defaults.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub dofs: std::collections::BTreeMap<String, DofDesc>,
    /// A softer repair; absent: stiff.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<StiffnessDesc>,
    /// Whether the bodies still collide.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub collide_connected: bool,
    /// Break force (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub break_force: Option<f32>,
    /// Break torque (N·m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub break_torque: Option<f32>,
    /// The window (s) the break thresholds are measured over; absent: one substep
    /// ([`crate::JointBuilder::break_window`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub break_window: Option<f32>,
}

impl JointDesc {
    /// A joint of `kind` between two bodies, frames at a world anchor, the rest default.
    pub fn new(kind: JointKind, body_a: BodyName, body_b: BodyName, anchor: [f32; 3]) -> Self {
        Self {
            kind,
            name: None,
            body_a,
            body_b,
            anchor: Some(anchor),
            world_anchors: None,
            anchor_a: None,
            anchor_b: None,
            axis: None,
            axis_a: None,
            axis_b: None,
            limits: None,
            spring: None,
            motor: None,
            dofs: Default::default(),
            stiffness: None,
            collide_connected: false,
            break_force: None,
            break_torque: None,
            break_window: None,
        }
    }

    /// The builder of this joint between `a` and `b`, or the first problem as (field from
    /// the joint, message): frames, limits, springs, motors, options.
    pub(crate) fn builder(
        &self,
        a: BodyHandle,
        b: BodyHandle,
    ) -> Result<JointBuilder, (String, String)> {
        let mut builder = JointBuilder::new(self.kind, a, b);
        let vector = |field: &str, v: [f32; 3], nonzero: bool| {
            let v = Vec3::from(v);
            if !v.is_finite() {
                Err((
                    field.to_string(),
                    format!("must be finite, got {:?}", v.to_array()),
                ))
            } else if nonzero && v.length() < 1e-6 {
                Err((field.to_string(), "must not be zero".to_string()))
            } else {
                Ok(v)
            }
        };
        match (
            self.anchor,
            self.world_anchors,
            self.anchor_a,
            self.anchor_b,
        ) {
            (Some(p), None, None, None) => {
                builder = builder.world_anchor(vector("anchor", p, false)?)
            }
            (None, Some([p, q]), None, None) => {
                builder = builder.world_anchors(
                    vector("world_anchors[0]", p, false)?,
                    vector("world_anchors[1]", q, false)?,
                )
            }
            (None, None, Some(p), Some(q)) => {
                builder = builder
                    .local_anchors(vector("anchor_a", p, false)?, vector("anchor_b", q, false)?)
            }
            _ => {
                return Err((
                    "anchor".into(),
                    "give `anchor`, or `world_anchors`, or both `anchor_a` and `anchor_b`".into(),
                ));
            }
        }
        match (self.axis, self.axis_a, self.axis_b) {
            (Some(axis), None, None) => builder = builder.world_axis(vector("axis", axis, true)?),
            (None, Some(p), Some(q)) => {
                builder = builder.local_axes(vector("axis_a", p, true)?, vector("axis_b", q, true)?)
            }
            (None, None, None) => {}
            _ => {
                return Err((
                    "axis".into(),
                    "give `axis`, or both `axis_a` and `axis_b`".into(),
                ));
            }
        }
        if let Some([lower, upper]) = self.limits {
            builder = builder.limits(lower, upper);
        }
        if let Some(spring) = self.spring {
            builder = builder.spring(spring.hertz, spring.damping_ratio, spring.rest);
        }
        if let Some(motor) = &self.motor {
            builder = builder.motor(motor.to_motor("motor")?);
        }
        if let Some((field, message)) = builder.misuse.clone() {
            return Err((field, message));
        }
        for (name, dof) in &self.dofs {
            let Some(index) = JointDof::ALL.iter().find(|d| d.name() == name) else {
                return Err((
                    format!("dofs.{name}"),
                    "unknown degree of freedom (linear_x … angular_z)".into(),
                ));
            };
            let axis = match dof {
                DofDesc::Mode(DofMode::Locked) => JointAxis::LOCKED,
                DofDesc::Mode(DofMode::Free) => JointAxis::FREE,
                DofDesc::Detailed {
                    limits,
                    spring,
                    motor,
                } => JointAxis {
                    mode: match limits {
                        Some([lower, upper]) => AxisMode::Limited {
                            lower: *lower,
                            upper: *upper,
                        },
                        None => AxisMode::Free,
                    },
                    spring: *spring,
                    motor: motor
                        .as_ref()
                        .map(|m| m.to_motor(&format!("dofs.{name}.motor")))
                        .transpose()?,
                },
            };
            builder.dofs[index.index()] = axis;
        }
        if let Some(s) = self.stiffness {
            builder = builder.stiffness(JointStiffness::Soft {
                hertz: s.hertz,
                damping_ratio: s.damping_ratio,
            });
        }
        builder = builder.collide_connected(self.collide_connected);
        builder.break_force = self.break_force;
        builder.break_torque = self.break_torque;
        builder.break_window = self.break_window;
        if let Some(name) = &self.name {
            builder = builder.name(name.clone());
        }
        check_dofs(self.kind, &builder.dofs).map_err(|p| (p.field, p.message))?;
        check_options(
            builder.stiffness,
            builder.break_force,
            builder.break_torque,
            builder.break_window,
        )
        .map_err(|p| (p.field, p.message))?;
        Ok(builder)
    }
}

impl MotorDesc {
    fn to_motor(&self, field: &str) -> Result<Motor, (String, String)> {
        let mode = match (self.velocity, self.position) {
            (Some(speed), None) => MotorMode::Velocity { speed },
            (None, Some(target)) => MotorMode::Position {
                target,
                hertz: self.hertz,
                damping_ratio: self.damping_ratio,
            },
            _ => {
                return Err((
                    field.to_string(),
                    "give one of `velocity` and `position`".into(),
                ));
            }
        };
        Ok(Motor {
            mode,
            max_force: self.max_force,
        })
    }
}

/// The index of the body `name` names among `bodies` (index in range, or a unique name).
pub(crate) fn resolve_body(name: &BodyName, names: &[Option<String>]) -> Result<usize, String> {
    match name {
        BodyName::Index(i) if *i < names.len() => Ok(*i),
        BodyName::Index(i) => Err(format!("no body {i} (the scene has {})", names.len())),
        BodyName::Name(n) => {
            let mut found = names
                .iter()
                .enumerate()
                .filter(|(_, m)| m.as_deref() == Some(n.as_str()));
            match (found.next(), found.next()) {
                (Some((i, _)), None) => Ok(i),
                (None, _) => Err(format!("no body named \"{n}\"")),
                _ => Err(format!("more than one body is named \"{n}\"")),
            }
        }
    }
}

/// Every problem of the scene's joints, with their paths (`joints[2].limits`): bodies that
/// exist and differ, at least one of them not static, frames (anchors within
/// [`crate::joint::rules::MAX_ANCHOR_DISTANCE`] of their bodies), limits, springs, motors.
/// `kinds`, `names` and `positions` (m) are the scene's bodies'.
pub(crate) fn joint_errors(
    joints: &[JointDesc],
    kinds: &[BodyKind],
    names: &[Option<String>],
    positions: &[[f32; 3]],
) -> Vec<SceneError> {
    let mut errors = Vec::new();
    for (k, joint) in joints.iter().enumerate() {
        let path = FieldPath::root().key("joints").index(k);
        let fail = |field: &str, message: String| {
            let path = field.split('.').fold(path.clone(), |p, key| p.key(key));
            SceneError::new(SceneErrorKind::Invalid, Some(path), message)
        };
        let a = resolve_body(&joint.body_a, names).map_err(|m| fail("body_a", m));
        let b = resolve_body(&joint.body_b, names).map_err(|m| fail("body_b", m));
        let (a, b) = match (a, b) {
            (Ok(a), Ok(b)) => (a, b),
            (a, b) => {
                errors.extend(a.err());
                errors.extend(b.err());
                continue;
            }
        };
        if a == b {
            errors.push(fail("body_b", "must differ from body_a".into()));
            continue;
        }
        let moves = |i: usize| kinds[i] == BodyKind::Dynamic || kinds[i] == BodyKind::Particle;
        if !moves(a) && !moves(b) {
            errors.push(fail(
                "body_b",
                "neither body is dynamic: the joint would move nothing".into(),
            ));
            continue;
        }
        // Handles are not known before a world exists; any serves the checks.
        let placeholder = crate::body::Handles::default().insert(0);
        if let Err((field, message)) = joint.builder(placeholder, placeholder) {
            errors.push(fail(&field, message));
            continue;
        }
        if let Some((key, index, problem)) = joint.anchor_problem(positions[a], positions[b]) {
            let field = match index {
                Some(i) => path.key(key).index(i),
                None => path.key(key),
            };
            errors.push(SceneError::new(
                SceneErrorKind::Invalid,
                Some(field),
                problem.message,
            ));
        }
    }
    errors
}

impl JointDesc {
    /// The first anchor of a joint whose bodies start at `position_a` and `position_b` that
    /// lies beyond [`crate::joint::rules::MAX_ANCHOR_DISTANCE`] of its body's origin: its
    /// field path and the problem. An anchor given in the world is measured from the body's
    /// position (a rotation keeps the distance).
    fn anchor_problem(
        &self,
        position_a: [f32; 3],
        position_b: [f32; 3],
    ) -> Option<(&'static str, Option<usize>, JointProblem)> {
        let from = |p: [f32; 3], origin: [f32; 3]| Vec3::from(p) - Vec3::from(origin);
        let anchors = match (
            self.anchor,
            self.world_anchors,
            self.anchor_a,
            self.anchor_b,
        ) {
            (Some(p), None, None, None) => [
                ("anchor", None, from(p, position_a)),
                ("anchor", None, from(p, position_b)),
            ],
            (None, Some([p, q]), None, None) => [
                ("world_anchors", Some(0), from(p, position_a)),
                ("world_anchors", Some(1), from(q, position_b)),
            ],
            (None, None, Some(p), Some(q)) => [
                ("anchor_a", None, Vec3::from(p)),
                ("anchor_b", None, Vec3::from(q)),
            ],
            _ => return None,
        };
        anchors.into_iter().find_map(|(key, index, anchor)| {
            let field = index.map_or(key.to_string(), |i| format!("{key}[{i}]"));
            anchor_reach(&field, anchor)
                .err()
                .map(|problem| (key, index, problem))
        })
    }
}
