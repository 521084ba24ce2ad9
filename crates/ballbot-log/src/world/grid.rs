//! A fixed grid of simulated times, for messages at bounded rates.

/// A fixed grid of simulated times: due at the first call at or after each multiple of the
/// interval.
#[derive(Clone, Copy, Debug)]
pub(super) struct Grid {
    interval_secs: f64,
    next_secs: f64,
}

impl Grid {
    /// A step landing on the grid up to rounding counts as on it.
    const TOLERANCE_SECS: f64 = 1e-9;

    pub(super) fn new(interval_secs: f64) -> Self {
        Self {
            interval_secs,
            next_secs: f64::NEG_INFINITY,
        }
    }

    /// Whether a message is due at `time_secs`; if so, moves to the next grid time.
    pub(super) fn due(&mut self, time_secs: f64) -> bool {
        if time_secs + Self::TOLERANCE_SECS < self.next_secs {
            return false;
        }
        self.next_secs = ((time_secs + Self::TOLERANCE_SECS) / self.interval_secs).floor()
            * self.interval_secs
            + self.interval_secs;
        true
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn grid_is_due_once_per_interval() {
        let mut grid = Grid::new(0.02);
        let dt = 1.0 / 8000.0;
        let due = (0..1600)
            .filter(|k| grid.due(f64::from(k + 1) * dt))
            .count();
        // 0.2 s: the first call (at dt), then at 0.02, 0.04, ..., 0.2 s.
        assert_eq!(due, 11);
    }
}
