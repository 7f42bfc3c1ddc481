//! The unit tests of `unit_check.rs`.

use crate::model::load;

/// `line:col: message` of every diagnostic of `src`.
fn errors(src: &str) -> Vec<String> {
    match load("t.yaml", src) {
        Ok(_) => Vec::new(),
        Err(d) => d
            .iter()
            .map(|d| format!("{}: {}", d.location, d.message))
            .collect(),
    }
}

fn helps(src: &str) -> Vec<String> {
    load("t.yaml", src)
        .err()
        .unwrap_or_default()
        .into_iter()
        .filter_map(|d| d.help)
        .collect()
}

const OSCILLATOR: &str = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  k: 4.0  # N/m\n  c: 0.1  # N*s/m\ncoordinates: [x]\n";

#[test]
fn a_consistent_file_passes_and_infers_its_coordinate() {
    let src = format!(
        "{OSCILLATOR}kinetic: m*x_dot^2/2\npotential: k*x^2/2\ngeneralized_forces: {{ x: -c*x_dot }}\ninitial: {{ x: 0.1 }}\n"
    );
    assert_eq!(errors(&src), Vec::<String>::new());
}

#[test]
fn without_units_nothing_is_checked() {
    let src = "name: a\nparameters: { m: 1, k: 2 }\ncoordinates: [x]\nkinetic: (m + k)*x_dot^2\n";
    assert_eq!(errors(src), Vec::<String>::new());
}

#[test]
fn energies_and_sums() {
    let src = format!("{OSCILLATOR}  - x  # m\nkinetic: m*x_dot/2\npotential: k*x^2/2 + m\n");
    let src = src.replace("coordinates: [x]\n", "coordinates:\n");
    assert_eq!(
        errors(&src),
        [
            "9:10: `kinetic` is kg*m/s, but an energy is J",
            "10:22: sum of unlike units in `potential`: `k*x^2/2` is J but `m` is kg",
        ]
    );
}

#[test]
fn an_inferred_unit_comes_from_the_most_uses_and_is_named_in_the_help() {
    // `x` is a length by its point and its potential energy (two votes), not m^2/s by
    // the wrong kinetic energy (one vote).
    let src =
        format!("{OSCILLATOR}kinetic: m*x_dot/2\npotential: k*x^2/2\npoints: {{ P: [x, 0] }}\n");
    assert_eq!(
        errors(&src),
        ["8:10: `kinetic` is kg*m/s, but an energy is J"]
    );
    let help = &helps(&src)[0];
    assert!(
        help.ends_with("(the unit of `x`, m, is inferred from `potential` at 9:12; declare the unit of `x` if it is another)"),
        "{help}"
    );
}

#[test]
fn functions_and_powers() {
    let src = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  l: 1.0  # m\n  g: 9.81  # m/s^2\ncoordinates:\n  - x  # m\nkinetic: m*x_dot^2/2\npotential: m*g*l*cos(x) + m*g*l*exp(x/l) + m*g*l^x/l^x + m*g*sqrt(l*x) + m*g*l*atan2(x, t)\n";
    assert_eq!(
        errors(src),
        [
            "10:22: the argument of `cos` in `potential` is m, but it must be a pure number (rad)",
            "10:48: `l^x` in `potential` raises `l`, which is m, to a power that is not a number",
            "10:50: the exponent `x` in `potential` is m, but an exponent is a pure number",
            "10:52: `l^x` in `potential` raises `l`, which is m, to a power that is not a number",
            "10:54: the exponent `x` in `potential` is m, but an exponent is a pure number",
            "10:89: the arguments of `atan2` in `potential` have unlike units: `x` is m but `t` is s",
        ]
    );
}

#[test]
fn parameters_without_a_unit_name_the_unit_their_use_implies() {
    let src = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  k: 100.0\ncoordinates:\n  - x  # m\nkinetic: m*x_dot^2/2\npotential: k*x^2/2\n";
    assert_eq!(errors(src), ["5:3: parameter `k` has no unit"]);
    assert_eq!(
        helps(src),
        ["write `k: 100.0  # N/m` (the unit its use implies), or `k: { value: 100.0, unit: N/m }`"]
    );
}

#[test]
fn map_forms_and_bad_units() {
    let src = "name: a\nunits: SI\nparameters:\n  m: { value: 1.0, unit: kg }\n  k: 4.0  # N/mm, spring\ncoordinates:\n  - { name: x, unit: m }\n  - { name: y, unit: furlong }\nkinetic: m*(x_dot^2 + y_dot^2)/2\n";
    assert_eq!(
        errors(src),
        [
            "5:15: unknown unit `mm` in the unit of parameter `k`",
            "8:22: unknown unit `furlong` in the unit of coordinate `y`",
        ]
    );
    // Issue 28: "in the unit in the unit of parameter" is said once.
    let src = "name: a\nunits: SI\nparameters:\n  m: { value: 1.0, unit: kg }\n  k: { value: 1.0, unit: N/m) }\n  c: { value: 1.0, unit: (N*s/m }\n  d: { value: 1.0, unit: N%m }\ncoordinates:\n  - { name: x, unit: m }\nkinetic: m*x_dot^2/2\n";
    assert_eq!(
        errors(src),
        [
            "5:29: unexpected `)` in the unit of parameter `k`: it closes no `(`",
            "6:32: unclosed `(` in the unit of parameter `c`",
            "7:27: unexpected `%` in the unit of parameter `d`",
        ]
    );
}

#[test]
fn constraint_forces_numbers_and_equations() {
    // The rod's multiplier is J per m of `Φ` = N: comparing it with a weight is right,
    // with a mass wrong. A number alone is in the unit of its key; inside an expression
    // it is a pure number, except 0.
    let src = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  l: 1.0  # m\n  g: 9.81  # m/s^2\ncoordinates:\n  - x  # m\n  - y  # m\npoints: { O: [0, 0], P: [x, y], Q: [x - 1, y + 0] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\nconstraints: { rod: sqrt(x^2 + y^2) - l }\nevents:\n  taut: lambda_rod - m*g\n  wrong: lambda_rod - m\ninitial: { x: 1, y: 0 }\nchecks:\n  equations_of_motion:\n    - m*x_ddot = -m*g*x/l\n    - m*y_ddot = -m*g*l\n";
    assert_eq!(
        errors(src),
        [
            "10:41: sum of unlike units in the x component of point `Q`: `x` is m but `1` is 1",
            "16:23: sum of unlike units in the function of event `wrong`: `lambda_rod` is N but `m` is kg",
            "21:18: the sides of equation of motion 2 have unlike units: `m*y_ddot` is N but `-m*g*l` is J",
        ]
    );
}

#[test]
fn bad_units_key() {
    let src = "name: a\nunits: imperial\ncoordinates: [x]\nkinetic: x_dot^2\n";
    assert_eq!(
        errors(src),
        ["2:8: `units` must be one of SI, found `imperial`"]
    );
}
