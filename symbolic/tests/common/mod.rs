//! Model sources and helpers shared by the symbolic crate's test files.

use eomgen_symbolic::expr::eval::Evaluator;
use eomgen_symbolic::mechanics::cross_check::solve;
use eomgen_symbolic::mechanics::{EquationsOfMotion, SymbolicModel};

/// The bundled double pendulum with a torque `tau0 cos(√(g/l1) t)` (tau0 = 3 N·m) on its
/// forearm, the second body.
pub fn double_pendulum_with_forearm_torque() -> String {
    let source = include_str!("../../../models/double_pendulum.yaml")
        .replace(
            "  g: 10.0    # m/s^2\n",
            "  g: 10.0    # m/s^2\n  tau0: 3.0  # N*m\n",
        )
        .replace(
            "gravity: [0, -g]\n",
            "gravity: [0, -g]\ntorques: { motor: { body: fore, value: tau0*cos(sqrt(g/l1)*t) } }\n",
        );
    assert!(source.contains("tau0: 3.0") && source.contains("torques:"));
    source
}

/// `M⁻¹ F` of one derivation (`q̈`, or `u̇` in generalized speeds) at symbol values
/// `bindings` (indexed by symbol id).
pub fn accelerations(model: &SymbolicModel, eom: &EquationsOfMotion, bindings: &[f64]) -> Vec<f64> {
    let roots: Vec<_> = eom
        .mass_matrix
        .iter()
        .chain(&eom.forcing)
        .copied()
        .collect();
    let v = Evaluator::new(&model.arena, &roots).eval(bindings);
    let n = eom.num_dofs;
    solve(v[..n * n].to_vec(), v[n * n..].to_vec()).expect("M is regular at the sampled states")
}
