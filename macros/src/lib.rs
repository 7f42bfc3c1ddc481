//! The `model!` proc macro: a thin shell around `eomgen-symbolic`.
//!
//! `eomgen::model!("models/double_pendulum.yaml")` reads the file (relative to the file that
//! invokes the macro, like `include_str!`), validates it, derives the equations of motion (by
//! momentum balance for a model given by the kinematics of its bodies, by Lagrange's equations
//! for one given by its energies: `mechanics::preferred_formulation`), and emits a struct
//! named after the model with an `impl MechanicalSystem`.
//! Every problem in the file becomes a compile error `path:line:col: message`, all of them at
//! once.

use std::path::{Path, PathBuf};

use proc_macro::TokenStream;
use proc_macro2::Span;
use syn::LitStr;

use eomgen_symbolic::codegen::{self, EmitOptions, GenerateError};
use eomgen_symbolic::model::ReadError;

/// Generates the equations of motion of a model file at compile time.
///
/// The argument is a string literal: a path relative to the invoking source file (or
/// absolute). The expansion is a `pub struct` named after the model's `name` in
/// UpperCamelCase, with one `pub f64` field per parameter and `Default` from the file, and
/// an `impl eomgen::MechanicalSystem<N>`.
///
/// # Errors
/// A compile error for an unreadable file, and one per diagnostic of the model file, each
/// starting `path:line:col:`.
#[proc_macro]
pub fn model(input: TokenStream) -> TokenStream {
    match expand(input.into()) {
        Ok(tokens) => tokens.into(),
        Err(failure) => failure.into_tokens().into(),
    }
}

/// Why a model could not be generated, and what stands in for it.
struct Failure {
    error: syn::Error,
    /// `(struct name, number of coordinates)` when the file names its model: the expansion
    /// then also defines the name (as `eomgen::__private::ModelWithErrors<N>`), so that the
    /// code using the model raises no further errors ("cannot find type") after the file's.
    stand_in: Option<(String, usize)>,
}

impl Failure {
    fn into_tokens(self) -> proc_macro2::TokenStream {
        let mut tokens = self.error.into_compile_error();
        if let Some((name, n)) = self.stand_in {
            let ident = proc_macro2::Ident::new(&name, Span::call_site());
            let n = proc_macro2::Literal::usize_unsuffixed(n);
            tokens.extend(quote::quote! {
                #[doc(hidden)]
                pub type #ident = ::eomgen::__private::ModelWithErrors<#n>;
            });
        }
        tokens
    }
}

impl From<syn::Error> for Failure {
    fn from(error: syn::Error) -> Self {
        Self {
            error,
            stand_in: None,
        }
    }
}

/// The stand-in's name and size: from the loaded file, or (when it does not load) from a
/// top-level `name:` line, with one coordinate.
fn stand_in(
    source: &str,
    file: Option<&eomgen_symbolic::model::ModelFile>,
) -> Option<(String, usize)> {
    let (name, n) = match file {
        Some(f) => (f.name.value.clone(), f.coordinates.len().max(1)),
        None => {
            let line = source.lines().find_map(|l| l.strip_prefix("name:"))?;
            let value = line
                .split('#')
                .next()?
                .trim()
                .trim_matches(|c| c == '"' || c == '\'');
            (value.to_string(), 1)
        }
    };
    let name = codegen::struct_name(&name);
    eomgen_symbolic::model::schema::is_identifier(&name).then_some((name, n))
}

fn base_dir() -> PathBuf {
    let from_span = proc_macro::Span::call_site().local_file().and_then(|file| {
        let file = if file.is_relative() {
            // rustc reports paths relative to the working directory of the compilation,
            // which cargo sets to the workspace root or the package root.
            std::env::current_dir().ok()?.join(file)
        } else {
            file
        };
        file.parent().map(Path::to_path_buf)
    });
    from_span
        .or_else(|| std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from))
        .unwrap_or_default()
}

fn expand(input: proc_macro2::TokenStream) -> Result<proc_macro2::TokenStream, Failure> {
    let literal: LitStr = syn::parse2(input).map_err(|e| {
        syn::Error::new(
            e.span(),
            "expected the path of a model file as a string literal: `model!(\"models/x.yaml\")`",
        )
    })?;
    let literal_path = literal.value();
    let path = {
        let p = PathBuf::from(&literal_path);
        if p.is_absolute() {
            p
        } else {
            base_dir().join(p)
        }
    };
    // Messages name the file as the user wrote it; an absolute path inside the package (as
    // build.rs writes them) is shown relative to the package root: `models/x.yaml`.
    let written = std::env::var_os("CARGO_MANIFEST_DIR")
        .filter(|_| path.is_absolute() && Path::new(&literal_path).is_absolute())
        .and_then(|root| {
            path.strip_prefix(PathBuf::from(root))
                .ok()
                .map(|r| r.display().to_string())
        })
        .unwrap_or_else(|| literal_path.clone());
    let source = eomgen_symbolic::model::read_model_file(&path).map_err(|e| match e {
        ReadError::NotText { diagnostic, text } => {
            syn::Error::new(literal.span(), diagnostic.render(&written, &text))
        }
        e => syn::Error::new(
            literal.span(),
            format!(
                "cannot read model file `{written}` (looked at `{}`): {e}",
                path.display()
            ),
        ),
    })?;
    let errors = |diagnostics: Vec<eomgen_symbolic::model::Diagnostic>| {
        let mut all: Option<syn::Error> = None;
        for d in diagnostics {
            let e = syn::Error::new(literal.span(), d.render(&written, &source));
            match &mut all {
                Some(a) => a.combine(e),
                None => all = Some(e),
            }
        }
        all.unwrap_or_else(|| syn::Error::new(Span::call_site(), "invalid model"))
    };
    let file = eomgen_symbolic::model::load(&written, &source).map_err(|d| Failure {
        error: errors(d),
        stand_in: stand_in(&source, None),
    })?;
    let options = EmitOptions {
        crate_path: "::eomgen".to_string(),
        tracked_files: vec![path.to_string_lossy().into_owned()],
        source_display: written.clone(),
    };
    let tokens = codegen::generate(&file, &options).map_err(|e| Failure {
        error: match e {
            GenerateError::Diagnostics(d) => errors(d),
            GenerateError::Emit(message) => syn::Error::new(literal.span(), message),
        },
        stand_in: stand_in(&source, Some(&file)),
    })?;
    Ok(tokens)
}
