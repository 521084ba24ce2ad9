//! The SQP's quadratic programs, solved by clarabel.
//!
//! The sparsity pattern of `A` is recorded once from the transcription's emission order and
//! converted to compressed sparse columns by a counting sort (O(nnz)); every later iteration
//! only refills the values through the recorded permutation and updates clarabel's copy in
//! place (`update_A`, `update_b`), so clarabel's symbolic analysis is done once per solve.

use super::error::TrajoptError;
use super::transcription::{Sink, Transcription};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// Records the emission order's `(row, col)`.
struct Pattern {
    entries: Vec<(usize, usize)>,
    rhs: Vec<f64>,
}

impl Sink for Pattern {
    fn entry(&mut self, row: usize, col: usize, _value: f64) {
        self.entries.push((row, col));
    }
    fn rhs(&mut self, row: usize, value: f64) {
        self.rhs[row] = value;
    }
}

/// Writes values straight into CSC storage through the permutation.
struct Values<'a> {
    slot: usize,
    permutation: &'a [usize],
    nzval: &'a mut [f64],
    rhs: &'a mut [f64],
}

impl Sink for Values<'_> {
    fn entry(&mut self, _row: usize, _col: usize, value: f64) {
        // The order is the recorded one: every emission has a slot.
        if let Some(&p) = self.permutation.get(self.slot) {
            self.nzval[p] = value;
        }
        self.slot += 1;
    }
    fn rhs(&mut self, row: usize, value: f64) {
        self.rhs[row] = value;
    }
}

/// Outcome of one QP.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum QpOutcome {
    Solved,
    Infeasible,
    Failed,
}

/// A clarabel solver kept across the SQP iterations of one solve.
pub(crate) struct Qp {
    solver: DefaultSolver<f64>,
    permutation: Vec<usize>,
    colptr: Vec<usize>,
    rowval: Vec<usize>,
    nzval: Vec<f64>,
    rhs: Vec<f64>,
    /// Diagonal of `P` per variable (`2 w`).
    pub hessian_diagonal: Vec<f64>,
}

fn settings() -> Result<DefaultSettings<f64>, TrajoptError> {
    DefaultSettingsBuilder::default()
        .verbose(false)
        // Data updates need the problem as given.
        .presolve_enable(false)
        .input_sparse_dropzeros(false)
        .build()
        .map_err(|e| TrajoptError::QpSetup(e.to_string()))
}

impl Qp {
    /// Builds the QP linearised at `z`.
    pub fn new(t: &Transcription, z: &[f64]) -> Result<Self, TrajoptError> {
        let n = t.variable_count();
        let m = t.row_count();
        let mut pattern = Pattern {
            entries: Vec::with_capacity(40 * n),
            rhs: vec![0.0; m],
        };
        t.assemble(z, true, &mut pattern);
        // Counting sort by column.
        let mut colptr = vec![0usize; n + 1];
        for &(_, c) in &pattern.entries {
            colptr[c + 1] += 1;
        }
        for c in 0..n {
            colptr[c + 1] += colptr[c];
        }
        let nnz = pattern.entries.len();
        let mut next = colptr.clone();
        let mut rowval = vec![0usize; nnz];
        let mut permutation = vec![0usize; nnz];
        for (slot, &(r, c)) in pattern.entries.iter().enumerate() {
            let p = next[c];
            rowval[p] = r;
            permutation[slot] = p;
            next[c] += 1;
        }
        // Rows are emitted in non-decreasing order, so the stable counting sort leaves each
        // column's rows ascending; a repeated (row, col) would be a transcription bug.
        for c in 0..n {
            if rowval[colptr[c]..colptr[c + 1]]
                .windows(2)
                .any(|w| w[0] >= w[1])
            {
                return Err(TrajoptError::QpSetup(format!(
                    "column {c} has unsorted or repeated rows"
                )));
            }
        }
        let mut nzval = vec![0.0; nnz];
        let mut rhs = pattern.rhs;
        t.assemble(
            z,
            true,
            &mut Values {
                slot: 0,
                permutation: &permutation,
                nzval: &mut nzval,
                rhs: &mut rhs,
            },
        );
        let a = CscMatrix::new(m, n, colptr.clone(), rowval.clone(), nzval.clone());
        // P: diagonal 2 w on the torque variables only.
        let hessian_diagonal: Vec<f64> = t.weights.iter().map(|w| 2.0 * w).collect();
        let mut pcol = vec![0usize; n + 1];
        let mut prow = Vec::new();
        let mut pval = Vec::new();
        for (j, &d) in hessian_diagonal.iter().enumerate() {
            if d != 0.0 {
                prow.push(j);
                pval.push(d);
            }
            pcol[j + 1] = prow.len();
        }
        let p = CscMatrix::new(n, n, pcol, prow, pval);
        let q = vec![0.0; n];
        let c = t.cones;
        let mut cones = vec![SupportedConeT::ZeroConeT(c.zero)];
        if c.nonnegative + c.traction > 0 {
            cones.push(SupportedConeT::NonnegativeConeT(c.nonnegative + c.traction));
        }
        let solver = DefaultSolver::new(&p, &q, &a, &rhs, &cones, settings()?)
            .map_err(|e| TrajoptError::QpSetup(e.to_string()))?;
        Ok(Self {
            solver,
            permutation,
            colptr,
            rowval,
            nzval,
            rhs,
            hessian_diagonal,
        })
    }

    /// Relinearises at `z` (kept here until [`Self::push`]).
    pub fn relinearize(&mut self, t: &Transcription, z: &[f64]) {
        t.assemble(
            z,
            true,
            &mut Values {
                slot: 0,
                permutation: &self.permutation,
                nzval: &mut self.nzval,
                rhs: &mut self.rhs,
            },
        );
    }

    /// Hands the current linearisation to clarabel.
    pub fn push(&mut self) -> Result<(), TrajoptError> {
        self.solver
            .update_A(&self.nzval)
            .map_err(|e| TrajoptError::QpSetup(e.to_string()))?;
        self.solver
            .update_b(&self.rhs)
            .map_err(|e| TrajoptError::QpSetup(e.to_string()))?;
        Ok(())
    }

    /// KKT stationarity residual `||P z + A(z)^T y||_inf` of the current linearisation at
    /// the point `z` it was made at, with the last QP's multipliers `y`; and `||P z||_inf`.
    pub fn stationarity(&self, z: &[f64]) -> (f64, f64) {
        let y = self.dual();
        let mut worst = 0.0_f64;
        let mut grad = 0.0_f64;
        for (j, zj) in z.iter().enumerate() {
            let g = self.hessian_diagonal[j] * zj;
            let aty: f64 = (self.colptr[j]..self.colptr[j + 1])
                .map(|p| self.nzval[p] * y[self.rowval[p]])
                .sum();
            worst = worst.max((g + aty).abs());
            grad = grad.max(g.abs());
        }
        (worst, grad)
    }

    /// Solves; the new point and the multipliers are in [`Self::primal`], [`Self::dual`].
    pub fn solve(&mut self) -> QpOutcome {
        self.solver.solve();
        let finite = || self.solver.solution.x.iter().all(|v| v.is_finite());
        match self.solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => QpOutcome::Solved,
            // clarabel can stall near a solution (seen with second-order cones on long horizons);
            // its last iterate is still a usable step: the SQP's merit line search and its
            // explicit KKT test (not the QP's own) decide what it is worth.
            SolverStatus::InsufficientProgress if finite() => QpOutcome::Solved,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                QpOutcome::Infeasible
            }
            _ => QpOutcome::Failed,
        }
    }

    /// The QP's minimiser (the new point, not the step).
    pub fn primal(&self) -> &[f64] {
        &self.solver.solution.x
    }

    /// The QP's multipliers (clarabel's `z`).
    pub fn dual(&self) -> &[f64] {
        &self.solver.solution.z
    }
}
