//! The command line before clap reads it: negative numbers and values that start with `-`
//! reach the options' own checks instead of clap's "unexpected argument".

/// `command` and all its subcommands with negative numbers allowed as values: `--t-end -1`
/// then reaches the option's own check ("must be positive") instead of clap's "unexpected
/// argument '-1'" (clap takes a value that starts with `-` for an option otherwise).
pub(super) fn allow_negative_numbers(command: clap::Command) -> clap::Command {
    let names: Vec<String> = command
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    names
        .iter()
        .fold(command.allow_negative_numbers(true), |command, name| {
            command.mut_subcommand(name, allow_negative_numbers)
        })
}

/// `args` with `--option VALUE` written `--option=VALUE` where `VALUE` starts with `-` but is
/// no option of the command (`--t-end -inf`, `--freqs -1..10`, `--at -pi/2`): clap takes
/// such a value for an unknown option otherwise ("unexpected argument '-inf'"), and only
/// plain negative numbers pass its `allow_negative_numbers`. The value then reaches the
/// option's own check. An option of the command after another (`--csv --json`) stays an
/// option, so a missing value is still reported as missing, and so does any word that
/// starts with `--` (`--csv --plot-phse`): no value starts with `--`, and a mistyped option
/// must be reported, not taken for a file name.
pub(super) fn join_hyphen_values(
    command: &clap::Command,
    args: Vec<std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut current = command;
    let mut out = Vec::with_capacity(args.len());
    let mut rest = args.into_iter();
    if let Some(program) = rest.next() {
        out.push(program);
    }
    while let Some(arg) = rest.next() {
        let Some(text) = arg.to_str().map(str::to_string) else {
            out.push(arg);
            continue;
        };
        if text == "--" {
            // Everything after `--` is a positional value already.
            out.push(arg);
            out.extend(rest);
            break;
        }
        if let Some(sub) = current.find_subcommand(&text) {
            current = sub;
            out.push(arg);
            continue;
        }
        let takes_one_value = |a: &clap::Arg| {
            a.get_action().takes_values() && a.get_num_args().is_none_or(|n| n.max_values() == 1)
        };
        let option = if let Some(long) = text.strip_prefix("--") {
            current
                .get_arguments()
                .find(|a| a.get_long() == Some(long) && takes_one_value(a))
        } else if let Some(short) = text.strip_prefix('-').filter(|s| s.chars().count() == 1) {
            current
                .get_arguments()
                .find(|a| a.get_short() == short.chars().next() && takes_one_value(a))
        } else {
            None
        };
        let Some(option) = option else {
            out.push(arg);
            continue;
        };
        let Some(value) = rest.next() else {
            out.push(arg);
            break;
        };
        match value.to_str() {
            Some(v)
                if v.starts_with('-')
                    && !v.starts_with("--")
                    && v != "-"
                    && !is_option_of(current, v) =>
            {
                let name = option.get_long().map_or_else(
                    || format!("-{}", option.get_short().unwrap_or_default()),
                    |long| format!("--{long}"),
                );
                out.push(format!("{name}={v}").into());
            }
            _ => {
                out.push(arg);
                out.push(value);
            }
        }
    }
    out
}

/// Whether `text` (which starts with `-`) is an option of `command`: `--name`, `--name=…`,
/// exactly `-x` for one of its short names, `--help`, `-h`, `--version`, `-V`, or `--`. A
/// longer word with one dash is a value, even when it starts with a short name's letter: an
/// expression such as `-height + q` or `-omega` (`--stop-when`), not `-h` and `eight + q`.
fn is_option_of(command: &clap::Command, text: &str) -> bool {
    if let Some(long) = text.strip_prefix("--") {
        let name = long.split_once('=').map_or(long, |(name, _)| name);
        name.is_empty()
            || matches!(name, "help" | "version")
            || command.get_arguments().any(|a| a.get_long() == Some(name))
    } else {
        let mut rest = text[1..].chars();
        let short = rest.next();
        if rest.next().is_some() {
            return false;
        }
        matches!(short, Some('h' | 'V'))
            || command
                .get_arguments()
                .any(|a| a.get_short().is_some() && a.get_short() == short)
    }
}
