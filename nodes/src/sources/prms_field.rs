//! Arithmetic in GF(q)\[x\] for the maximum-length q-level generator of
//! [`super::prms`]: the search for a primitive polynomial of a degree and the
//! linear recurrence it defines.
//!
//! # Convention
//!
//! A monic polynomial p(x) = xⁿ + c₁xⁿ⁻¹ + … + cₙ over GF(q) (q prime) is
//! stored as its coefficients `[c₁, …, cₙ]`. It defines the recurrence
//!
//! ```text
//! s[k] = −(c₁ s[k−1] + c₂ s[k−2] + … + cₙ s[k−n])   (mod q)
//! ```
//!
//! whose nonzero solutions have the maximal period qⁿ − 1 exactly when p is
//! primitive, i.e. when x has multiplicative order qⁿ − 1 modulo p (then
//! every nonzero residue is a power of x, the residues form a field, and p is
//! irreducible as well). That is the test [`is_primitive`] applies: xᴺ = 1
//! for N = qⁿ − 1 and x^(N/r) ≠ 1 for every prime r dividing N
//! (Lidl & Niederreiter, *Finite Fields*, Thm. 3.16 and §3.1).
//!
//! [`primitive`] returns the first primitive polynomial of degree n in the
//! lexicographic order of `[c₁, …, cₙ]` (so the generator is the same on
//! every machine); the tests of [`super::prms`] walk whole periods and check
//! the smallest cases against published tables.

/// The primes q the generator accepts.
pub const PRIMES: [u32; 6] = [2, 3, 5, 7, 11, 13];

/// Largest period qⁿ − 1 the generator accepts (a period counts in `u64`
/// with room to spare; longer ones are of no use at any real sample rate).
pub const MAX_PERIOD: u64 = 1 << 40;

/// qⁿ − 1, or `None` past [`MAX_PERIOD`].
pub fn period(q: u32, n: u32) -> Option<u64> {
    let mut p: u64 = 1;
    for _ in 0..n {
        p = p.checked_mul(u64::from(q))?;
    }
    let p = p - 1;
    (p <= MAX_PERIOD).then_some(p)
}

/// The distinct prime factors of `n` (trial division; n ≤ 2⁴⁰ here).
fn prime_factors(mut n: u64) -> Vec<u64> {
    let mut f = Vec::new();
    let mut d = 2;
    while d * d <= n {
        if n.is_multiple_of(d) {
            f.push(d);
            while n.is_multiple_of(d) {
                n /= d;
            }
        }
        d += 1;
    }
    if n > 1 {
        f.push(n);
    }
    f
}

/// a·b mod p for residues of degree < n (coefficients lowest first).
fn mul_mod(a: &[u32], b: &[u32], c: &[u32], q: u32) -> Vec<u32> {
    let n = c.len();
    let mut prod = vec![0u64; 2 * n];
    for (i, &ai) in a.iter().enumerate() {
        for (j, &bj) in b.iter().enumerate() {
            prod[i + j] = (prod[i + j] + u64::from(ai) * u64::from(bj)) % u64::from(q);
        }
    }
    // Reduce with xⁿ = −(c₁xⁿ⁻¹ + … + cₙ).
    for d in (n..2 * n).rev() {
        let t = prod[d];
        if t == 0 {
            continue;
        }
        prod[d] = 0;
        for (i, &ci) in c.iter().enumerate() {
            // c_{i+1} multiplies x^{n−1−i}.
            let k = d - 1 - i;
            let sub = t * u64::from(ci) % u64::from(q);
            prod[k] = (prod[k] + u64::from(q) - sub) % u64::from(q);
        }
    }
    prod.truncate(n);
    prod.into_iter().map(|v| v as u32).collect()
}

/// xᵉ mod p.
fn x_pow(e: u64, c: &[u32], q: u32) -> Vec<u32> {
    let n = c.len();
    let mut result = vec![0u32; n];
    result[0] = 1;
    let mut base = vec![0u32; n];
    if n == 1 {
        // x ≡ −c₁ (mod x + c₁).
        base[0] = (q - c[0] % q) % q;
    } else {
        base[1] = 1;
    }
    let mut e = e;
    while e > 0 {
        if e & 1 == 1 {
            result = mul_mod(&result, &base, c, q);
        }
        base = mul_mod(&base, &base, c, q);
        e >>= 1;
    }
    result
}

fn is_one(r: &[u32]) -> bool {
    r[0] == 1 && r[1..].iter().all(|&v| v == 0)
}

/// Whether xⁿ + c₁xⁿ⁻¹ + … + cₙ is primitive over GF(q).
pub fn is_primitive(c: &[u32], q: u32) -> bool {
    let n = c.len() as u32;
    if n == 0 || c[c.len() - 1] == 0 {
        return false;
    }
    let Some(order) = period(q, n) else { return false };
    if !is_one(&x_pow(order, c, q)) {
        return false;
    }
    prime_factors(order).into_iter().all(|r| !is_one(&x_pow(order / r, c, q)))
}

/// The first primitive polynomial of degree `n` over GF(`q`) in lexicographic
/// order of `[c₁, …, cₙ]`, or `None` if q is not one of [`PRIMES`], n is 0
/// or the period qⁿ − 1 exceeds [`MAX_PERIOD`].
pub fn primitive(q: u32, n: u32) -> Option<Vec<u32>> {
    if !PRIMES.contains(&q) || n == 0 {
        return None;
    }
    period(q, n)?;
    let mut c = vec![0u32; n as usize];
    loop {
        if is_primitive(&c, q) {
            return Some(c);
        }
        // Next coefficient vector, last coefficient fastest.
        let mut i = c.len();
        loop {
            if i == 0 {
                return None;
            }
            i -= 1;
            c[i] += 1;
            if c[i] < q {
                break;
            }
            c[i] = 0;
        }
    }
}

/// The recurrence's state: the last n symbols, oldest first, and the taps.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Recurrence {
    q: u32,
    /// −cᵢ mod q, matched to `window` (oldest first: −cₙ … −c₁).
    neg_taps: Vec<u32>,
    window: Vec<u32>,
}

impl Recurrence {
    /// The recurrence of p, started with every one of its n symbols at 1
    /// (any nonzero start gives a shift of the same sequence).
    pub fn new(c: &[u32], q: u32) -> Self {
        let neg_taps = c.iter().rev().map(|&ci| (q - ci % q) % q).collect();
        Self { q, neg_taps, window: vec![1; c.len()] }
    }

    /// The symbol that leaves the window (the sequence's next element); the
    /// recurrence's new symbol enters it.
    #[inline]
    pub fn step(&mut self) -> u32 {
        let out = self.window[0];
        let mut acc: u64 = 0;
        for (&w, &t) in self.window.iter().zip(&self.neg_taps) {
            acc += u64::from(w) * u64::from(t);
        }
        self.window.rotate_left(1);
        let last = self.window.len() - 1;
        self.window[last] = (acc % u64::from(self.q)) as u32;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periods_count_and_stop_at_the_cap() {
        assert_eq!(period(3, 2), Some(8));
        assert_eq!(period(5, 9), Some(1_953_124));
        assert_eq!(period(2, 40), Some((1 << 40) - 1));
        assert_eq!(period(2, 41), None);
        assert_eq!(period(13, 40), None);
    }

    #[test]
    fn factors_are_the_distinct_primes() {
        assert_eq!(prime_factors(8), vec![2]);
        assert_eq!(prime_factors(1_953_124), vec![2, 19, 31, 829]);
        assert_eq!(prime_factors(97), vec![97]);
    }

    /// Published primitive polynomials (Lidl & Niederreiter, *Finite Fields*,
    /// Table C; Church, *Tables of irreducible polynomials for the first four
    /// prime moduli*, Ann. Math. 1935) are found primitive, and known
    /// reducible or imprimitive ones are not.
    #[test]
    fn known_primitive_and_imprimitive_polynomials() {
        // GF(2): x⁴ + x + 1 primitive; x⁴ + x³ + x² + x + 1 irreducible, order 5.
        assert!(is_primitive(&[0, 0, 1, 1], 2));
        assert!(!is_primitive(&[1, 1, 1, 1], 2));
        // GF(3): x² + x + 2 and x² + 2x + 2 primitive; x² + 1 irreducible, order 4.
        assert!(is_primitive(&[1, 2], 3));
        assert!(is_primitive(&[2, 2], 3));
        assert!(!is_primitive(&[0, 1], 3));
        // GF(3): x³ + 2x + 1 primitive.
        assert!(is_primitive(&[0, 2, 1], 3));
        // GF(5): x² + x + 2 primitive; x² + 2 irreducible but not primitive.
        assert!(is_primitive(&[1, 2], 5));
        assert!(!is_primitive(&[0, 2], 5));
        // GF(7): x + 4 primitive (x ≡ 3, a generator of GF(7)*); x + 5 (x ≡ 2, order 3) not.
        assert!(is_primitive(&[4], 7));
        assert!(!is_primitive(&[5], 7));
        // A zero constant term is never primitive.
        assert!(!is_primitive(&[1, 0], 3));
    }

    #[test]
    fn the_search_finds_the_first_primitive_polynomial() {
        assert_eq!(primitive(3, 2), Some(vec![1, 2]));
        assert_eq!(primitive(2, 4), Some(vec![0, 0, 1, 1]));
        assert_eq!(primitive(4, 2), None, "4 is not prime");
        assert_eq!(primitive(3, 0), None);
        assert_eq!(primitive(13, 20), None, "period past the cap");
        for &q in &PRIMES {
            for n in 1..=6 {
                let c = primitive(q, n).unwrap();
                assert!(is_primitive(&c, q), "q {q} n {n}");
            }
        }
    }
}
