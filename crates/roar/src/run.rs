//! The state every stage shares while a run goes on: the config, the statistics it fills in,
//! the stage clock and the progress reports.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::config::ReconstructConfig;
use crate::error::PipelineError;
use crate::report::RunStats;

/// One progress report.
#[derive(Debug, Clone)]
pub struct Progress {
    /// What is running ("target", "init", "optimize", "untangle", "decimate", …).
    pub stage: &'static str,
    /// Iteration within the optimize stage (0-based), or 0.
    pub iteration: usize,
    /// Total iterations of the optimize stage.
    pub iterations: usize,
    /// Last loss value (NaN before the first).
    pub loss: f64,
    /// Current face count (0 before the init).
    pub faces: usize,
}

/// What every stage shares: the effective config, the statistics it fills in, the stage clock
/// and the progress reports (which also check for cancellation).
pub(crate) struct Run<'a> {
    pub config: &'a ReconstructConfig,
    pub stats: RunStats,
    pub clock: StageClock,
    pub progress: &'a mut dyn FnMut(&Progress),
    pub cancel: Option<Arc<AtomicBool>>,
}

impl Run<'_> {
    /// Reports progress; fails with [`PipelineError::Cancelled`] once
    /// [`Reconstruction::cancel`] is set.
    pub fn report(
        &mut self,
        stage: &'static str,
        iteration: usize,
        loss: f64,
        faces: usize,
    ) -> Result<(), PipelineError> {
        (self.progress)(&Progress {
            stage,
            iteration,
            iterations: self.config.optimize.iterations,
            loss,
            faces,
        });
        match &self.cancel {
            Some(flag) if flag.load(Ordering::Relaxed) => Err(PipelineError::Cancelled),
            _ => Ok(()),
        }
    }
}

/// Accumulates wall time per stage name.
pub(crate) struct StageClock {
    pub seconds: BTreeMap<String, f64>,
    last: Option<Instant>,
}

impl StageClock {
    pub fn start() -> Self {
        Self {
            seconds: BTreeMap::new(),
            last: Some(Instant::now()),
        }
    }

    /// Charges the time since the previous lap (or since creation) to `stage`.
    pub fn lap(&mut self, stage: &str) {
        let now = Instant::now();
        let since = self.last.unwrap_or(now);
        *self.seconds.entry(stage.to_string()).or_insert(0.0) += (now - since).as_secs_f64();
        self.last = Some(now);
    }
}
