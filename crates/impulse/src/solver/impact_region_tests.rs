use glam::Vec3;

use super::*;
use crate::contact::ContactConstraint;

/// A chain of `n` bodies (slots 0..n, body index = slot), each on the ground (the immovable
/// slot n; normal +y) and touching the next (normal +x): body k's point on the ground and, for
/// k > 0, one between k and k − 1.
fn chain(n: u32) -> Vec<ContactConstraint> {
    let mut rows = Vec::new();
    for k in 0..n {
        let mut ground = ContactConstraint::default();
        (ground.body_a, ground.body_b, ground.local_a, ground.local_b) = (k, n, k, n);
        ground.normal.direction = Vec3::Y;
        rows.push(ground);
        if k > 0 {
            let mut side = ContactConstraint::default();
            (side.body_a, side.body_b, side.local_a, side.local_b) = (k, k - 1, k, k - 1);
            side.normal.direction = Vec3::X;
            rows.push(side);
        }
    }
    rows
}

/// Body 500 of a 1,000-body chain (1,999 points) falls at 3 m/s onto the ground (its ground
/// point closes at 3 m/s, faster than the 1 m/s impact speed; every other body rests): the
/// region is body 500, and its points are every point touching it: its ground point and its
/// two chain points, to 499 and from 501. The ground, which touches every body, does not carry
/// the region on.
#[test]
fn the_region_is_the_impacts_bodies_and_stops_at_the_ground() {
    let n = 1000;
    let rows = chain(n);
    let mut linear = vec![Vec3::ZERO; n as usize + 1];
    linear[500] = Vec3::new(0.0, -3.0, 0.0);
    let angular = vec![Vec3::ZERO; n as usize + 1];
    let mut region = ImpactRegion::default();
    let kind = region.find(&rows, &linear, &angular, 1.0, n as usize, |_| true);
    assert_eq!(kind, RegionKind::Local);
    let inside: Vec<u32> = (0..=n).filter(|&s| region.contains(s)).collect();
    assert_eq!(inside, vec![500]);
    let mut pairs: Vec<(u32, u32)> = region
        .points
        .iter()
        .map(|&k| (rows[k as usize].local_a, rows[k as usize].local_b))
        .collect();
    pairs.sort_unstable();
    assert_eq!(pairs, vec![(500, 499), (500, n), (501, 500)]);
    assert_eq!(region.size, 3);
}

/// Bodies 200 and 700 both close on the ground at 3 m/s as the step starts, but the substep's
/// main solve struck only body 700's ground row (changed its normal velocity by more than the
/// limit): the region is body 700 alone, found from the velocities before and after the solve
/// as [`ImpactRegion::find_in`] reads them.
#[test]
fn only_the_rows_the_substep_struck_seed_the_region() {
    let n = 1000;
    let rows = chain(n);
    let mut linear = vec![Vec3::ZERO; n as usize + 1];
    linear[200] = Vec3::new(0.0, -3.0, 0.0);
    linear[700] = Vec3::new(0.0, -3.0, 0.0);
    let angular = vec![Vec3::ZERO; n as usize + 1];
    // The main solve stopped body 700 (3 m/s of change) and left body 200 falling.
    let mut after = linear.clone();
    after[700] = Vec3::ZERO;
    let change = SubstepChange {
        linear_before: &linear,
        angular_before: &angular,
        linear_after: &after,
        angular_after: &angular,
        limit: 0.5,
    };
    let bodies = crate::body::Bodies {
        linear_velocity: linear.clone(),
        angular_velocity: angular.clone(),
        ..Default::default()
    };
    let mut region = ImpactRegion::default();
    let kind = region.find_in(&rows, &bodies, 1.0, n as usize, false, change, None);
    assert_eq!(kind, RegionKind::Local);
    let inside: Vec<u32> = (0..=n).filter(|&s| region.contains(s)).collect();
    assert_eq!(inside, vec![700]);
    assert_eq!(region.size, 3);
}

/// An island below the size for local sweeps, or one whose region is more than half of it,
/// sweeps whole: the 60-body chain (119 points) whatever its impact, and the 1,000-body chain
/// with every body falling; a 300-body chain (599 points) with one body falling sweeps
/// around it.
#[test]
fn a_small_island_or_a_region_of_most_of_it_sweeps_whole() {
    let mut region = ImpactRegion::default();
    let small = chain(60);
    let mut linear = vec![Vec3::new(0.0, -3.0, 0.0); 1001];
    linear[1000] = Vec3::ZERO;
    let angular = vec![Vec3::ZERO; 1001];
    assert!(small.len() < LOCAL_IMPACT_MIN_POINTS);
    assert_eq!(
        region.find(&small, &linear, &angular, 1.0, 60, |_| true),
        RegionKind::Whole
    );
    let medium = chain(300);
    let mut one_falling = vec![Vec3::ZERO; 301];
    one_falling[150] = Vec3::new(0.0, -3.0, 0.0);
    assert_eq!(
        region.find(&medium, &one_falling, &angular, 1.0, 300, |_| true),
        RegionKind::Local
    );
    assert_eq!(region.size, 3);
    // Another island: its closing contacts are found anew.
    region.start_step();
    let large = chain(1000);
    assert_eq!(
        region.find(&large, &linear, &angular, 1.0, 1000, |_| true),
        RegionKind::Whole
    );
    // At rest (a new step), no seed: an empty region (the impact test would not have asked).
    let rest = vec![Vec3::ZERO; 1001];
    region.start_step();
    assert_eq!(
        region.find(&large, &rest, &angular, 1.0, 1000, |_| true),
        RegionKind::Local
    );
    assert_eq!(region.size, 0);
}
