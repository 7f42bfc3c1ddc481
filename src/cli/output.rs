//! Standard output, written as a Unix tool writes it: every command prints through
//! [`stdout`] (or [`outln!`], [`out!`]), which keeps the first write error; [`finish`]
//! flushes and returns it, and [`super::error::exit`] turns it into the exit status.
//!
//! - A closed pipe (`eomgen … | head -1`: the reader went away, `EPIPE`) ends the program
//!   quietly with status 141, what a shell reports for a tool that the signal `SIGPIPE`
//!   ended (128 + 13). Rust ignores `SIGPIPE`, so the write returns `EPIPE` instead of
//!   killing the process; the temporary files of atomic writes are then still removed. Not
//!   0: the output was not all delivered, and under `set -o pipefail` a pipeline sees the
//!   same status as with `cat`.
//! - Any other write error (`> /dev/full`: no space left on device) is one line on standard
//!   error and status 1.
//!
//! After the first error every further write fails at once without touching the stream, so a
//! command that goes on printing after a failure neither blocks nor loses the first reason.

use std::io::{self, Write};
use std::sync::Mutex;

/// The first error of a write to standard output, if any.
static FIRST_ERROR: Mutex<Option<(io::ErrorKind, String)>> = Mutex::new(None);

/// The exit status of a closed pipe: 128 + SIGPIPE (13).
pub(super) const BROKEN_PIPE_STATUS: u8 = 141;

/// Standard output with its first error kept ([`stdout`]).
pub(super) struct Stdout(io::StdoutLock<'static>);

/// Standard output, locked for the caller: writes go to the process's standard output
/// (line-buffered), and the first failing write is recorded for [`finish`].
pub(super) fn stdout() -> Stdout {
    Stdout(io::stdout().lock())
}

/// The error kept by a failed write, as the one later writes return.
fn failed() -> Option<io::Error> {
    let first = FIRST_ERROR.lock().ok()?;
    first
        .as_ref()
        .map(|(kind, message)| io::Error::new(*kind, message.clone()))
}

/// Keeps `error` as the first error unless one is already kept, and returns it.
fn record(error: io::Error) -> io::Error {
    if let Ok(mut first) = FIRST_ERROR.lock()
        && first.is_none()
    {
        *first = Some((error.kind(), error.to_string()));
    }
    error
}

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if let Some(e) = failed() {
            return Err(e);
        }
        self.0.write(buf).map_err(record)
    }

    fn flush(&mut self) -> io::Result<()> {
        if let Some(e) = failed() {
            return Err(e);
        }
        self.0.flush().map_err(record)
    }
}

/// Prints a line on standard output through [`stdout`], like `println!`; a failure is kept
/// for [`finish`] (and makes the program's status nonzero), never a panic.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = ::std::writeln!($crate::cli::output::stdout(), $($arg)*);
    }};
}
pub(crate) use outln;

/// Prints on standard output through [`stdout`], like `print!` (see [`outln!`]).
macro_rules! out {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = ::std::write!($crate::cli::output::stdout(), $($arg)*);
    }};
}
pub(crate) use out;

/// Prints a line on standard error, like `eprintln!` but never a panic: a message that cannot
/// be written (standard error to a full device) is dropped, since there is nowhere to say so.
macro_rules! errln {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = ::std::writeln!(::std::io::stderr(), $($arg)*);
    }};
}
pub(crate) use errln;

/// Flushes standard output and returns the first error of any write to it.
///
/// # Errors
/// The first write error (kind and message), including one of this flush.
pub(super) fn finish() -> Result<(), io::Error> {
    let _ = stdout().flush();
    match failed() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// How [`super::error::exit`] reports a failed standard output: nothing for a closed pipe (the reader
/// chose to stop), else `cannot write standard output: <reason>`.
pub(super) fn message(error: &io::Error) -> Option<String> {
    (error.kind() != io::ErrorKind::BrokenPipe)
        .then(|| format!("cannot write standard output: {error}"))
}

/// The exit status of a failed standard output: [`BROKEN_PIPE_STATUS`] for a closed pipe, 1
/// for any other error.
pub(super) fn status(error: &io::Error) -> u8 {
    if error.kind() == io::ErrorKind::BrokenPipe {
        BROKEN_PIPE_STATUS
    } else {
        1
    }
}
