//! Output files: the one writer of every file the command line writes ([`write()`]), and the
//! check of a command's outputs before it does any work ([`Outputs::check`]).
//!
//! What a path names decides how it is written (docs/reliability.md, "Atomic outputs"):
//!
//! - a **regular file**, or a name that does not exist yet: the bytes go to a temporary file
//!   `.eomgen-…` in the same directory, renamed onto the name when complete, so a failed or
//!   killed run leaves the previous file whole. An existing file keeps its permissions (and
//!   its owner and group where the process may set them); a new one gets the ordinary mode
//!   of a new file (0666 less the umask);
//! - a **symbolic link** is followed to its final target (which need not exist yet), and that
//!   target is replaced as above, in its own directory: the link stays a link and its target
//!   is the new file. A link that the kernel's `fs.protected_symlinks` rule would not follow
//!   (another user's, in a sticky world-writable directory) is refused ([`may_follow`]);
//! - the program's own **standard output or error** (`-`, `/dev/stdout`, `/dev/fd/1`, or any
//!   name of the same open file) is written through the stream, in order with what the command
//!   prints, and standard output's errors are reported as standard output's
//!   ([`super::output`]);
//! - another of the program's **open descriptors**, named exactly `/dev/fd/N` or
//!   `/proc/self/fd/N`, is written through a duplicate of it, never reopened or truncated
//!   (`3>>log.csv` appends); another process's `/proc/<pid>/fd/N` is opened and appended to;
//! - anything else that is not a regular file (`/dev/null`, a FIFO, a terminal) is opened
//!   for writing and the bytes are streamed into it: never truncated, renamed over or
//!   removed.

use std::fs::{self, Metadata, OpenOptions};
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};

use super::error::CliError;

/// An output that cannot be written, or two outputs that would write one file.
#[derive(Debug, thiserror::Error)]
pub(super) enum FileError {
    /// A chart's format is chosen by its extension, and this one names none.
    #[error("{option} `{path}`: a chart file must end in .svg or .png")]
    ChartExtension {
        /// The option that names the file (`--plot`).
        option: String,
        /// The path as given.
        path: String,
    },
    /// The path names a directory.
    #[error("{option} `{path}` is a directory; give a file name")]
    Directory {
        /// The option that names the file.
        option: String,
        /// The path as given.
        path: String,
    },
    /// The path names no file (empty, ending in `/` or in `..`).
    #[error("{option} `{path}` names no file; give a file name")]
    NoFileName {
        /// The option that names the file.
        option: String,
        /// The path as given.
        path: String,
    },
    /// The file's directory does not exist (or is not a directory).
    #[error("{option} `{path}`: the directory `{directory}` does not exist")]
    NoDirectory {
        /// The option that names the file.
        option: String,
        /// The path as given.
        path: String,
        /// The directory the file would be created in (after any symbolic links).
        directory: String,
    },
    /// The path cannot be used: its directory is not writable, a link loops, a component
    /// cannot be searched.
    #[error("{option} `{path}` cannot be written: {reason}")]
    Unusable {
        /// The option that names the file.
        option: String,
        /// The path as given.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
    /// Two outputs of one run name the same file: one of them would be lost.
    #[error("{first} and {second} both write `{path}`; give each output its own file")]
    SamePath {
        /// The option named first.
        first: String,
        /// The option named second.
        second: String,
        /// The path as the second option gives it.
        path: String,
    },
    /// An output names a file the command reads (its model file, under any name: a link
    /// to it, a hard link, another spelling of its path): writing it would destroy the input.
    #[error(
        "{option} `{path}` is the model file `{input}` that this command reads; give the output another name"
    )]
    InputFile {
        /// The option that names the output.
        option: String,
        /// The output's path as given.
        path: String,
        /// The input's path as given.
        input: String,
    },
    /// Writing the file failed.
    #[error("cannot write `{path}`: {reason}")]
    Write {
        /// The path as given.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
    /// A stale companion file could not be removed.
    #[error("cannot remove `{path}`, left by an earlier run: {reason}")]
    Remove {
        /// The companion's path.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
}

impl From<FileError> for CliError {
    /// A refused output is a usage error (exit 2), found before any work; a failed write or
    /// removal is a failure (exit 1).
    fn from(e: FileError) -> Self {
        match e {
            FileError::Write { .. } | FileError::Remove { .. } => CliError::failure(e.to_string()),
            _ => CliError::usage(e.to_string()),
        }
    }
}

/// The most symbolic links followed from one path (Linux's limit, `ELOOP` beyond).
const MAX_LINKS: usize = 40;

/// One of the program's standard streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stream {
    Output,
    Error,
}

/// How a path is written ([`resolve`]).
#[derive(Debug)]
enum Target {
    /// The program's standard output or error: written through the stream.
    Standard(Stream),
    /// Not a regular file, or another process's descriptor (`/proc/<pid>/fd/N`): opened and
    /// written in place, never truncated (appended to when `append`).
    InPlace { path: PathBuf, append: bool },
    /// A regular file at the end of any symbolic links, replaced by rename; `existing` is
    /// the file there now, if any.
    Regular {
        path: PathBuf,
        existing: Option<Metadata>,
    },
    /// One of the program's own open descriptors (`/dev/fd/N`, `/proc/self/fd/N`): written
    /// through a duplicate of it, at its offset and with its flags (`3>>log` appends), never
    /// reopened or truncated.
    Descriptor(i32),
    /// A directory: refused.
    Directory,
}

/// What a path of the form `/dev/fd/N` or `/proc/<pid>/fd/N` names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FdPath {
    /// Descriptor `N` of this process (`/dev/fd/N`, `/proc/self/fd/N`,
    /// `/proc/thread-self/fd/N`, or `/proc/<our pid>/fd/N`).
    Own(i32),
    /// A descriptor of another process: opened through its link, appended to.
    Other,
}

/// Whether `path` is exactly `/dev/fd/N` or `/proc/<pid>/fd/N` (no other path under `/proc`,
/// such as `/proc/self/cwd/…` or `/proc/self/root/…`, which are ordinary paths).
fn fd_path(path: &str) -> Option<FdPath> {
    let number = |text: &str| {
        (!text.is_empty() && text.bytes().all(|b| b.is_ascii_digit()))
            .then(|| text.parse::<i32>().ok())
            .flatten()
    };
    if let Some(n) = path.strip_prefix("/dev/fd/") {
        return number(n).map(FdPath::Own);
    }
    let (process, n) = path.strip_prefix("/proc/")?.split_once("/fd/")?;
    let n = number(n)?;
    let own = matches!(process, "self" | "thread-self")
        || number(process).is_some_and(|pid| u32::try_from(pid) == Ok(std::process::id()));
    if own {
        Some(FdPath::Own(n))
    } else {
        number(process).map(|_| FdPath::Other)
    }
}

/// What `path` names, following symbolic links ([`Target`]).
fn resolve(path: &str) -> io::Result<Target> {
    // `-` is standard output, as for most programs (it used to be a file named `-`, with a
    // companion `--events.csv`).
    if path == "-" {
        return Ok(Target::Standard(Stream::Output));
    }
    let descriptor = fd_path(path);
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => return Ok(Target::Directory),
        Ok(m) => {
            if let Some(stream) = standard_stream(&m) {
                return Ok(Target::Standard(stream));
            }
            match descriptor {
                Some(FdPath::Own(n)) => return Ok(Target::Descriptor(n)),
                Some(FdPath::Other) => {
                    return Ok(Target::InPlace {
                        path: PathBuf::from(path),
                        append: true,
                    });
                }
                None => {}
            }
            if !m.is_file() {
                return Ok(Target::InPlace {
                    path: PathBuf::from(path),
                    append: false,
                });
            }
        }
        // A descriptor that is not open names nothing to write to (and no place to create).
        Err(_) if descriptor.is_some() => {
            return Err(io::Error::other("no such open file descriptor"));
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    // A regular file or a new name: follow the links one by one to the name to replace.
    let mut current = PathBuf::from(path);
    for _ in 0..MAX_LINKS {
        let metadata = match fs::symlink_metadata(&current) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Ok(Target::Regular {
                    path: current,
                    existing: None,
                });
            }
            Err(e) => return Err(e),
        };
        if !metadata.file_type().is_symlink() {
            return Ok(Target::Regular {
                path: current,
                existing: Some(metadata),
            });
        }
        if !may_follow(&current, &metadata)? {
            return Err(io::Error::new(
                io::ErrorKind::PermissionDenied,
                format!(
                    "the symbolic link `{}` is owned by another user in a sticky world-writable \
                     directory, and is not followed (the rule of fs.protected_symlinks)",
                    current.display()
                ),
            ));
        }
        let link = fs::read_link(&current)?;
        current = match current.parent() {
            Some(dir) => dir.join(link),
            None => link,
        };
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// Whether the writer may follow the symbolic `link` (whose own metadata is `metadata`): the
/// kernel's rule of `fs.protected_symlinks`, applied here because the writer follows links
/// itself (to replace the final target) where the kernel's check would not run. A link in a
/// sticky world-writable directory (`/tmp`) is followed only when its owner is the caller
/// (effective user) or the directory's owner: otherwise another user may have planted it to
/// make the writer — root, say — replace a file it points to.
#[cfg(unix)]
fn may_follow(link: &Path, metadata: &Metadata) -> io::Result<bool> {
    use std::os::unix::fs::MetadataExt as _;
    let directory = fs::metadata(directory_of(link))?;
    let sticky_world_writable = directory.mode() & 0o1002 == 0o1002;
    // SAFETY: `geteuid` has no preconditions and cannot fail (POSIX).
    let caller = unsafe { libc::geteuid() };
    Ok(!sticky_world_writable || metadata.uid() == caller || metadata.uid() == directory.uid())
}

#[cfg(not(unix))]
fn may_follow(_: &Path, _: &Metadata) -> io::Result<bool> {
    Ok(true)
}

/// The standard stream that is the same open file as `metadata`'s, if any.
#[cfg(unix)]
fn standard_stream(metadata: &Metadata) -> Option<Stream> {
    use std::os::fd::AsFd as _;
    use std::os::unix::fs::MetadataExt as _;
    let same = |fd: std::os::fd::BorrowedFd<'_>| {
        fd.try_clone_to_owned()
            .ok()
            .and_then(|fd| fs::File::from(fd).metadata().ok())
            .is_some_and(|s| s.dev() == metadata.dev() && s.ino() == metadata.ino())
    };
    if same(io::stdout().as_fd()) {
        Some(Stream::Output)
    } else if same(io::stderr().as_fd()) {
        Some(Stream::Error)
    } else {
        None
    }
}

#[cfg(not(unix))]
fn standard_stream(_: &Metadata) -> Option<Stream> {
    None
}

/// The directory a file at `path` is created in (`.` for a bare name).
fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The operating system's message of `e` without the temporary file's path that the
/// temporary-file errors append (`… at path "dir/.eomgen-…"`): the user named another path.
fn os_error(e: &io::Error) -> String {
    let text = e.to_string();
    match text.split_once(" at path ") {
        Some((message, _)) => message.to_string(),
        None => text,
    }
}

/// Writes `bytes` to `path` as its kind asks (see the module's documentation): a regular file
/// (or the final target of a symbolic link) is replaced atomically keeping its mode, a
/// device or FIFO is written in place, the program's standard output or error through the
/// stream.
///
/// # Errors
/// [`FileError::Write`] naming `path` with the operating system's reason (or that a
/// directory is in the way). A write to standard output that fails is kept by
/// [`super::output`] (status 1, or 141 for a closed pipe) and is not an error here.
pub(super) fn write(path: &str, bytes: &[u8]) -> Result<(), FileError> {
    let fail = |e: io::Error| FileError::Write {
        path: path.to_string(),
        reason: os_error(&e),
    };
    match resolve(path).map_err(fail)? {
        // Found when the file is written, after the work: a failed write, not a usage error
        // (the check before the work refuses it as one).
        Target::Directory => Err(FileError::Write {
            path: path.to_string(),
            reason: "a directory is in the way".to_string(),
        }),
        Target::Standard(Stream::Output) => {
            let _ = super::output::stdout().write_all(bytes);
            Ok(())
        }
        Target::Standard(Stream::Error) => io::stderr().write_all(bytes).map_err(fail),
        Target::InPlace {
            path: target,
            append,
        } => {
            let file = OpenOptions::new()
                .write(true)
                .append(append)
                .open(target)
                .map_err(fail)?;
            write_all(file, bytes).map_err(fail)
        }
        Target::Descriptor(n) => write_all(duplicate(n).map_err(fail)?, bytes).map_err(fail),
        Target::Regular {
            path: target,
            existing,
        } => {
            // The last guard of an input: a file this process read is never replaced, even
            // where a command did not name it before the work.
            // Found after the work, like a directory in the way: a failed write (status 1).
            if let Some((device, inode)) = existing.as_ref().and_then(inode)
                && let Some(input) = input_named(&Identity::Inode(device, inode))
            {
                return Err(FileError::Write {
                    path: path.to_string(),
                    reason: format!(
                        "it is the model file `{input}` that this command reads, which no output replaces"
                    ),
                });
            }
            replace(&target, existing.as_ref(), bytes).map_err(fail)
        }
    }
}

/// Writes all of `bytes` into `file` and flushes it.
fn write_all(mut file: fs::File, bytes: &[u8]) -> io::Result<()> {
    file.write_all(bytes)?;
    file.flush()
}

/// A duplicate of this process's open descriptor `n` (`dup`): the same open file, offset and
/// flags, so the bytes go where the shell's redirection (`3>>log.csv`) points, appended or at
/// the offset, with nothing reopened or truncated.
#[cfg(unix)]
fn duplicate(n: i32) -> io::Result<fs::File> {
    use std::os::fd::BorrowedFd;
    // SAFETY: `resolve` found `n` open (its metadata was read through `/dev/fd/N` just
    // before), and the borrow lasts only for the `dup` below, which fails with EBADF rather
    // than misbehaves if it was closed since.
    let fd = unsafe { BorrowedFd::borrow_raw(n) };
    Ok(fs::File::from(fd.try_clone_to_owned()?))
}

#[cfg(not(unix))]
fn duplicate(_: i32) -> io::Result<fs::File> {
    Err(io::Error::from(io::ErrorKind::Unsupported))
}

/// Writes `bytes` to a temporary file in `target`'s directory, with the owner, group and
/// permissions of `existing` (or a new file's mode), and renames it onto `target`.
fn replace(target: &Path, existing: Option<&Metadata>, bytes: &[u8]) -> io::Result<()> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".eomgen-");
    // The mode of an ordinary new file (the umask applies), not a temporary file's 0600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut temporary = builder.tempfile_in(directory_of(target))?;
    if let Some(existing) = existing {
        // Owner first: changing it may clear set-id bits that the mode then restores. A
        // process may not give a file away (only root may), so a refusal leaves the owner
        // the writer; the mode is set exactly (fchmod is not masked by the umask).
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt as _;
            let _ = std::os::unix::fs::fchown(
                temporary.as_file(),
                Some(existing.uid()),
                Some(existing.gid()),
            );
        }
        temporary
            .as_file()
            .set_permissions(existing.permissions())?;
    }
    temporary.write_all(bytes)?;
    temporary.persist(target).map_err(|e| e.error)?;
    Ok(())
}

/// Whether `path` is written in place (a device, FIFO or standard stream, see [`write()`])
/// rather than replaced as a regular file.
pub(super) fn writes_in_place(path: &str) -> bool {
    matches!(
        resolve(path),
        Ok(Target::Standard(_) | Target::InPlace { .. } | Target::Descriptor(_))
    )
}

/// What [`remove_stale`] did with a companion file of an earlier run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Stale {
    /// No regular file of that name: nothing to do.
    Absent,
    /// A file that eomgen wrote, removed.
    Removed,
    /// A regular file that eomgen did not write (or cannot be read to tell): kept, and stale
    /// beside this run's outputs; the caller warns.
    Kept,
}

/// Removes `path`, a companion file that an earlier run wrote beside an output and that this
/// run does not write (`FILE-events.csv` of a run without events), so that the files beside
/// an output always come from the same run. Only a regular file that `is_ours` recognises
/// from its bytes (the header or the marker eomgen writes in it) is removed: a file of that
/// name that eomgen did not write is the user's and is kept ([`Stale::Kept`]); a symbolic
/// link, a device or a FIFO of that name is left alone, and so is a missing file.
///
/// # Errors
/// [`FileError::Remove`] when a file of ours is there and cannot be removed.
pub(super) fn remove_stale(
    path: &str,
    is_ours: impl Fn(&[u8]) -> bool,
) -> Result<Stale, FileError> {
    match fs::symlink_metadata(path) {
        Ok(m) if m.is_file() => {
            if !fs::read(path).is_ok_and(|bytes| is_ours(&bytes)) {
                return Ok(Stale::Kept);
            }
            fs::remove_file(path).map_err(|e| FileError::Remove {
                path: path.to_string(),
                reason: os_error(&e),
            })?;
            Ok(Stale::Removed)
        }
        _ => Ok(Stale::Absent),
    }
}

/// [`remove_stale`], with a warning on standard error when the file is kept (a regular file
/// of that name that eomgen did not write).
///
/// # Errors
/// As [`remove_stale`].
pub(super) fn remove_stale_or_warn(
    path: &str,
    is_ours: impl Fn(&[u8]) -> bool,
) -> Result<(), FileError> {
    if remove_stale(path, is_ours)? == Stale::Kept {
        super::output::errln!(
            "warning: `{path}` is not from this run and was not written by eomgen; it was kept"
        );
    }
    Ok(())
}

/// What an output option writes, which decides what its path must look like.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Format {
    /// A chart: `.svg` or `.png`, chosen by the extension.
    Chart,
    /// A file of one fixed format (CSV, HTML, GIF, JSON): any name.
    Fixed,
}

/// One planned output: the option that names it, its path and format.
#[derive(Debug, Clone)]
struct Planned {
    option: String,
    path: String,
    format: Format,
}

/// Which file a planned output is, to find two outputs that write one file.
#[derive(Debug, PartialEq, Eq)]
enum Identity {
    /// An existing file (device and inode, after symbolic links).
    Inode(u64, u64),
    /// A new file: its directory, made absolute, and its name.
    Name(PathBuf),
    /// A device, FIFO or standard stream: written in place, so two outputs there are both
    /// delivered, one after the other (`--csv /dev/null --plot-phase /dev/null`).
    Stream,
}

/// Every file this process has read as an input (a model file, under any of its names),
/// recorded where it is read ([`read_input`]): no output may replace one, whether or not the
/// command named it among its inputs ([`Outputs::check`] before the work, [`write`] at the
/// write).
static READ_INPUTS: std::sync::Mutex<Vec<(Identity, String)>> = std::sync::Mutex::new(Vec::new());

/// Records that the process reads `path` (a model file). Anything that is not a regular file
/// (a bundled model's name, a missing path) records nothing.
pub(super) fn read_input(path: &str) {
    if let Some(identity) = input_identity(path)
        && let Ok(mut inputs) = READ_INPUTS.lock()
        && !inputs.iter().any(|(i, _)| *i == identity)
    {
        inputs.push((identity, path.to_string()));
    }
}

/// The input recorded by [`read_input`] that `identity` is, as it was named.
fn input_named(identity: &Identity) -> Option<String> {
    let inputs = READ_INPUTS.lock().ok()?;
    inputs
        .iter()
        .find(|(i, _)| i == identity)
        .map(|(_, name)| name.clone())
}

/// A command's outputs, checked together before it does any work ([`Outputs::check`]), and
/// the files it reads, which no output may overwrite.
#[derive(Debug, Default)]
pub(super) struct Outputs {
    outputs: Vec<Planned>,
    inputs: Vec<String>,
}

impl Outputs {
    /// No output yet.
    pub(super) fn new() -> Self {
        Self::default()
    }

    /// Adds the output `path` of `option` (nothing when `None`), in `format`.
    #[must_use]
    pub(super) fn add(mut self, option: &str, path: Option<&str>, format: Format) -> Self {
        if let Some(path) = path {
            self.outputs.push(Planned {
                option: option.to_string(),
                path: path.to_string(),
                format,
            });
        }
        self
    }

    /// Adds a file the command reads: `name_or_path` is a model's name or its file's path. A
    /// name that is no file (a bundled model) adds nothing to check; a path that cannot be
    /// read is left to the command's own error.
    #[must_use]
    pub(super) fn input(mut self, name_or_path: &str) -> Self {
        self.inputs.push(name_or_path.to_string());
        self
    }

    /// Adds a chart (`.svg` or `.png`) of `option`.
    #[must_use]
    pub(super) fn chart(self, option: &str, path: Option<&str>) -> Self {
        self.add(option, path, Format::Chart)
    }

    /// Adds a file of fixed format of `option`.
    #[must_use]
    pub(super) fn file(self, option: &str, path: Option<&str>) -> Self {
        self.add(option, path, Format::Fixed)
    }

    /// Checks every output before the command computes anything: a chart's extension, a
    /// path that is a directory, a directory that does not exist or cannot be written (a
    /// temporary file is created there and removed), two outputs of one file, and an output
    /// that is one of the files the command reads (the same device and inode, after links).
    ///
    /// # Errors
    /// The first refused output ([`FileError`], a usage error).
    pub(super) fn check(&self) -> Result<(), FileError> {
        // A model's name that resolves to a bundled model is no file, even where a file of
        // that name exists (an earlier run's output named after the model).
        let inputs: Vec<(Identity, &str)> = self
            .inputs
            .iter()
            .filter_map(|name| match eomgen::resolve(name) {
                Ok(eomgen::Resolved::File(path)) => Some((input_identity(&path)?, name.as_str())),
                _ => None,
            })
            .collect();
        let mut seen: Vec<(Identity, &str)> = Vec::with_capacity(self.outputs.len());
        for planned in &self.outputs {
            let identity = check_one(planned)?;
            let input = inputs
                .iter()
                .find(|(i, _)| *i == identity)
                .map(|(_, input)| input.to_string())
                .or_else(|| input_named(&identity));
            if let Some(input) = input {
                return Err(FileError::InputFile {
                    option: planned.option.clone(),
                    path: planned.path.clone(),
                    input,
                });
            }
            if identity != Identity::Stream
                && let Some((_, first)) = seen.iter().find(|(i, _)| *i == identity)
            {
                return Err(FileError::SamePath {
                    first: first.to_string(),
                    second: planned.option.clone(),
                    path: planned.path.clone(),
                });
            }
            seen.push((identity, &planned.option));
        }
        Ok(())
    }
}

/// Checks one planned output and says which file it is.
fn check_one(planned: &Planned) -> Result<Identity, FileError> {
    let Planned {
        option,
        path,
        format,
    } = planned;
    let unusable = |e: io::Error| FileError::Unusable {
        option: option.clone(),
        path: path.clone(),
        reason: os_error(&e),
    };
    // `out/` names a directory: a file output would otherwise create the file `out`.
    if path.ends_with('/') {
        return Err(FileError::NoFileName {
            option: option.clone(),
            path: path.clone(),
        });
    }
    if *format == Format::Chart && !(path.ends_with(".svg") || path.ends_with(".png")) {
        return Err(FileError::ChartExtension {
            option: option.clone(),
            path: path.clone(),
        });
    }
    match resolve(path).map_err(unusable)? {
        Target::Directory => Err(FileError::Directory {
            option: option.clone(),
            path: path.clone(),
        }),
        Target::Standard(_) | Target::InPlace { .. } | Target::Descriptor(_) => {
            Ok(Identity::Stream)
        }
        Target::Regular {
            path: target,
            existing,
        } => {
            let Some(name) = target.file_name() else {
                return Err(FileError::NoFileName {
                    option: option.clone(),
                    path: path.clone(),
                });
            };
            let directory = directory_of(&target);
            if !directory.is_dir() {
                return Err(FileError::NoDirectory {
                    option: option.clone(),
                    path: path.clone(),
                    directory: directory.display().to_string(),
                });
            }
            // Where the file will be renamed into place: it must take a new file.
            tempfile::Builder::new()
                .prefix(".eomgen-")
                .tempfile_in(directory)
                .map_err(unusable)?;
            Ok(match existing.as_ref().and_then(inode) {
                Some((device, inode)) => Identity::Inode(device, inode),
                None => {
                    let absolute = fs::canonicalize(directory).map_err(unusable)?;
                    Identity::Name(absolute.join(name))
                }
            })
        }
    }
}

/// Which file the input `path` is: an existing regular file (after symbolic links), by device
/// and inode, or by canonical name where there are no inodes; `None` for anything else.
fn input_identity(path: &str) -> Option<Identity> {
    let metadata = fs::metadata(path).ok().filter(Metadata::is_file)?;
    match inode(&metadata) {
        Some((device, inode)) => Some(Identity::Inode(device, inode)),
        None => fs::canonicalize(path).ok().map(Identity::Name),
    }
}

/// The device and inode of a file.
#[cfg(unix)]
fn inode(metadata: &Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt as _;
    Some((metadata.dev(), metadata.ino()))
}

#[cfg(not(unix))]
fn inode(_: &Metadata) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A directory found in the way when the file is written (after the check before the
    /// work) is a failed write naming the file, status 1, not a usage error.
    #[test]
    fn a_directory_in_the_way_at_write_time_is_a_failed_write() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("index.html");
        std::fs::create_dir(&path).unwrap();
        let path = path.to_string_lossy().into_owned();
        let error = write(&path, b"x").unwrap_err();
        assert!(
            matches!(&error, FileError::Write { path: p, .. } if *p == path),
            "{error:?}"
        );
        assert_eq!(CliError::from(error).code, 1);
    }

    /// A file the process has read is never replaced by a write, under any of its names (a
    /// link to it here), even where no command named it before the work; another file is.
    #[test]
    fn a_file_read_as_an_input_is_never_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model.yaml");
        std::fs::write(&model, "name: m\n").unwrap();
        let link = dir.path().join("chart.svg");
        std::os::unix::fs::symlink(&model, &link).unwrap();
        read_input(&model.to_string_lossy());
        let error = write(&link.to_string_lossy(), b"<svg/>").unwrap_err();
        assert!(
            matches!(&error, FileError::Write { reason, .. } if reason.contains("model file")),
            "{error:?}"
        );
        assert_eq!(CliError::from(error).code, 1);
        assert_eq!(std::fs::read_to_string(&model).unwrap(), "name: m\n");
        let other = dir.path().join("other.svg");
        write(&other.to_string_lossy(), b"<svg/>").unwrap();
        assert_eq!(std::fs::read_to_string(&other).unwrap(), "<svg/>");
    }

    /// Exactly `/dev/fd/N` and `/proc/<pid>/fd/N` name descriptors; other paths under
    /// `/proc` are ordinary.
    #[test]
    fn only_descriptor_paths_are_descriptors() {
        let own = format!("/proc/{}/fd/4", std::process::id());
        for (path, kind) in [
            ("/dev/fd/3", Some(FdPath::Own(3))),
            ("/proc/self/fd/12", Some(FdPath::Own(12))),
            ("/proc/thread-self/fd/0", Some(FdPath::Own(0))),
            (own.as_str(), Some(FdPath::Own(4))),
            ("/proc/1/fd/3", Some(FdPath::Other)),
            ("/proc/self/cwd/out.csv", None),
            ("/proc/self/root/tmp/x.csv", None),
            ("/proc/self/fd/3/", None),
            ("/proc/self/fd/../fd/3", None),
            ("/dev/fd/", None),
            ("/dev/fd/-1", None),
            ("/dev/fd/3x", None),
            ("/dev/fd/99999999999", None),
        ] {
            assert_eq!(fd_path(path), kind, "{path}");
        }
    }
}
