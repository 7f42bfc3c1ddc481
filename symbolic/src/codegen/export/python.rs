//! The Python module of [`super::export`] ([`super::Language::Python`]).

use std::fmt::Write;

use super::{Arg, Exported, Language, Output, Shape, body, literal_in, operand};
use crate::codegen::tape::{Tape, Value};

impl Exported<'_> {
    /// The Python module (see [`Language::Python`]).
    pub(super) fn python(&self) -> String {
        let mut s = String::from("r\"\"\"");
        for line in self.header(Language::Python) {
            let _ = writeln!(s, "{line}");
        }
        s.push_str(
            "\nEvery function takes the parameters p last, defaulting to PARAMETERS; matrices are\n2-D NumPy arrays.\n\"\"\"\n\nimport numpy as np\n\n\ndef _sign(x):\n    \"\"\"-1, 0 or 1 (0 for NaN, as eomgen's sign).\"\"\"\n    return float(x > 0) - float(x < 0)\n\n\ndef _step(x):\n    \"\"\"1 for x >= 0, else 0 (also for NaN, as eomgen's step).\"\"\"\n    return float(x >= 0)\n\n\n",
        );
        let names = |v: Vec<String>| {
            v.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(
            s,
            "NAME = {:?}\nCOORDINATES = ({},)\nPARAMETER_NAMES = ({}{})\nPARAMETERS = np.array([{}])\n",
            self.name,
            names(self.coordinates.clone()),
            names(self.parameters.iter().map(|(n, _)| n.clone()).collect()),
            if self.parameters.is_empty() { "" } else { "," },
            self.parameters
                .iter()
                .map(|(_, v)| literal_in(*v, Language::Python))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if self.m() > 0 {
            let _ = writeln!(s, "CONSTRAINTS = ({},)\n", names(self.constraints.clone()));
        }
        for f in std::iter::once(&self.initial_state).chain(&self.functions) {
            let args: Vec<String> = f
                .args
                .iter()
                .map(|a| match a {
                    Arg::P => "p=PARAMETERS".to_string(),
                    other => other.name().to_string(),
                })
                .collect();
            let _ = writeln!(
                s,
                "\ndef {}({}):\n    \"\"\"{}.\"\"\"",
                f.name,
                args.join(", "),
                f.doc
            );
            body(&mut s, f, Language::Python, &self.name);
            for o in &f.outputs {
                let _ = writeln!(s, "    {} = {}", o.name, python_array(f.tape, o));
            }
            let names: Vec<&str> = f.outputs.iter().map(|o| o.name).collect();
            let _ = writeln!(s, "    return {}\n", names.join(", "));
        }
        let (n, m) = (self.n(), self.m());
        // In speeds `q'` comes from the kinematic equations, and `qd'` is `u'`.
        let (rates, q_rate, a, from) = match self.speeds.is_empty() {
            true => ("qd", "qd", "q''", ""),
            false => (
                "coordinate_rates(t, q, qd, p)",
                "q'",
                "u'",
                ", q' from coordinate_rates",
            ),
        };
        if m == 0 {
            let _ = writeln!(
                s,
                "\ndef rhs(t, y, p=PARAMETERS):\n    \"\"\"dy/dt = [{q_rate}; {a}] ({}){from}, {a} from M {a} = F.\"\"\"\n    y = np.asarray(y, dtype=float)\n    q, qd = y[:{n}], y[{n}:]\n    M, F = mass_matrix_and_forcing(t, q, qd, p)\n    return np.concatenate(({rates}, np.linalg.solve(M, F)))",
                2 * n
            );
        } else {
            let _ = writeln!(
                s,
                "\ndef _accelerations(t, q, qd, p):\n    \"\"\"[{a}; lambda] of [M J'; J 0][{a}; lambda] = [F; gamma].\"\"\"\n    M, F = mass_matrix_and_forcing(t, q, qd, p)\n    J = constraint_jacobian(t, q, p)\n    gamma = constraint_gamma(t, q, qd, p)\n    A = np.block([[M, J.T], [J, np.zeros(({m}, {m}))]])\n    return np.linalg.solve(A, np.concatenate((F, gamma)))\n\n\ndef rhs(t, y, p=PARAMETERS):\n    \"\"\"dy/dt = [{q_rate}; {a}] ({}){from}, {a} from the constraints' index-1 system.\"\"\"\n    y = np.asarray(y, dtype=float)\n    q, qd = y[:{n}], y[{n}:]\n    return np.concatenate(({rates}, _accelerations(t, q, qd, p)[:{n}]))\n\n\ndef multipliers(t, q, qd, p=PARAMETERS):\n    \"\"\"lambda ({m}): M {a} = F - J' lambda.\"\"\"\n    return _accelerations(t, np.asarray(q, dtype=float), np.asarray(qd, dtype=float), p)[{n}:]",
                2 * n
            );
        }
        s
    }
}

/// An output as a NumPy expression: a float for a scalar, an array otherwise.
fn python_array(tape: &Tape, o: &Output) -> String {
    let x = |v: Value| operand(tape, v, Language::Python);
    if o.shape == Shape::Scalar {
        return format!("float({})", x(o.values[0]));
    }
    if o.shape == Shape::Vector {
        let items: Vec<String> = o.values.iter().map(|&v| x(v)).collect();
        return format!("np.array([{}], dtype=float)", items.join(", "));
    }
    let rows: Vec<String> = (0..o.rows)
        .map(|r| {
            let items: Vec<String> = (0..o.cols).map(|c| x(o.values[r * o.cols + c])).collect();
            format!("        [{}],\n", items.join(", "))
        })
        .collect();
    format!("np.array([\n{}    ], dtype=float)", rows.concat())
}
