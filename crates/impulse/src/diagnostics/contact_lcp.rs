//! The contact LCP of a step as an explicit problem (A, b, bounds), so any solver of
//! `impulse-lcp` can be run on a real step and compared with the engine's own PGS.
//!
//! Rows are ordered per contact point as the solver orders them: normal, then (with friction)
//! the two tangents. A = J M⁻¹ Jᵀ is assembled from the same Jacobian rows and inverse masses
//! the solver used, and b = target − J·v* from the same targets and prospective velocities v*,
//! so that w = Aγ − b ≥ 0, γ ≥ 0, wᵀγ = 0 is exactly the problem PGS iterated on (docs/method.md, eq. (2)
//! with the complementarity of "Resolving a collision in the context of a second collision").
//! Normal rows that were soft in the last solve (soft contact without a relax solve) add their
//! regularisation to A's diagonal, so the problem stays the one the engine solved.
//!
//! Joint rows (docs/method.md, "Joints") follow the contact rows: locked rows and springs are
//! free variables (bounds ±∞), limits unilateral ([0, ∞)), motors boxed (±max_force·h), so a
//! step with joints exports a mixed (boxed) LCP. Each group's recorded J·v* has only its own
//! impulses taken out (the contacts' record and the joints' are taken apart), so b adds the
//! coupling A_cj·λ_j to each contact row and A_jc·γ_c to each joint row. A breakable joint's
//! locked rows are exported free like any other: the ball bound its strength puts on a locked
//! group's impulse (|λ_g| ≤ threshold·h) is not a box, so it is not part of the exported problem;
//! a joint that broke in the step is not passed here at all ([`crate::World::contact_lcp`]).

use std::collections::BTreeMap;

use glam::Vec3;
use impulse_lcp::{Bounds, CsrMatrix, Lcp, ProblemError};

use crate::contact::{ContactConstraint, JacobianRow, linear_inverse_mass};
use crate::joint::{JointConstraint, ROWS_PER_DOF};

/// A step's contact LCP together with what the engine found for it.
#[derive(Clone, Debug)]
pub struct ContactLcp {
    /// The problem in our convention (w = Aγ − b), with friction rows bounded by μ·γ_n (`findex`).
    pub problem: Lcp,
    /// The engine's impulses at exit, in row order (N·s).
    pub engine_solution: Vec<f64>,
    /// For each row, the index of its contact point (0, 1, …, in the order the step solved
    /// them): a point's normal row and, with friction, its two tangent rows share one index.
    /// `usize::MAX` for a joint row.
    pub contact_of_row: Vec<usize>,
    /// For each row, the dense index of its joint ([`crate::World::joints`] order), `None`
    /// for a contact row. Joint rows come after every contact row.
    pub joint_of_row: Vec<Option<usize>>,
}

impl ContactLcp {
    /// Number of contact points the problem's rows belong to.
    pub fn contact_points(&self) -> usize {
        self.contact_of_row
            .iter()
            .rfind(|&&k| k != usize::MAX)
            .map_or(0, |&k| k + 1)
    }

    /// Number of joint rows (the rows after the contact rows).
    pub fn joint_rows(&self) -> usize {
        self.joint_of_row.iter().filter(|j| j.is_some()).count()
    }
}

/// Builds the LCP of `constraints` (as left by the solver). Errors only if the assembled data
/// is not finite, which a blown-up step can cause.
pub(crate) fn assemble_lcp(
    constraints: &[ContactConstraint],
    joints: &[&JointConstraint],
) -> Result<ContactLcp, ProblemError> {
    let with_friction = |c: &ContactConstraint| c.friction > 0.0;
    // Row layout and per-body incidence lists.
    struct Incidence {
        row: usize,
        sign: f32,
        direction: Vec3,
        angular: Vec3,
        inverse_inertia_angular: Vec3,
        inverse_mass: Vec3,
    }
    let mut by_body: BTreeMap<u32, Vec<Incidence>> = BTreeMap::new();
    let mut b = Vec::new();
    let mut mu = Vec::new();
    let mut friction_index = Vec::new();
    let mut engine_solution = Vec::new();
    let mut contact_of_row = Vec::new();
    let mut entries: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for (k, c) in constraints.iter().enumerate() {
        // A soft normal row is the rigid row plus a diagonal term (see `soft_diagonal`).
        let softness = c.soft_diagonal();
        if softness != 0.0 {
            entries.insert((b.len(), b.len()), softness as f64);
        }
        let normal_row = b.len();
        let mut rows: Vec<(&JacobianRow, f32, f32, Option<usize>)> =
            vec![(&c.normal, c.target_normal_velocity, c.normal_impulse, None)];
        if with_friction(c) {
            for t in 0..2 {
                rows.push((&c.tangents[t], 0.0, c.tangent_impulses[t], Some(normal_row)));
            }
        }
        for (row, target, impulse, findex) in rows {
            let index = b.len();
            b.push((target - row.velocity_before) as f64);
            mu.push(if findex.is_some() {
                c.friction as f64
            } else {
                0.0
            });
            friction_index.push(findex);
            engine_solution.push(impulse as f64);
            contact_of_row.push(k);
            let sides = [
                (
                    c.body_a,
                    1.0,
                    row.angular_a,
                    row.inverse_inertia_angular_a,
                    c.inverse_mass_a,
                ),
                (
                    c.body_b,
                    -1.0,
                    row.angular_b,
                    row.inverse_inertia_angular_b,
                    c.inverse_mass_b,
                ),
            ];
            for (body, sign, angular, inverse_inertia_angular, inverse_mass) in sides {
                if inverse_mass == Vec3::ZERO && inverse_inertia_angular == Vec3::ZERO {
                    continue; // an immovable body couples nothing
                }
                by_body.entry(body).or_default().push(Incidence {
                    row: index,
                    sign,
                    direction: row.direction,
                    angular,
                    inverse_inertia_angular,
                    inverse_mass,
                });
            }
        }
    }
    let contact_rows = b.len();
    let mut lo = vec![0.0f64; contact_rows];
    let mut hi = vec![f64::INFINITY; contact_rows];
    let mut joint_of_row = vec![None; contact_rows];
    for j in joints {
        for i in 0..6 {
            for kind in 0..ROWS_PER_DOF {
                let target = j.targets[i][kind];
                if !target.active {
                    continue;
                }
                let row = &j.rows[i];
                let index = b.len();
                let softness = target.soft_diagonal(row);
                if softness != 0.0 {
                    entries.insert((index, index), softness as f64);
                }
                // J·v + bias = 0 is the row's target: t = −bias, J·v* from the record.
                b.push((-target.bias - target.sign * j.velocity_before[i]) as f64);
                mu.push(0.0);
                friction_index.push(None);
                lo.push(target.lower as f64);
                hi.push(target.upper as f64);
                engine_solution.push(j.impulses[i][kind] as f64);
                contact_of_row.push(usize::MAX);
                joint_of_row.push(Some(j.joint as usize));
                let sides = [
                    (
                        j.body_a,
                        -target.sign,
                        row.angular_a,
                        row.response_a,
                        j.inverse_mass_a,
                    ),
                    (
                        j.body_b,
                        target.sign,
                        row.angular_b,
                        row.response_b,
                        j.inverse_mass_b,
                    ),
                ];
                for (body, sign, angular, response, inverse_mass) in sides {
                    if inverse_mass == Vec3::ZERO && response == Vec3::ZERO {
                        continue;
                    }
                    by_body.entry(body).or_default().push(Incidence {
                        row: index,
                        sign,
                        direction: row.linear,
                        angular,
                        inverse_inertia_angular: response,
                        inverse_mass,
                    });
                }
            }
        }
    }
    let n = b.len();
    // A_ij = Σ_bodies s_i s_j (d_iᵀ M⁻¹ d_j + (r×d)_i · I⁻¹(r×d)_j), plus the soft rows' terms;
    // M⁻¹ is the body's per-axis inverse mass (zero on locked translation axes).
    for incidences in by_body.values() {
        for p in incidences {
            for q in incidences {
                let value = p.sign
                    * q.sign
                    * (linear_inverse_mass(p.inverse_mass, p.direction, q.direction)
                        + p.angular.dot(q.inverse_inertia_angular));
                *entries.entry((p.row, q.row)).or_insert(0.0) += value as f64;
            }
        }
    }
    // Each group's record took only its own impulses out: add the other group's coupling.
    if n > contact_rows && contact_rows > 0 {
        for (&(i, j), &value) in &entries {
            if (i < contact_rows) != (j < contact_rows) {
                b[i] += value * engine_solution[j];
            }
        }
    }
    let mut indptr = vec![0usize; n + 1];
    let mut indices = Vec::with_capacity(entries.len());
    let mut values = Vec::with_capacity(entries.len());
    for (&(i, j), &v) in &entries {
        indptr[i + 1] += 1;
        indices.push(j);
        values.push(v);
    }
    for i in 0..n {
        indptr[i + 1] += indptr[i];
    }
    let a = CsrMatrix::new(n, n, indptr, indices, values)?;
    let bounds = if friction_index.iter().any(Option::is_some) {
        Bounds::Friction {
            lo,
            hi,
            friction_index,
            mu,
        }
    } else if n > contact_rows {
        Bounds::Box { lo, hi }
    } else {
        Bounds::NonNegative
    };
    let problem = Lcp::new(a, b, bounds)?;
    Ok(ContactLcp {
        problem,
        engine_solution,
        contact_of_row,
        joint_of_row,
    })
}

#[cfg(test)]
#[path = "contact_lcp_tests.rs"]
mod tests;
