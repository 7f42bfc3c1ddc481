//! The C99 source of [`super::export`] ([`super::Language::C`]).

use std::fmt::Write;

use super::{Arg, Exported, Function, Language, body, literal_in, operand};

/// The most `double`s of the right-hand side's workspace kept on the stack (32 kB).
const STACK_WORKSPACE: usize = 4096;

impl Exported<'_> {
    /// The C source (see [`Language::C`]).
    pub(super) fn c(&self) -> String {
        let mut s = String::new();
        s.push_str("/*\n");
        for line in self.header(Language::C) {
            let _ = writeln!(s, "{}", format!(" * {line}").trim_end());
        }
        let returns = if self.m() > 0 {
            format!("{0}_rhs and {0}_multipliers return", self.name)
        } else {
            format!("{}_rhs returns", self.name)
        };
        let _ = writeln!(
            s,
            " *\n * Each function is named {0}_<function> and writes its outputs to the arrays it is\n * given (matrices row-major: M[i*n + j]); {returns} 0, 1 where a pivot\n * of the linear system (Gaussian elimination with partial pivoting) is zero or not finite, or\n * 2 where memory for it is lacking. Compile with: cc -O2 -c {0}.c (link with -lm).\n */",
            self.name
        );
        s.push_str("#include <math.h>\n#include <stdlib.h>\n\n");
        let prefix = &self.name;
        let _ = writeln!(
            s,
            "/* sign(x): -1, 0 or 1 (0 for NaN); step(x): 1 for x >= 0, else 0. */\nstatic inline double {prefix}_sign(double x) {{ return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }}\nstatic inline double {prefix}_step(double x) {{ return x >= 0.0 ? 1.0 : 0.0; }}\n"
        );
        let _ = writeln!(
            s,
            "/* The parameters' values in the file, in the order of p. */\nconst double {prefix}_parameters[{}] = {{{}}};\n",
            self.parameters.len().max(1),
            if self.parameters.is_empty() {
                "0.0".to_string()
            } else {
                self.parameters
                    .iter()
                    .map(|(_, v)| literal_in(*v, Language::C))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        );
        for f in std::iter::once(&self.initial_state).chain(&self.functions) {
            self.c_function(&mut s, f);
        }
        self.c_solve(&mut s);
        self.c_rhs(&mut s);
        s
    }

    fn c_function(&self, s: &mut String, f: &Function) {
        let prefix = &self.name;
        let mut params: Vec<String> = f
            .args
            .iter()
            .map(|a| match a {
                Arg::Time => "double t".to_string(),
                other => format!("const double *{}", other.name()),
            })
            .collect();
        params.extend(f.outputs.iter().map(|o| format!("double *{}", o.name)));
        let _ = writeln!(s, "/* {}. */", f.doc);
        let _ = writeln!(s, "void {prefix}_{}({})\n{{", f.name, params.join(", "));
        for a in f.args {
            let _ = writeln!(s, "    (void){};", a.name());
        }
        body(s, f, Language::C, &self.name);
        for o in &f.outputs {
            for (k, &v) in o.values.iter().enumerate() {
                let _ = writeln!(
                    s,
                    "    {}[{k}] = {};",
                    o.name,
                    operand(f.tape, v, Language::C)
                );
            }
        }
        s.push_str("}\n\n");
    }

    fn c_solve(&self, s: &mut String) {
        let prefix = &self.name;
        let _ = writeln!(
            s,
            "/* Solves A x = b in place (A row-major k x k, overwritten; b becomes x) by Gaussian\n * elimination with partial pivoting; 1 where a pivot is zero or not finite. */\nstatic int {prefix}_solve(int k, double *A, double *b)\n{{\n    int i, j, r;\n    for (j = 0; j < k; ++j) {{\n        int pivot = j;\n        double best = fabs(A[j * k + j]);\n        for (r = j + 1; r < k; ++r) {{\n            if (fabs(A[r * k + j]) > best) {{\n                best = fabs(A[r * k + j]);\n                pivot = r;\n            }}\n        }}\n        if (!(best > 0.0) || !isfinite(best)) {{\n            return 1;\n        }}\n        if (pivot != j) {{\n            double swap;\n            for (i = 0; i < k; ++i) {{\n                swap = A[j * k + i];\n                A[j * k + i] = A[pivot * k + i];\n                A[pivot * k + i] = swap;\n            }}\n            swap = b[j];\n            b[j] = b[pivot];\n            b[pivot] = swap;\n        }}\n        for (r = j + 1; r < k; ++r) {{\n            double factor = A[r * k + j] / A[j * k + j];\n            for (i = j + 1; i < k; ++i) {{\n                A[r * k + i] -= factor * A[j * k + i];\n            }}\n            b[r] -= factor * b[j];\n        }}\n    }}\n    for (j = k - 1; j >= 0; --j) {{\n        double sum = b[j];\n        for (i = j + 1; i < k; ++i) {{\n            sum -= A[j * k + i] * b[i];\n        }}\n        b[j] = sum / A[j * k + j];\n    }}\n    return 0;\n}}\n"
        );
    }

    fn c_rhs(&self, s: &mut String) {
        let prefix = &self.name;
        let (n, m) = (self.n(), self.m());
        let k = n + m;
        let (nn, kk, mn) = (n * n, k * k, m * n);
        // `M`, `A` and `J` on the stack up to 32 kB, else from the heap (a 1000-mass chain's
        // would take 16 MB of stack).
        let heap = nn + kk + mn > STACK_WORKSPACE;
        let _ = writeln!(
            s,
            "/* q'' and, with constraints, lambda into x ({k}) at (t, q, qd): 0; 1 where a pivot of the\n * linear system is zero or not finite; 2 where memory for it is lacking. */\nstatic int {prefix}_accelerations(double t, const double *q, const double *qd, const double *p, double *x)\n{{"
        );
        if heap {
            let _ = writeln!(
                s,
                "    double *M = (double *)malloc(sizeof(double) * {});\n    if (M == NULL) {{\n        return 2;\n    }}",
                nn + kk + mn
            );
        } else {
            let _ = writeln!(s, "    double M[{}];", nn + kk + mn);
        }
        let _ = writeln!(
            s,
            "    double *A = M + {nn};\n    double *J = A + {kk};\n    int i, j, status;\n    (void)J;\n    {prefix}_mass_matrix_and_forcing(t, q, qd, p, M, x);"
        );
        if m > 0 {
            let _ = writeln!(
                s,
                "    {prefix}_constraint_jacobian(t, q, p, J);\n    {prefix}_constraint_gamma(t, q, qd, p, x + {n});"
            );
        }
        let _ = writeln!(
            s,
            "    for (i = 0; i < {k}; ++i) {{\n        for (j = 0; j < {k}; ++j) {{\n            A[i * {k} + j] = i < {n} && j < {n} ? M[i * {n} + j] : 0.0;\n        }}\n    }}"
        );
        if m > 0 {
            let _ = writeln!(
                s,
                "    for (i = 0; i < {m}; ++i) {{\n        for (j = 0; j < {n}; ++j) {{\n            A[({n} + i) * {k} + j] = J[i * {n} + j];\n            A[j * {k} + {n} + i] = J[i * {n} + j];\n        }}\n    }}"
            );
        }
        let _ = writeln!(s, "    status = {prefix}_solve({k}, A, x);");
        if heap {
            s.push_str("    free(M);\n");
        }
        let _ = writeln!(
            s,
            "    return status;\n}}\n\n/* dy/dt = {what} ({two}) at (t, y): the status of {prefix}_accelerations. */\nint {prefix}_rhs(double t, const double *y, const double *p, double *ydot)\n{{\n    double x[{k}];\n    int i, status = {prefix}_accelerations(t, y, y + {n}, p, x);\n    if (status != 0) {{\n        return status;\n    }}\n{rates}    for (i = 0; i < {n}; ++i) {{\n{copy}        ydot[{n} + i] = x[i];\n    }}\n    return 0;\n}}",
            two = 2 * n,
            what = match self.speeds.is_empty() {
                true => "[qd; q'']",
                false => "[q'; u'] (q' from coordinate_rates)",
            },
            rates = match self.speeds.is_empty() {
                true => String::new(),
                false => format!("    {prefix}_coordinate_rates(t, y, y + {n}, p, ydot);\n"),
            },
            copy = match self.speeds.is_empty() {
                true => format!("        ydot[i] = y[{n} + i];\n"),
                false => String::new(),
            },
        );
        if m > 0 {
            let _ = writeln!(
                s,
                "\n/* lambda ({m}) at (t, q, qd): the status of {prefix}_accelerations. */\nint {prefix}_multipliers(double t, const double *q, const double *qd, const double *p, double *lambda)\n{{\n    double x[{k}];\n    int i, status = {prefix}_accelerations(t, q, qd, p, x);\n    if (status != 0) {{\n        return status;\n    }}\n    for (i = 0; i < {m}; ++i) {{\n        lambda[i] = x[{n} + i];\n    }}\n    return 0;\n}}"
            );
        }
    }
}
