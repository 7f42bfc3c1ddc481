//! Serialisation of nalgebra values in reports: matrices as lists of rows, complex numbers as
//! `{"re", "im"}`.

use nalgebra::{Complex, DMatrix};
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
