//! Rendering shared by the commands: what more than one command prints or writes the same way.
//!
//! Only presentation lives here (no numerics): the commands call the library for results and
//! render them with these.

/// Escapes text for HTML content and attribute values.
pub(super) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// Runs `write` on a temporary file beside `path` (same directory, same extension, so that a
/// chart library picks the same format) and renames it onto `path` only when `write`
/// succeeded: a run that fails or is killed leaves any previous file at `path` as it was,
/// never a truncated one. The rename is atomic on one file system, which the same directory
/// guarantees.
///
/// # Errors
/// The error of `write`, or a message when the temporary file cannot be created or renamed.
pub(super) fn atomically<T>(
    path: &str,
    write: impl FnOnce(&str) -> Result<T, String>,
) -> Result<T, String> {
    let target = std::path::Path::new(path);
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    let suffix = target
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    builder.prefix(".eomgen-").suffix(&suffix);
    // The mode of an ordinary new file (the umask applies), not a temporary file's 0600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let temporary = builder
        .tempfile_in(dir)
        .map_err(|e| format!("cannot write `{path}`: {}", os_error(&e)))?;
    let temporary_path = temporary.path().to_string_lossy().into_owned();
    let value = write(&temporary_path)?;
    temporary
        .persist(target)
        .map_err(|e| format!("cannot write `{path}`: {}", os_error(&e.error)))?;
    Ok(value)
}

/// The operating system's message of `e` without the temporary file's path that the
/// temporary-file errors append (`… at path "dir/.eomgen-…"`): the user named another path.
fn os_error(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.split_once(" at path ") {
        Some((message, _)) => message.to_string(),
        None => text,
    }
}

/// Writes `contents` to `path` atomically ([`atomically`]).
///
/// # Errors
/// A message naming the file when it cannot be written.
pub(super) fn write_file(path: &str, contents: impl AsRef<[u8]>) -> Result<(), String> {
    atomically(path, |temporary| {
        std::fs::write(temporary, contents.as_ref())
            .map_err(|e| format!("cannot write `{path}`: {e}"))
    })
}
