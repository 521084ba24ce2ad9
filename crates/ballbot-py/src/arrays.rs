//! Shape-checked numpy input and owned numpy output.

use crate::errors::{Kind, error};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
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
    let copy_row = |r: numpy::ndarray::ArrayViewD<'_, f64>| {
        let mut row = [0.0; N];
        for (slot, v) in row.iter_mut().zip(r.iter()) {
            *slot = *v;
        }
        row
    };
    match shape.as_slice() {
        [n] if *n == N => Ok(Rows {
            rows: vec![copy_row(view)],
            single: true,
        }),
        [_, n] if *n == N => {
            // C-contiguous input (the usual case) is read as one slice; strided views row by row.
            if let Ok(flat) = array.as_slice() {
                let rows = flat
                    .chunks_exact(N)
                    .map(|c| {
                        let mut row = [0.0; N];
                        row.copy_from_slice(c);
                        row
                    })
                    .collect();
                return Ok(Rows {
                    rows,
                    single: false,
                });
            }
            let rows = view.outer_iter().map(copy_row).collect();
            Ok(Rows {
                rows,
                single: false,
            })
        }
        _ => Err(error(
            py,
            Kind::Shape,
            format!("`{name}` must have shape ({N},) or (n, {N}), got {shape:?}"),
        )),
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
        [] | [1] => Ok(vec![view.iter().copied().next().unwrap_or(0.0); n]),
        [m] if *m == n => Ok(view.iter().copied().collect()),
        _ => Err(error(
            py,
            Kind::Shape,
            format!("`{name}` must be a scalar or have shape ({n},), got {shape:?}"),
        )),
    }
}

/// Reads a matrix of any size: `(rows, cols, row-major values)`. A 1-D array of length `n`
/// is a column `(n, 1)` when `column_ok`, else a shape error.
pub fn matrix(
    py: Python<'_>,
    array: &PyReadonlyArrayDyn<'_, f64>,
    name: &str,
    column_ok: bool,
) -> PyResult<(usize, usize, Vec<f64>)> {
    let shape = array.shape().to_vec();
    let values: Vec<f64> = array.as_array().iter().copied().collect();
    match shape.as_slice() {
        [r, c] => Ok((*r, *c, values)),
        [n] if column_ok => Ok((*n, 1, values)),
        _ => Err(error(
            py,
            Kind::Shape,
            format!(
                "`{name}` must be a 2-D array{}, got shape {shape:?}",
                if column_ok {
                    " (or 1-D for a column)"
                } else {
                    ""
                }
            ),
        )),
    }
}

/// An owned numpy array of `shape` holding the row-major `values`.
pub fn array_out<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let array = PyArray1::from_vec(py, values);
    Ok(array.reshape(shape)?.to_dyn().clone())
}

/// A column of values; a single input row gives a 0-d array.
pub fn column_out<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    single: bool,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let n = values.len();
    if single {
        array_out(py, values, &[])
    } else {
        array_out(py, values, &[n])
    }
}

/// Rows of length `N` as an `(n, N)` array, or `(N,)` for a single input row.
pub fn rows_out<'py, const N: usize>(
    py: Python<'py>,
    values: Vec<[f64; N]>,
    single: bool,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let n = values.len();
    let flat: Vec<f64> = values.into_iter().flatten().collect();
    if single {
        array_out(py, flat, &[N])
    } else {
        array_out(py, flat, &[n, N])
    }
}

/// Reads a 4-vector (a WIP state) from a numpy array of shape (4,) or any sequence of four
/// numbers. The fast path (a float64 numpy array, or a list/tuple) is what `step` calls use.
pub fn vec4(py: Python<'_>, value: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 4]> {
    if let Ok(array) = value.cast::<numpy::PyArrayDyn<f64>>() {
        if array.shape() != [4] {
            return Err(error(
                py,
                Kind::Shape,
                format!(
                    "`{name}` must have shape (4,), got {:?}",
                    array.shape().to_vec()
                ),
            ));
        }
        // A contiguous array is copied directly (no borrow bookkeeping: the copy is taken
        // while we hold the GIL); a strided view goes through the sequence protocol below.
        if let Ok(v) = array.to_vec()
            && let [a, b, c, d] = v.as_slice()
        {
            return Ok([*a, *b, *c, *d]);
        }
    }
    value.extract::<[f64; 4]>().map_err(|_| {
        error(
            py,
            Kind::Shape,
            format!("`{name}` must be a float array of shape (4,) or a sequence of 4 numbers"),
        )
    })
}

/// Reserves a vector of `len` elements, or raises `MemoryError` (instead of aborting the
/// interpreter on an impossible allocation).
pub fn reserve<T>(len: usize) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        pyo3::exceptions::PyMemoryError::new_err(format!("cannot allocate {len} elements"))
    })?;
    Ok(v)
}
