//! An island's locked joint rows solved together ([`IslandJoints`]): one sparse Cholesky
//! factorization of their K = J M⁻¹ Jᵀ per solve, and each sweep's update of all of them at once
//! from it, in place of one locked group after another.
//!
//! Gauss-Seidel over the joints of a chain passes a load on by one link a sweep, and a heavy
//! body at the end of light links needs far more sweeps than a substep has: the chain
//! stretches. The locked rows are
//! equalities, so their block of the LCP is a linear system: solved directly, a chain or a
//! ragdoll holds its joints exactly after every sweep, whatever the mass ratio, and the
//! sweeps are left to the contacts, limits, springs and motors (block Gauss-Seidel with the
//! locked rows as one block). The soft form is the locked groups' (docs/method.md,
//! "Joints"): Δλ = −s_m·K⁻¹(J·v + bias) − s_i·λ row by row, so a rigid solve (the relax
//! solve's) leaves J·v = 0 on every locked row.
//!
//! K is sparse: two joints' rows couple only through a body they share. The joints are put in
//! reverse Cuthill-McKee order over that graph (Cuthill and McKee 1969; George and Liu,
//! "Computer Solution of Large Sparse Positive Definite Systems", 1981), which keeps every
//! row's nonzeros close to the diagonal, and the factor is stored in that envelope (a
//! skyline): a chain or a tree of joints factors in time linear in its rows, without fill
//! beyond the envelope. The factorization is in f64: a chain with a 100:1 end mass makes K
//! ill-conditioned for f32's 24 bits.
//!
//! The joints solved together are a spanning forest of the island's bodies ([`spanning_forest`]):
//! a joint closing a loop keeps its own locked groups, swept with the springs and limits.
//! Breakable joints keep the per-joint groups too: their groups' impulses are bounded by their
//! strength one group at a time ([`JointConstraint::solve`]).

use std::ops::{Deref, DerefMut};

use glam::DVec3;

use super::rows::{JointConstraint, LOCK};
use crate::body::Velocities;

/// A locked row whose pivot is at most this fraction of its K_pp depends on the rows before it
/// in the order (to the rounding of f32 Jacobians): it is left out of the factorization, as a
/// rank-revealing Cholesky drops it, rather than regularized: a regularized redundant row
/// takes an impulse of the rounding over the regularization, which the f32 velocities cannot
/// cancel.
const DEPENDENT: f64 = 1e-6;

/// Most locked rows an island solves directly (its envelope grows with the joint graph's
/// bandwidth; a larger island keeps the per-joint groups).
const MAX_DIRECT_ROWS: usize = 4096;

/// Most factor entries per row (the envelope's mean width) an island solves directly.
const MAX_ENVELOPE_PER_ROW: usize = 96;

/// The joints of an island's step: their rows ([`JointConstraint`], the vector this derefs to)
/// and, when two or more of its joints with locked rows form a forest and none is breakable,
/// the factorization that solves those rows together.
#[derive(Debug, Default)]
pub(crate) struct IslandJoints {
    constraints: Vec<JointConstraint>,
    direct: Option<LockedRows>,
}

impl Deref for IslandJoints {
    type Target = Vec<JointConstraint>;
    fn deref(&self) -> &Vec<JointConstraint> {
        &self.constraints
    }
}

impl DerefMut for IslandJoints {
    fn deref_mut(&mut self) -> &mut Vec<JointConstraint> {
        &mut self.constraints
    }
}

impl<'a> IntoIterator for &'a IslandJoints {
    type Item = &'a JointConstraint;
    type IntoIter = std::slice::Iter<'a, JointConstraint>;
    fn into_iter(self) -> Self::IntoIter {
        self.constraints.iter()
    }
}

impl<'a> IntoIterator for &'a mut IslandJoints {
    type Item = &'a mut JointConstraint;
    type IntoIter = std::slice::IterMut<'a, JointConstraint>;
    fn into_iter(self) -> Self::IntoIter {
        self.constraints.iter_mut()
    }
}

impl IslandJoints {
    /// Starts a step of substeps of `h` seconds: every joint's substep length, and with
    /// `direct` ([`crate::settings::SolveSettings::direct_joint_solve`]) the order and envelope of the
    /// locked rows (the joints were assembled for this step).
    pub(crate) fn start_step(&mut self, h: f32, direct: bool) {
        for joint in &mut self.constraints {
            joint.start_step(h);
        }
        self.direct = if direct {
            LockedRows::new(&self.constraints)
        } else {
            None
        };
    }

    /// Every joint's targets at the island's current poses (the main solve with repair, the
    /// relax solve without; [`JointConstraint::update_targets`]), then the locked rows' K
    /// factorized at those poses.
    pub(crate) fn update_targets(
        &mut self,
        displacement: &[glam::Vec3],
        orientation: &[glam::Quat],
        with_repair: bool,
    ) {
        for joint in &mut self.constraints {
            joint.update_targets(displacement, orientation, with_repair);
        }
        if let Some(direct) = &mut self.direct {
            // K depends on the poses alone (the inverse inertias are the step's start's): a
            // substep's main solve, at the poses its previous relax solve factorized, reuses
            // that factorization.
            let same_poses = direct.factorized
                && direct.displacement == displacement
                && direct.orientation == orientation;
            if !same_poses {
                direct.displacement.clear();
                direct.displacement.extend_from_slice(displacement);
                direct.orientation.clear();
                direct.orientation.extend_from_slice(orientation);
                direct.factorize(&self.constraints);
            }
        }
    }

    /// The joints' relax solve under split impulse, after the positions moved: their targets
    /// without repair at the current poses (each body's displacement and orientation), then sweeps of the joints' rows alone, at most
    /// `sweeps` and until no row's velocity changes by more than `tolerance`. Split impulse
    /// repairs the contacts' overlap apart from the velocities, but the joints repair their
    /// drift with a velocity bias in the main solve; without this solve that bias stays in the
    /// velocities, and a door slammed onto its limit swung back off it at 6 % of the slam's
    /// speed, the repair of the limit's overshoot and of its hinge's give.
    pub(crate) fn relax(
        &mut self,
        velocities: &mut Velocities<'_>,
        (displacement, orientation): (&[glam::Vec3], &[glam::Quat]),
        sweeps: u32,
        tolerance: f32,
    ) {
        self.update_targets(displacement, orientation, false);
        for sweep in 0..sweeps {
            if sweep_joints(self, velocities, sweep % 2 == 0, true) <= tolerance {
                break;
            }
        }
    }

    /// Whether this island's locked rows are solved together (for tests and reports).
    #[cfg(test)]
    pub(crate) fn solves_directly(&self) -> bool {
        self.direct.as_ref().is_some_and(|d| d.factorized)
    }
}

/// Sweeps the joints' rows once, first to last (`forward`) or last to first, and with
/// `converge_limits` (a solve's first sweep) again while an engaged limit and the locked rows
/// disagree; returns the largest row velocity change (m/s or rad/s) of the first pass. With
/// the locked rows factorized, each joint's springs, motors and limits are swept (a joint
/// closing a loop takes its locked groups too) and then the forest's locked rows are solved at
/// once; otherwise each joint takes its rows in turn, its locked groups as blocks.
pub(crate) fn sweep_joints(
    joints: &mut IslandJoints,
    velocities: &mut Velocities<'_>,
    forward: bool,
    converge_limits: bool,
) -> f32 {
    let largest = joint_pass(joints, velocities, forward);
    // A limit that pushes is coupled to the locked rows: stopping the body's turn at the limit
    // moves the anchor, the locked rows' answer turns the body again when its centre of mass is
    // off the axis, and one pass leaves the limit overshot; the repair of the overshoot then
    // pushes the body back off the limit (a door slammed at 3 rad/s left its limit at 15 % of
    // that). The joints' rows alone are passed over again until they agree: block Gauss-Seidel
    // between the limits and the locked rows, converged, as if solved together. Only in a
    // solve's first sweep (`converge_limits`): the sweeps after it pass over the joints again
    // anyway, and an island of ragdolls in a pile, its limits engaged in every step, took the
    // passes in each of its up to 32 impact sweeps a substep (up to 0.49 s a step).
    if converge_limits
        && largest > LIMIT_TOLERANCE
        && joints.iter().any(JointConstraint::limit_engaged)
    {
        for _ in 0..LIMIT_PASSES {
            if joint_pass(joints, velocities, forward) <= LIMIT_TOLERANCE {
                break;
            }
        }
    }
    largest
}

/// Row velocity change (m/s or rad/s) below which the joints' extra passes of an island with
/// an engaged limit stop ([`sweep_joints`]).
const LIMIT_TOLERANCE: f32 = 1e-5;

/// Most extra passes over the joints' rows in a sweep of an island with an engaged limit.
const LIMIT_PASSES: u32 = 64;

/// One pass over the joints' rows ([`sweep_joints`]).
fn joint_pass(joints: &mut IslandJoints, velocities: &mut Velocities<'_>, forward: bool) -> f32 {
    let IslandJoints {
        constraints,
        direct,
    } = joints;
    let direct = direct.as_mut().filter(|d| d.factorized);
    let in_tree = |k: usize| direct.as_ref().is_some_and(|d| d.in_tree[k]);
    let mut largest = 0.0f32;
    let mut one = |k: usize, j: &mut JointConstraint| {
        largest = largest.max(j.solve(velocities, !in_tree(k)));
    };
    if forward {
        for (k, j) in constraints.iter_mut().enumerate() {
            one(k, j);
        }
    } else {
        for (k, j) in constraints.iter_mut().enumerate().rev() {
            one(k, j);
        }
    }
    if let Some(direct) = direct {
        largest = largest.max(direct.solve(constraints, velocities));
    }
    largest
}

/// The locked rows of an island's joints in elimination order, and the Cholesky factor of
/// their K in its envelope.
#[derive(Debug)]
struct LockedRows {
    /// (joint, degree of freedom) of each row, in elimination order; a joint's rows are
    /// consecutive.
    rows: Vec<(u32, u8)>,
    /// Each joint (its index in the island) with the range of its rows in `rows`, in
    /// elimination order: the solve's passes load a joint's bodies once for all its rows.
    runs: Vec<(usize, std::ops::Range<usize>)>,
    /// The first column of each row's envelope (the first row of the earliest joint sharing a
    /// body with its joint, or of its own joint).
    first: Vec<u32>,
    /// Where each row's envelope starts in `factor` (one more entry than rows).
    offsets: Vec<usize>,
    /// L (K = L·Lᵀ) by rows: row p holds columns first[p]..=p.
    factor: Vec<f64>,
    /// Per joint of the island, whether its locked rows are in the factorization (a joint of
    /// the spanning forest); a joint closing a loop keeps its own locked groups.
    in_tree: Vec<bool>,
    /// 1/L_pp; zero for a row left out.
    inverse_diagonal: Vec<f64>,
    /// Whether `factor` holds the factorization of the current K.
    factorized: bool,
    /// Work space: the right-hand side, then the solution.
    work: Vec<f64>,
    /// Each row's velocity J·v before the update (m/s or rad/s).
    velocity: Vec<f32>,
    /// Each row's Jacobian on its (up to two) movable bodies.
    sides: Vec<[SignedSide; 2]>,
    /// The island's displacements and orientations `factor` was computed at.
    displacement: Vec<glam::Vec3>,
    orientation: Vec<glam::Quat>,
}

/// A row's Jacobian on one movable body, its sign folded in, in f64: J = (linear, angular) on
/// (v, ω), M⁻¹Jᵀ = (moved, response).
#[derive(Clone, Copy, Debug)]
struct SignedSide {
    /// The body's island slot; `u32::MAX` for no body.
    slot: u32,
    linear: DVec3,
    moved: DVec3,
    angular: DVec3,
    response: DVec3,
}

impl SignedSide {
    const IMMOVABLE: Self = Self {
        slot: u32::MAX,
        linear: DVec3::ZERO,
        moved: DVec3::ZERO,
        angular: DVec3::ZERO,
        response: DVec3::ZERO,
    };
}

impl LockedRows {
    /// The elimination order and envelope of `joints`' locked rows; `None` when they are not
    /// solved together (fewer than two joints with locked rows, a breakable joint, or too many
    /// rows).
    fn new(joints: &[JointConstraint]) -> Option<Self> {
        // Fewer than two joints have fewer than two with locked rows (most islands have none).
        if joints.len() < 2 || joints.iter().any(|joint| joint.strength.is_breakable()) {
            return None;
        }
        let with_rows = spanning_forest(joints);
        if with_rows.len() < 2 {
            return None;
        }
        let mut in_tree = vec![false; joints.len()];
        for &j in &with_rows {
            in_tree[j] = true;
        }
        let order = reverse_cuthill_mckee(joints, &with_rows);
        let mut rows = Vec::new();
        let mut runs = Vec::with_capacity(order.len());
        let mut start_row = vec![u32::MAX; joints.len()];
        let mut position = vec![usize::MAX; joints.len()];
        for (p, &j) in order.iter().enumerate() {
            position[j] = p;
            start_row[j] = rows.len() as u32;
            let start = rows.len();
            rows.extend(joints[j].locked_dofs().map(|i| (j as u32, i as u8)));
            runs.push((j, start..rows.len()));
        }
        if rows.len() > MAX_DIRECT_ROWS {
            return None;
        }
        let neighbours = neighbours(joints, &with_rows);
        let mut first = Vec::with_capacity(rows.len());
        let mut offsets = Vec::with_capacity(rows.len() + 1);
        offsets.push(0);
        for (p, &(j, _)) in rows.iter().enumerate() {
            let j = j as usize;
            let earliest = neighbours[j]
                .iter()
                .filter(|&&k| position[k] < position[j])
                .map(|&k| start_row[k])
                .fold(start_row[j], u32::min);
            first.push(earliest);
            offsets.push(offsets[p] + p + 1 - earliest as usize);
        }
        // A joint graph of wide bandwidth (a dense mesh of joints) keeps the per-joint groups.
        if offsets[rows.len()] > MAX_ENVELOPE_PER_ROW * rows.len() {
            return None;
        }
        Some(Self {
            factor: vec![0.0; offsets[rows.len()]],
            work: vec![0.0; rows.len()],
            velocity: vec![0.0; rows.len()],
            in_tree,
            inverse_diagonal: vec![0.0; rows.len()],
            sides: vec![[SignedSide::IMMOVABLE; 2]; rows.len()],
            displacement: Vec::new(),
            orientation: Vec::new(),
            rows,
            runs,
            first,
            offsets,
            factorized: false,
        })
    }

    /// Each row's Jacobian on its movable bodies at the joints' current rows.
    fn gather_sides(&mut self, joints: &[JointConstraint]) {
        for (p, &(j, i)) in self.rows.iter().enumerate() {
            let mut sides = [SignedSide::IMMOVABLE; 2];
            for (side, row) in sides
                .iter_mut()
                .zip(joints[j as usize].movable_sides(i as usize))
            {
                *side = SignedSide {
                    slot: row.slot,
                    linear: (row.sign * row.linear).as_dvec3(),
                    moved: (row.sign * row.inverse_mass * row.linear).as_dvec3(),
                    angular: (row.sign * row.angular).as_dvec3(),
                    response: (row.sign * row.response).as_dvec3(),
                };
            }
            self.sides[p] = sides;
        }
    }

    /// K at the joints' current rows, factorized in place; leaves `factorized` false (the
    /// per-joint groups take over) if a pivot is not finite.
    fn factorize(&mut self, joints: &[JointConstraint]) {
        self.factorized = false;
        self.gather_sides(joints);
        let n = self.rows.len();
        for p in 0..n {
            let first_p = self.first[p] as usize;
            let (done, current) = self.factor.split_at_mut(self.offsets[p]);
            let (offsets, sides) = (&self.offsets, &self.sides);
            let row_p = &mut current[..=p - first_p];
            for q in first_p..p {
                let first_q = self.first[q] as usize;
                let row_q = &done[offsets[q]..offsets[q + 1]];
                let start = first_p.max(first_q);
                let mut s = coupling(sides, p, q);
                for (a, b) in row_p[start - first_p..q - first_p]
                    .iter()
                    .zip(&row_q[start - first_q..q - first_q])
                {
                    s -= a * b;
                }
                row_p[q - first_p] = s * self.inverse_diagonal[q];
            }
            let diagonal = coupling(sides, p, p);
            let (off_diagonal, pivot) = row_p.split_at_mut(p - first_p);
            let s = diagonal - off_diagonal.iter().map(|l| l * l).sum::<f64>();
            if !s.is_finite() {
                return;
            }
            // A row that the rows before it already determine (a loop of joints, two joints on
            // one degree of freedom) or that no body responds to is left out: its impulse stays,
            // and a zero 1/L_pp zeroes its column below and its part of each solve.
            if diagonal <= 1e-12 || s <= DEPENDENT * diagonal {
                off_diagonal.fill(0.0);
                pivot[0] = 1.0;
                self.inverse_diagonal[p] = 0.0;
                continue;
            }
            pivot[0] = s.sqrt();
            self.inverse_diagonal[p] = 1.0 / pivot[0];
        }
        self.factorized = true;
    }

    /// One update of every locked row at once: r = J·v + bias at the current velocities,
    /// x = K⁻¹·r, Δλ = −s_m·x − s_i·λ, applied to the bodies. Returns the largest row velocity
    /// change.
    fn solve(&mut self, joints: &mut [JointConstraint], velocities: &mut Velocities<'_>) -> f32 {
        let n = self.rows.len();
        for (j, range) in &self.runs {
            let joint = &joints[*j];
            let v = joint.load(velocities);
            for p in range.clone() {
                let i = self.rows[p].1 as usize;
                let velocity = joint.rows[i].velocity(&v);
                self.velocity[p] = velocity;
                self.work[p] = f64::from(velocity + joint.targets[i][LOCK].bias);
            }
        }
        // L·y = r, then Lᵀ·x = y, both in the envelope.
        for p in 0..n {
            let first = self.first[p] as usize;
            let row = self.offsets[p];
            let mut s = self.work[p];
            for k in first..p {
                s -= self.factor[row + k - first] * self.work[k];
            }
            self.work[p] = s * self.inverse_diagonal[p];
        }
        for p in (0..n).rev() {
            let first = self.first[p] as usize;
            let row = self.offsets[p];
            let x = self.work[p] * self.inverse_diagonal[p];
            self.work[p] = x;
            for k in first..p {
                self.work[k] -= self.factor[row + k - first] * x;
            }
        }
        for (j, range) in &self.runs {
            let joint = &mut joints[*j];
            let mut v = joint.load(velocities);
            for p in range.clone() {
                let i = self.rows[p].1 as usize;
                let target = joint.targets[i][LOCK];
                let old = joint.impulses[i][LOCK];
                let delta = -(self.work[p] as f32) * target.mass_scale - old * target.impulse_scale;
                if delta != 0.0 && delta.is_finite() {
                    joint.impulses[i][LOCK] = old + delta;
                    let row = joint.rows[i];
                    row.apply(joint, delta, &mut v);
                }
            }
            joint.store(velocities, v);
        }
        // The change reported is each row's velocity change, J·Δv, read back once every
        // impulse is applied (a row's Δλ·K_pp would count the coupled rows' share twice).
        let mut largest = 0.0f32;
        for (j, range) in &self.runs {
            let joint = &joints[*j];
            let v = joint.load(velocities);
            for p in range.clone() {
                let i = self.rows[p].1 as usize;
                largest = largest.max((joint.rows[i].velocity(&v) - self.velocity[p]).abs());
            }
        }
        largest
    }
}

/// Entry (p, q) of K = J M⁻¹ Jᵀ: the two rows' coupling through each body they share, summed
/// in f64.
#[inline]
fn coupling(sides: &[[SignedSide; 2]], p: usize, q: usize) -> f64 {
    let mut sum = 0.0f64;
    for a in &sides[p] {
        for b in &sides[q] {
            if a.slot == b.slot && a.slot != u32::MAX {
                sum += a.linear.dot(b.moved) + a.angular.dot(b.response);
            }
        }
    }
    sum
}

/// The joints with locked rows that form a spanning forest of the graph of bodies (every
/// immovable body one node, the world): a joint that would close a loop, through movable
/// bodies or through the world (a bridge held at both ends), is left out. A tree's locked rows
/// are independent, so its K is positive definite; a loop's rows are redundant (a planar
/// loop of hinges locks the out-of-plane motion twice), and without pivoting their
/// near-zero pivots would spoil the rows after them.
fn spanning_forest(joints: &[JointConstraint]) -> Vec<usize> {
    const WORLD: u32 = u32::MAX;
    let mut parent: std::collections::HashMap<u32, u32> = Default::default();
    fn root(parent: &mut std::collections::HashMap<u32, u32>, mut x: u32) -> u32 {
        while let Some(&p) = parent.get(&x) {
            if p == x {
                break;
            }
            let grand = parent.get(&p).copied().unwrap_or(p);
            parent.insert(x, grand);
            x = p;
        }
        x
    }
    let mut forest = Vec::new();
    for (k, joint) in joints.iter().enumerate() {
        if joint.locked_dofs().next().is_none() {
            continue;
        }
        let mut nodes = joint.movable_slots().collect::<Vec<_>>();
        while nodes.len() < 2 {
            nodes.push(WORLD);
        }
        let (a, b) = (root(&mut parent, nodes[0]), root(&mut parent, nodes[1]));
        if a != b {
            parent.insert(a, b);
            parent.entry(b).or_insert(b);
            forest.push(k);
        }
    }
    forest
}

/// The joints (of `with_rows`) sharing a movable body with each joint.
fn neighbours(joints: &[JointConstraint], with_rows: &[usize]) -> Vec<Vec<usize>> {
    let mut by_slot: std::collections::HashMap<u32, Vec<usize>> = Default::default();
    for &j in with_rows {
        for slot in joints[j].movable_slots() {
            by_slot.entry(slot).or_default().push(j);
        }
    }
    let mut neighbours = vec![Vec::new(); joints.len()];
    for &j in with_rows {
        let list: &mut Vec<usize> = &mut neighbours[j];
        for slot in joints[j].movable_slots() {
            list.extend(by_slot[&slot].iter().copied().filter(|&k| k != j));
        }
        list.sort_unstable();
        list.dedup();
    }
    neighbours
}

/// The joints of `with_rows` in reverse Cuthill-McKee order over the graph of shared movable
/// bodies: breadth first from a joint of least degree in each connected part, neighbours by
/// increasing degree, the whole order reversed.
fn reverse_cuthill_mckee(joints: &[JointConstraint], with_rows: &[usize]) -> Vec<usize> {
    let neighbours = neighbours(joints, with_rows);
    let mut by_degree = with_rows.to_vec();
    by_degree.sort_by_key(|&j| (neighbours[j].len(), j));
    let mut visited = vec![false; joints.len()];
    let mut order = Vec::with_capacity(with_rows.len());
    for &start in &by_degree {
        if visited[start] {
            continue;
        }
        visited[start] = true;
        let mut head = order.len();
        order.push(start);
        while head < order.len() {
            let j = order[head];
            head += 1;
            let mut next: Vec<usize> = neighbours[j]
                .iter()
                .copied()
                .filter(|&k| !visited[k])
                .collect();
            next.sort_by_key(|&k| (neighbours[k].len(), k));
            for k in next {
                visited[k] = true;
                order.push(k);
            }
        }
    }
    order.reverse();
    order
}
