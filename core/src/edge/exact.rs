//! Exact signs of sums of products of floating-point numbers, by Shewchuk's
//! expansion arithmetic ("Adaptive Precision Floating-Point Arithmetic and Fast
//! Robust Geometric Predicates", 1997): a value is kept as a sum of f64
//! components that do not overlap, and every operation is exact.
//!
//! The 3D edge functions use it where their f32 value is within its certified
//! error of zero ([`super::Triangle3D`]): there the exact sign decides, and an
//! exact zero goes to the tie rule — so samples on shared vertices are decided
//! consistently, which no rounding-affected evaluation guarantees.

/// `a + b` as `(sum, error)` with `sum + error = a + b` exactly (Knuth's TwoSum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

/// Splits `a` into two halves of 26 bits (Dekker/Veltkamp).
#[inline]
fn split(a: f64) -> (f64, f64) {
    const SPLITTER: f64 = 134_217_729.0; // 2^27 + 1
    let c = SPLITTER * a;
    let hi = c - (c - a);
    (hi, a - hi)
}

/// `a · b` as `(product, error)` with `product + error = a · b` exactly
/// (Dekker's TwoProduct; no fused multiply-add needed).
#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    let err = ((p - ah * bh) - al * bh) - ah * bl;
    (p, al * bl - err)
}

/// An exact value: the sum of non-overlapping components, smallest first,
/// no zeros.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expansion(Vec<f64>);

impl Expansion {
    /// The exact value of one f64.
    pub fn of(v: f64) -> Expansion {
        Expansion(if v == 0.0 { Vec::new() } else { vec![v] })
    }

    /// The exact product of two f64.
    pub fn product(a: f64, b: f64) -> Expansion {
        let (p, e) = two_product(a, b);
        Expansion(e_then(e, p))
    }

    /// Adds one f64 exactly (Shewchuk's GROW-EXPANSION with zero elimination).
    pub fn grow(&self, b: f64) -> Expansion {
        let mut out = Vec::with_capacity(self.0.len() + 1);
        let mut q = b;
        for &e in &self.0 {
            let (s, h) = two_sum(q, e);
            if h != 0.0 {
                out.push(h);
            }
            q = s;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion(out)
    }

    /// The exact sum.
    pub fn add(&self, other: &Expansion) -> Expansion {
        other.0.iter().fold(self.clone(), |acc, &b| acc.grow(b))
    }

    /// The exact difference.
    pub fn sub(&self, other: &Expansion) -> Expansion {
        other.0.iter().fold(self.clone(), |acc, &b| acc.grow(-b))
    }

    /// The exact product with one f64 (SCALE-EXPANSION).
    pub fn scale(&self, b: f64) -> Expansion {
        let mut out = Expansion::default();
        for &e in &self.0 {
            let (p, err) = two_product(e, b);
            out = out.grow(err).grow(p);
        }
        out
    }

    /// The exact product.
    pub fn mul(&self, other: &Expansion) -> Expansion {
        other
            .0
            .iter()
            .fold(Expansion::default(), |acc, &b| acc.add(&self.scale(b)))
    }

    /// The value rounded to about an f64 (the components' sum).
    #[cfg(test)]
    pub fn approximate(&self) -> f64 {
        self.0.iter().sum()
    }

    /// The sign of the exact value: −1, 0 or 1.
    pub fn signum(&self) -> i32 {
        match self.0.last() {
            None => 0,
            Some(&v) if v > 0.0 => 1,
            Some(_) => -1,
        }
    }
}

/// `[e, p]` without zeros (the two parts of a TwoProduct, smallest first).
fn e_then(e: f64, p: f64) -> Vec<f64> {
    [e, p].into_iter().filter(|&v| v != 0.0).collect()
}

/// An exact 3-vector.
pub type Vector = [Expansion; 3];

/// The exact vector of three f64.
pub fn vector(v: [f64; 3]) -> Vector {
    v.map(Expansion::of)
}

/// The exact cross product of two vectors of f64.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> Vector {
    let component =
        |i: usize, j: usize| Expansion::product(a[i], b[j]).sub(&Expansion::product(a[j], b[i]));
    [component(1, 2), component(2, 0), component(0, 1)]
}

/// The exact cross product of two exact vectors.
pub fn cross_exact(a: &Vector, b: &Vector) -> Vector {
    let component = |i: usize, j: usize| a[i].mul(&b[j]).sub(&a[j].mul(&b[i]));
    [component(1, 2), component(2, 0), component(0, 1)]
}

/// The exact difference of two vectors of f64.
pub fn difference(a: [f64; 3], b: [f64; 3]) -> Vector {
    std::array::from_fn(|k| Expansion::of(a[k]).sub(&Expansion::of(b[k])))
}

/// The exact dot product of an exact vector with one of f64.
pub fn dot(a: &Vector, b: [f64; 3]) -> Expansion {
    a[0].scale(b[0])
        .add(&a[1].scale(b[1]))
        .add(&a[2].scale(b[2]))
}

/// The exact dot product of two exact vectors.
pub fn dot_exact(a: &Vector, b: &Vector) -> Expansion {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// `base + x·dx + y·dy`, exactly, per component.
pub fn affine(base: [f64; 3], x: f64, dx: [f64; 3], y: f64, dy: [f64; 3]) -> Vector {
    std::array::from_fn(|k| {
        Expansion::of(base[k])
            .add(&Expansion::product(x, dx[k]))
            .add(&Expansion::product(y, dy[k]))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_and_sums_are_exact() {
        // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60: not representable in one f64.
        let a = 1.0 + 2f64.powi(-30);
        let sq = Expansion::product(a, a);
        let rest = sq.grow(-1.0).grow(-(2f64.powi(-29)));
        assert_eq!(rest, Expansion::of(2f64.powi(-60)));
        assert_eq!(rest.signum(), 1);
        // A sum that cancels to exactly zero.
        let z = Expansion::of(1e30).grow(1.0).grow(-1e30).grow(-1.0);
        assert_eq!(z.signum(), 0);
        let tiny = Expansion::of(1e30).grow(1e-30).grow(-1e30);
        assert_eq!(tiny.signum(), 1);
    }

    #[test]
    fn determinant_signs_match_a_rational_evaluation() {
        // det[a, b, c] of small integers: exact in any arithmetic.
        let mut rng = fastrand::Rng::with_seed(3);
        for _ in 0..2000 {
            let v = |rng: &mut fastrand::Rng| [0, 1, 2].map(|_| f64::from(rng.i32(-20..20)));
            let (a, b, c) = (v(&mut rng), v(&mut rng), v(&mut rng));
            let exact = dot(&cross(a, b), c).signum();
            let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            assert_eq!(exact, det.signum() as i32 * i32::from(det != 0.0));
        }
    }

    #[test]
    fn nearly_parallel_vectors_get_the_exact_sign() {
        // b = a + tiny: a × b·c is dominated by rounding in plain f64.
        let a = [0.1f32, 0.7, 0.3].map(f64::from);
        let b = [0.1f32, 0.7, 0.300_000_04].map(f64::from);
        let c = [0.2f32, 1.4, 0.6].map(f64::from); // c = 2a
        assert_eq!(dot(&cross(a, b), c).signum(), 0);
    }
}
