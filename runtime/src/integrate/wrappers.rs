//! The parts every integrator type writes alike, written once: the constructors and controller
//! accessors of a method with a [`PiController`](super::PiController), its
//! [`Integrator`](super::Integrator) name and order, and the [`super::driver::Method`] that hands a
//! problem to the one driver loop ([`super::driver::run`]) with its stepper. Each method's file
//! keeps its type, its documentation and its stepper; these macros only spell out the glue
//! (and a stepper that keeps its ends in `StepEnds` its state accessors).

/// `new`, `with_controller`, `controller`, `Default` and the [`Integrator`](super::Integrator)
/// implementation of an adaptive explicit pair: a struct with one field
/// `controller: PiController`, adaptive unless
/// [`IntegratorOptions::fixed_step`](super::IntegratorOptions::fixed_step), whose stepper is `$stepper` for a system of
/// dimension `$dim`.
macro_rules! pi_controlled_integrator {
    (
        $ty:ident,
        name: $name:literal,
        order: $order:literal,
        error_order: $error_order:expr,
        controller: $controller:expr,
        new_doc: $new_doc:literal,
        stepper: |$dim:ident| $stepper:expr $(,)?
    ) => {
        impl Default for $ty {
            fn default() -> Self {
                Self {
                    controller: $controller,
                }
            }
        }

        impl $ty {
            #[doc = $new_doc]
            pub fn new() -> Self {
                Self::default()
            }

            /// Uses `controller` for the step sizes.
            pub fn with_controller(mut self, controller: PiController) -> Self {
                self.controller = controller;
                self
            }

            /// The step-size controller.
            pub fn controller(&self) -> &PiController {
                &self.controller
            }
        }

        impl Integrator for $ty {
            fn name(&self) -> &'static str {
                $name
            }

            fn order(&self) -> u32 {
                $order
            }
        }

        impl driver::Method for $ty {
            fn run(
                &mut self,
                problem: &Problem<'_>,
                system: &mut dyn OdeSystem,
            ) -> Result<Solution, IntegrationFailure> {
                let control =
                    Control::from_options(problem.options, &mut self.controller, $error_order);
                driver::run(problem, system, control, |shape| {
                    let $dim = shape.dim;
                    Ok($stepper)
                })
            }
        }
    };
}

/// `new` and the [`Integrator`](super::Integrator) implementation of a constant-step explicit
/// Runge–Kutta method given by its tableau (a `Default` struct with no settings).
macro_rules! fixed_step_integrator {
    ($ty:ident, name: $name:literal, order: $order:literal, tableau: $tableau:expr $(,)?) => {
        impl $ty {
            /// The method.
            pub fn new() -> Self {
                Self::default()
            }
        }

        impl Integrator for $ty {
            fn name(&self) -> &'static str {
                $name
            }

            fn order(&self) -> u32 {
                $order
            }
        }

        impl driver::Method for $ty {
            fn run(
                &mut self,
                problem: &Problem<'_>,
                system: &mut dyn OdeSystem,
            ) -> Result<Solution, IntegrationFailure> {
                driver::run(problem, system, Control::Fixed, |shape| {
                    Ok(ExplicitRk::new($tableau, shape.dim))
                })
            }
        }
    };
}

/// `Stepper::{t, y, derivative}` of a stepper that keeps its step's ends in a field
/// `ends: StepEnds`: the current time, state and `F` there.
macro_rules! stepper_state_from_ends {
    () => {
        fn t(&self) -> f64 {
            self.ends.t
        }

        fn y(&self) -> &[f64] {
            &self.ends.y
        }

        fn derivative(&self) -> &[f64] {
            &self.ends.f
        }
    };
}
