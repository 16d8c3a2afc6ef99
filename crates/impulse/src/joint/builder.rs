//! [`JointBuilder`]: the description of a joint to insert, with helpers that place its frames
//! from a world anchor and axis.

use glam::{Quat, Vec3};

use super::forms::JointKind;
use super::types::Spring;
use super::types::{AxisMode, JointAxis, JointDof, JointStiffness, Motor, MotorMode};
use crate::body::BodyHandle;

/// Where the joint's anchors are given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Anchors {
    /// In each body's own frame (m, from the body origin).
    Local { a: Vec3, b: Vec3 },
    /// In the world frame (m), at the bodies' poses when the joint is inserted.
    World { a: Vec3, b: Vec3 },
}

/// How the joint's frames are oriented.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Axes {
    /// Each frame's rotation in its body's frame.
    Local { a: Quat, b: Quat },
    /// The joint axis (the frames' x axis) in the world frame, at insertion; both frames take
    /// the shortest rotation from x to it.
    World(Vec3),
}

/// A joint to insert into a [`crate::World`] ([`crate::World::insert_joint`]) between body A
/// and body B. The joint acts between a frame on each body (an anchor point and three axes,
/// given in the body's frame or placed from a world anchor and axis at insertion) and
/// constrains the six degrees of freedom of B's frame relative to A's, along and about A's
/// frame axes ([`JointDof`]); the kind sets which are locked ([`JointKind`]), and
/// [`JointBuilder::dof`] sets any of them. The joint's axis is its frames' x axis (a hinge's
/// axis, a slider's direction). Checked when inserted: both bodies in the world and distinct,
/// at least one of them dynamic, every number finite, axes and rotations non-zero, limits
/// ordered (angles within [−π, π]), springs of positive frequency, motors of non-negative
/// force, springs and motors on non-locked degrees of freedom only.
///
/// Joined bodies do not collide with each other unless [`JointBuilder::collide_connected`]
/// says so. Sign conventions: positions and velocities are B's relative to A's (a hinge's
/// angle is positive counter-clockwise about the axis); a joint's impulse acts on B along the
/// row and on A against it.
///
/// ```
/// use impulse::glam::Vec3;
/// use impulse::{BodyBuilder, JointBuilder, SharedShape, SolverSettings, World};
///
/// let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, SolverSettings::default())?;
/// let post = world.insert(BodyBuilder::fixed(SharedShape::cuboid(0.1, 1.0, 0.1)))?;
/// let door = world.insert(BodyBuilder::dynamic(SharedShape::cuboid(0.5, 1.0, 0.05))
///     .translation(Vec3::new(0.6, 0.0, 0.0)))?;
/// // A hinge about the world y axis through (0.1, 0, 0), opening at most a quarter turn.
/// let hinge = world.insert_joint(
///     JointBuilder::revolute(post, door)
///         .world_anchor(Vec3::new(0.1, 0.0, 0.0))
///         .world_axis(Vec3::Y)
///         .limits(-1.5708, 0.0),
/// )?;
/// world.step()?;
/// assert!(world.joint(hinge).is_some());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct JointBuilder {
    pub(crate) kind: JointKind,
    pub(crate) body_a: BodyHandle,
    pub(crate) body_b: BodyHandle,
    pub(crate) anchors: Anchors,
    pub(crate) axes: Axes,
    pub(crate) dofs: [JointAxis; 6],
    pub(crate) stiffness: JointStiffness,
    pub(crate) collide_connected: bool,
    pub(crate) break_force: Option<f32>,
    pub(crate) break_torque: Option<f32>,
    pub(crate) break_window: Option<f32>,
    pub(crate) name: Option<String>,
    /// A builder call that does not fit the kind (field, message), reported at insertion.
    pub(crate) misuse: Option<(String, String)>,
}

impl JointBuilder {
    /// A joint of `kind` between `body_a` and `body_b`, anchors at both body origins, frames
    /// aligned with the bodies' frames, with the kind's locked degrees of freedom. For a
    /// distance joint the anchor distance is then free: give it with
    /// [`JointBuilder::distance`] or [`JointBuilder::limits`].
    pub fn new(kind: JointKind, body_a: BodyHandle, body_b: BodyHandle) -> Self {
        let dofs = kind.form().dofs();
        Self {
            kind,
            body_a,
            body_b,
            anchors: Anchors::Local {
                a: Vec3::ZERO,
                b: Vec3::ZERO,
            },
            axes: Axes::Local {
                a: Quat::IDENTITY,
                b: Quat::IDENTITY,
            },
            dofs,
            stiffness: JointStiffness::Stiff,
            collide_connected: false,
            break_force: None,
            break_torque: None,
            break_window: None,
            name: None,
            misuse: None,
        }
    }

    /// [`JointKind::Fixed`]: the two bodies move as one.
    pub fn fixed(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        Self::new(JointKind::Fixed, body_a, body_b)
    }

    /// [`JointKind::Spherical`]: a ball-and-socket joint at the anchors.
    pub fn spherical(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        Self::new(JointKind::Spherical, body_a, body_b)
    }

    /// [`JointKind::Revolute`]: a hinge about the frames' x axis.
    pub fn revolute(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        Self::new(JointKind::Revolute, body_a, body_b)
    }

    /// [`JointKind::Prismatic`]: a slider along the frames' x axis.
    pub fn prismatic(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        Self::new(JointKind::Prismatic, body_a, body_b)
    }

    /// [`JointKind::Distance`]: the anchors' distance kept within [`min`, `max`] (m); equal
    /// bounds make a rod, `min` = 0 a rope.
    pub fn distance(body_a: BodyHandle, body_b: BodyHandle, min: f32, max: f32) -> Self {
        Self::new(JointKind::Distance, body_a, body_b).limits(min, max)
    }

    /// [`JointKind::Generic`]: all six degrees of freedom locked until [`JointBuilder::dof`]
    /// frees or limits them.
    pub fn generic(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        Self::new(JointKind::Generic, body_a, body_b)
    }

    /// The kind's one non-locked degree of freedom, which [`JointBuilder::limits`],
    /// [`JointBuilder::spring`] and [`JointBuilder::motor`] act on: a hinge's angle, a
    /// slider's or a distance joint's distance; `None` for the other kinds.
    pub fn main_dof(kind: JointKind) -> Option<JointDof> {
        kind.form().main_dof()
    }

    /// Anchors in each body's frame (m, from the body origin, not the centre of mass).
    pub fn local_anchors(mut self, anchor_a: Vec3, anchor_b: Vec3) -> Self {
        self.anchors = Anchors::Local {
            a: anchor_a,
            b: anchor_b,
        };
        self
    }

    /// Both anchors at one world point (m), placed in each body's frame at the bodies' poses
    /// when the joint is inserted.
    pub fn world_anchor(self, anchor: Vec3) -> Self {
        self.world_anchors(anchor, anchor)
    }

    /// A world anchor for each body (m): a distance joint's two ends.
    pub fn world_anchors(mut self, anchor_a: Vec3, anchor_b: Vec3) -> Self {
        self.anchors = Anchors::World {
            a: anchor_a,
            b: anchor_b,
        };
        self
    }

    /// The frames' rotations in each body's frame: the joint axis is each rotation applied to
    /// x.
    pub fn local_frames(mut self, rotation_a: Quat, rotation_b: Quat) -> Self {
        self.axes = Axes::Local {
            a: rotation_a,
            b: rotation_b,
        };
        self
    }

    /// The joint axis in each body's frame (non-zero; normalised): each frame takes the
    /// shortest rotation from x to its axis.
    pub fn local_axes(mut self, axis_a: Vec3, axis_b: Vec3) -> Self {
        for (field, axis) in [("axis_a", axis_a), ("axis_b", axis_b)] {
            if !(axis.is_finite() && axis.length() > 1e-6) {
                self.misuse = Some((
                    field.to_string(),
                    format!("must be finite and non-zero, got {:?}", axis.to_array()),
                ));
            }
        }
        self.local_frames(shortest_arc(axis_a), shortest_arc(axis_b))
    }

    /// The joint axis in the world frame (non-zero; normalised), placed in each body's frame
    /// at the bodies' poses when the joint is inserted.
    pub fn world_axis(mut self, axis: Vec3) -> Self {
        self.axes = Axes::World(axis);
        self
    }

    /// Sets one degree of freedom's mode.
    pub fn dof(mut self, dof: JointDof, mode: AxisMode) -> Self {
        self.dofs[dof.index()].mode = mode;
        self
    }

    /// A spring on one degree of freedom (not locked).
    pub fn dof_spring(mut self, dof: JointDof, spring: Spring) -> Self {
        self.dofs[dof.index()].spring = Some(spring);
        self
    }

    /// A motor on one degree of freedom (not locked).
    pub fn dof_motor(mut self, dof: JointDof, motor: Motor) -> Self {
        self.dofs[dof.index()].motor = Some(motor);
        self
    }

    /// Limits of the kind's main degree of freedom ([`JointBuilder::main_dof`]): a hinge's
    /// angle (rad, within [−π, π]), a slider's position or a distance joint's length (m).
    pub fn limits(self, lower: f32, upper: f32) -> Self {
        self.on_main_dof("limits", |axis| {
            axis.mode = AxisMode::Limited { lower, upper }
        })
    }

    /// A spring on the kind's main degree of freedom: natural frequency (Hz), damping ratio
    /// and the rest position (rad or m; a distance joint's rest length).
    pub fn spring(self, hertz: f32, damping_ratio: f32, rest: f32) -> Self {
        self.on_main_dof("spring", |axis| {
            axis.spring = Some(Spring {
                hertz,
                damping_ratio,
                rest,
            })
        })
    }

    /// A motor on the kind's main degree of freedom.
    pub fn motor(self, motor: Motor) -> Self {
        self.on_main_dof("motor", |axis| axis.motor = Some(motor))
    }

    /// A velocity motor on the kind's main degree of freedom: `speed` (rad/s or m/s) with at
    /// most `max_force` (N·m or N).
    pub fn motor_velocity(self, speed: f32, max_force: f32) -> Self {
        self.motor(Motor {
            mode: MotorMode::Velocity { speed },
            max_force,
        })
    }

    /// A position motor (servo) on the kind's main degree of freedom: towards `target` (rad or
    /// m) as a spring of `hertz` and `damping_ratio`, with at most `max_force`.
    pub fn motor_position(
        self,
        target: f32,
        hertz: f32,
        damping_ratio: f32,
        max_force: f32,
    ) -> Self {
        self.motor(Motor {
            mode: MotorMode::Position {
                target,
                hertz,
                damping_ratio,
            },
            max_force,
        })
    }

    /// How the locked rows and limits repair drift ([`JointStiffness`]; default stiff).
    pub fn stiffness(mut self, stiffness: JointStiffness) -> Self {
        self.stiffness = stiffness;
        self
    }

    /// Whether the two bodies still collide with each other (default `false`).
    pub fn collide_connected(mut self, collide: bool) -> Self {
        self.collide_connected = collide;
        self
    }

    /// Makes the joint breakable with strength `force` (N) for its locked translations and
    /// `torque` (N·m) for its locked rotations (either may be infinite). The solver bounds the
    /// locked rows' impulse by strength × substep (as friction by its disc); a substep that
    /// ends at that bound breaks the joint there, so neighbours receive at most that pulse
    /// (the brittle failure of Bullet's and PhysX's breaking impulse thresholds). It is then
    /// no longer solved; [`crate::World::joint_events`] reports it at the end of the step.
    pub fn breakable(mut self, force: f32, torque: f32) -> Self {
        self.break_force = Some(force);
        self.break_torque = Some(torque);
        self
    }

    /// Measures the break thresholds over a window of `seconds` (s, ≥ 0; default 0: one
    /// substep): the joint breaks when its locked translations passed force × `seconds` of
    /// impulse over the last `seconds` (an exponential window; torques alike). A steady load
    /// breaks it at the same force as without a window; a blow breaks it when its impulse
    /// reaches force × `seconds`, however many substeps carry it, so its impact strength does
    /// not depend on the substep length. Bullet's (and Blender's) breaking threshold, an
    /// impulse per Bullet substep, is force = threshold / substep with a window of that
    /// substep. Only for a [`Self::breakable`] joint.
    pub fn break_window(mut self, seconds: f32) -> Self {
        self.break_window = Some(seconds);
        self
    }

    /// A name, shown in errors and events.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// The kind.
    pub fn kind(&self) -> JointKind {
        self.kind
    }

    fn on_main_dof(mut self, what: &str, set: impl FnOnce(&mut JointAxis)) -> Self {
        match Self::main_dof(self.kind) {
            Some(dof) => set(&mut self.dofs[dof.index()]),
            None => {
                self.misuse = Some((
                    what.to_string(),
                    format!(
                        "a {} joint has no main degree of freedom: use a generic joint and `dof`",
                        self.kind.name()
                    ),
                ))
            }
        }
        self
    }
}

/// The shortest rotation taking x to `axis` (identity for a zero axis, which the checks at
/// insertion refuse).
pub(crate) fn shortest_arc(axis: Vec3) -> Quat {
    let axis = axis.normalize_or_zero();
    if axis == Vec3::ZERO {
        Quat::IDENTITY
    } else {
        Quat::from_rotation_arc(Vec3::X, axis)
    }
}
