//! The soft-constraint coefficients of a joint's rows ([`Softness`]) and the stiffest repair a
//! joint takes ([`joint_softness`]).

use super::types::JointStiffness;

/// The soft-constraint coefficients of a spring of `hertz` and damping ratio ζ over a substep
/// of h (Catto 2011; Box2D v3's `b2MakeSoft`): with ω = 2πf and a = hω(2ζ + hω), bias rate
/// ω/(2ζ + hω), mass scale a/(1 + a), impulse scale 1/(1 + a).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Softness {
    pub bias_rate: f32,
    pub mass_scale: f32,
    pub impulse_scale: f32,
}

impl Softness {
    /// A rigid row: no bias, the whole effective mass, no relaxation.
    pub(crate) const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    pub(crate) fn new(hertz: f32, damping_ratio: f32, h: f32) -> Self {
        if hertz <= 0.0 {
            return Self::RIGID;
        }
        let omega = 2.0 * std::f32::consts::PI * hertz;
        let a1 = 2.0 * damping_ratio + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// The stiffest repair a joint takes: a quarter of the substep rate (Box2D v3's
/// `b2PrepareJoint` cap), with damping ratio 2 (its default).
pub(crate) fn joint_softness(stiffness: JointStiffness, h: f32) -> Softness {
    let cap = 0.25 / h;
    match stiffness {
        JointStiffness::Stiff => Softness::new(cap, 2.0, h),
        JointStiffness::Soft {
            hertz,
            damping_ratio,
        } => Softness::new(hertz.min(cap), damping_ratio, h),
    }
}
