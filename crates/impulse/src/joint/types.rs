//! The public description of a joint's degrees of freedom: which are locked, limited or free,
//! and the spring and motor a free or limited one may carry (the kinds of joint, which set
//! them, are the forms of `forms/`).

use serde::{Deserialize, Serialize};

/// One of a joint's six degrees of freedom, in body A's joint frame: translations along and
/// rotations about its x, y and z axes. Index order: `LinearX` = 0 … `AngularZ` = 5.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointDof {
    /// Translation along the frame's x axis (m); a distance joint's anchor distance.
    LinearX,
    /// Translation along the frame's y axis (m).
    LinearY,
    /// Translation along the frame's z axis (m).
    LinearZ,
    /// Rotation about the frame's x axis (rad): a hinge's angle.
    AngularX,
    /// Rotation about the frame's y axis (rad).
    AngularY,
    /// Rotation about the frame's z axis (rad).
    AngularZ,
}

impl JointDof {
    /// All six, in index order.
    pub const ALL: [JointDof; 6] = [
        JointDof::LinearX,
        JointDof::LinearY,
        JointDof::LinearZ,
        JointDof::AngularX,
        JointDof::AngularY,
        JointDof::AngularZ,
    ];

    /// Index 0–5 (linear x, y, z, then angular x, y, z).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Whether it is a rotation.
    pub fn is_angular(self) -> bool {
        self.index() >= 3
    }

    /// Lower-case name, as in scene files (`linear_x` … `angular_z`).
    pub fn name(self) -> &'static str {
        match self {
            JointDof::LinearX => "linear_x",
            JointDof::LinearY => "linear_y",
            JointDof::LinearZ => "linear_z",
            JointDof::AngularX => "angular_x",
            JointDof::AngularY => "angular_y",
            JointDof::AngularZ => "angular_z",
        }
    }
}

/// What a joint does to one degree of freedom.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisMode {
    /// Held at zero by a bilateral row (an equality: its impulse has either sign).
    Locked,
    /// Kept within [lower, upper] (m or rad; lower ≤ upper) by two unilateral rows, one per
    /// bound, each pushing only away from its bound (a limit is a contact in joint space).
    /// Angles within (−π, π].
    Limited {
        /// Lower bound (m or rad).
        lower: f32,
        /// Upper bound (m or rad).
        upper: f32,
    },
    /// Not constrained (a spring or motor may still act on it).
    Free,
}

/// A damped spring on a free or limited degree of freedom, parameterised as the soft contacts
/// are (docs/method.md, "Overlap repair": Catto's soft constraints): a stiffness as a
/// frequency and a damping ratio, independent of the bodies' masses, implicit in the substep.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spring {
    /// Natural frequency (Hz) > 0 of the spring acting on the row's effective mass.
    pub hertz: f32,
    /// Damping ratio ζ ≥ 0 (1 is critical).
    pub damping_ratio: f32,
    /// The position it pulls towards (m or rad; a distance joint's rest length).
    pub rest: f32,
}

/// What a motor drives its degree of freedom towards.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotorMode {
    /// A relative velocity (m/s or rad/s, positive along or about the frame axis, B relative
    /// to A).
    Velocity {
        /// Target speed.
        speed: f32,
    },
    /// A position (m or rad), reached as a spring of `hertz` and `damping_ratio` would, but
    /// with the motor's bounded force (a servo).
    Position {
        /// Target position (m or rad).
        target: f32,
        /// Natural frequency (Hz) > 0 of the servo.
        hertz: f32,
        /// Damping ratio ζ ≥ 0.
        damping_ratio: f32,
    },
}

/// A motor on a free or limited degree of freedom: a row whose impulse is bounded by
/// ±`max_force`·h in each substep of h seconds (a boxed row of the LCP).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Motor {
    /// Velocity or position target.
    pub mode: MotorMode,
    /// Largest force (N) or torque (N·m) ≥ 0 it applies.
    pub max_force: f32,
}

/// One degree of freedom of a joint: its mode, and an optional spring and motor (on a
/// non-locked one only).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointAxis {
    /// Locked, limited or free.
    pub mode: AxisMode,
    /// Spring towards a rest position.
    pub spring: Option<Spring>,
    /// Motor with a bounded force.
    pub motor: Option<Motor>,
}

impl JointAxis {
    /// A locked degree of freedom.
    pub const LOCKED: JointAxis = JointAxis {
        mode: AxisMode::Locked,
        spring: None,
        motor: None,
    };

    /// A free degree of freedom.
    pub const FREE: JointAxis = JointAxis {
        mode: AxisMode::Free,
        spring: None,
        motor: None,
    };
}

/// How a joint's locked rows and limits repair the error they find (drift, a limit passed):
/// both are the soft constraint of docs/method.md ("Overlap repair") in the main solve of each
/// substep, and rigid (no repair velocity) in its relax solve, as Box2D v3's joint softness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointStiffness {
    /// As stiff as the substep allows: a spring of a quarter of the substep rate, damping
    /// ratio 2 (Box2D v3's cap and default ratio for joints).
    Stiff,
    /// A softer joint: the repair as a spring of `hertz` (capped at a quarter of the substep
    /// rate) and `damping_ratio`.
    Soft {
        /// Natural frequency (Hz) > 0.
        hertz: f32,
        /// Damping ratio ζ ≥ 0.
        damping_ratio: f32,
    },
}
