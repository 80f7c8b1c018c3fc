//! Plane projective transforms (homographies) from four point pairs: how a
//! scan or photograph of a flat sheet maps the sheet's millimetres to the
//! image's pixels.

/// A 3×3 projective transform, row-major, `h[8]` = 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homography(pub [f64; 9]);

impl Homography {
    /// The transform taking each `from[i]` to `to[i]`; None when three of
    /// the points are collinear.
    ///
    /// ```
    /// use pixelpie::stipple::calibrate::Homography;
    /// let sq = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
    /// let to = [(10.0, 10.0), (30.0, 12.0), (8.0, 40.0), (33.0, 45.0)];
    /// let h = Homography::from_points(&sq, &to).unwrap();
    /// let (x, y) = h.apply((1.0, 1.0));
    /// assert!((x - 33.0).abs() < 1e-9 && (y - 45.0).abs() < 1e-9);
    /// ```
    #[must_use]
    pub fn from_points(from: &[(f64, f64); 4], to: &[(f64, f64); 4]) -> Option<Self> {
        // 8 unknowns h0..h7: u = (h0 x + h1 y + h2) / (h6 x + h7 y + 1), …
        let mut a = [[0.0f64; 9]; 8];
        for (i, (&(x, y), &(u, v))) in from.iter().zip(to).enumerate() {
            a[2 * i] = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, u];
            a[2 * i + 1] = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, v];
        }
        let h = solve8(a)?;
        Some(Self([h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], 1.0]))
    }

    /// The image of `p`.
    #[must_use]
    pub fn apply(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let h = &self.0;
        let w = h[6] * x + h[7] * y + h[8];
        (
            (h[0] * x + h[1] * y + h[2]) / w,
            (h[3] * x + h[4] * y + h[5]) / w,
        )
    }

    /// The inverse transform; None when singular.
    #[must_use]
    pub fn inverse(&self) -> Option<Self> {
        let m = &self.0;
        let c = [
            m[4] * m[8] - m[5] * m[7],
            m[2] * m[7] - m[1] * m[8],
            m[1] * m[5] - m[2] * m[4],
            m[5] * m[6] - m[3] * m[8],
            m[0] * m[8] - m[2] * m[6],
            m[2] * m[3] - m[0] * m[5],
            m[3] * m[7] - m[4] * m[6],
            m[1] * m[6] - m[0] * m[7],
            m[0] * m[4] - m[1] * m[3],
        ];
        let det = m[0] * c[0] + m[1] * c[3] + m[2] * c[6];
        if det.abs() < 1e-300 || !det.is_finite() {
            return None;
        }
        let s = c[8];
        if s.abs() < 1e-300 {
            return None;
        }
        Some(Self(c.map(|v| v / s)))
    }
}

/// Solves an 8×8 system given as rows [a | b] by Gaussian elimination with
/// partial pivoting.
fn solve8(mut a: [[f64; 9]; 8]) -> Option<[f64; 8]> {
    for col in 0..8 {
        let piv = (col..8).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, piv);
        let pivot = a[col];
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / pivot[col];
                for (v, p) in row.iter_mut().zip(pivot).skip(col) {
                    *v -= f * p;
                }
            }
        }
    }
    Some(std::array::from_fn(|i| a[i][8] / a[i][i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_undoes_the_transform() {
        let from = [(0.0, 0.0), (210.0, 0.0), (0.0, 297.0), (210.0, 297.0)];
        let to = [
            (31.0, 22.0),
            (1710.0, 80.0),
            (-12.0, 2411.0),
            (1650.0, 2390.0),
        ];
        let h = Homography::from_points(&from, &to).unwrap();
        let inv = h.inverse().unwrap();
        for p in [(5.0, 7.0), (100.0, 200.0), (209.0, 1.0)] {
            let q = inv.apply(h.apply(p));
            assert!(
                (q.0 - p.0).abs() < 1e-6 && (q.1 - p.1).abs() < 1e-6,
                "{q:?}"
            );
        }
        let line = [(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0)];
        assert!(Homography::from_points(&line, &to).is_none());
    }
}
