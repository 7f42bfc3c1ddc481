//! Rendering shared by the commands: what more than one command prints or writes the same way.
//!
//! Only presentation lives here (no numerics): the commands call the library for results and
//! render them with these. Numbers and HTML escaping are the library's
//! ([`eomgen::text`]), which the animation page and the report's rows share.

pub(super) use eomgen::text::{escape, num};

/// A progress bar on standard error, `len` steps drawn with the indicatif `template`
/// (`{msg}` is `message`), or a hidden one when `quiet` (a `--json` run) or when standard
/// error is not a terminal: scripts, pipes and tests see nothing.
pub(super) fn progress_bar(
    len: usize,
    template: &str,
    message: &'static str,
    quiet: bool,
) -> indicatif::ProgressBar {
    use std::io::IsTerminal as _;
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .map(|style| style.progress_chars("=> "))
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(message);
    bar
}
