//! serde support for `faer::Mat<f64>` fields (`#[serde(with = "serde_mat")]`): stored as
//! `{rows, cols, data}` with `data` in column-major order.

use faer::Mat;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

#[derive(Serialize, Deserialize)]
struct Stored {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

/// Writes `m` as `{rows, cols, data}`.
pub fn serialize<S: Serializer>(m: &Mat<f64>, s: S) -> Result<S::Ok, S::Error> {
    let data = (0..m.ncols())
        .flat_map(|j| (0..m.nrows()).map(move |i| m[(i, j)]))
        .collect();
    Stored {
        rows: m.nrows(),
        cols: m.ncols(),
        data,
    }
    .serialize(s)
}

/// Reads a matrix written by [`serialize`], checking that `data` has `rows * cols` values.
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Mat<f64>, D::Error> {
    let st = Stored::deserialize(d)?;
    if st.rows.checked_mul(st.cols) != Some(st.data.len()) {
        return Err(D::Error::custom(format!(
            "matrix of {} x {} holds {} values",
            st.rows,
            st.cols,
            st.data.len()
        )));
    }
    Ok(Mat::from_fn(st.rows, st.cols, |i, j| {
        st.data[j * st.rows + i]
    }))
}
