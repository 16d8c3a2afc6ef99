//! Unit tests of split impulse's position solve ([`super`]).

use super::*;

/// One row between a 1 kg body (slot 0) and the immovable slot (1), pushing along +y
/// towards a pseudo-velocity of 0.01 m/s: the first sweep meets the target exactly, the
/// second changes nothing, so the solve reports two sweeps and a pseudo-impulse of 0.01 N·s.
#[test]
fn a_single_row_reaches_its_target_in_one_sweep_and_reports_two() {
    let mut row = ContactConstraint {
        local_a: 0,
        local_b: 1,
        inverse_mass_a: Vec3::ONE,
        position_target: 0.01,
        ..ContactConstraint::default()
    };
    row.normal.direction = Vec3::Y;
    row.normal.effective_mass = 1.0;
    row.normal.inverse_effective_mass = 1.0;
    let mut constraints = [row];
    let (mut linear, mut angular) = ([Vec3::ZERO; 2], [Vec3::ZERO; 2]);
    let mut solve = |constraints: &mut [ContactConstraint]| {
        let mut velocities = Velocities {
            linear: &mut linear,
            angular: &mut angular,
        };
        let sweeps = solve_positions(constraints, Sweep::default(), 10, 1e-6, &mut velocities);
        (sweeps, velocities.linear[0])
    };
    assert_eq!(solve(&mut constraints), (2, Vec3::new(0.0, 0.01, 0.0)));
    assert_eq!(constraints[0].position_impulse, 0.01);
    // A row already at its target: one sweep, nothing changed.
    assert_eq!(solve(&mut constraints), (1, Vec3::new(0.0, 0.01, 0.0)));
    assert_eq!(constraints[0].position_impulse, 0.01);
}
