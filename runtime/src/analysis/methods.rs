//! The registry of integration methods: one [`Method`] per [`Integrator`], its
//! command-line name, its name in the literature, and the integrator it builds.
//!
//! A front end selects a method by name (`"dp54".parse::<Method>()`), and every analysis
//! that compares methods (work–precision, stability) iterates over [`Method::ALL`].
//!
//! References: E. Hairer, S. P. Nørsett, G. Wanner, *Solving Ordinary Differential Equations
//! I*, 2nd ed., Springer, 1993 (the explicit Runge–Kutta methods and DOP853); E. Hairer,
//! G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996 (Radau
//! IIA 5); E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd ed.,
//! Springer, 2006 (symplectic Euler, Störmer–Verlet, implicit midpoint); J. H. Verner,
//! "Numerically optimal Runge–Kutta pairs with interpolants", Numer. Algorithms 53, 383–396,
//! 2010, doi:10.1007/s11075-009-9290-3 (the Verner pairs).

use std::fmt;
use std::str::FromStr;

use nalgebra::Complex;
use serde::Serialize;

use crate::integrate::stability_function::{
    StabilityPolynomial, implicit_midpoint_stability, partitioned_oscillator_spectral_radius,
};
use crate::integrate::{
    BogackiShampine32, DormandPrince54, DormandPrince853, ExplicitEuler, ExplicitMidpoint,
    ImplicitMidpoint, Integrator, RadauIIA5, RungeKutta4, StormerVerlet, SymplecticEuler, Tableau,
    Taylor, Verner65, Verner76, Verner87, Verner98,
};

/// An integration method, by its command-line name.
///
/// Adaptive methods ([`Method::is_adaptive`]) control their step by `rtol`/`atol`; the
/// others take a fixed step `dt`. Serialised (and displayed, and parsed) by its
/// command-line name, [`Method::name`] (`"dp54"`).
///
/// # Examples
/// ```
/// use eomgen_runtime::analysis::Method;
///
/// let method: Method = "dp54".parse().unwrap();
/// assert_eq!(method, Method::Dp54);
/// assert!(method.is_adaptive());
/// assert_eq!(method.display_name(), "Dormand–Prince 5(4)");
/// assert_eq!(method.integrator().name(), "dp54");
/// let error = "rk5".parse::<Method>().unwrap_err();
/// assert!(error.to_string().contains("euler, midpoint, rk4"));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Explicit Euler, order 1, fixed step.
    Euler,
    /// Explicit midpoint, order 2, fixed step.
    Midpoint,
    /// Classical Runge–Kutta 4, fixed step.
    Rk4,
    /// Bogacki–Shampine 3(2) (ode23), adaptive, Hermite dense output.
    Bs32,
    /// Dormand–Prince 5(4), adaptive, dense output.
    Dp54,
    /// DOP853, Hairer's Dormand–Prince 8(5,3), adaptive, order-7 dense output.
    Dop853,
    /// Verner's "most efficient" 6(5) pair, adaptive, order-6 dense output.
    Vern6,
    /// Verner's "most efficient" 7(6) pair, adaptive, order-7 dense output.
    Vern7,
    /// Verner's "most efficient" 8(7) pair, adaptive, order-8 dense output.
    Vern8,
    /// Verner's "most efficient" 9(8) pair, adaptive, order-9 dense output.
    Vern9,
    /// The Taylor method of the model's generated recurrences, adaptive order and step from
    /// the tolerance (Jorba & Zou 2005); unconstrained models whose equations have
    /// recurrences.
    Taylor,
    /// Symplectic Euler, order 1, fixed step (symplectic for constant M and
    /// velocity-independent forces).
    SymplecticEuler,
    /// Störmer–Verlet (leapfrog in q, q̇), order 2, fixed step (symplectic for constant M
    /// and velocity-independent forces).
    StormerVerlet,
    /// Implicit midpoint, order 2, fixed step, Newton with the generated Jacobians
    /// (symplectic for any M(q)).
    ImplicitMidpoint,
    /// Radau IIA order 5 (RADAU5), adaptive, L-stable, Newton with the generated Jacobians.
    Radau5,
}

/// A method name that is none of [`Method::ALL`]'s.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown integration method `{name}` (valid: {})", Method::names().join(", "))]
pub struct UnknownMethod {
    /// The name as given.
    pub name: String,
}

/// What the registry holds of one method: a row of the one table that the library, the
/// CLI's `--help`, the Python package (`eomgen.METHODS`) and the docs read.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct MethodInfo {
    /// The method.
    pub method: Method,
    /// The command-line name (`"dp54"`), which [`FromStr`] parses.
    pub name: &'static str,
    /// The literature's name (`"Dormand–Prince 5(4)"`), as charts and tables label it.
    pub display_name: &'static str,
    /// Whether it controls its step by `rtol`/`atol` (otherwise it takes the fixed step
    /// `dt`).
    pub adaptive: bool,
    /// Whether each step solves a nonlinear system by Newton's method with the model's
    /// Jacobians.
    pub implicit: bool,
    /// One line on the method: order, step, dense output, what it suits (`--method`'s help).
    pub summary: &'static str,
    /// A new integrator of the method, with its default settings.
    #[serde(skip)]
    pub build: Constructor,
    /// The amplification per step `ρ(z)`, `z = hλ`, of a fixed-step method (the modulus of
    /// its stability function; for the partitioned methods, the spectral radius of a step on
    /// the oscillator of frequency `|z|/h`, exact for an undamped mode); `None` for an
    /// adaptive method, whose step control handles stability.
    #[serde(skip)]
    pub amplification: Option<Amplification>,
}

/// A new integrator of a method, with its default settings ([`MethodInfo::build`]).
pub type Constructor = fn() -> Box<dyn Integrator>;

/// The amplification per step `ρ(z)` of a fixed-step method ([`MethodInfo::amplification`]).
pub type Amplification = fn(Complex<f64>) -> f64;

/// A row of [`TABLE`].
const fn row(
    method: Method,
    (name, display_name): (&'static str, &'static str),
    (adaptive, implicit): (bool, bool),
    summary: &'static str,
    (build, amplification): (Constructor, Option<Amplification>),
) -> MethodInfo {
    MethodInfo {
        method,
        name,
        display_name,
        adaptive,
        implicit,
        summary,
        build,
        amplification,
    }
}

/// `|R(z)|` of an explicit tableau.
fn tableau_amplification(tableau: Tableau, z: Complex<f64>) -> f64 {
    StabilityPolynomial::of_tableau(&tableau).eval(z).norm()
}

/// `(adaptive, implicit)` of an explicit method with an error estimate.
const ADAPTIVE: (bool, bool) = (true, false);
/// `(adaptive, implicit)` of an explicit method with a fixed step.
const FIXED: (bool, bool) = (false, false);
/// `(adaptive, implicit)` of an implicit method with a fixed step.
const IMPLICIT_FIXED: (bool, bool) = (false, true);
/// `(adaptive, implicit)` of an implicit method with an error estimate.
const IMPLICIT_ADAPTIVE: (bool, bool) = (true, true);

/// The methods, in [`Method`]'s order (the order the CLI lists them): adding a method is a
/// variant of [`Method`] and a row here.
#[rustfmt::skip]
static TABLE: [MethodInfo; 15] = [
    row(Method::Euler, ("euler", "explicit Euler"), FIXED,
        "Explicit Euler, order 1, fixed step `--dt`",
        (|| Box::new(ExplicitEuler::new()), Some(|z| tableau_amplification(Tableau::euler(), z)))),
    row(Method::Midpoint, ("midpoint", "explicit midpoint"), FIXED,
        "Explicit midpoint, order 2, fixed step `--dt`",
        (|| Box::new(ExplicitMidpoint::new()), Some(|z| tableau_amplification(Tableau::midpoint(), z)))),
    row(Method::Rk4, ("rk4", "RK4"), FIXED,
        "Classical Runge–Kutta 4, fixed step `--dt`",
        (|| Box::new(RungeKutta4::new()), Some(|z| tableau_amplification(Tableau::rk4(), z)))),
    row(Method::Bs32, ("bs32", "Bogacki–Shampine 3(2)"), ADAPTIVE,
        "Bogacki–Shampine 3(2) (ode23), adaptive, Hermite dense output",
        (|| Box::new(BogackiShampine32::new()), None)),
    row(Method::Dp54, ("dp54", "Dormand–Prince 5(4)"), ADAPTIVE,
        "Dormand–Prince 5(4), adaptive, dense output (default)",
        (|| Box::new(DormandPrince54::new()), None)),
    row(Method::Dop853, ("dop853", "DOP853"), ADAPTIVE,
        "DOP853, Hairer's Dormand–Prince 8(5,3), adaptive, order-7 dense output",
        (|| Box::new(DormandPrince853::new()), None)),
    row(Method::Vern6, ("vern6", "Verner 6(5)"), ADAPTIVE,
        "Verner's most efficient 6(5) pair, adaptive, order-6 dense output",
        (|| Box::new(Verner65::new()), None)),
    row(Method::Vern7, ("vern7", "Verner 7(6)"), ADAPTIVE,
        "Verner's most efficient 7(6) pair, adaptive, order-7 dense output",
        (|| Box::new(Verner76::new()), None)),
    row(Method::Vern8, ("vern8", "Verner 8(7)"), ADAPTIVE,
        "Verner's most efficient 8(7) pair, adaptive, order-8 dense output",
        (|| Box::new(Verner87::new()), None)),
    row(Method::Vern9, ("vern9", "Verner 9(8)"), ADAPTIVE,
        "Verner's most efficient 9(8) pair, adaptive, order-9 dense output (tolerances of 1e-12 and below)",
        (|| Box::new(Verner98::new()), None)),
    row(Method::Taylor, ("taylor", "Taylor"), ADAPTIVE,
        "Taylor series of the model's generated recurrences, order and step from the tolerance (Jorba & Zou), the series as dense output; models without abs, sign, step (constraints: none or projection)",
        (|| Box::new(Taylor::new()), None)),
    row(Method::SymplecticEuler, ("symplectic-euler", "symplectic Euler"), FIXED,
        "Symplectic Euler, order 1, fixed step `--dt` (symplectic for constant M and velocity-independent forces)",
        (|| Box::new(SymplecticEuler::new()), Some(|z| partitioned_oscillator_spectral_radius(z.norm())))),
    row(Method::StormerVerlet, ("stormer-verlet", "Störmer–Verlet"), FIXED,
        "Störmer–Verlet (leapfrog in q, q̇), order 2, fixed step `--dt` (symplectic for constant M and velocity-independent forces)",
        (|| Box::new(StormerVerlet::new()), Some(|z| partitioned_oscillator_spectral_radius(z.norm())))),
    row(Method::ImplicitMidpoint, ("implicit-midpoint", "implicit midpoint"), IMPLICIT_FIXED,
        "Implicit midpoint, order 2, fixed step `--dt`, Newton with the generated Jacobians (symplectic for any M(q))",
        (|| Box::new(ImplicitMidpoint::new()), Some(|z| implicit_midpoint_stability(z).norm()))),
    row(Method::Radau5, ("radau5", "Radau IIA 5"), IMPLICIT_ADAPTIVE,
        "Radau IIA order 5 (RADAU5), adaptive, L-stable, Newton with the generated Jacobians",
        (|| Box::new(RadauIIA5::new()), None)),
];

impl Method {
    /// Every method, in the order the CLI lists them.
    pub const ALL: [Method; 15] = {
        let mut all = [Method::Euler; 15];
        let mut i = 0;
        while i < all.len() {
            all[i] = TABLE[i].method;
            i += 1;
        }
        all
    };

    /// The method's row of the registry's table.
    pub fn info(self) -> &'static MethodInfo {
        // The table is in the variants' order (`every_row_is_its_variants`).
        &TABLE[self as usize]
    }

    /// The rows of every method, in [`Method::ALL`]'s order.
    pub fn table() -> &'static [MethodInfo] {
        &TABLE
    }

    /// The command-line name (`"dp54"`, `"stormer-verlet"`), which [`FromStr`] parses.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The command-line names of [`Method::ALL`], in order.
    pub fn names() -> Vec<&'static str> {
        TABLE.iter().map(|row| row.name).collect()
    }

    /// The literature's name of the method (`"Dormand–Prince 5(4)"`), as charts and tables
    /// label it.
    pub fn display_name(self) -> &'static str {
        self.info().display_name
    }

    /// One line on the method (`--method`'s help).
    pub fn summary(self) -> &'static str {
        self.info().summary
    }

    /// A new integrator of this method, with its default settings.
    pub fn integrator(self) -> Box<dyn Integrator> {
        (self.info().build)()
    }

    /// The amplification per step `ρ(z)`, `z = hλ`, of a fixed-step method
    /// ([`MethodInfo::amplification`]); `None` for an adaptive one.
    pub fn amplification(self, z: Complex<f64>) -> Option<f64> {
        self.info().amplification.map(|rho| rho(z))
    }

    /// Whether the method controls its step by `rtol`/`atol` (otherwise it takes the fixed
    /// step `dt`).
    pub fn is_adaptive(self) -> bool {
        self.info().adaptive
    }

    /// Whether each step solves a nonlinear system by Newton's method with the model's
    /// Jacobians (implicit midpoint, Radau IIA 5).
    pub fn is_implicit(self) -> bool {
        self.info().implicit
    }
}

impl fmt::Display for Method {
    /// The command-line name, [`Method::name`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = UnknownMethod;

    /// The method whose [`Method::name`] is `name` (exactly, case-sensitive).
    ///
    /// # Errors
    /// [`UnknownMethod`], whose message lists the valid names.
    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| UnknownMethod {
                name: name.to_string(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Method::info` indexes the table by the variant's discriminant.
    #[test]
    fn every_row_is_its_variants() {
        for (i, row) in TABLE.iter().enumerate() {
            assert_eq!(row.method as usize, i, "{}", row.name);
            assert_eq!(row.method.info().name, row.name);
        }
        let mut names = Method::names();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), TABLE.len());
    }

    #[test]
    fn every_name_parses_back_to_its_method() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>(), Ok(m));
            assert_eq!(m.to_string(), m.name());
            assert_eq!(
                serde_json::to_value(m).unwrap(),
                serde_json::Value::String(m.name().to_string())
            );
        }
    }

    /// Adaptive: the methods with an error estimate, and the Taylor method, whose steps come
    /// from its series' radius of convergence.
    #[test]
    fn adaptive_methods_are_those_with_an_error_estimate() {
        let adaptive: Vec<_> = Method::ALL
            .into_iter()
            .filter(|m| m.is_adaptive())
            .collect();
        assert_eq!(
            adaptive,
            [
                Method::Bs32,
                Method::Dp54,
                Method::Dop853,
                Method::Vern6,
                Method::Vern7,
                Method::Vern8,
                Method::Vern9,
                Method::Taylor,
                Method::Radau5
            ]
        );
    }

    #[test]
    fn integrator_names_match_except_dopri5() {
        for m in Method::ALL {
            let expected = m.name();
            assert_eq!(m.integrator().name(), expected);
        }
    }

    #[test]
    fn unknown_name_is_a_typed_error_listing_the_names() {
        let e = "Dp54".parse::<Method>().unwrap_err();
        assert_eq!(e.name, "Dp54");
        assert_eq!(
            e.to_string(),
            "unknown integration method `Dp54` (valid: euler, midpoint, rk4, bs32, dp54, dop853, vern6, vern7, vern8, vern9, taylor, symplectic-euler, stormer-verlet, implicit-midpoint, radau5)"
        );
    }
}
