//! Shape-checked numpy input.

use crate::errors::{Kind, error};
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A batch of fixed-length rows read from a numpy array of shape `(N,)` (one row) or `(n, N)`.
pub struct Rows<const N: usize> {
    /// The rows.
    pub rows: Vec<[f64; N]>,
    /// Whether the input was a single row (shape `(N,)`), so the output drops the batch axis.
    pub single: bool,
}

/// Reads `array` as rows of length `N`; `name` is the argument's name for the message.
pub fn rows<const N: usize>(
    py: Python<'_>,
    array: &PyReadonlyArrayDyn<'_, f64>,
    name: &str,
) -> PyResult<Rows<N>> {
    let shape = array.shape().to_vec();
    let view = array.as_array();
    let bad = || {
        error(
            py,
            Kind::Shape,
            format!("`{name}` must have shape ({N},) or (n, {N}), got {shape:?}"),
        )
    };
    match shape.as_slice() {
        [n] if *n == N => {
            let mut row = [0.0; N];
            for (i, v) in view.iter().enumerate() {
                row[i] = *v;
            }
            Ok(Rows {
                rows: vec![row],
                single: true,
            })
        }
        [_, n] if *n == N => {
            let rows = view
                .rows()
                .into_iter()
                .map(|r| {
                    let mut row = [0.0; N];
                    for (i, v) in r.iter().enumerate() {
                        row[i] = *v;
                    }
                    row
                })
                .collect();
            Ok(Rows {
                rows,
                single: false,
            })
        }
        _ => Err(bad()),
    }
}

/// Reads a scalar or a 1-D array of length `n` (broadcast a scalar to `n`).
pub fn broadcast(
    py: Python<'_>,
    array: &PyReadonlyArrayDyn<'_, f64>,
    n: usize,
    name: &str,
) -> PyResult<Vec<f64>> {
    let shape = array.shape().to_vec();
    let view = array.as_array();
    match shape.as_slice() {
        [] => Ok(vec![view.iter().copied().next().unwrap_or(0.0); n]),
        [m] if *m == n => Ok(view.iter().copied().collect()),
        [1] => Ok(vec![view.iter().copied().next().unwrap_or(0.0); n]),
        _ => Err(error(
            py,
            Kind::Shape,
            format!("`{name}` must be a scalar or have shape ({n},), got {shape:?}"),
        )),
    }
}
