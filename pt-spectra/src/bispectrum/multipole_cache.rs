//! The multipole tensors' cache file ([`super::multipole_basis::MultipoleLoopBasis`] in
//! [`crate::store::TableStore`]): one declared layout of f64 values, read back only if every count fits.
//!
//! Per triangle: its Legendre side, its orientations (3 components of the line of sight and 3 multipole
//! weights each), the templates at the sides (3m), σ²'s two vectors (2m), then the families B₂₂₂, B₃₂₁ᴵ,
//! J, L, the tree level and the tree level per orientation, each as: the number of rows r, the row length
//! ℓ, whether its values are f32 (0 or 1), the length d of the rows of rule − half rule (ℓ for f64 rows), 4r
//! indices, then the values on the rule (rℓ) and rule − half rule (rd) and U (r or 0). J and L in f32
//! (flag 1) hold the renormalised rows J − U s; in f64 (flag 0, files written before they were stored in
//! f32) the bare J, renormalised and moved to f32 when read.

use super::multipole_tensors::{Rows, TriangleTensors};
use super::one_loop::Vec3;

/// A triangle's orientations: lines of sight and multipole weights.
pub(super) type Orientations = (Vec<Vec3>, Vec<[f64; 3]>);

/// Appends `rows` with row length `len`.
pub(super) fn write_rows(rows: &Rows, len: usize, out: &mut Vec<f64>) {
    let single = !rows.single.0.is_empty();
    let diff_len = if single && !rows.index.is_empty() {
        rows.single.1.len() / rows.index.len()
    } else {
        len
    };
    out.extend([
        rows.index.len() as f64,
        len as f64,
        f64::from(u8::from(single)),
        diff_len as f64,
    ]);
    out.extend(rows.index.iter().flatten().map(|&i| f64::from(i)));
    if single {
        out.extend(
            rows.single
                .0
                .iter()
                .chain(&rows.single.1)
                .map(|&x| f64::from(x)),
        );
    } else {
        out.extend(rows.fine.iter().chain(&rows.diff));
    }
    out.extend(&rows.uv);
}

/// A reader of the values, `None` past their end.
pub(super) struct Reader<'a> {
    pub(super) values: &'a [f64],
}

impl<'a> Reader<'a> {
    pub(super) fn take(&mut self, n: usize) -> Option<&'a [f64]> {
        if n > self.values.len() {
            return None;
        }
        let (head, rest) = self.values.split_at(n);
        self.values = rest;
        Some(head)
    }

    /// A count stored as f64: a non-negative integer below `max`.
    pub(super) fn count(&mut self, max: usize) -> Option<usize> {
        let v = self.take(1)?[0];
        (v >= 0.0 && v.fract() == 0.0 && v < max as f64).then_some(v as usize)
    }

    /// `n` indices of `N` entries each, every entry an integer in [0, 65536).
    pub(super) fn indices<const N: usize>(&mut self, n: usize) -> Option<Vec<[u16; N]>> {
        self.take(N * n)?
            .chunks_exact(N)
            .map(|c| {
                let ok = c
                    .iter()
                    .all(|&x| x >= 0.0 && x.fract() == 0.0 && x < 65536.0);
                ok.then(|| std::array::from_fn(|i| c[i] as u16))
            })
            .collect()
    }

    /// Rows of length `len` with or without U.
    pub(super) fn rows(&mut self, len: usize, with_uv: bool) -> Option<Rows> {
        let r = self.count(1 << 24)?;
        if self.count(1 << 24)? != len {
            return None;
        }
        let single = self.count(2)? == 1;
        let diff_len = self.count(len + 1)?;
        let index = self.indices::<4>(r)?;
        let fine = self.take(r * len)?.to_vec();
        let diff = self.take(r * diff_len)?.to_vec();
        let uv = if with_uv {
            self.take(r)?.to_vec()
        } else {
            Vec::new()
        };
        let to32 = |v: Vec<f64>| v.into_iter().map(|x| x as f32).collect::<Vec<f32>>();
        if single {
            return Some(Rows {
                index,
                uv,
                single: (to32(fine), to32(diff)),
                ..Rows::default()
            });
        }
        (diff_len == len).then_some(Rows {
            index,
            fine,
            diff,
            uv,
            single: (Vec::new(), Vec::new()),
        })
    }

    /// One triangle's side, orientations and tensors on `m` templates with `no` orientations.
    pub(super) fn triangle(
        &mut self,
        m: usize,
        no: usize,
    ) -> Option<(usize, Orientations, TriangleTensors)> {
        let side = self.count(3)?;
        let o = self.take(6 * no)?;
        let los = o.chunks_exact(6).map(|c| [c[0], c[1], c[2]]).collect();
        let weights = o.chunks_exact(6).map(|c| [c[3], c[4], c[5]]).collect();
        let sides = self.take(3 * m)?.to_vec();
        let sigma = [self.take(m)?.to_vec(), self.take(m)?.to_vec()];
        let t = TriangleTensors {
            sides,
            sigma,
            b222: self.rows(m * (m + 1) * (m + 2) / 6, false)?,
            b321: self.rows(m * (m + 1) / 2, false)?,
            j: self.rows(m, true)?,
            l: self.rows(m, true)?,
            tree: self.rows(1, false)?,
            tree_o: self.rows(1, false)?,
        };
        Some((side, (los, weights), t))
    }
}

/// Appends one triangle's side, orientations and tensors (the layout of the module docs).
pub(super) fn write_triangle(
    side: usize,
    (los, weights): &Orientations,
    t: &TriangleTensors,
    m: usize,
    out: &mut Vec<f64>,
) {
    out.push(side as f64);
    for (n, w) in los.iter().zip(weights) {
        out.extend(n.iter().chain(w));
    }
    out.extend(t.sides.iter().chain(&t.sigma[0]).chain(&t.sigma[1]));
    write_rows(&t.b222, m * (m + 1) * (m + 2) / 6, out);
    write_rows(&t.b321, m * (m + 1) / 2, out);
    write_rows(&t.j, m, out);
    write_rows(&t.l, m, out);
    write_rows(&t.tree, 1, out);
    write_rows(&t.tree_o, 1, out);
}
