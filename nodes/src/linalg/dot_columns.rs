//! Many dot products against one vector at once, for rows stored by
//! columns: the sums of [`super::dot`], bit for bit, four rows at a time in
//! vector registers instead of one short row at a time.

/// Rows computed together: one vector of running sums per lane of [`super::dot`].
pub const ROWS: usize = 4;

/// `out[i] = dot(row_i[..w.len()], w)` for `out.len()` rows (a multiple of
/// [`ROWS`]) whose element t sits at `cols[t·stride + i]`: each row's sum
/// is [`super::dot`]'s — its four running sums over the whole chunks of
/// four, their pairwise total, then the tail in order — so every result
/// has the same bits as the row-by-row dot product, while the additions
/// run across four rows in one vector.
///
/// # Panics
///
/// When `out.len()` is not a multiple of [`ROWS`], is wider than `stride`,
/// or the last column's `out.len()` values run past the end of `cols`
/// (callers size all three once, up front).
#[inline(always)]
pub fn dot_columns(cols: &[f64], stride: usize, w: &[f64], out: &mut [f64]) {
    let rows = out.len();
    assert!(
        rows.is_multiple_of(ROWS) && (w.is_empty() || (stride >= rows && (w.len() - 1) * stride + rows <= cols.len())),
        "dot_columns: {rows} rows of {} columns (stride {stride}) do not fit in {} values",
        w.len(),
        cols.len()
    );
    let full = w.len() / 4 * 4;
    for (b, o) in out.chunks_exact_mut(ROWS).enumerate() {
        let base = cols[b * ROWS..].as_ptr();
        // SAFETY: column t < w.len() of this block is
        // cols[t·stride + b·ROWS ..][..ROWS], within `cols` by the assert.
        let col = |t: usize| -> [f64; ROWS] { unsafe { base.add(t * stride).cast::<[f64; ROWS]>().read_unaligned() } };
        // acc[l][r]: lane l of row b·ROWS + r's four running sums.
        let mut acc = [[0.0f64; ROWS]; 4];
        for (t, x4) in w[..full].chunks_exact(4).enumerate() {
            for (l, a) in acc.iter_mut().enumerate() {
                let (c, x) = (col(4 * t + l), x4[l]);
                for r in 0..ROWS {
                    a[r] += c[r] * x;
                }
            }
        }
        let mut s = [0.0f64; ROWS];
        for r in 0..ROWS {
            s[r] = (acc[0][r] + acc[1][r]) + (acc[2][r] + acc[3][r]);
        }
        for (t, &x) in w.iter().enumerate().skip(full) {
            let c = col(t);
            for r in 0..ROWS {
                s[r] += c[r] * x;
            }
        }
        o.copy_from_slice(&s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::dot;
    use crate::rng::Rng;

    #[test]
    fn every_row_has_the_bits_of_its_dot_product() {
        let mut r = Rng::new(11);
        // Lengths around the chunk of four, stride wider than the rows,
        // values over many magnitudes and signs (so association shows).
        for len in 0..=13 {
            for rows in [4, 8, 12] {
                let stride = rows + 3;
                let mut value = || (2.0 * r.uniform() - 1.0) * 10f64.powi((r.uniform() * 12.0) as i32 - 6);
                let cols: Vec<f64> = (0..len.max(1) * stride).map(|_| value()).collect();
                let w: Vec<f64> = (0..len).map(|_| value()).collect();
                let mut out = vec![f64::NAN; rows];
                dot_columns(&cols, stride, &w, &mut out);
                for (i, o) in out.iter().enumerate() {
                    let row: Vec<f64> = (0..len).map(|t| cols[t * stride + i]).collect();
                    assert_eq!(o.to_bits(), dot(&row, &w).to_bits(), "len {len}, rows {rows}, row {i}");
                }
            }
        }
    }

    #[test]
    fn signed_zeros_come_out_as_the_dot_products() {
        // dot starts its sums from +0: a row of −0 products sums to +0.
        let cols = [-0.0; 4 * 5];
        let mut out = [1.0; 4];
        dot_columns(&cols, 4, &[1.0; 5], &mut out);
        let want = dot(&[-0.0; 5], &[1.0; 5]);
        assert!(out.iter().all(|o| o.to_bits() == want.to_bits()));
    }
}
