//! Reading a model file: bounded in size before it is read, then decoded as UTF-8.
//!
//! Every reader of model files (the macro, the run-time compiler `JitModel::load`, the
//! command line) goes through [`read_model_file`], so that none reads `/dev/zero` until
//! memory runs out: at most [`MAX_FILE_BYTES`] + 1 bytes are ever read, from a regular file,
//! a device or a FIFO alike.

use std::io::Read as _;
use std::path::Path;

use super::diagnostic::Diagnostic;

/// The largest model file read, in bytes (4 MiB). The largest generated models are far
/// below it: `eomgen new n-link-pendulum 100` is 0.4 MB and `eomgen new n-mass-chain 1000`
/// 0.15 MB (`templates::MAX_SIZES`); a hand-written model is a few kB.
pub const MAX_FILE_BYTES: u64 = 4 * 1024 * 1024;

/// Why a model file could not be read as text.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The file holds more than `limit` bytes (only `limit + 1` were read).
    #[error(
        "the file is larger than {limit} bytes ({} MiB), the largest model file read",
        limit / (1024 * 1024)
    )]
    TooLarge {
        /// [`MAX_FILE_BYTES`].
        limit: u64,
    },
    /// The file is not UTF-8: the located diagnostic at the first invalid byte.
    #[error("{}", diagnostic.message)]
    NotText {
        /// Where and why.
        diagnostic: Diagnostic,
        /// The file's text with invalid bytes replaced, for the diagnostic's snippet.
        text: String,
    },
}

/// The text of the model file at `path`, read through a limit of [`MAX_FILE_BYTES`].
///
/// # Errors
/// [`ReadError::Io`] if it cannot be opened or read (a directory, a missing file),
/// [`ReadError::TooLarge`] past the limit, [`ReadError::NotText`] if it is not UTF-8.
pub fn read_model_file(path: &Path) -> Result<String, ReadError> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(ReadError::TooLarge {
            limit: MAX_FILE_BYTES,
        });
    }
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.into_bytes();
        // `decode` fails where `from_utf8` did.
        let diagnostic = super::yaml::decode(&bytes)
            .err()
            .unwrap_or_else(|| Diagnostic::new(super::Location::default(), "not UTF-8"));
        ReadError::NotText {
            diagnostic,
            text: String::from_utf8_lossy(&bytes).into_owned(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 28: `check /dev/zero` read until memory ran out.
    #[test]
    fn a_device_is_read_only_up_to_the_limit() {
        let error = read_model_file(Path::new("/dev/zero")).unwrap_err();
        assert!(matches!(error, ReadError::TooLarge { limit } if limit == MAX_FILE_BYTES));
        assert!(
            error.to_string().contains("4194304 bytes (4 MiB)"),
            "{error}"
        );
    }

    /// The largest files `eomgen new` writes are read.
    #[test]
    fn the_largest_templates_are_within_the_limit() {
        use crate::model::templates::{MAX_SIZES, n_link_pendulum, n_mass_chain};
        let pendulum = n_link_pendulum(MAX_SIZES[0]).len() as u64;
        let chain = n_mass_chain(MAX_SIZES[1]).len() as u64;
        assert!(
            pendulum.max(chain) * 2 < MAX_FILE_BYTES,
            "{pendulum} and {chain} bytes"
        );
    }
}
