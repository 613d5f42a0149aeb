//! Closing-speed bounds on the arm command: one-sided limits `r·q̇ ≤ b`, each the speed at which a
//! point of the robot closes on a surface (the skin's approach bound, `docs/resolver.md`).

/// Rows `r` (model joint order) and bounds `b` of the limits `r·q̇ ≤ b` of one cycle.
/// Allocates in [`ClosingBounds::with_capacity`] only while within its capacity.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClosingBounds {
    nv: usize,
    rows: Vec<f64>,
    bounds: Vec<f64>,
}

/// Gauss-Seidel sweeps over the rows: neighbouring cells' rows are nearly parallel, so a few
/// sweeps leave a residual far below the bounds' scale.
const SWEEPS: usize = 4;

impl ClosingBounds {
    /// Room for `rows` limits on a model with `nv` joints.
    pub fn with_capacity(nv: usize, rows: usize) -> Self {
        Self { nv, rows: Vec::with_capacity(nv * rows), bounds: Vec::with_capacity(rows) }
    }

    /// Removes every limit.
    pub fn clear(&mut self) {
        self.rows.clear();
        self.bounds.clear();
    }

    /// Adds the limit `row·q̇ ≤ bound`; `row` has one entry per model joint.
    pub fn push(&mut self, row: &[f64], bound: f64) {
        debug_assert_eq!(row.len(), self.nv);
        self.rows.extend_from_slice(row);
        self.bounds.push(bound);
    }

    /// Number of limits.
    pub fn len(&self) -> usize {
        self.bounds.len()
    }

    /// Whether there is no limit.
    pub fn is_empty(&self) -> bool {
        self.bounds.is_empty()
    }

    /// The limits as `(row, bound)`.
    pub fn iter(&self) -> impl Iterator<Item = (&[f64], f64)> {
        self.rows.chunks_exact(self.nv.max(1)).zip(self.bounds.iter().copied())
    }
}

/// Brings the arm velocities `v` (arm order; `index[i]` is arm joint `i`'s model index) within
/// `bounds`, the joints `others` (model indices; the base's) moving at their `qd` (model order):
/// each violated limit is met by the least change of `v` in the metric of the virtual inertia,
/// `v ← v − W r (r·q̇ − b) / (rᵀ W r)` with `W = diag(w)` (`w_i = 1 / inertia_i`, 0 for a held
/// joint), the velocity change an impulse along the row would make. Limits only slow a point
/// down toward its surface; motion away from it is never changed.
pub(crate) fn bound_closing(
    v: &mut [f64],
    index: &[usize],
    w: &[f64],
    others: &[usize],
    qd: &[f64],
    bounds: &ClosingBounds,
) {
    for _ in 0..SWEEPS {
        let mut met = true;
        for (row, b) in bounds.iter() {
            let arm: f64 = index.iter().zip(v.iter()).map(|(&j, vi)| row[j] * vi).sum();
            let other: f64 = others.iter().map(|&j| row[j] * qd[j]).sum();
            let excess = arm + other - b;
            if excess <= 0.0 {
                continue;
            }
            let norm: f64 = index.iter().zip(w).map(|(&j, wi)| wi * row[j] * row[j]).sum();
            if norm <= f64::EPSILON {
                continue; // the arm cannot change this point's speed
            }
            met = false;
            let k = excess / norm;
            for ((vi, &j), wi) in v.iter_mut().zip(index).zip(w) {
                *vi -= k * wi * row[j];
            }
        }
        if met {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closing_bound_slows_only_the_closing_component_by_the_least_change() {
        // model joints: 0 = base (moving at 0.1), 1-2 = arm
        let mut b = ClosingBounds::with_capacity(3, 2);
        b.push(&[1.0, 1.0, 0.0], 0.15);
        let mut v = [0.2, 0.3];
        bound_closing(&mut v, &[1, 2], &[1.0, 1.0], &[0], &[0.1, 9.0, 9.0], &b);
        assert!((0.1 + v[0] - 0.15).abs() < 1e-12, "{v:?}");
        assert_eq!(v[1], 0.3, "a joint the row does not involve keeps its speed");
        let mut away = [-0.2, 0.3];
        bound_closing(&mut away, &[1, 2], &[1.0, 1.0], &[0], &[0.1, 0.0, 0.0], &b);
        assert_eq!(away, [-0.2, 0.3], "moving away is never limited");
    }

    #[test]
    fn closing_bound_meets_several_rows_and_spares_held_joints() {
        let mut b = ClosingBounds::with_capacity(3, 2);
        b.push(&[0.0, 1.0, 1.0], 0.1);
        b.push(&[0.0, 1.0, 0.5], 0.1);
        let mut v = [1.0, 1.0, 1.0];
        bound_closing(&mut v[..2], &[1, 2], &[1.0, 2.0], &[0], &[0.0; 3], &b);
        for (row, bound) in b.iter() {
            assert!(row[1] * v[0] + row[2] * v[1] <= bound + 1e-3, "{v:?}");
        }
        let mut held = [1.0, 1.0];
        bound_closing(&mut held, &[1, 2], &[0.0, 1.0], &[0], &[0.0; 3], &b);
        assert_eq!(held[0], 1.0, "a held joint (w = 0) is not moved by the bound");
    }
}
