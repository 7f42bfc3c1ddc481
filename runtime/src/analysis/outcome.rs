//! The one rule every study follows: a study that measured nothing is a failure.
//!
//! A study is a set of runs (integrations, analyses at grid points, checks), each of which
//! measured something or failed with a reason. A report whose every run failed holds no
//! result, only zeros and blanks where numbers would be; a front end must not present it as
//! a success. Each study's report implements [`StudyRuns`], and its front end calls
//! [`StudyRuns::check_measured`] before it reports success (`eomgen study …` and `eomgen
//! report` exit 1 with the first failure's reason).

/// How many runs of a study measured something, how many failed, and why the first failed.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RunTally {
    /// Runs that measured something.
    pub measured: usize,
    /// Runs that failed.
    pub failed: usize,
    /// The reason of the first failed run, in the report's order.
    pub first_failure: Option<String>,
}

impl RunTally {
    /// Counts a run that measured something.
    pub fn measured(&mut self) {
        self.measured += 1;
    }

    /// Counts a run that failed with `reason`.
    pub fn failed(&mut self, reason: impl std::fmt::Display) {
        self.failed += 1;
        if self.first_failure.is_none() {
            self.first_failure = Some(reason.to_string());
        }
    }

    /// Counts a run whose failure, if it failed, is `failure`.
    pub fn add(&mut self, failure: Option<impl std::fmt::Display>) {
        match failure {
            None => self.measured(),
            Some(reason) => self.failed(reason),
        }
    }
}

/// A study that measured nothing: every one of its runs failed (or it had none).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", self.message())]
pub struct NothingMeasured {
    /// The study (`work-precision`).
    pub study: &'static str,
    /// How many runs failed.
    pub failed: usize,
    /// Why the first failed (`no run` when there was none).
    pub first_failure: String,
}

impl NothingMeasured {
    /// `study: every run failed (k of k), …; the first failed: …`, or, without runs,
    /// `study: no run was made, so nothing was measured`.
    fn message(&self) -> String {
        if self.failed == 0 {
            format!("{}: no run was made, so nothing was measured", self.study)
        } else {
            format!(
                "{}: every run failed ({} of {}), so nothing was measured; the first failed: {}",
                self.study, self.failed, self.failed, self.first_failure
            )
        }
    }
}

/// The report of a study made of runs, each of which measured something or failed.
pub trait StudyRuns {
    /// The study's name, as its command names it (`work-precision`).
    fn study(&self) -> &'static str;

    /// Counts the runs of the report that measured something and those that failed.
    fn tally(&self) -> RunTally;

    /// The rule: the report holds a result only if some run measured something.
    ///
    /// # Errors
    /// [`NothingMeasured`] when no run did (every run failed, or there was none).
    ///
    /// # Examples
    /// ```
    /// use eomgen_runtime::analysis::{RunTally, StudyRuns};
    ///
    /// struct Runs(Vec<Result<f64, String>>);
    /// impl StudyRuns for Runs {
    ///     fn study(&self) -> &'static str { "example" }
    ///     fn tally(&self) -> RunTally {
    ///         let mut tally = RunTally::default();
    ///         for run in &self.0 {
    ///             tally.add(run.as_ref().err());
    ///         }
    ///         tally
    ///     }
    /// }
    /// assert!(Runs(vec![Err("diverged".into()), Ok(1e-6)]).check_measured().is_ok());
    /// let none = Runs(vec![Err("diverged".into()), Err("underflow".into())]).check_measured();
    /// assert_eq!(none.unwrap_err().first_failure, "diverged");
    /// let empty = Runs(vec![]).check_measured().unwrap_err();
    /// assert_eq!(empty.to_string(), "example: no run was made, so nothing was measured");
    /// ```
    fn check_measured(&self) -> Result<(), NothingMeasured> {
        let tally = self.tally();
        if tally.measured > 0 {
            return Ok(());
        }
        Err(NothingMeasured {
            study: self.study(),
            failed: tally.failed,
            first_failure: tally.first_failure.unwrap_or_else(|| "no run".to_string()),
        })
    }
}
