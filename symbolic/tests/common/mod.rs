//! Model sources shared by the symbolic crate's test files.

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
