//! The rules of a joint's values, checked with the same messages by [`crate::World::insert_joint`]
//! and the scene validator (which adds the file, line and field path).

use std::f32::consts::PI;

use super::forms::JointKind;
pub(crate) use super::forms::JointProblem;
use super::types::{AxisMode, JointAxis, JointDof, JointStiffness, MotorMode};

fn problem(field: impl Into<String>, message: impl Into<String>) -> JointProblem {
    JointProblem {
        field: field.into(),
        message: message.into(),
    }
}

/// `value` finite and > 0.
fn positive(field: &str, value: f32) -> Result<(), JointProblem> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(problem(
            field,
            format!("must be finite and > 0, got {value}"),
        ))
    }
}

/// Highest spring or motor frequency (Hz) and damping ratio a joint takes: 10⁶. A spring far
/// stiffer than the substep rate already acts as a rigid row (its soft coefficients reach
/// their limits); 10³⁰ Hz overflows them (h·ω·(2ζ + h·ω) is infinite in f32) and gives NaN.
pub(crate) const MAX_SPRING: f32 = 1.0e6;

/// `value` finite, > 0 and at most [`MAX_SPRING`] (a frequency, Hz).
fn frequency(field: &str, value: f32) -> Result<(), JointProblem> {
    positive(field, value)?;
    if value <= MAX_SPRING {
        Ok(())
    } else {
        Err(problem(
            field,
            format!("must be at most {MAX_SPRING:e} Hz, got {value:e}"),
        ))
    }
}

/// `value` finite, ≥ 0 and at most [`MAX_SPRING`] (a damping ratio).
fn damping_ratio(field: &str, value: f32) -> Result<(), JointProblem> {
    non_negative(field, value)?;
    if value <= MAX_SPRING {
        Ok(())
    } else {
        Err(problem(
            field,
            format!("must be at most {MAX_SPRING:e}, got {value:e}"),
        ))
    }
}

/// `value` finite and ≥ 0.
fn non_negative(field: &str, value: f32) -> Result<(), JointProblem> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(problem(
            field,
            format!("must be finite and ≥ 0, got {value}"),
        ))
    }
}

fn finite(field: &str, value: f32) -> Result<(), JointProblem> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(problem(field, format!("must be finite, got {value}")))
    }
}

/// The field name of a degree of freedom's part: the kind's main one is named as its builder
/// calls name it (`limits`, `spring`, `motor`), the others `dofs.<name>.<part>`.
pub(crate) fn dof_field(kind: JointKind, dof: JointDof, part: &str) -> String {
    if kind.form().main_dof() == Some(dof) {
        part.to_string()
    } else {
        format!("dofs.{}.{part}", dof.name())
    }
}

/// Checks the degrees of freedom of a joint of `kind`: limits ordered and finite (angles within
/// [−π, π]), springs and motors well formed and on non-locked degrees of freedom only, and
/// what the kind's form checks besides ([`super::forms::JointForm::check_limits`], a distance
/// joint's lengths ≥ 0 and not both 0; [`super::forms::JointForm::check_dofs`]).
pub(crate) fn check_dofs(kind: JointKind, dofs: &[JointAxis; 6]) -> Result<(), JointProblem> {
    let form = kind.form();
    for dof in JointDof::ALL {
        let axis = &dofs[dof.index()];
        let field = |part: &str| dof_field(kind, dof, part);
        if let AxisMode::Limited { lower, upper } = axis.mode {
            finite(&format!("{}.lower", field("limits")), lower)?;
            finite(&format!("{}.upper", field("limits")), upper)?;
            if lower > upper {
                return Err(problem(
                    field("limits"),
                    format!("lower ({lower}) must be ≤ upper ({upper})"),
                ));
            }
            if dof.is_angular() && (lower < -PI || upper > PI) {
                return Err(problem(
                    field("limits"),
                    format!("angles must be within [−π, π], got [{lower}, {upper}]"),
                ));
            }
            form.check_limits(dof, lower, upper)
                .map_err(|message| problem(field("limits"), message))?;
        }
        let locked = axis.mode == AxisMode::Locked;
        if let Some(spring) = axis.spring {
            if locked {
                return Err(problem(
                    field("spring"),
                    "a locked degree of freedom takes no spring",
                ));
            }
            frequency(&format!("{}.hertz", field("spring")), spring.hertz)?;
            damping_ratio(
                &format!("{}.damping_ratio", field("spring")),
                spring.damping_ratio,
            )?;
            finite(&format!("{}.rest", field("spring")), spring.rest)?;
        }
        if let Some(motor) = axis.motor {
            if locked {
                return Err(problem(
                    field("motor"),
                    "a locked degree of freedom takes no motor",
                ));
            }
            non_negative(&format!("{}.max_force", field("motor")), motor.max_force)?;
            match motor.mode {
                MotorMode::Velocity { speed } => {
                    finite(&format!("{}.velocity", field("motor")), speed)?
                }
                MotorMode::Position {
                    target,
                    hertz,
                    damping_ratio,
                } => {
                    finite(&format!("{}.position", field("motor")), target)?;
                    frequency(&format!("{}.hertz", field("motor")), hertz)?;
                    self::damping_ratio(
                        &format!("{}.damping_ratio", field("motor")),
                        damping_ratio,
                    )?;
                }
            }
        }
    }
    form.check_dofs(dofs)
}

/// Checks the repair stiffness, the break thresholds and their window.
pub(crate) fn check_options(
    stiffness: JointStiffness,
    break_force: Option<f32>,
    break_torque: Option<f32>,
    break_window: Option<f32>,
) -> Result<(), JointProblem> {
    if let JointStiffness::Soft {
        hertz,
        damping_ratio,
    } = stiffness
    {
        frequency("stiffness.hertz", hertz)?;
        self::damping_ratio("stiffness.damping_ratio", damping_ratio)?;
    }
    for (field, value) in [("break_force", break_force), ("break_torque", break_torque)] {
        if let Some(value) = value
            && (value.is_nan() || value <= 0.0)
        {
            return Err(problem(
                field,
                format!("must be > 0 (may be infinite), got {value}"),
            ));
        }
    }
    if let Some(window) = break_window {
        if !(window.is_finite() && window >= 0.0) {
            return Err(problem(
                "break_window",
                format!("must be finite and >= 0 s, got {window}"),
            ));
        }
        if break_force.is_none() && break_torque.is_none() {
            return Err(problem(
                "break_window",
                "is for a breakable joint: give break_force or break_torque too".to_string(),
            ));
        }
    }
    Ok(())
}

/// How far (m) a joint's anchor may lie from its body's origin: the reach a shape may have
/// ([`crate::body::rules::MAX_SHAPE_EXTENT`], 10⁶ m), since an anchor is a point carried by
/// the body as its shape's points are. The anchor's lever arm enters the joint's rows as
/// r × d and its effective mass as |r|²/I: an anchor 10¹⁰ m from a ball 0.25 m across makes
/// rows whose f32 products lose every digit of the ball's own motion (the joint then pumps
/// energy in at its first step).
pub(crate) const MAX_ANCHOR_DISTANCE: f32 = crate::body::rules::MAX_SHAPE_EXTENT;

/// A joint's anchor `anchor` (m, in its body's frame, from the body's origin) within
/// [`MAX_ANCHOR_DISTANCE`] of the origin. `field` names it as the caller's input does
/// (`anchor_a`, or `anchor`, `world_anchors[1]` for a world anchor).
pub(crate) fn anchor_reach(field: &str, anchor: glam::Vec3) -> Result<(), JointProblem> {
    let distance = anchor.length();
    if distance.is_finite() && distance <= MAX_ANCHOR_DISTANCE {
        Ok(())
    } else {
        Err(problem(
            field,
            format!(
                "the anchor lies {distance:e} m from its body's origin; at most \
                 {MAX_ANCHOR_DISTANCE:e} m (the reach of a shape)"
            ),
        ))
    }
}
