//! `--stop-when` and `--event` of `eomgen simulate` (issue 6, item 2; lecture 17, HW21,
//! HW36): event functions given on the command line, parsed once and evaluated at run time on
//! the states the integrator offers, beside the model file's own `events:`.

use eomgen::{EventDirection, EventSpec, ModelInfo, RhsError};
use eomgen_symbolic::model::parser::{closest, eval_expr, identifiers, parse_expr};
use eomgen_symbolic::model::{BinOp, Expr, ExprKind, Location};

use super::CliError;

/// Where a name in a command-line event function takes its value from.
#[derive(Debug, Clone, Copy)]
enum Source {
    /// Parameter `i` (its value when the run starts).
    Parameter(f64),
    /// `y[i]`: a coordinate or a rate.
    State(usize),
    /// `q̈[i]`.
    Acceleration(usize),
    /// `λ[i]`.
    Multiplier(usize),
    /// `t`.
    Time,
}

/// One event function from the command line.
#[derive(Debug)]
pub struct CliEvent {
    spec: EventSpec,
    function: Expr,
    names: Vec<(String, Source)>,
}

/// The command-line events of one run, evaluated together.
#[derive(Debug)]
pub struct CliEvents {
    events: Vec<CliEvent>,
    needs_accelerations: bool,
    needs_multipliers: bool,
    /// Scratch: `ẏ` (for `q̈`).
    dy: Vec<f64>,
}

impl CliEvents {
    /// Parses `--stop-when` (terminal) and `--event` (not terminal) arguments for `model`. An
    /// argument that names one of the model's own events makes it terminal (or leaves it as
    /// is) instead of adding one.
    ///
    /// Syntax: `EXPR`, `LHS = RHS` (the function is `LHS − RHS`), either followed by
    /// `, rising`, `, falling` or `, both` (default). Names: parameters, coordinates, `t`,
    /// rates `x_dot`, accelerations `x_ddot`, constraint forces `lambda_<constraint>`, `pi`.
    ///
    /// # Errors
    /// A usage error naming the argument, the column and what would be right.
    pub fn parse(
        model: &mut dyn ModelInfo,
        stop_when: &[String],
        event: &[String],
    ) -> Result<Self, CliError> {
        let mut events = Vec::new();
        let args = stop_when
            .iter()
            .map(|a| (a, true, "--stop-when"))
            .chain(event.iter().map(|a| (a, false, "--event")));
        for (k, (text, terminal, option)) in args.enumerate() {
            let trimmed = text.trim();
            let own = model.event_specs().iter().any(|e| e.name == trimmed);
            if own {
                if terminal {
                    model.set_event_terminal(trimmed, true);
                }
                continue;
            }
            events.push(parse_one(model, text, option, terminal, k)?);
        }
        let uses =
            |pred: fn(&Source) -> bool| events.iter().any(|e| e.names.iter().any(|(_, s)| pred(s)));
        let needs_multipliers = uses(|s| matches!(s, Source::Multiplier(_)));
        let needs_accelerations = uses(|s| matches!(s, Source::Acceleration(_)));
        Ok(Self {
            events,
            needs_accelerations,
            needs_multipliers,
            dy: vec![0.0; 2 * model.num_dofs()],
        })
    }

    /// The specs of the added events, in argument order (`--stop-when` first).
    pub fn specs(&self) -> Vec<EventSpec> {
        self.events.iter().map(|e| e.spec.clone()).collect()
    }

    /// Whether there is nothing to add.
    pub fn is_empty(&self) -> bool {
        self.events.is_empty()
    }

    /// The added functions at `(t, y)` into `g`.
    ///
    /// # Errors
    /// As the right-hand side, when `q̈` or `λ` is needed and cannot be solved for.
    pub fn values(
        &mut self,
        model: &mut dyn ModelInfo,
        t: f64,
        y: &[f64],
        g: &mut [f64],
    ) -> Result<(), RhsError> {
        if self.needs_accelerations {
            model.rhs(t, y, &mut self.dy)?;
        }
        let lambda = if self.needs_multipliers {
            model.constraint_forces(t, y)?
        } else {
            Vec::new()
        };
        let n = self.dy.len() / 2;
        for (event, out) in self.events.iter().zip(g.iter_mut()) {
            let lookup = |name: &str| {
                let (_, source) = event.names.iter().find(|(n, _)| n == name)?;
                Some(match *source {
                    Source::Parameter(v) => v,
                    Source::State(i) => y[i],
                    Source::Acceleration(i) => self.dy[n + i],
                    Source::Multiplier(i) => lambda.get(i).copied().unwrap_or(f64::NAN),
                    Source::Time => t,
                })
            };
            // Every name was resolved when parsing, so the only failure left is NaN.
            *out = eval_expr(&event.function, &lookup).unwrap_or(f64::NAN);
        }
        Ok(())
    }
}

/// Parses one `EXPR[, direction]` argument.
fn parse_one(
    model: &dyn ModelInfo,
    text: &str,
    option: &str,
    terminal: bool,
    k: usize,
) -> Result<CliEvent, CliError> {
    let (body, direction) = match text.rsplit_once(',') {
        Some((body, word)) => {
            let word = word.trim();
            let direction = EventDirection::from_name(word).ok_or_else(|| {
                CliError::usage(format!(
                    "{option} `{text}`: the direction after the comma must be rising, falling or both, found `{word}`"
                ))
            })?;
            (body, direction)
        }
        None => (text, EventDirection::Both),
    };
    let at = Location { line: 1, column: 1 };
    let parse = |part: &str, offset: usize| {
        parse_expr(part, at.offset(offset)).map_err(|d| {
            CliError::usage(format!(
                "{option} `{text}`: column {}: {}{}",
                d.location.column,
                d.message,
                d.help.map(|h| format!(" ({h})")).unwrap_or_default()
            ))
        })
    };
    let function = match body.split_once('=') {
        Some((lhs, rhs)) => {
            let (l, r) = (parse(lhs, 0)?, parse(rhs, lhs.chars().count() + 1)?);
            Expr {
                location: l.location,
                kind: ExprKind::Binary {
                    op: BinOp::Sub,
                    lhs: Box::new(l),
                    rhs: Box::new(r),
                },
            }
        }
        None => parse(body, 0)?,
    };
    let names = resolve(model, &function, text, option)?;
    let name = if terminal {
        format!("stop_when_{}", k + 1)
    } else {
        format!("event_{}", k + 1)
    };
    Ok(CliEvent {
        spec: EventSpec::new(name, direction, terminal),
        function,
        names,
    })
}

/// The source of every name in `function`, or a usage error with a suggestion.
fn resolve(
    model: &dyn ModelInfo,
    function: &Expr,
    text: &str,
    option: &str,
) -> Result<Vec<(String, Source)>, CliError> {
    let n = model.num_dofs();
    let mut known: Vec<(String, Source)> = Vec::new();
    for (name, value) in model.parameter_names().iter().zip(model.parameter_values()) {
        known.push((name.to_string(), Source::Parameter(value)));
    }
    for (i, c) in model.coordinate_names().iter().enumerate() {
        known.push((c.to_string(), Source::State(i)));
        known.push((format!("{c}_dot"), Source::State(n + i)));
        known.push((format!("{c}_ddot"), Source::Acceleration(i)));
    }
    for (i, c) in model.constraint_names().iter().enumerate() {
        known.push((format!("lambda_{c}"), Source::Multiplier(i)));
    }
    known.push(("t".to_string(), Source::Time));
    let mut ids = Vec::new();
    identifiers(function, &mut ids);
    let mut names = Vec::new();
    for (id, at) in ids {
        if id == "pi" || names.iter().any(|(n, _)| *n == id) {
            continue;
        }
        match known.iter().find(|(n, _)| *n == id) {
            Some(entry) => names.push(entry.clone()),
            None => {
                let candidates: Vec<&str> = known.iter().map(|(n, _)| n.as_str()).collect();
                let hint = match closest(&id, &candidates) {
                    Some(c) => format!("did you mean `{c}`?"),
                    None => format!("names here are: {}, pi", candidates.join(", ")),
                };
                return Err(CliError::usage(format!(
                    "{option} `{text}`: column {}: unknown name `{id}` for model `{}`; {hint}",
                    at.column,
                    model.name()
                )));
            }
        }
    }
    Ok(names)
}
