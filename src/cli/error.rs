//! The error of a command and the exit status of a run: 0 success, 1 a failed computation
//! or write, 2 a usage error, 141 standard output closed by its reader.

use std::io::Write as _;
use std::process::ExitCode;

use super::output::{self, outln};

/// A CLI failure: the message for stderr and the exit code.
#[derive(Debug)]
pub struct CliError {
    /// What went wrong, with what would be right.
    pub message: String,
    /// Exit status (2 usage, 1 failure of the computation).
    pub code: u8,
    /// What `--json` prints on standard output for this error (model-file diagnostics).
    pub json: Option<serde_json::Value>,
}

impl CliError {
    pub(super) fn usage(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 2,
            json: None,
        }
    }
    pub(super) fn failure(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 1,
            json: None,
        }
    }
    /// The error of a model that could not be opened or read, which happens before any
    /// output: with `--json`, `{"error": message}` on standard output (the form of a model
    /// file's diagnostics, without them), so that a script reading the output always gets JSON.
    pub(super) fn before_output(mut self) -> Self {
        if self.json.is_none() {
            // Pure rendering of this error's message: no library report behind it.
            self.json = Some(serde_json::json!({ "error": self.message }));
        }
        self
    }
}

/// The exit status of a command line clap did not accept, or of `--help` and `--version`:
/// help and version on standard output with status 0 (a failed write of them is reported as
/// any other), usage errors on standard error with status 2 (a message that cannot be written
/// there is dropped, the status still tells).
pub(super) fn parse_failure(e: &clap::Error) -> ExitCode {
    let code = u8::try_from(e.exit_code()).unwrap_or(2);
    match e.print() {
        Ok(()) => ExitCode::from(code),
        Err(_) if e.use_stderr() => ExitCode::from(code),
        Err(io) => output_failure(&io, None),
    }
}

/// The end of a command's run: its error's JSON form on standard output for `--json`,
/// standard output flushed, then the error on standard error, and the exit status.
pub(super) fn exit(result: Result<(), CliError>) -> ExitCode {
    if let Err(e) = &result
        && let Some(json) = &e.json
        && std::env::args().any(|a| a == "--json")
    {
        // Every command that reports numbers takes `--json`; an error with a JSON form
        // (a model file's diagnostics) is then printed as JSON on standard output too.
        outln!("{}", serde_json::to_string_pretty(json).unwrap_or_default());
    }
    // Standard output is complete (flushed) before any message on standard error.
    let written = output::finish();
    match (result, written) {
        (Ok(()), Ok(())) => ExitCode::SUCCESS,
        (Err(e), Ok(())) => {
            let _ = writeln!(std::io::stderr(), "error: {}", e.message);
            ExitCode::from(e.code)
        }
        (result, Err(io)) => output_failure(&io, result.err()),
    }
}

/// The end of a run whose standard output failed: the command's own error if it had one,
/// then the write error (none for a closed pipe, [`output::message`]). The status is the
/// command's when it failed (1); otherwise, and after a usage error whose JSON
/// (`check --json bad.yaml > /dev/full`) was not delivered, the failed write's
/// ([`output::status`]: 1, or 141 for a closed pipe).
fn output_failure(io: &std::io::Error, error: Option<CliError>) -> ExitCode {
    let mut stderr = std::io::stderr();
    if let Some(e) = &error {
        let _ = writeln!(stderr, "error: {}", e.message);
    }
    if let Some(message) = output::message(io) {
        let _ = writeln!(stderr, "error: {message}");
    }
    ExitCode::from(match error {
        Some(e) if e.code != 2 => e.code,
        _ => output::status(io),
    })
}
