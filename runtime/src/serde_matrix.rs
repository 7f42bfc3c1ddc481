//! Serialisation of nalgebra values in reports: matrices as lists of rows, complex numbers as
//! `{"re", "im"}`.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serializer;
use serde::ser::{SerializeSeq as _, SerializeStruct as _};

/// `m` as a list of rows.
pub(crate) fn rows<S: Serializer>(m: &DMatrix<f64>, s: S) -> Result<S::Ok, S::Error> {
    let mut seq = s.serialize_seq(Some(m.nrows()))?;
    for r in m.row_iter() {
        let row: Vec<f64> = r.iter().copied().collect();
        seq.serialize_element(&row)?;
    }
    seq.end()
}

/// One complex number as `{"re", "im"}`.
pub(crate) fn complex<S: Serializer>(c: &Complex<f64>, s: S) -> Result<S::Ok, S::Error> {
    let mut st = s.serialize_struct("Complex", 2)?;
    st.serialize_field("re", &c.re)?;
    st.serialize_field("im", &c.im)?;
    st.end()
}

/// A wrapper that serialises one complex number as `{"re", "im"}`.
struct One<'a>(&'a Complex<f64>);

impl serde::Serialize for One<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        complex(self.0, s)
    }
}

/// A list of complex numbers, each `{"re", "im"}`.
pub(crate) fn complex_list<S: Serializer>(v: &[Complex<f64>], s: S) -> Result<S::Ok, S::Error> {
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for c in v {
        seq.serialize_element(&One(c))?;
    }
    seq.end()
}

/// A complex vector, each entry `{"re", "im"}`.
pub(crate) fn complex_vector<S: Serializer>(
    v: &DVector<Complex<f64>>,
    s: S,
) -> Result<S::Ok, S::Error> {
    complex_list(v.as_slice(), s)
}

/// A list of optional complex numbers, each `{"re", "im"}` or `null`.
pub(crate) fn option_complex_list<S: Serializer>(
    v: &[Option<Complex<f64>>],
    s: S,
) -> Result<S::Ok, S::Error> {
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for c in v {
        seq.serialize_element(&c.as_ref().map(One))?;
    }
    seq.end()
}

/// A complex matrix as a list of rows, each entry `{"re", "im"}`.
pub(crate) fn complex_rows<S: Serializer>(
    m: &DMatrix<Complex<f64>>,
    s: S,
) -> Result<S::Ok, S::Error> {
    struct Row<'a>(Vec<&'a Complex<f64>>);
    impl serde::Serialize for Row<'_> {
        fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            let mut seq = s.serialize_seq(Some(self.0.len()))?;
            for c in &self.0 {
                seq.serialize_element(&One(c))?;
            }
            seq.end()
        }
    }
    let mut seq = s.serialize_seq(Some(m.nrows()))?;
    for i in 0..m.nrows() {
        seq.serialize_element(&Row((0..m.ncols()).map(|j| &m[(i, j)]).collect()))?;
    }
    seq.end()
}
