//! Compressed rows: a list of lists stored as one array of values and one of row starts (row r is
//! `values[start[r]..start[r + 1]]`), for adjacency that is built once and read often.

/// Compressed rows from (row, value) pairs; values keep their input order within a row. Returns
/// `(start, values)`, `start` with `rows + 1` entries.
pub fn compressed_rows(
    rows: usize,
    pairs: impl Iterator<Item = (u32, u32)> + Clone,
) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; rows + 1];
    for (r, _) in pairs.clone() {
        start[r as usize + 1] += 1;
    }
    for i in 0..rows {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut values = vec![0u32; start[rows] as usize];
    for (r, v) in pairs {
        values[fill[r as usize] as usize] = v;
        fill[r as usize] += 1;
    }
    (start, values)
}
