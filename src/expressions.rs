//! Expressions given beside a model (the CLI's `--set`, `--init`, `--t-out`, `--stop-when`
//! and `--event`), parsed by the model file's own expression parser and evaluated against a
//! model: parameter assignments, initial values, and event functions added to a simulation.
//!
//! Syntax: the model file's expressions (numbers, `pi`, `+ - * / ^`, the functions of the
//! model format); see `docs/model-format.md`.

use eomgen_runtime::analysis::AddedEvents;
use eomgen_runtime::analysis::vibration::Forcing;
use eomgen_runtime::{EventDirection, EventSpec, ModelInfo, RhsError, UnknownParameter};
use eomgen_symbolic::model::parser::{closest, eval_expr, identifiers, parse_expr};
use eomgen_symbolic::model::{BinOp, Expr, ExprKind, Location};

/// An expression or assignment that could not be used. Each message starts with `what` (the
/// option or context the text came from, e.g. `--set k`) and says what would be right.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExpressionError {
    /// The text does not parse as an expression.
    #[error("{what}: `{text}` is not an expression (column {column}): {message}")]
    Syntax {
        /// Where the text came from.
        what: String,
        /// The text.
        text: String,
        /// 1-based column of the mistake.
        column: u32,
        /// What is wrong.
        message: String,
    },
    /// The expression names something unknown or cannot be evaluated.
    #[error("{what}: {message} in `{text}`")]
    Evaluation {
        /// Where the text came from.
        what: String,
        /// The text.
        text: String,
        /// What is wrong.
        message: String,
    },
    /// The value is infinite or NaN.
    #[error("{what}: `{text}` evaluates to {value}, not a finite number")]
    NotFinite {
        /// Where the text came from.
        what: String,
        /// The text.
        text: String,
        /// The value.
        value: f64,
    },
    /// An assignment without `NAME=VALUE` form.
    #[error("{option} takes NAME=VALUE, got `{text}` (for example `{option} theta1=pi/2`)")]
    NotAnAssignment {
        /// The option (`--set`).
        option: String,
        /// The text.
        text: String,
    },
    /// A parameter the model does not have.
    #[error(transparent)]
    UnknownParameter(#[from] UnknownParameter),
    /// Parameter values at which a body is not a physical one (a mass ≤ 0, an inertia that
    /// is not positive definite or breaks `I₃ ≤ I₁ + I₂`): the rules the model file's
    /// defaults are held to ([`check_bodies`]).
    #[error("{set}: {problem} with these values")]
    Unphysical {
        /// The assignments that led there (`--set l=1`).
        set: String,
        /// What is wrong, as the model file's check says it.
        problem: String,
    },
    /// An initial value for a name that is neither a coordinate nor a rate.
    #[error(
        "{option} {name}: `{model}` has no coordinate or rate `{name}` (coordinates: {coordinates}; {rates})"
    )]
    UnknownCoordinate {
        /// The option (`--init`).
        option: String,
        /// The name given.
        name: String,
        /// The model's name.
        model: String,
        /// The coordinates, comma separated.
        coordinates: String,
        /// The state's second half with its label: `rates: x_dot, …`, or `speeds: u, …` (a
        /// model in generalized speeds, whose state holds them rather than the rates).
        rates: String,
    },
    /// An event's direction that is none of rising, falling, both.
    #[error(
        "{option} `{text}`: the direction after the comma must be rising, falling or both, found `{word}`"
    )]
    EventDirection {
        /// The option (`--stop-when`).
        option: String,
        /// The whole argument.
        text: String,
        /// The word after the comma.
        word: String,
    },
    /// An event function that does not parse.
    #[error("{option} `{text}`: column {column}: {message}{}", help.as_ref().map(|h| format!(" ({h})")).unwrap_or_default())]
    EventSyntax {
        /// The option.
        option: String,
        /// The whole argument.
        text: String,
        /// 1-based column of the mistake.
        column: u32,
        /// What is wrong.
        message: String,
        /// What would be right, if known.
        help: Option<String>,
    },
    /// A name in an event function that the model does not have.
    #[error(
        "{option} `{text}`: column {column}: unknown name `{name}` for model `{model}`; {hint}"
    )]
    EventUnknownName {
        /// The option.
        option: String,
        /// The whole argument.
        text: String,
        /// 1-based column of the name.
        column: u32,
        /// The unknown name.
        name: String,
        /// The model's name.
        model: String,
        /// The closest known name, or every known name.
        hint: String,
    },
}

/// Evaluates `text` as an expression in which names are looked up with `lookup` (`pi` is
/// known); `what` names where the text came from, for the error.
///
/// # Errors
/// [`ExpressionError::Syntax`], [`ExpressionError::Evaluation`] (an unknown name) or
/// [`ExpressionError::NotFinite`].
///
/// # Examples
/// ```
/// let v = eomgen::expressions::evaluate("2*pi/4", "--t-out", &|_| None).unwrap();
/// assert_eq!(v, std::f64::consts::PI / 2.0);
/// assert!(eomgen::expressions::evaluate("1/0", "--t-out", &|_| None).is_err());
/// ```
pub fn evaluate(
    text: &str,
    what: &str,
    lookup: &dyn Fn(&str) -> Option<f64>,
) -> Result<f64, ExpressionError> {
    let start = Location { line: 1, column: 1 };
    let expr = parse_expr(text, start).map_err(|d| ExpressionError::Syntax {
        what: what.to_string(),
        text: text.to_string(),
        column: d.location.column,
        message: d.message.clone(),
    })?;
    let v = eval_expr(&expr, lookup).map_err(|d| ExpressionError::Evaluation {
        what: what.to_string(),
        text: text.to_string(),
        message: d.message.clone(),
    })?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ExpressionError::NotFinite {
            what: what.to_string(),
            text: text.to_string(),
            value: v,
        })
    }
}

/// Splits `NAME=VALUE` into its trimmed halves; `option` names the option for the error.
///
/// # Errors
/// [`ExpressionError::NotAnAssignment`] when either half is empty or there is no `=`.
pub fn split_assignment<'a>(
    text: &'a str,
    option: &str,
) -> Result<(&'a str, &'a str), ExpressionError> {
    text.split_once('=')
        .map(|(n, v)| (n.trim(), v.trim()))
        .filter(|(n, v)| !n.is_empty() && !v.is_empty())
        .ok_or_else(|| ExpressionError::NotAnAssignment {
            option: option.to_string(),
            text: text.to_string(),
        })
}

/// Looks up `model`'s current parameter values by name (for expressions beside a model).
pub fn parameter_lookup(model: &dyn ModelInfo) -> impl Fn(&str) -> Option<f64> + '_ {
    let names = model.description().parameter_names();
    let values = model.parameter_values();
    move |n: &str| names.iter().position(|p| *p == n).map(|i| values[i])
}

/// Applies `NAME=VALUE` parameter assignments in order (a value may use the parameters set
/// before it), as `--set` does.
///
/// # Errors
/// [`ExpressionError::NotAnAssignment`], an error of [`evaluate`], or
/// [`ExpressionError::UnknownParameter`].
///
/// # Examples
/// ```
/// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// eomgen::expressions::set_parameters(model.as_mut(), &["g=9.81", "l=g/pi^2"]).unwrap();
/// let l = model.parameter_values()[1];
/// assert_eq!(l, 9.81 / std::f64::consts::PI.powi(2));
/// ```
pub fn set_parameters(
    model: &mut dyn ModelInfo,
    assignments: &[impl AsRef<str>],
) -> Result<(), ExpressionError> {
    for s in assignments {
        let (name, text) = split_assignment(s.as_ref(), "--set")?;
        let value = evaluate(text, &format!("--set {name}"), &parameter_lookup(model))?;
        model.set_parameter(name, value)?;
    }
    if !assignments.is_empty() {
        check_bodies(model).map_err(|problem| ExpressionError::Unphysical {
            set: assignments
                .iter()
                .map(|s| format!("--set {}", s.as_ref()))
                .collect::<Vec<_>>()
                .join(" "),
            problem,
        })?;
    }
    Ok(())
}

/// Holds `model`'s bodies at its current parameter values to the rules a model file's
/// defaults are held to when it is loaded (`eomgen_symbolic::model::rules`): every mass
/// positive, every planar moment of inertia ≥ 0, every 3-D inertia tensor finite, positive
/// definite and within the triangle inequality `I₃ ≤ I₁ + I₂` (to 0.1 %). Applied after
/// parameters are set (`--set`, and the Python package's parameters), once all are set, so
/// that a value may pass through an impossible body on the way (`I1`, then `I3`). A body
/// whose mass or inertia depends on more than the parameters is not judged here.
///
/// # Errors
/// The first problem, in the words of the model file's check (`the inertia of body `top` is
/// not positive definite: [[-0.98, 0, 0], …] kg·m²`).
pub fn check_bodies(model: &dyn ModelInfo) -> Result<(), String> {
    use eomgen_symbolic::model::rules::{
        InertiaProblem, inertia_problem, mass_problem, planar_inertia_problem,
    };
    let lookup = parameter_lookup(model);
    // A value that is not finite is judged (a NaN mass is not positive); an expression of
    // more than the parameters is not.
    let value = |text: &str| match evaluate(text, "", &lookup) {
        Ok(v) => Some(v),
        Err(ExpressionError::NotFinite { value, .. }) => Some(value),
        Err(_) => None,
    };
    for body in model.description().body_centres.iter() {
        let name = &*body.body;
        if let Some(problem) = value(&body.mass).and_then(|m| mass_problem(name, m)) {
            return Err(problem);
        }
        let inertia: Option<Vec<f64>> = body.inertia.iter().map(|i| value(i)).collect();
        match inertia.as_deref() {
            Some(&[i]) => {
                if let Some(problem) = planar_inertia_problem(name, i) {
                    return Err(problem);
                }
            }
            Some(&[xx, yy, zz, xy, yz, xz]) => {
                if let Some(
                    InertiaProblem::NotPositiveDefinite(problem)
                    | InertiaProblem::NotARigidBody(problem),
                ) = inertia_problem(name, [xx, yy, zz, xy, yz, xz])
                {
                    return Err(problem);
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The items of a comma list of assignments, `q=0.1,q_dot=atan2(1, 2)` → `["q=0.1",
/// "q_dot=atan2(1, 2)"]`: split at the commas outside parentheses (a function's arguments stay
/// together), each item trimmed; empty items are dropped.
///
/// # Examples
/// ```
/// let items = eomgen::expressions::split_list("q=0.1, q_dot=atan2(1, 2)");
/// assert_eq!(items, ["q=0.1", "q_dot=atan2(1, 2)"]);
/// ```
pub fn split_list(list: &str) -> Vec<&str> {
    let mut items = Vec::new();
    let (mut depth, mut start) = (0usize, 0);
    for (i, c) in list.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            ',' if depth == 0 => {
                items.push(&list[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&list[start..]);
    items
        .into_iter()
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect()
}

/// Applies `NAME=VALUE` initial values (`theta1=pi/2`, `theta1_dot=0`; values may use the
/// parameters) to the state `y = [q; q̇]` of `model`, as `--init` does. Each item may be a
/// comma list, `q=0.1,q_dot=0` (split by [`split_list`]), as `--at` takes.
///
/// # Shapes
/// `y` has `2n` entries, `n = model.num_dofs()`.
///
/// # Errors
/// [`ExpressionError::NotAnAssignment`], an error of [`evaluate`], or
/// [`ExpressionError::UnknownCoordinate`].
///
/// # Examples
/// ```
/// let model = (eomgen::models::find("simple_pendulum").unwrap().make)();
/// let mut y = model.initial_state();
/// eomgen::expressions::set_initial_values(model.as_ref(), &mut y, &["q=pi/6", "q_dot=1"]).unwrap();
/// assert_eq!(y, [std::f64::consts::PI / 6.0, 1.0]);
/// eomgen::expressions::set_initial_values(model.as_ref(), &mut y, &["q=atan2(1, 1),q_dot=0"]).unwrap();
/// assert_eq!(y, [std::f64::consts::PI / 4.0, 0.0]);
/// ```
pub fn set_initial_values(
    model: &dyn ModelInfo,
    y: &mut [f64],
    assignments: &[impl AsRef<str>],
) -> Result<(), ExpressionError> {
    let description = model.description();
    let names: Vec<String> = (0..2 * model.num_dofs())
        .map(|i| description.state_name(i))
        .collect();
    set_named_values(model, y, assignments, &names)
}

/// Applies `NAME=VALUE` values, as [`set_initial_values`], to `y = [δq; δq̇]` of a
/// linearisation of `model`, which is in the coordinates and their rates (`x_dot`) whether or
/// not the model is in generalized speeds.
///
/// # Errors
/// As [`set_initial_values`].
pub fn set_linearized_values(
    model: &dyn ModelInfo,
    y: &mut [f64],
    assignments: &[impl AsRef<str>],
) -> Result<(), ExpressionError> {
    let coordinates = model.description().coordinate_names();
    let names: Vec<String> = (coordinates.iter().map(|c| c.to_string()))
        .chain(coordinates.iter().map(|c| format!("{c}_dot")))
        .collect();
    set_named_values(model, y, assignments, &names)
}

/// Applies `NAME=VALUE` values to the entries of `y` named `names` (`2n`: coordinates, then
/// the second half).
fn set_named_values(
    model: &dyn ModelInfo,
    y: &mut [f64],
    assignments: &[impl AsRef<str>],
    names: &[String],
) -> Result<(), ExpressionError> {
    let n = model.num_dofs();
    let coordinates = model.description().coordinate_names();
    for s in assignments.iter().flat_map(|s| split_list(s.as_ref())) {
        let (name, text) = split_assignment(s, "--init")?;
        let value = evaluate(text, &format!("--init {name}"), &parameter_lookup(model))?;
        let index = names.iter().position(|x| x == name).ok_or_else(|| {
            let second = &names[n..];
            // The speeds of a model in generalized speeds, unless the names are a
            // linearisation's rates (`x_dot`).
            let speeds = model.description().has_speeds()
                && !(second.iter().zip(&coordinates)).all(|(r, c)| *r == format!("{c}_dot"));
            let label = if speeds { "speeds" } else { "rates" };
            ExpressionError::UnknownCoordinate {
                option: "--init".to_string(),
                name: name.to_string(),
                model: model.description().name.to_string(),
                coordinates: coordinates.join(", "),
                rates: format!("{label}: {}", second.join(", ")),
            }
        })?;
        y[index] = value;
    }
    Ok(())
}

/// Where a name in an added event function takes its value from.
#[derive(Debug, Clone, Copy)]
enum Source {
    /// A parameter (its value when the run starts).
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

/// One added event function.
#[derive(Debug)]
struct ExpressionEvent {
    spec: EventSpec,
    function: Expr,
    names: Vec<(String, Source)>,
}

/// Event functions written as expressions (issue 6, item 2; lecture 17, HW21, HW36): the
/// CLI's `--stop-when` and `--event`, parsed once and evaluated on the states the integrator
/// offers, beside the model file's own `events:`. Pass them to
/// [`simulate_with_events`](eomgen_runtime::analysis::simulate_with_events).
#[derive(Debug)]
pub struct ExpressionEvents {
    events: Vec<ExpressionEvent>,
    needs_accelerations: bool,
    needs_multipliers: bool,
    /// Scratch: `ẏ` (for `q̈`).
    dy: Vec<f64>,
}

impl ExpressionEvents {
    /// Parses terminal (`stop_when`, named `stop_when_K`) and non-terminal (`event`, named
    /// `event_K`, K counting from 1 over both lists) event functions for `model`. An
    /// argument that names one of the model's own events makes it terminal (or leaves it as
    /// is) instead of adding one — this changes `model`.
    ///
    /// Syntax: `EXPR`, `LHS = RHS` (the function is `LHS − RHS`), either followed by
    /// `, rising`, `, falling` or `, both` (default). Names: parameters, coordinates, `t`,
    /// rates `x_dot`, accelerations `x_ddot`, constraint forces `lambda_<constraint>`, `pi`.
    ///
    /// # Errors
    /// [`ExpressionError::EventDirection`], [`ExpressionError::EventSyntax`] or
    /// [`ExpressionError::EventUnknownName`], naming the argument, the column and what would
    /// be right.
    ///
    /// # Examples
    /// ```
    /// use eomgen::analysis::{SimulationOptions, simulate_with_events};
    /// use eomgen::expressions::ExpressionEvents;
    ///
    /// let mut model = (eomgen::models::find("simple_pendulum").unwrap().make)();
    /// let mut events = ExpressionEvents::parse(model.as_mut(), &["q_dot = 0, falling"], &[] as &[&str])?;
    /// let options = SimulationOptions { initial_state: Some(vec![0.5, 0.0]), ..Default::default() };
    /// let run = simulate_with_events(model.as_mut(), &options, Some(&mut events)).unwrap();
    /// let stop = &run.solution.events[run.solution.terminated_by_event.unwrap()];
    /// assert_eq!(stop.name, "stop_when_1");
    /// # Ok::<(), eomgen::expressions::ExpressionError>(())
    /// ```
    pub fn parse(
        model: &mut dyn ModelInfo,
        stop_when: &[impl AsRef<str>],
        event: &[impl AsRef<str>],
    ) -> Result<Self, ExpressionError> {
        let mut events = Vec::new();
        let args = stop_when
            .iter()
            .map(|a| (a.as_ref(), true, "--stop-when"))
            .chain(event.iter().map(|a| (a.as_ref(), false, "--event")));
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

    /// Whether there is nothing to add.
    pub fn is_empty(&self) -> bool {
        self.events.is_empty()
    }
}

impl AddedEvents for ExpressionEvents {
    /// The specs of the added events, in argument order (the terminal ones first).
    fn specs(&self) -> Vec<EventSpec> {
        self.events.iter().map(|e| e.spec.clone()).collect()
    }

    /// The added functions at `(t, y)` into `g`.
    ///
    /// # Errors
    /// As the right-hand side, when `q̈` or `λ` is needed and cannot be solved for.
    fn values(
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
) -> Result<ExpressionEvent, ExpressionError> {
    let (body, direction) = match text.rsplit_once(',') {
        Some((body, word)) => {
            let word = word.trim();
            let direction =
                EventDirection::from_name(word).ok_or_else(|| ExpressionError::EventDirection {
                    option: option.to_string(),
                    text: text.to_string(),
                    word: word.to_string(),
                })?;
            (body, direction)
        }
        None => (text, EventDirection::Both),
    };
    let at = Location { line: 1, column: 1 };
    let parse = |part: &str, offset: usize| {
        parse_expr(part, at.offset(offset)).map_err(|d| ExpressionError::EventSyntax {
            option: option.to_string(),
            text: text.to_string(),
            column: d.location.column,
            message: d.message.clone(),
            help: d.help.clone(),
        })
    };
    let function = match body.split_once('=') {
        Some((lhs, rhs)) => {
            let (l, r) = (parse(lhs, 0)?, parse(rhs, lhs.chars().count() + 1)?);
            Expr {
                location: l.location,
                kind: ExprKind::Binary {
                    op: BinOp::Sub,
                    op_location: r.location,
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
    Ok(ExpressionEvent {
        spec: EventSpec::new(name, direction, terminal),
        function,
        names,
    })
}

/// The source of every name in `function`, or an error with a suggestion.
fn resolve(
    model: &dyn ModelInfo,
    function: &Expr,
    text: &str,
    option: &str,
) -> Result<Vec<(String, Source)>, ExpressionError> {
    let n = model.num_dofs();
    let mut known: Vec<(String, Source)> = Vec::new();
    for (name, value) in model
        .description()
        .parameter_names()
        .iter()
        .zip(model.parameter_values())
    {
        known.push((name.to_string(), Source::Parameter(value)));
    }
    for (i, c) in model.description().coordinate_names().iter().enumerate() {
        known.push((c.to_string(), Source::State(i)));
        known.push((model.description().state_name(n + i), Source::State(n + i)));
        // In generalized speeds the accelerations solved for are the speeds' rates `u̇`,
        // not `q̈`: no `x_ddot` there.
        if !model.description().has_speeds() {
            known.push((format!("{c}_ddot"), Source::Acceleration(i)));
        }
    }
    for (i, c) in model.description().constraint_names().iter().enumerate() {
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
                return Err(ExpressionError::EventUnknownName {
                    option: option.to_string(),
                    text: text.to_string(),
                    column: at.column,
                    name: id,
                    model: model.description().name.to_string(),
                    hint,
                });
            }
        }
    }
    Ok(names)
}

/// A function of time given as text beside a model (`study convolution --forcing`, the Python
/// package's `Model.convolution`): an expression of `t` and the model's parameters (at their
/// values when it was parsed), or one of the names `impulse` and `step`, which the caller
/// handles and for which [`TimeFunction::value`] is 0.
#[derive(Debug, Clone)]
pub struct TimeFunction {
    /// The trimmed text.
    text: String,
    /// The expression; `None` for `impulse` and `step`.
    expression: Option<Expr>,
    /// The parameters' names and values.
    parameters: Vec<(String, f64)>,
}

impl TimeFunction {
    /// Parses `text` against `model`'s parameters and evaluates it once at `t = 0`, so that an
    /// unknown name is found here; `what` names where the text came from in the errors
    /// (`--forcing`).
    ///
    /// # Errors
    /// [`ExpressionError::Syntax`] when the text does not parse, and
    /// [`ExpressionError::Evaluation`] when it names something other than `t` and the
    /// parameters (the message lists them). A value that is not finite at some `t` is for
    /// the caller to refuse, where it is used.
    ///
    /// # Examples
    /// ```
    /// use eomgen::expressions::TimeFunction;
    /// let model = (eomgen::models::find("forced_oscillator").unwrap().make)();
    /// let f = TimeFunction::parse("k*sin(2*t)", "--forcing", model.as_ref()).unwrap();
    /// assert!((f.value(0.25).unwrap() - model.parameter_values()[1] * 0.5f64.sin()).abs() < 1e-15);
    /// assert!(TimeFunction::parse("sin(2*s)", "--forcing", model.as_ref()).is_err());
    /// assert_eq!(TimeFunction::parse(" step ", "--forcing", model.as_ref()).unwrap().name(), Some("step"));
    /// ```
    pub fn parse(text: &str, what: &str, model: &dyn ModelInfo) -> Result<Self, ExpressionError> {
        let text = text.trim().to_string();
        let expression = match text.as_str() {
            "impulse" | "step" => None,
            _ => Some(
                parse_expr(&text, Location { line: 1, column: 1 }).map_err(|d| {
                    ExpressionError::Syntax {
                        what: what.to_string(),
                        text: text.clone(),
                        column: d.location.column,
                        message: format!(
                            "{}; give `impulse`, `step` or an expression of t such as `sin(2*t)`",
                            d.message
                        ),
                    }
                })?,
            ),
        };
        let lookup = parameter_lookup(model);
        let parameters = model
            .description()
            .parameter_names()
            .iter()
            .filter_map(|p| lookup(p).map(|v| (p.to_string(), v)))
            .collect();
        let function = TimeFunction {
            text,
            expression,
            parameters,
        };
        function
            .value(0.0)
            .map_err(|message| ExpressionError::Evaluation {
                what: what.to_string(),
                text: function.text.clone(),
                message: format!(
                    "{message} (names: t and the parameters {})",
                    model.description().parameter_names().join(", ")
                ),
            })?;
        Ok(function)
    }

    /// Calls `run` with this function as the forcing of a convolution study
    /// ([`eomgen_runtime::analysis::vibration::convolution_response`]): `impulse` and `step`
    /// by name, else the expression, whose value where it cannot be evaluated is NaN (which
    /// the study reports as a forcing that is not finite, with its time). The one mapping of
    /// the command line's `study convolution --forcing` and the Python package's
    /// `convolution(forcing=…)`.
    pub fn with_forcing<R>(&self, run: impl FnOnce(Forcing<'_>) -> R) -> R {
        let function = |t: f64| self.value(t).unwrap_or(f64::NAN);
        let forcing = match self.name() {
            Some("impulse") => Forcing::Impulse,
            Some(_) => Forcing::Step,
            None => Forcing::Function {
                label: self.text(),
                f: &function,
            },
        };
        run(forcing)
    }

    /// `impulse` or `step` when the text is one of those names, else `None`.
    pub fn name(&self) -> Option<&str> {
        self.expression.is_none().then_some(self.text.as_str())
    }

    /// The trimmed text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The value at `t` (0 for `impulse` and `step`).
    ///
    /// # Errors
    /// Why the expression cannot be evaluated at `t` (a name it does not know).
    pub fn value(&self, t: f64) -> Result<f64, String> {
        let Some(expression) = &self.expression else {
            return Ok(0.0);
        };
        let lookup = |name: &str| -> Option<f64> {
            if name == "t" {
                return Some(t);
            }
            self.parameters
                .iter()
                .find(|(p, _)| p == name)
                .map(|(_, v)| *v)
        };
        eval_expr(expression, &lookup).map_err(|d| d.message.clone())
    }
}
