//! The one construction of ode_solvers' steppers that `peers.rs` (a bench) and
//! `work_precision_peers.rs` (the work-precision program) both use, so that the peer runs in
//! both with the same settings.

/// ode_solvers' `$solver` (`Dopri5` or `Dop853`, whose `from_param` take the same arguments)
/// on `$system` (an ode_solvers `System`) from `$y0` (its state vector) over `0 ≤ t ≤ $t_end`
/// at `rtol = atol = $tol`, with the controller's `beta` and step-ratio bounds `[fac_min,
/// fac_max]`, safety 0.9, `h_max = $t_end`, automatic first step, at most `$n_max` steps,
/// stiffness test every 1000 steps (the default), every step recorded (`OutputType::Sparse`).
macro_rules! peer_stepper {
    ($solver:ident, $system:expr, $y0:expr, $t_end:expr, $tol:expr, $beta:expr,
     $fac_min:expr, $fac_max:expr, $n_max:expr) => {
        // (f, x, x_end, dx (unused by Sparse), y, rtol, atol, safety, beta, fac_min,
        //  fac_max, h_max, h (0: automatic), n_max, n_stiff, out_type)
        $solver::from_param(
            $system,
            0.0,
            $t_end,
            $t_end,
            $y0,
            $tol,
            $tol,
            0.9,
            $beta,
            $fac_min,
            $fac_max,
            $t_end,
            0.0,
            $n_max,
            1000,
            ode_solvers::OutputType::Sparse,
        )
    };
}
