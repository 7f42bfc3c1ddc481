//! The MATLAB/Octave function file of [`super::export`] ([`super::Language::Matlab`]).

use std::fmt::Write;

use super::{Exported, Language, Output, Shape, body, literal_in, operand};
use crate::codegen::tape::{Tape, Value};

/// The names a model's MATLAB function must not take: the file's local functions and
/// MATLAB's keywords.
const RESERVED: &[&str] = &[
    "parameters",
    "rhs",
    "accelerations",
    "multipliers",
    "real_or_nan",
    "initial_state",
    "mass_matrix_and_forcing",
    "kinetic_energy",
    "potential_energy",
    "point_positions",
    "forcing_jacobian_q",
    "forcing_jacobian_qdot",
    "mass_matrix_product_jacobian",
    "constraint_residuals",
    "constraint_jacobian",
    "constraint_gamma",
    "coordinate_rates",
    "break",
    "case",
    "catch",
    "classdef",
    "continue",
    "else",
    "elseif",
    "end",
    "for",
    "function",
    "global",
    "if",
    "otherwise",
    "parfor",
    "persistent",
    "return",
    "spmd",
    "switch",
    "try",
    "while",
];

impl Exported<'_> {
    /// The model's MATLAB function name: its name, with `_model` after one that is
    /// [`RESERVED`].
    fn matlab_name(&self) -> String {
        if RESERVED.contains(&self.name.as_str()) {
            format!("{}_model", self.name)
        } else {
            self.name.clone()
        }
    }

    /// The MATLAB/Octave function file (see [`Language::Matlab`]).
    pub(super) fn matlab(&self) -> String {
        let name = self.matlab_name();
        let mut s = format!("function model = {name}()\n");
        for line in self.header(Language::Matlab) {
            let _ = writeln!(s, "{}", format!("% {line}").trim_end());
        }
        let _ = writeln!(
            s,
            "%\n% Save as {name}.m. model = {name}() returns the functions as handles and the\n% parameters' values: [t, y] = ode45(model.rhs, [0 10], model.initial_state()).\n% Every function takes the parameters p last, defaulting to model.parameters."
        );
        let quoted = |v: &[String]| {
            v.iter()
                .map(|x| format!("'{}'", x.replace('\'', "''")))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(s, "model.name = '{}';", self.name);
        let _ = writeln!(s, "model.coordinates = {{{}}};", quoted(&self.coordinates));
        let names: Vec<String> = self.parameters.iter().map(|(n, _)| n.clone()).collect();
        let _ = writeln!(s, "model.parameter_names = {{{}}};", quoted(&names));
        let _ = writeln!(s, "model.parameters = parameters();");
        if self.m() > 0 {
            let _ = writeln!(s, "model.constraints = {{{}}};", quoted(&self.constraints));
            let _ = writeln!(s, "model.multipliers = @multipliers;");
        }
        let _ = writeln!(s, "model.rhs = @rhs;");
        for f in std::iter::once(&self.initial_state).chain(&self.functions) {
            let _ = writeln!(s, "model.{0} = @{0};", f.name);
        }
        s.push_str("end\n\n");
        s.push_str("function y = real_or_nan(y)\n% NaN where MATLAB's result is complex (eomgen, C and NumPy give NaN there).\nif ~isreal(y), y = NaN; end\nend\n\n");
        let _ = writeln!(
            s,
            "function p = parameters()\n% The parameters' values in the file, in the order of p.\np = [{}];\nend\n",
            self.parameters
                .iter()
                .map(|(_, v)| literal_in(*v, Language::Matlab))
                .collect::<Vec<_>>()
                .join("; ")
        );
        for f in std::iter::once(&self.initial_state).chain(&self.functions) {
            let args: Vec<&str> = f.args.iter().map(|a| a.name()).collect();
            let outs: Vec<&str> = f.outputs.iter().map(|o| o.name).collect();
            let _ = writeln!(
                s,
                "function [{}] = {}({})\n% {}.\nif nargin < {} || isempty(p), p = parameters(); end",
                outs.join(", "),
                f.name,
                args.join(", "),
                f.doc,
                f.args.len()
            );
            body(&mut s, f, Language::Matlab, &self.name);
            for o in &f.outputs {
                matlab_assign(&mut s, f.tape, o);
            }
            s.push_str("end\n\n");
        }
        let (n, m) = (self.n(), self.m());
        let _ = writeln!(
            s,
            "function ydot = rhs(t, y, p)\n% dy/dt = [{rates}; {second}] ({}).\nif nargin < 3 || isempty(p), p = parameters(); end\nq = y(1:{n});\nqd = y({}:{});\nx = accelerations(t, q, qd, p);\nydot = [{rates}; x(1:{n})];\nend\n",
            2 * n,
            n + 1,
            2 * n,
            rates = match self.speeds.is_empty() {
                true => "qd",
                false => "coordinate_rates(t, q, qd, p)",
            },
            second = match self.speeds.is_empty() {
                true => "q''",
                false => "u'",
            },
        );
        let a = if self.speeds.is_empty() { "q''" } else { "u'" };
        if m > 0 {
            let _ = writeln!(
                s,
                "function lambda = multipliers(t, q, qd, p)\n% lambda ({m}): M {a} = F - J' lambda.\nif nargin < 4 || isempty(p), p = parameters(); end\nx = accelerations(t, q, qd, p);\nlambda = x({}:{});\nend\n\nfunction x = accelerations(t, q, qd, p)\n% [{a}; lambda] of [M J'; J 0][{a}; lambda] = [F; gamma].\n[M, F] = mass_matrix_and_forcing(t, q, qd, p);\nJ = constraint_jacobian(t, q, p);\ngamma = constraint_gamma(t, q, qd, p);\nx = [M, J'; J, zeros({m})] \\ [F; gamma];\nend",
                n + 1,
                n + m
            );
        } else {
            let _ = writeln!(
                s,
                "function x = accelerations(t, q, qd, p)\n% q'' of M q'' = F.\n[M, F] = mass_matrix_and_forcing(t, q, qd, p);\nx = M \\ F;\nend"
            );
        }
        s
    }
}

/// Assigns an output in MATLAB: a scalar, a column vector or a matrix, entry by entry.
fn matlab_assign(s: &mut String, tape: &Tape, o: &Output) {
    let x = |v: Value| operand(tape, v, Language::Matlab);
    if o.shape == Shape::Scalar {
        let _ = writeln!(s, "{} = {};", o.name, x(o.values[0]));
        return;
    }
    let _ = writeln!(s, "{} = zeros({}, {});", o.name, o.rows, o.cols);
    for r in 0..o.rows {
        for c in 0..o.cols {
            let v = o.values[r * o.cols + c];
            if o.shape == Shape::Vector {
                let _ = writeln!(s, "{}({}) = {};", o.name, r + 1, x(v));
            } else {
                let _ = writeln!(s, "{}({}, {}) = {};", o.name, r + 1, c + 1, x(v));
            }
        }
    }
}
