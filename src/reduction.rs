//! Method II.2 for the studies: a model's holonomic constraints eliminated symbolically
//! ([`eomgen_symbolic::model::reduce`]) and the reduced file compiled at run time
//! ([`JitModel::from_source`]), which
//! [`analysis::constraint_methods_with_reduced`](crate::analysis::constraint_methods_with_reduced)
//! runs beside the DAE (lectures 8–10, HW13).

use eomgen_symbolic::model::reduce::{ReduceError, ReduceOptions, ReducedModel, reduce};

use crate::{DynFirstOrder, JitModel, LoadError, ModelInfo, ModelSource};

/// Most choices of kept coordinates [`reduced_twin`] tries.
pub const MAX_CHOICES: usize = 64;

/// A model reduced to minimal coordinates and compiled.
#[derive(Debug, Clone)]
pub struct ReducedTwin {
    /// The reduction: the file's text, the eliminations and notes.
    pub reduced: ReducedModel,
    /// The reduced file compiled.
    pub model: JitModel,
}

impl ReducedTwin {
    /// The kept coordinates, comma separated (`x`), as the study's row names them.
    pub fn label(&self) -> String {
        self.reduced.kept.join(", ")
    }

    /// A new instance with the file's default parameters.
    pub fn instantiate(&self) -> Box<dyn ModelInfo> {
        Box::new(DynFirstOrder::new(self.model.clone()))
    }
}

/// Why a model has no reduced twin.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReducedTwinError {
    /// The model file could not be read or loaded.
    #[error("`{path}` cannot be read as a model file: {message}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
    /// No choice of kept coordinates reduces: the first choice's reason.
    #[error("its constraints cannot be eliminated: {0}")]
    NotReducible(ReduceError),
    /// The reduced file did not compile.
    #[error(transparent)]
    Compile(#[from] LoadError),
}

/// The model of `source` reduced to minimal coordinates (method II.2).
///
/// The coordinates kept are chosen among the choices of as many coordinates as the model has
/// degrees of freedom (in the file's order, first coordinates first, at most
/// [`MAX_CHOICES`]): the first that reduces with a start where the reduced coordinates are
/// regular ([`ReduceError::SingularStart`] otherwise). The branches are those of the file's
/// initial state or equilibria ([`reduce`]).
///
/// # Errors
/// [`ReducedTwinError::Read`], [`ReducedTwinError::NotReducible`] (with the reason of the
/// first choice: a constraint that is not polynomial of degree ≤ 2 in a coordinate, a part of
/// the format the elimination does not rewrite, no holonomic constraints),
/// [`ReducedTwinError::Compile`].
///
/// # Examples
/// ```
/// let rod = eomgen::ModelSource::open("two_masses_rod")?;
/// let twin = eomgen::reduction::reduced_twin(&rod)?;
/// assert_eq!(twin.label(), "x1");
/// assert_eq!(twin.reduced.eliminations[0].solution, "x1 + l0");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reduced_twin(source: &ModelSource) -> Result<ReducedTwin, ReducedTwinError> {
    let path = source.path().to_string();
    let read = |message: String| ReducedTwinError::Read {
        path: path.clone(),
        message,
    };
    let bytes = source.bytes().map_err(|e| read(e.to_string()))?;
    let text = eomgen_symbolic::model::decode(&bytes).map_err(|d| read(d.message))?;
    let file = eomgen_symbolic::model::load(&path, text)
        .map_err(|d| read(format!("{} error(s)", d.len())))?;
    let names: Vec<&str> = file
        .coordinates
        .iter()
        .map(|c| c.name.value.as_str())
        .collect();
    let keep = names.len().saturating_sub(file.constraints.len());
    let mut first_error = None;
    for choice in choices(names.len(), keep).take(MAX_CHOICES) {
        let kept: Vec<&str> = choice.iter().map(|&i| names[i]).collect();
        match reduce(&file, &kept, &ReduceOptions::default()) {
            Ok(r) => return compile(r),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(ReducedTwinError::NotReducible(first_error.unwrap_or_else(
        || ReduceError::NoConstraints {
            model: file.name.value.clone(),
        },
    )))
}

fn compile(reduced: ReducedModel) -> Result<ReducedTwin, ReducedTwinError> {
    let path = format!("{}.yaml", reduced.file.name.value);
    let model = JitModel::from_source(&path, &reduced.text)?;
    Ok(ReducedTwin { reduced, model })
}

/// The `k`-element subsets of `0..n` in lexicographic order.
fn choices(n: usize, k: usize) -> impl Iterator<Item = Vec<usize>> {
    let mut next = (k <= n).then(|| (0..k).collect::<Vec<usize>>());
    std::iter::from_fn(move || {
        let current = next.take()?;
        // The next subset: the last index that can move, moved, and the ones after it reset.
        let mut c = current.clone();
        let mut i = k;
        while i > 0 {
            i -= 1;
            if c[i] < n - k + i {
                c[i] += 1;
                for j in i + 1..k {
                    c[j] = c[j - 1] + 1;
                }
                next = Some(c);
                break;
            }
        }
        Some(current)
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn choices_are_the_subsets_in_order() {
        let all: Vec<Vec<usize>> = super::choices(4, 2).collect();
        assert_eq!(
            all,
            vec![
                vec![0, 1],
                vec![0, 2],
                vec![0, 3],
                vec![1, 2],
                vec![1, 3],
                vec![2, 3]
            ]
        );
        assert_eq!(super::choices(2, 0).count(), 1);
        assert_eq!(super::choices(1, 2).count(), 0);
    }
}
