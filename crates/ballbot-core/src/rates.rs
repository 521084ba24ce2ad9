//! The loop rates of the paper's drivetrain, in one place: a 400 Hz outer (LQR) loop and an
//! 8 kHz inner loop (motor speed PIs, and the simulators' physics step).
//!
//! Everything that defaults to one of these rates (the LQR design, the robot loop's
//! configuration, the simulators, the Python bindings' keyword defaults) reads it from here.
//!
//! ```
//! use ballbot_core::rates::{INNER_LOOP_DT_SECS, INNER_PER_OUTER, OUTER_LOOP_DT_SECS};
//! assert_eq!(OUTER_LOOP_DT_SECS, INNER_LOOP_DT_SECS * INNER_PER_OUTER as f64);
//! ```

/// The paper's outer-loop (LQR) rate: 400 Hz.
///
/// ```
/// use ballbot_core::rates::{INNER_LOOP_RATE_HZ, OUTER_LOOP_RATE_HZ};
/// // The 8 kHz inner loop runs 20 steps per outer step.
/// assert_eq!(INNER_LOOP_RATE_HZ / OUTER_LOOP_RATE_HZ, 20.0);
/// ```
pub const OUTER_LOOP_RATE_HZ: f64 = 400.0;

/// The paper's inner-loop (motor speed PI) rate: 8 kHz.
///
/// ```
/// use ballbot_core::rates::INNER_LOOP_RATE_HZ;
/// assert_eq!(INNER_LOOP_RATE_HZ, 8000.0);
/// ```
pub const INNER_LOOP_RATE_HZ: f64 = 8000.0;

/// The outer-loop period `1 / 400` s = 2.5 ms.
///
/// ```
/// use ballbot_core::rates::OUTER_LOOP_DT_SECS;
/// assert_eq!(OUTER_LOOP_DT_SECS, 0.0025);
/// ```
pub const OUTER_LOOP_DT_SECS: f64 = 1.0 / OUTER_LOOP_RATE_HZ;

/// The inner-loop period `1 / 8000` s = 125 us.
///
/// ```
/// use ballbot_core::rates::INNER_LOOP_DT_SECS;
/// assert_eq!(INNER_LOOP_DT_SECS, 0.000125);
/// ```
pub const INNER_LOOP_DT_SECS: f64 = 1.0 / INNER_LOOP_RATE_HZ;

/// The outer-loop period in microseconds, for loops clocked in whole microseconds (derived
/// from [`OUTER_LOOP_RATE_HZ`]).
///
/// ```
/// use ballbot_core::rates::OUTER_LOOP_PERIOD_US;
/// assert_eq!(OUTER_LOOP_PERIOD_US, 2500);
/// ```
pub const OUTER_LOOP_PERIOD_US: u64 = (1e6 / OUTER_LOOP_RATE_HZ) as u64;

/// Inner steps per outer step: 20 (derived from the two rates).
///
/// ```
/// use ballbot_core::rates::INNER_PER_OUTER;
/// assert_eq!(INNER_PER_OUTER, 20);
/// ```
pub const INNER_PER_OUTER: u64 = (INNER_LOOP_RATE_HZ / OUTER_LOOP_RATE_HZ) as u64;
