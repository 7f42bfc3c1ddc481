//! The commands: one file per command or study, each parsing its own options, calling the
//! library and rendering the result (text, JSON, charts, files).
//!
//! A command imports the library and the shared pieces of the CLI (`crate::cli::…`: the
//! error, opening a model, the integration and operating-point options, files, charts), never
//! another command: what two commands share is a shared piece. `tests/cli.rs`
//! (`commands_import_no_other_command`) checks that no file here names `super::` or
//! `commands::` outside its tests.

pub(super) mod animate;
pub(super) mod check;
pub(super) mod constraint_methods;
pub(super) mod convolution;
pub(super) mod equations;
pub(super) mod euler_roundoff;
pub(super) mod expm;
pub(super) mod floquet;
pub(super) mod free_response;
pub(super) mod frf;
pub(super) mod launch;
pub(super) mod list;
pub(super) mod modal_damping;
pub(super) mod modes;
pub(super) mod parameter_sweep;
pub(super) mod periodic_orbit;
pub(super) mod rayleigh;
pub(super) mod reduce;
pub(super) mod report;
pub(super) mod rolling_contact;
pub(super) mod simulate;
pub(super) mod stability;
pub(super) mod work_precision;
