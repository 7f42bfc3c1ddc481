//! The equations exported as C (`eomgen::listing::export`, `eomgen equations --c`) against
//! eomgen's own values, for every bundled model: the exported files are compiled together
//! with the machine's C compiler, evaluated at three seeded states per model near its initial
//! state, and every output (`M`, `F`, the right-hand side, the multipliers, the three exact
//! Jacobians, `T`, `V`, the points, `Φ`, `J`, `γ`, the initial state) is compared with the
//! model compiled at run time. The two compute the same operations with different `sin`,
//! `sqrt`, … (the C library's against the `libm` crate's), so they agree to an ulp or so per
//! operation: the tolerance is `1e-13` relative to the output's largest entry (at least 1).
//! The same for the MATLAB file under Octave where the machine has it. The Python module is
//! tested by the Python package's suite (`python/tests/test_export.py`), where NumPy is
//! installed.

use std::fmt::Write as _;
use std::process::Command;

use eomgen::listing::{Language, export};
use eomgen::{ConstraintWorkspace, DynMechanicalSystem, JitModel, Stabilization};
use rand::RngExt;

use crate::common::seeded_rng;

/// The agreement asked of every output, relative to its largest entry (at least 1).
const TOLERANCE: f64 = 1e-13;

/// States per model.
const STATES: usize = 3;

/// One state at which a model is evaluated.
struct State {
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    a: Vec<f64>,
}

/// One output's values, named as the C driver prints them.
type Values = Vec<(String, Vec<f64>)>;

/// The states of a model: its initial state, moved by up to 0.1 in each coordinate and 0.5 in
/// each rate, at t in [0, 1).
fn states(model: &JitModel, seed: u64) -> Vec<State> {
    let n = model.num_dofs();
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let mut rng = seeded_rng(seed);
    let mut u = move || rng.random_range(-1.0..1.0);
    (0..STATES)
        .map(|_| State {
            t: 0.5 + 0.5 * u(),
            q: q0.iter().map(|x| x + 0.1 * u()).collect(),
            qd: qd0.iter().map(|x| x + 0.5 * u()).collect(),
            a: (0..n).map(|_| u()).collect(),
        })
        .collect()
}

/// A column-major `rows × cols` matrix row-major.
fn row_major(values: &[f64], rows: usize, cols: usize) -> Vec<f64> {
    (0..rows * cols)
        .map(|k| values[k / cols + (k % cols) * rows])
        .collect()
}

/// eomgen's values at `state`, in the order the C driver prints them.
fn reference(model: &JitModel, state: &State) -> Values {
    let d = model.description();
    let (n, m, h) = (
        model.num_dofs(),
        d.constraints.len(),
        d.holonomic_constraints,
    );
    let (q, qd, t) = (&state.q[..], &state.qd[..], state.t);
    let mut out: Values = Vec::new();
    let (mut y0q, mut y0qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut y0q, &mut y0qd);
    out.push(("y0".into(), [y0q, y0qd].concat()));
    let (mut mass, mut forcing) = (vec![0.0; n * n], vec![0.0; n]);
    model.mass_matrix_and_forcing(q, qd, t, &mut mass, &mut forcing);
    out.push(("M".into(), row_major(&mass, n, n)));
    out.push(("F".into(), forcing));
    let mut jacobian = vec![0.0; n * n];
    model.forcing_jacobian_q(q, qd, t, &mut jacobian);
    out.push(("dF_dq".into(), row_major(&jacobian, n, n)));
    model.forcing_jacobian_qdot(q, qd, t, &mut jacobian);
    out.push(("dF_dqd".into(), row_major(&jacobian, n, n)));
    model.mass_matrix_product_jacobian(q, t, &state.a, &mut jacobian);
    out.push(("dMa_dq".into(), row_major(&jacobian, n, n)));
    out.push(("T".into(), vec![model.kinetic_energy(q, qd, t)]));
    out.push(("V".into(), vec![model.potential_energy(q, t)]));
    if !d.points.is_empty() {
        let mut points = vec![[0.0; 3]; d.points.len()];
        model.point_positions(q, t, &mut points);
        out.push(("r".into(), points.concat()));
    }
    if m > 0 {
        if h > 0 {
            let mut phi = vec![0.0; h];
            model.constraint_residuals(q, t, &mut phi);
            out.push(("Phi".into(), phi));
        }
        let mut j = vec![0.0; m * n];
        model.constraint_jacobian(q, t, &mut j);
        out.push(("J".into(), j));
        let mut gamma = vec![0.0; m];
        model.constraint_gamma(q, qd, t, &mut gamma);
        out.push(("gamma".into(), gamma));
    }
    let mut qdd = vec![0.0; n];
    let mut workspace = ConstraintWorkspace::new(n, m, h);
    let solved = if m > 0 {
        workspace
            .accelerations_into(model, q, qd, t, Stabilization::None, &mut qdd)
            .is_ok()
    } else {
        let (mut mass, mut forcing) = (vec![0.0; n * n], vec![0.0; n]);
        model.mass_matrix_and_forcing(q, qd, t, &mut mass, &mut forcing);
        qdd = solve(mass, forcing);
        qdd.iter().all(|x| x.is_finite())
    };
    assert!(solved, "{}: the state's linear system is singular", d.name);
    // In generalized speeds `qd` is `u`, and `q̇` comes from the kinematic equations.
    let mut rates = vec![0.0; n];
    model.coordinate_rates(q, qd, t, &mut rates);
    out.push(("ydot".into(), [rates, qdd].concat()));
    if m > 0 {
        out.push(("lambda".into(), workspace.multipliers.clone()));
    }
    out
}

/// `M⁻¹ F` (`M` column-major) by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    let at = |r: usize, c: usize| r + c * n;
    for j in 0..n {
        let p = (j..n)
            .max_by(|&x, &y| a[at(x, j)].abs().total_cmp(&a[at(y, j)].abs()))
            .unwrap_or(j);
        for c in 0..n {
            a.swap(at(j, c), at(p, c));
        }
        b.swap(j, p);
        for r in j + 1..n {
            let f = a[at(r, j)] / a[at(j, j)];
            for c in j + 1..n {
                a[at(r, c)] -= f * a[at(j, c)];
            }
            b[r] -= f * b[j];
        }
    }
    for j in (0..n).rev() {
        let s = b[j] - (j + 1..n).map(|c| a[at(j, c)] * b[c]).sum::<f64>();
        b[j] = s / a[at(j, j)];
    }
    b
}

/// A C array literal.
fn array(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
    format!("{{{}}}", items.join(", "))
}

/// The files exported: every bundled model and four fixtures in generalized speeds (whose
/// `qd` is `u` and whose `rhs` takes `q̇` from `coordinate_rates`; the rolling disc's and the
/// Euler parameters' with their auxiliary speeds held by `J = [0 I]`), as
/// `(name, file, text)`.
fn exported_files() -> Vec<(String, String, String)> {
    let bundled = eomgen::models::ALL.iter().map(|entry| {
        (
            entry.name.to_string(),
            entry.file.to_string(),
            entry.source().to_string(),
        )
    });
    let fixtures = [
        "free_rigid_body_speeds",
        "heavy_top_speeds",
        "rolling_disc_speeds",
        "free_rigid_body_quaternion_speeds",
    ]
    .map(|name| {
        let file = format!("{}/tests/fixtures/{name}.yaml", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&file).unwrap();
        (name.to_string(), file, text)
    });
    bundled.chain(fixtures).collect()
}

/// The C driver's statements for one model at one state: each output printed on a line,
/// `name v v …`, in [`reference`]'s order.
fn driver(name: &str, model: &JitModel, state: &State) -> String {
    let d = model.description();
    let (n, m, h, points) = (
        model.num_dofs(),
        d.constraints.len(),
        d.holonomic_constraints,
        d.points.len(),
    );
    let mut s = String::from("    {\n");
    let _ = writeln!(
        s,
        "        const double t = {:?}, q[] = {}, qd[] = {}, a[] = {};",
        state.t,
        array(&state.q),
        array(&state.qd),
        array(&state.a)
    );
    let _ = writeln!(
        s,
        "        const double *p = {name}_parameters;\n        double y0[{}], M[{}], F[{n}], D[{}], T, V, y[{}], ydot[{}];\n        (void)a;",
        2 * n,
        n * n,
        n * n,
        2 * n,
        2 * n
    );
    let print = |s: &mut String, label: &str, array: &str, len: usize| {
        let _ = writeln!(s, "        put(\"{label}\", {array}, {len});");
    };
    let _ = writeln!(s, "        {name}_initial_state(p, y0);");
    print(&mut s, "y0", "y0", 2 * n);
    let _ = writeln!(
        s,
        "        {name}_mass_matrix_and_forcing(t, q, qd, p, M, F);"
    );
    print(&mut s, "M", "M", n * n);
    print(&mut s, "F", "F", n);
    for (function, label, args) in [
        ("forcing_jacobian_q", "dF_dq", "t, q, qd, p"),
        ("forcing_jacobian_qdot", "dF_dqd", "t, q, qd, p"),
        ("mass_matrix_product_jacobian", "dMa_dq", "t, q, a, p"),
    ] {
        let _ = writeln!(s, "        {name}_{function}({args}, D);");
        print(&mut s, label, "D", n * n);
    }
    let _ = writeln!(
        s,
        "        {name}_kinetic_energy(t, q, qd, p, &T);\n        {name}_potential_energy(t, q, p, &V);"
    );
    print(&mut s, "T", "&T", 1);
    print(&mut s, "V", "&V", 1);
    if points > 0 {
        let _ = writeln!(
            s,
            "        double r[{}];\n        {name}_point_positions(t, q, p, r);",
            3 * points
        );
        print(&mut s, "r", "r", 3 * points);
    }
    if m > 0 {
        if h > 0 {
            let _ = writeln!(
                s,
                "        double Phi[{h}];\n        {name}_constraint_residuals(t, q, p, Phi);"
            );
            print(&mut s, "Phi", "Phi", h);
        }
        let _ = writeln!(
            s,
            "        double J[{}], gamma[{m}], lambda[{m}];\n        {name}_constraint_jacobian(t, q, p, J);\n        {name}_constraint_gamma(t, q, qd, p, gamma);",
            m * n
        );
        print(&mut s, "J", "J", m * n);
        print(&mut s, "gamma", "gamma", m);
    }
    let _ = writeln!(
        s,
        "        for (int i = 0; i < {n}; ++i) {{ y[i] = q[i]; y[{n} + i] = qd[i]; }}\n        if ({name}_rhs(t, y, p, ydot) != 0) printf(\"singular\\n\");"
    );
    print(&mut s, "ydot", "ydot", 2 * n);
    if m > 0 {
        let _ = writeln!(
            s,
            "        if ({name}_multipliers(t, q, qd, p, lambda) != 0) printf(\"singular\\n\");"
        );
        print(&mut s, "lambda", "lambda", m);
    }
    s.push_str("    }\n");
    s
}

/// Whether `c` agrees with `r` within [`TOLERANCE`] of the larger of 1 and `r`'s largest
/// entry; the worst difference so scaled.
fn agreement(c: &[f64], r: &[f64]) -> f64 {
    let scale = r.iter().fold(1.0_f64, |s, x| s.max(x.abs()));
    c.iter()
        .zip(r)
        .map(|(a, b)| if a == b { 0.0 } else { (a - b).abs() / scale })
        .fold(0.0, f64::max)
}

/// Parses the driver's lines `name v v …`.
fn parse(stdout: &str) -> Values {
    stdout
        .lines()
        .map(|line| {
            let mut words = line.split_whitespace();
            let name = words.next().unwrap_or_default().to_string();
            let values = words
                .map(|w| w.parse::<f64>().unwrap_or(f64::NAN))
                .collect();
            (name, values)
        })
        .collect()
}

/// Holds the lines `got` from the exported code (`what` runs it) to eomgen's, output by
/// output (`models` names each line's model); the worst difference relative to each output's
/// scale.
fn compare(what: &str, models: &[&str], got: &Values, expected: &Values) -> f64 {
    assert_eq!(got.len(), expected.len(), "{what}: the driver's lines");
    let mut worst = 0.0_f64;
    for ((model, (name, c)), (reference_name, r)) in models.iter().zip(got).zip(expected) {
        assert_eq!(name, reference_name, "{model}: the driver's order");
        assert_eq!(c.len(), r.len(), "{model}: {name}'s length");
        let difference = agreement(c, r);
        assert!(
            difference <= TOLERANCE,
            "{model}: {name} differs by {difference:.2e} (relative): {what} {c:?}, eomgen {r:?}"
        );
        worst = worst.max(difference);
    }
    worst
}

/// Every bundled model exported as C, compiled with `cc` in one program and evaluated at
/// [`STATES`] states each: every output within [`TOLERANCE`] of eomgen's.
#[test]
fn exported_c_computes_what_eomgen_computes_on_every_bundled_model() {
    let dir = tempfile::tempdir().unwrap();
    let mut source = String::from("#include <stdio.h>\n");
    let mut main = String::from(
        "static void put(const char *name, const double *x, int n)\n{\n    printf(\"%s\", name);\n    for (int i = 0; i < n; ++i) printf(\" %.17g\", x[i]);\n    printf(\"\\n\");\n}\n\nint main(void)\n{\n",
    );
    let mut expected: Values = Vec::new();
    let mut models = Vec::new();
    let files = exported_files();
    for (k, (name, file, text)) in files.iter().enumerate() {
        let code = export(file, text, Language::C).unwrap_or_else(|e| panic!("{name}: {e}"));
        source.push_str(&code);
        let model = JitModel::from_source(file, text).unwrap();
        for state in states(&model, 1000 + k as u64) {
            main.push_str(&driver(name, &model, &state));
            let values = reference(&model, &state);
            models.extend(std::iter::repeat_n(name.as_str(), values.len()));
            expected.extend(values);
        }
    }
    main.push_str("    return 0;\n}\n");
    let c = dir.path().join("models.c");
    std::fs::write(&c, source + &main).unwrap();
    let program = dir.path().join("models");
    let compiled = Command::new("cc")
        .args(["-std=c99", "-O0", "-Wall", "-Wextra", "-Werror"])
        .arg(&c)
        .arg("-o")
        .arg(&program)
        .arg("-lm")
        .output()
        .expect("cc runs (the Rust toolchain links with it)");
    assert!(
        compiled.status.success(),
        "cc: {}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let run = Command::new(&program).output().unwrap();
    assert!(run.status.success());
    let got = parse(&String::from_utf8(run.stdout).unwrap());
    let worst = compare("C", &models, &got, &expected);
    println!(
        "{} models, {} outputs: worst relative difference {worst:.2e}",
        files.len(),
        got.len()
    );
}

/// The Octave statements for one model at one state, printing what [`reference`] computes in
/// its order (`put.m` prints a matrix row by row).
fn octave_driver(name: &str, model: &JitModel, state: &State) -> String {
    let d = model.description();
    let (m, h) = (d.constraints.len(), d.holonomic_constraints);
    let column = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        format!("[{}]", items.join("; "))
    };
    let mut s = format!(
        "m = {name}();\nt = {:?}; q = {}; qd = {}; a = {}; p = m.parameters;\n",
        state.t,
        column(&state.q),
        column(&state.qd),
        column(&state.a)
    );
    s.push_str(
        "put('y0', m.initial_state(p));\n[M, F] = m.mass_matrix_and_forcing(t, q, qd, p);\nput('M', M); put('F', F);\nput('dF_dq', m.forcing_jacobian_q(t, q, qd, p));\nput('dF_dqd', m.forcing_jacobian_qdot(t, q, qd, p));\nput('dMa_dq', m.mass_matrix_product_jacobian(t, q, a, p));\nput('T', m.kinetic_energy(t, q, qd, p));\nput('V', m.potential_energy(t, q, p));\n",
    );
    if !d.points.is_empty() {
        s.push_str("put('r', m.point_positions(t, q, p));\n");
    }
    if m > 0 {
        if h > 0 {
            s.push_str("put('Phi', m.constraint_residuals(t, q, p));\n");
        }
        s.push_str("put('J', m.constraint_jacobian(t, q, p));\nput('gamma', m.constraint_gamma(t, q, qd, p));\n");
    }
    s.push_str("put('ydot', m.rhs(t, [q; qd], p));\n");
    if m > 0 {
        s.push_str("put('lambda', m.multipliers(t, q, qd, p));\n");
    }
    s
}

/// Every bundled model exported as a MATLAB file and run by Octave, where the machine has
/// it (`octave-cli`; else the test says it was skipped): every output within [`TOLERANCE`]
/// of eomgen's at one state per model.
#[test]
fn exported_matlab_computes_what_eomgen_computes_under_octave() {
    if Command::new("octave-cli")
        .arg("--version")
        .output()
        .is_err()
    {
        println!("skipped: octave-cli is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("put.m"),
        "function put(name, x)\nx = x.';\nfprintf('%s', name);\nfprintf(' %.17g', x(:));\nfprintf('\\n');\nend\n",
    )
    .unwrap();
    let mut script = String::new();
    let mut expected: Values = Vec::new();
    let mut models = Vec::new();
    for (k, entry) in eomgen::models::ALL.iter().enumerate() {
        let code = export(entry.file, entry.source(), Language::Matlab)
            .unwrap_or_else(|e| panic!("{}: {e}", entry.name));
        std::fs::write(dir.path().join(format!("{}.m", entry.name)), code).unwrap();
        let model = entry.model().unwrap();
        let state = states(&model, 2000 + k as u64).swap_remove(0);
        script.push_str(&octave_driver(entry.name, &model, &state));
        let values = reference(&model, &state);
        models.extend(std::iter::repeat_n(entry.name, values.len()));
        expected.extend(values);
    }
    std::fs::write(dir.path().join("driver.m"), script).unwrap();
    let run = Command::new("octave-cli")
        .args(["--no-gui", "--norc", "--quiet", "driver.m"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8(run.stdout).unwrap();
    assert!(
        run.status.success(),
        "octave: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let worst = compare("Octave", &models, &parse(&stdout), &expected);
    println!("Octave: worst relative difference {worst:.2e}");
}
