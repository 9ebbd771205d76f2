//! Training data of the walk-and-reach task: per trial, three actions (normal step, shortened
//! step, reach), each a time-normalised block of joint angles with its step parameters.

use crate::data::TrialSet;
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

/// One action of one trial.
#[derive(Clone, Debug, PartialEq)]
pub struct TrialAction {
    /// `I × N` joint angles (exponential-map channels), row-major, one action period.
    pub angles: Vec<f64>,
    /// The action's step parameter: the pelvis travel for steps; for the reach, the length of
    /// the step before it (the reach posture depends on how the approach ended).
    pub step_length: f64,
    /// Duration of the action (seconds).
    pub duration: f64,
    /// Pelvis forward travel since the action's start at each sample (metres, `N` values), or
    /// empty when unknown.
    pub root: Vec<f64>,
}

/// A training set: trials of three actions each.
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// Channels `I`.
    pub n_channels: usize,
    /// Samples per action `N`.
    pub n_samples: usize,
    /// The trials.
    pub trials: Vec<[TrialAction; 3]>,
    /// Initial pelvis-to-drawer distance of each trial when known (metres).
    pub distances: Vec<f64>,
}

impl Dataset {
    /// Checks shapes and values.
    ///
    /// # Errors
    /// No trials; an action whose angle block is not `I × N` (trials or actions of different
    /// sample counts); NaN or infinity; a non-positive duration or negative step parameter;
    /// root curves of the wrong length.
    pub fn validate(&self) -> Result<()> {
        if self.trials.is_empty() {
            return Err(Error::Empty("trials"));
        }
        if self.n_channels == 0 || self.n_samples == 0 {
            return Err(Error::Empty("channels/samples"));
        }
        let len = self.n_channels * self.n_samples;
        for (r, trial) in self.trials.iter().enumerate() {
            for (a, act) in trial.iter().enumerate() {
                if act.angles.len() != len {
                    return Err(Error::ShapeMismatch(format!(
                        "trial {r} action {} has {} angle values, expected {} channels x {} samples",
                        a + 1,
                        act.angles.len(),
                        self.n_channels,
                        self.n_samples
                    )));
                }
                ensure_finite("angles", &act.angles)?;
                if !(act.duration.is_finite() && act.duration > 0.0) {
                    return Err(Error::invalid(
                        "duration",
                        format!(
                            "trial {r} action {}: must be > 0, got {}",
                            a + 1,
                            act.duration
                        ),
                    ));
                }
                if !(act.step_length.is_finite() && act.step_length >= 0.0) {
                    return Err(Error::invalid(
                        "step_length",
                        format!(
                            "trial {r} action {}: must be >= 0, got {}",
                            a + 1,
                            act.step_length
                        ),
                    ));
                }
                if !act.root.is_empty() && act.root.len() != self.n_samples {
                    return Err(Error::ShapeMismatch(format!(
                        "trial {r} action {}: root curve of {} samples",
                        a + 1,
                        act.root.len()
                    )));
                }
                ensure_finite("root", &act.root)?;
            }
        }
        ensure_finite("distances", &self.distances)?;
        Ok(())
    }

    /// The angles of action `a` (0, 1 or 2) of every trial as an `R × I × N` set.
    ///
    /// # Errors
    /// `a > 2`, or an invalid dataset.
    pub fn action_set(&self, a: usize) -> Result<TrialSet> {
        if a > 2 {
            return Err(Error::invalid(
                "action",
                format!("must be 0, 1 or 2, got {a}"),
            ));
        }
        let blocks: Vec<Vec<f64>> = self.trials.iter().map(|t| t[a].angles.clone()).collect();
        TrialSet::stack(&blocks, self.n_channels, self.n_samples)
    }

    /// `(step parameter, duration)` of action `a` for every trial.
    pub fn params(&self, a: usize) -> Vec<(f64, f64)> {
        self.trials
            .iter()
            .map(|t| (t[a].step_length, t[a].duration))
            .collect()
    }
}
