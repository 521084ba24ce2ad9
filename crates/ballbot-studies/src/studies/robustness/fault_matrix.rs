//! The fault-injection matrix: every fault class in every condition at every heading, each
//! cell a seeded run in the rapier3d world with the shipped loop and an MCAP log.

use super::fault_run::{
    Cell, CellError, CellProtocol, CellResult, ControllerVariant, run_cell_observed,
};
use super::faults::{Condition, FaultClass, FaultMagnitudes};
use crate::studies::driver::{self, Bisection, Study};
use ballbot_log::LogError;
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::{WorldError, WorldParams};
use serde::Serialize;
use std::path::PathBuf;

/// What the matrix runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultMatrixSettings {
    /// The controllers (default: the design, and the design with balance-point estimation).
    pub controllers: Vec<ControllerVariant>,
    /// The fault classes (default: all 17).
    pub classes: Vec<FaultClass>,
    /// The conditions (default: standing, cruising, braking).
    pub conditions: Vec<Condition>,
    /// Headings of travel (deg).
    pub headings_deg: Vec<f64>,
    /// Seed of the sensor noise; every cell uses it (the cells differ in their faults).
    pub seed: u64,
    /// The protocol of each cell.
    pub protocol: CellProtocol,
    /// How large each fault is.
    pub magnitudes: FaultMagnitudes,
    /// Where each cell writes its MCAP log (`None`: no logs).
    pub log_dir: Option<PathBuf>,
}

impl FaultMatrixSettings {
    /// The issue's matrix: 17 classes x 3 conditions x headings 0, 90 and 180 deg (153
    /// cells), for each of the two controllers (306).
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FaultMatrixSettings;
    /// assert_eq!(FaultMatrixSettings::full().cells().len(), 306);
    /// ```
    pub fn full() -> Self {
        Self {
            controllers: ControllerVariant::ALL.to_vec(),
            classes: FaultClass::ALL.to_vec(),
            conditions: Condition::ALL.to_vec(),
            headings_deg: vec![0.0, 90.0, 180.0],
            seed: 1,
            protocol: CellProtocol::fault_matrix(),
            magnitudes: FaultMagnitudes::fault_matrix(),
            log_dir: None,
        }
    }

    /// Every class in every condition at heading 0 only (51 cells per controller, 102),
    /// shorter runs: the CI size.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FaultMatrixSettings;
    /// assert_eq!(FaultMatrixSettings::quick().cells().len(), 102);
    /// ```
    pub fn quick() -> Self {
        Self {
            headings_deg: vec![0.0],
            protocol: CellProtocol {
                moving_inject_secs: 3.0,
                observe_secs: 4.0,
                ..CellProtocol::fault_matrix()
            },
            ..Self::full()
        }
    }

    /// Checks the settings: at least one class, condition and heading, finite headings, and a
    /// protocol whose times are finite and ordered.
    ///
    /// ```
    /// use ballbot_studies::studies::robustness::FaultMatrixSettings;
    /// let mut s = FaultMatrixSettings::quick();
    /// assert!(s.validate().is_ok());
    /// s.headings_deg.clear();
    /// assert!(s.validate().unwrap_err().to_string().contains("headings_deg"));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let check = |ok: bool, field, requirement| {
            if ok {
                Ok(())
            } else {
                Err(WorldError::InvalidParameter { field, requirement })
            }
        };
        check(
            !self.controllers.is_empty(),
            "controllers",
            "must not be empty",
        )?;
        check(!self.classes.is_empty(), "classes", "must not be empty")?;
        check(
            !self.conditions.is_empty(),
            "conditions",
            "must not be empty",
        )?;
        check(
            !self.headings_deg.is_empty() && self.headings_deg.iter().all(|h| h.is_finite()),
            "headings_deg",
            "must be non-empty and finite",
        )?;
        let p = &self.protocol;
        let pos = |v: f64| v.is_finite() && v > 0.0;
        check(
            pos(p.cruise_m_per_s),
            "protocol.cruise_m_per_s",
            "must be finite and > 0",
        )?;
        check(
            p.settle_secs.is_finite() && p.settle_secs >= 0.0,
            "protocol.settle_secs",
            "must be finite and >= 0",
        )?;
        check(
            pos(p.standing_inject_secs),
            "protocol.standing_inject_secs",
            "must be finite and > 0",
        )?;
        check(
            pos(p.moving_inject_secs) && p.moving_inject_secs > p.settle_secs,
            "protocol.moving_inject_secs",
            "must be finite and > settle_secs",
        )?;
        check(
            pos(p.observe_secs),
            "protocol.observe_secs",
            "must be finite and > 0",
        )?;
        check(
            pos(p.rest_speed_m_per_s),
            "protocol.rest_speed_m_per_s",
            "must be finite and > 0",
        )?;
        check(
            pos(p.max_command_error_m_per_s),
            "protocol.max_command_error_m_per_s",
            "must be finite and > 0",
        )?;
        check(
            p.log_telemetry_every_steps >= 1,
            "protocol.log_telemetry_every_steps",
            "must be >= 1",
        )
    }

    /// The cells: controller, then class, condition and heading.
    pub fn cells(&self) -> Vec<Cell> {
        let mut cells = Vec::new();
        for &controller in &self.controllers {
            for &class in &self.classes {
                for &condition in &self.conditions {
                    for &heading_deg in &self.headings_deg {
                        cells.push(Cell {
                            controller,
                            class,
                            condition,
                            heading_deg,
                            seed: self.seed,
                        });
                    }
                }
            }
        }
        cells
    }

    /// The log file of `cell` in `dir`.
    fn log_path(dir: &std::path::Path, cell: &Cell) -> PathBuf {
        dir.join(format!(
            "{}_{}_{}_{:03.0}deg.mcap",
            cell.controller.as_str(),
            cell.class.as_str(),
            cell.condition.as_str(),
            cell.heading_deg
        ))
    }
}

/// Counts over the matrix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultMatrixSummary {
    /// Cells run.
    pub cells: usize,
    /// Cells that ended in their expected safe state.
    pub as_expected: usize,
    /// Cells that ended in a safe state other than the expected one.
    pub safe_but_other: usize,
    /// Cells that ended unsafe: fell undetected, drifting off the command, or in an
    /// unexpected mode.
    pub unsafe_cells: usize,
    /// Cells in which the body passed the fall limit.
    pub fell: usize,
    /// Cells whose fault could not act (a bump never reached).
    pub not_exercised: usize,
    /// Logs written, and how many read back whole.
    pub logs: usize,
    /// Logs that read back whole.
    pub logs_read_back_whole: usize,
}

/// The matrix's result: every cell, in [`FaultMatrixSettings::cells`] order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultMatrix {
    /// The counts.
    pub summary: FaultMatrixSummary,
    /// Every cell.
    pub cells: Vec<CellResult>,
}

impl FaultMatrix {
    /// The cells of `controller` for `class`, in condition-then-heading order.
    pub fn row(&self, controller: ControllerVariant, class: FaultClass) -> Vec<&CellResult> {
        self.cells
            .iter()
            .filter(|c| c.cell.controller == controller && c.cell.class == class)
            .collect()
    }

    fn new(cells: Vec<CellResult>) -> Self {
        let count = |f: &dyn Fn(&CellResult) -> bool| cells.iter().filter(|c| f(c)).count();
        let logs = count(&|c| c.log.is_some());
        let summary = FaultMatrixSummary {
            cells: cells.len(),
            as_expected: count(&|c| c.as_expected),
            safe_but_other: count(&|c| !c.as_expected && c.observed.is_safe()),
            unsafe_cells: count(&|c| !c.observed.is_safe()),
            fell: count(&|c| c.fell),
            not_exercised: count(&|c| !c.exercised),
            logs,
            logs_read_back_whole: count(&|c| c.log.as_ref().is_some_and(|l| l.read_back_whole)),
        };
        Self { summary, cells }
    }
}

/// Runs the matrix on `world` (MiaPURE's default world in `ballbot robustness`) on `threads`
/// threads (0: every core); `progress(done, total)` after each cell.
pub fn run_fault_matrix(
    world: &WorldParams,
    settings: &FaultMatrixSettings,
    threads: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<FaultMatrix, CellError> {
    settings.validate()?;
    if let Some(dir) = &settings.log_dir {
        std::fs::create_dir_all(dir).map_err(|source| CellError::Log {
            path: dir.clone(),
            source: LogError::Io {
                path: dir.clone(),
                source,
            },
        })?;
    }
    let study = FaultMatrixStudy { world, settings };
    let total = settings.cells().len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let records = driver::execute(&study, threads, &|_| {
        let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        progress(n, total);
    })?;
    let results = records
        .into_iter()
        .flat_map(|r| r.trials.into_iter().map(|(_, cell)| cell))
        .collect();
    Ok(FaultMatrix::new(results))
}

/// The fault-injection matrix as a [`Study`]: one job per cell ([`FaultMatrixSettings::cells`]),
/// one trial each ([`run_cell_observed`], with the cell's MCAP log when the settings have a log
/// folder), passing when the cell ended in its expected safe state. [`run_fault_matrix`] runs
/// it with [`driver::execute`]; [`driver::replay`] runs a cell again with an observer.
pub struct FaultMatrixStudy<'a> {
    /// The world (each cell replaces its sensor seed).
    pub world: &'a WorldParams,
    /// The matrix.
    pub settings: &'a FaultMatrixSettings,
}

impl Study for FaultMatrixStudy<'_> {
    type Job = Cell;
    type Trial = CellResult;
    type Error = CellError;

    fn jobs(&self) -> Vec<Cell> {
        self.settings.cells()
    }

    fn bisection(&self, _cell: &Cell) -> Option<Bisection> {
        None
    }

    fn trial(
        &self,
        cell: &Cell,
        _value: Option<f64>,
        observe: &mut dyn FnMut(&WorldRobot),
    ) -> Result<CellResult, CellError> {
        let s = self.settings;
        let log = s
            .log_dir
            .as_deref()
            .map(|dir| FaultMatrixSettings::log_path(dir, cell));
        run_cell_observed(
            self.world,
            &s.protocol,
            &s.magnitudes,
            *cell,
            log.as_deref(),
            observe,
        )
    }

    fn passed(&self, result: &CellResult) -> bool {
        result.as_expected
    }

    fn describe(&self, cell: &Cell, _value: Option<f64>, result: &CellResult) -> String {
        format!(
            "fault {} {} {:.0} deg ({}): {}",
            cell.class.as_str(),
            cell.condition.as_str(),
            cell.heading_deg,
            cell.controller.as_str(),
            result.mark()
        )
    }
}
