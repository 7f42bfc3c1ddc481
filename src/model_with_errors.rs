//! The stand-in that `model!` emits beside the compile errors of a model file with mistakes.
//!
//! A model file with mistakes expands to its compile errors (each `file:line:col` with a
//! `help:`) and to `type Name = ModelWithErrors<N>;`, so that the code that uses the model
//! still type-checks and the errors of the file are the only ones the user reads (rather
//! than "cannot find type `Name`" at every use). The crate cannot be built while those
//! errors stand, so no value of this type is ever evaluated: its methods return an empty
//! description (no coordinates, although `N` may be more) and zeros only to satisfy the trait.

use std::borrow::Cow;

use crate::{MechanicalSystem, ModelDescription, UnknownParameter};
use nalgebra::{SMatrix, SVector};

/// What `model!` names a model with errors (see the module docs): `N` is the number of
/// coordinates the file declares (1 when the file could not be read that far).
#[doc(hidden)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ModelWithErrors<const N: usize>;

impl<const N: usize> MechanicalSystem<N> for ModelWithErrors<N> {
    fn description(&self) -> &ModelDescription {
        static DESCRIPTION: ModelDescription = ModelDescription {
            name: Cow::Borrowed("model with errors"),
            summary: Cow::Borrowed("a model file with errors (see the compile errors)"),
            ..ModelDescription::EMPTY
        };
        &DESCRIPTION
    }
    fn parameter_values(&self) -> Vec<f64> {
        Vec::new()
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), UnknownParameter> {
        let _ = value;
        Err(UnknownParameter {
            model: self.description().name.to_string(),
            name: name.to_string(),
            known: String::new(),
        })
    }
    fn initial_state(&self) -> (SVector<f64, N>, SVector<f64, N>) {
        (SVector::zeros(), SVector::zeros())
    }
    fn mass_matrix(&self, _: &SVector<f64, N>, _: f64) -> SMatrix<f64, N, N> {
        SMatrix::zeros()
    }
    fn forcing(&self, _: &SVector<f64, N>, _: &SVector<f64, N>, _: f64) -> SVector<f64, N> {
        SVector::zeros()
    }
    fn mass_matrix_and_forcing(
        &self,
        _: &SVector<f64, N>,
        _: &SVector<f64, N>,
        _: f64,
    ) -> (SMatrix<f64, N, N>, SVector<f64, N>) {
        (SMatrix::zeros(), SVector::zeros())
    }
    fn forcing_jacobian_q(
        &self,
        _: &SVector<f64, N>,
        _: &SVector<f64, N>,
        _: f64,
    ) -> SMatrix<f64, N, N> {
        SMatrix::zeros()
    }
    fn forcing_jacobian_qdot(
        &self,
        _: &SVector<f64, N>,
        _: &SVector<f64, N>,
        _: f64,
    ) -> SMatrix<f64, N, N> {
        SMatrix::zeros()
    }
    fn mass_matrix_product_jacobian(
        &self,
        _: &SVector<f64, N>,
        _: f64,
        _: &SVector<f64, N>,
    ) -> SMatrix<f64, N, N> {
        SMatrix::zeros()
    }
    fn kinetic_energy(&self, _: &SVector<f64, N>, _: &SVector<f64, N>, _: f64) -> f64 {
        0.0
    }
    fn potential_energy(&self, _: &SVector<f64, N>, _: f64) -> f64 {
        0.0
    }
    fn point_positions(&self, _: &SVector<f64, N>, _: f64, _: &mut [[f64; 3]]) {}
}
